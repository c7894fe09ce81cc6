"""The time to hover: when a run, after the detection, is slow and level for long enough.

``time_to_hover_s`` (docs/RECOVERY.md) is measured from the detection to the
first control tick from which, for :data:`HOVER_HOLD_S`, the true CM speed
stays below :data:`HOVER_SPEED_M_S` and the tilt of the body z axis from
vertical below :data:`HOVER_TILT_DEG`, tested at every control tick
(5 ms resolution) on the true state. The loop keeps the first tick of the
current run of the condition (``ST_HOVER_RUN_T``) and the first tick of the
first run that lasted long enough (``ST_T_HOVER``).
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import ST_HOVER_RUN_T, ST_T_DETECT, ST_T_HOVER, X_QUAT, X_VEL

HOVER_SPEED_M_S = 0.2
HOVER_TILT_DEG = 5.0
HOVER_HOLD_S = 0.5
_COS_TILT = math.cos(math.radians(HOVER_TILT_DEG))


@compiled
def track_hover(t: float, x: np.ndarray, stats: np.ndarray) -> None:
    """The hover condition at the tick ``t`` (s) of the true state ``x`` (after a detection)."""
    if np.isnan(stats[ST_T_DETECT]) or not np.isnan(stats[ST_T_HOVER]):
        return
    q1 = x[X_QUAT + 1]
    q2 = x[X_QUAT + 2]
    n2 = x[X_QUAT] ** 2 + q1 * q1 + q2 * q2 + x[X_QUAT + 3] ** 2
    level = 1.0 - 2.0 * (q1 * q1 + q2 * q2) / n2 > _COS_TILT
    speed = math.sqrt(x[X_VEL] ** 2 + x[X_VEL + 1] ** 2 + x[X_VEL + 2] ** 2)
    if not (level and speed < HOVER_SPEED_M_S):
        stats[ST_HOVER_RUN_T] = np.nan
        return
    if np.isnan(stats[ST_HOVER_RUN_T]):
        stats[ST_HOVER_RUN_T] = t
    if t - stats[ST_HOVER_RUN_T] >= HOVER_HOLD_S - 1e-9:
        stats[ST_T_HOVER] = stats[ST_HOVER_RUN_T]
