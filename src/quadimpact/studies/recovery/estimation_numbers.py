"""The estimation part of a recovery study: the estimate's errors and the time to hover.

Pure functions of the trials table (its ``est_*`` columns, ``time_to_hover_s``;
docs/RESULTS.md): :func:`estimation_numbers` for the report's numbers,
:func:`estimation_lines` for its section.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd

__all__ = ["PHASE_TEXT", "estimation_lines", "estimation_numbers"]

PHASE_TEXT = {
    "pre": "before the first contact",
    "crash": "the crash (first contact to stage 4, or the end)",
    "post": "after stage 4",
}
_QUANTITIES = (
    ("attitude", "deg", "attitude error", "°", 2),
    ("velocity", "m_s", "velocity error", "m/s", 3),
    ("bias", "rad_s", "gyro-bias error", "rad/s", 4),
    ("position", "m", "position error", "m", 3),
)


def _q(values: pd.Series) -> dict[str, float]:
    v = values.to_numpy(dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return {"n": 0, "median": math.nan, "p90": math.nan}
    return {"n": int(v.size), "median": float(np.median(v)), "p90": float(np.quantile(v, 0.9))}


def estimation_numbers(table: pd.DataFrame) -> dict[str, Any]:
    """Median and 90th percentile over the trials of each error's per-trial RMS, by phase.

    Also the time to hover (median, p90 over the trials that reached it) and
    the share of trials that reached it. Empty when the table has no
    estimation columns (an older study).
    """
    if "est_attitude_rms_crash_deg" not in table:
        return {}
    out: dict[str, Any] = {"estimator": _values(table, "estimator"),
                           "sensors": _values(table, "sensors")}  # fmt: skip
    for q, unit, *_ in _QUANTITIES:
        for phase in PHASE_TEXT:
            out[f"{q}_{phase}"] = _q(table[f"est_{q}_rms_{phase}_{unit}"])
    hover = table["time_to_hover_s"] if "time_to_hover_s" in table else pd.Series(dtype=float)
    out["time_to_hover_s"] = _q(hover)
    out["hover_share"] = (
        float(np.isfinite(hover.to_numpy(dtype=float)).mean()) if len(hover) else 0.0
    )
    return out


def _values(table: pd.DataFrame, column: str) -> list[Any]:
    if column not in table:
        return []
    return [v for v in pd.unique(table[column]) if v is not None and v == v]


def _cell(x: dict[str, float], digits: int) -> str:
    if not x["n"]:
        return "–"
    return f"{x['median']:.{digits}f} / {x['p90']:.{digits}f}"


def estimation_lines(numbers: dict[str, Any]) -> list[str]:
    """The report's estimation section (Markdown lines; none without the numbers)."""
    e = numbers.get("estimation") or {}
    if not e:
        return []
    est = ", ".join(str(v) for v in e["estimator"]) or "ideal"
    sensors = ", ".join(str(v) for v in e["sensors"]) or "the IMU preset"
    lines = [
        "## Estimation",
        "",
        f"Estimator: {est}; sensors: {sensors}. "
        "Each trial's error RMS in each phase, then the median / 90th percentile over "
        "the trials (docs/ESTIMATION.md 4). The ideal estimator reads the true state (its "
        "errors are zero but for the gyro bias, which it does not correct).",
        "",
        "| error | " + " | ".join(PHASE_TEXT.values()) + " |",
        "|---|" + "---|" * len(PHASE_TEXT),
    ]
    for q, _, label, unit, digits in _QUANTITIES:
        cells = [_cell(e[f"{q}_{phase}"], digits) for phase in PHASE_TEXT]
        lines.append(f"| {label} ({unit}) | " + " | ".join(cells) + " |")
    th = e["time_to_hover_s"]
    lines += [
        "",
        f"Time to hover (detection to speed < 0.2 m/s and tilt < 5° held for 0.5 s): reached in "
        f"{100 * e['hover_share']:.1f} % of the trials; median {th['median']:.3f} s, "
        f"p90 {th['p90']:.3f} s"
        if th["n"]
        else "Time to hover: no trial reached hover (speed < 0.2 m/s, tilt < 5° for 0.5 s).",
        "",
        "Without a pose sensor the velocity and position estimates come from integrating the "
        "accelerometer: they drift, and stage 5 holds a drifting position estimate.",
        "",
    ]
    return lines
