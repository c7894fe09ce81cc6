"""A crash's simulated run against its flight log (where the log is available)."""

from __future__ import annotations

import math
from pathlib import Path

from quadimpact.experiments.compare import compare
from quadimpact.experiments.crashes import Crash
from quadimpact.experiments.logs import FlightLog
from quadimpact.results.result import SimulationResult

COMPARE_PNG = "compare.png"
COMPARE_CSV = "compare.csv"


def attitude_rms_for_crash(
    crash: Crash, result: SimulationResult, log: FlightLog | None, folder: Path
) -> float:
    """RMS attitude error (deg) over the first 0.3 s after impact, NaN without the log.

    The error is the angle of the rotation between the simulated and the logged
    attitude (free of the Euler angles' singularity near 90 deg of pitch). The
    comparison table and plot are written into ``folder``. The scenarios fly
    rear first as the real vehicle did, so the log is read in its own frame.
    """
    if log is None:
        return math.nan
    comparison = compare(result, log)
    folder.mkdir(parents=True, exist_ok=True)
    comparison.table().to_csv(folder / COMPARE_CSV, index=False)
    comparison.plot(folder / COMPARE_PNG, title=f"Crash {crash.number}: simulation vs log")
    return comparison.error("attitude", 0.3, "rotation")
