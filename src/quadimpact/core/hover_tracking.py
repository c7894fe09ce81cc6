"""Hover tests on the true state: the time to hover, and the held hover of suite 2.

``time_to_hover_s`` (docs/RECOVERY.md) is measured from the detection to the
first control tick from which, for :data:`HOVER_HOLD_S`, the true CM speed
stays below :data:`HOVER_SPEED_M_S` and the tilt of the body z axis from
vertical below :data:`HOVER_TILT_DEG`, tested at every control tick
(5 ms resolution) on the true state. The loop keeps the first tick of the
current run of the condition (``HV_HOVER_RUN_T``) and the first tick of the
first run that lasted long enough (``HV_T_HOVER``), in ``stats[ST_HOVER:]``.

The **held hover** (:func:`track_held_hover`, the benchmark's success from
suite 2 on, docs/BENCHMARK.md 1) adds two conditions and starts elsewhere:
the body rate below :data:`HELD_RATE_RAD_S`, and no contact open (a hover touches
nothing); it is tested from the first contact
with an obstacle (``ST_ONSET_T``) on, whatever the controller declares or
detects. The loop keeps the first tick of its first run that lasted
:data:`HOVER_HOLD_S` (``HH_T_HELD``) and the CM position there (``HH_HELD_X``),
in ``stats[ST_HELD:]``. The slots of both are declared in ``core/hover_slots.py``
(no compiled code), which ``core/layout.py`` reads their sizes from.
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.contact_slots import CS_ACTIVE
from quadimpact.core.hover_slots import (
    HH_HELD_RUN_T,
    HH_HELD_RUN_X,
    HH_HELD_X,
    HH_T_HELD,
    HV_HOVER_RUN_T,
    HV_T_HOVER,
)
from quadimpact.core.layout import (
    ST_HELD,
    ST_HOVER,
    ST_ONSET_T,
    ST_T_DETECT,
    X_OMEGA,
    X_POS,
    X_QUAT,
    X_VEL,
)

HOVER_SPEED_M_S = 0.2
HOVER_TILT_DEG = 5.0
HOVER_HOLD_S = 0.5
#: The held hover's body-rate bound, rad/s: 20 deg/s, PX4's land detector's bound on the
#: rotation of a vehicle at rest (``LNDMC_ROT_MAX``); a hover is "not turning".
HELD_RATE_RAD_S = math.radians(20.0)
_COS_TILT = math.cos(math.radians(HOVER_TILT_DEG))


@compiled(inline="always")
def _slow_and_level(x: np.ndarray) -> bool:
    """Whether the true state ``x`` is slow (CM speed) and level (tilt of the body z axis)."""
    q1 = x[X_QUAT + 1]
    q2 = x[X_QUAT + 2]
    n2 = x[X_QUAT] ** 2 + q1 * q1 + q2 * q2 + x[X_QUAT + 3] ** 2
    level = 1.0 - 2.0 * (q1 * q1 + q2 * q2) / n2 > _COS_TILT
    speed = math.sqrt(x[X_VEL] ** 2 + x[X_VEL + 1] ** 2 + x[X_VEL + 2] ** 2)
    return level and speed < HOVER_SPEED_M_S


@compiled
def start_hover_tracking(stats: np.ndarray) -> None:
    """Start both hover tests of a run: no run of either condition, no hover yet (NaN)."""
    stats[ST_HOVER + HV_HOVER_RUN_T] = np.nan
    stats[ST_HOVER + HV_T_HOVER] = np.nan
    stats[ST_HELD + HH_HELD_RUN_T] = np.nan
    stats[ST_HELD + HH_T_HELD] = np.nan


@compiled
def track_hover(t: float, x: np.ndarray, stats: np.ndarray) -> None:
    """The hover condition at the tick ``t`` (s) of the true state ``x`` (after a detection)."""
    if np.isnan(stats[ST_T_DETECT]) or not np.isnan(stats[ST_HOVER + HV_T_HOVER]):
        return
    if not _slow_and_level(x):
        stats[ST_HOVER + HV_HOVER_RUN_T] = np.nan
        return
    if np.isnan(stats[ST_HOVER + HV_HOVER_RUN_T]):
        stats[ST_HOVER + HV_HOVER_RUN_T] = t
    if t - stats[ST_HOVER + HV_HOVER_RUN_T] >= HOVER_HOLD_S - 1e-9:
        stats[ST_HOVER + HV_T_HOVER] = stats[ST_HOVER + HV_HOVER_RUN_T]


@compiled
def _touching(cs: np.ndarray) -> bool:
    """Whether any pair (a feature and a shape, the ground included) is in a contact episode."""
    for c in range(cs.shape[0]):
        if cs[c, CS_ACTIVE] >= 0.5:
            return True
    return False


@compiled
def track_held_hover(t: float, x: np.ndarray, cs: np.ndarray, stats: np.ndarray) -> None:
    """The held-hover condition at the tick ``t`` (s) of the true state ``x``.

    Tested from the first contact with an obstacle on: slow, level, the body
    rate below :data:`HELD_RATE_RAD_S` and no contact open (``cs``: the pairs'
    contact state): a hover touches nothing.
    """
    if np.isnan(stats[ST_ONSET_T]) or not np.isnan(stats[ST_HELD + HH_T_HELD]):
        return
    rate = math.sqrt(x[X_OMEGA] ** 2 + x[X_OMEGA + 1] ** 2 + x[X_OMEGA + 2] ** 2)
    if not (_slow_and_level(x) and rate < HELD_RATE_RAD_S) or _touching(cs):
        stats[ST_HELD + HH_HELD_RUN_T] = np.nan
        return
    if np.isnan(stats[ST_HELD + HH_HELD_RUN_T]):
        stats[ST_HELD + HH_HELD_RUN_T] = t
        for i in range(3):
            stats[ST_HELD + HH_HELD_RUN_X + i] = x[X_POS + i]
    if t - stats[ST_HELD + HH_HELD_RUN_T] >= HOVER_HOLD_S - 1e-9:
        stats[ST_HELD + HH_T_HELD] = stats[ST_HELD + HH_HELD_RUN_T]
        for i in range(3):
            stats[ST_HELD + HH_HELD_X + i] = stats[ST_HELD + HH_HELD_RUN_X + i]
