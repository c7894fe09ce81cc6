"""A crash's simulated run against its flight log (where the log is available)."""

from __future__ import annotations

import math
from pathlib import Path

from quadimpact.experiments.compare import Comparison, compare
from quadimpact.experiments.crashes import Crash
from quadimpact.experiments.logs import FlightLog
from quadimpact.results.result import SimulationResult

COMPARE_PNG = "compare.png"
COMPARE_CSV = "compare.csv"


def compare_crash(
    crash: Crash,
    result: SimulationResult,
    log: FlightLog | None,
    folder: Path,
    title: str = "simulation",
    classify_log: bool = True,
) -> Comparison | None:
    """The run against its log (None without the log); table and plot written into ``folder``.

    The scenarios fly rear first as the real vehicle did, so the log is read
    in its own frame. ``title`` names the run in the plot's title;
    ``classify_log``: also classify the log's own response type.
    """
    if log is None:
        return None
    comparison = compare(result, log, classify_log=classify_log)
    folder.mkdir(parents=True, exist_ok=True)
    comparison.table().to_csv(folder / COMPARE_CSV, index=False)
    comparison.plot(folder / COMPARE_PNG, title=f"Crash {crash.number}: {title} vs log")
    return comparison


def attitude_rms(comparison: Comparison | None) -> float:
    """RMS attitude error (deg) over the first 0.3 s after impact, NaN without the log.

    The error is the angle of the rotation between the simulated and the logged
    attitude (free of the Euler angles' singularity near 90 deg of pitch).
    """
    return math.nan if comparison is None else comparison.error("attitude", 0.3, "rotation")


def position_rms_mm(comparison: Comparison | None) -> float:
    """RMS position error (mm) over the first 0.3 s after impact (X, Y and altitude
    displacements since the impact together), NaN without the log."""
    return math.nan if comparison is None else 1e3 * comparison.error("position", 0.3)


def attitude_rms_for_crash(
    crash: Crash, result: SimulationResult, log: FlightLog | None, folder: Path
) -> float:
    """:func:`attitude_rms` of :func:`compare_crash` (table and plot written into ``folder``)."""
    return attitude_rms(compare_crash(crash, result, log, folder))
