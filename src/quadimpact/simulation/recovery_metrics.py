"""Detection and recovery metrics of a run (docs/RECOVERY.md section 6).

Pure functions of the kernel's stats (detection, stage entries, extremes)
and the episodes table, so they can be tested on hand-made inputs. Times are
in seconds of simulated time (an impact trial starts at 0); a stage's time is
the control tick at which the run entered it (the authors' tables give the
end of that 5-ms interval, tick + 5 ms). Distances in m, inertial NED
(altitude ``h = -Z``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import fields
from typing import Any

import numpy as np

from quadimpact.core import layout as L
from quadimpact.core.geometry import contact_record
from quadimpact.core.hover_slots import HH_HELD_X, HH_T_HELD, HV_T_HOVER
from quadimpact.linalg import dot, norm
from quadimpact.results.summary_record import RecoveryPart
from quadimpact.rotations import quat_to_matrix
from quadimpact.simulation.metrics import (
    GRAZE_IMPULSE_FRACTION,
    RunImpacts,
    Table,
    episode_lists,
    impacts_of_table,
    n_rows,
)

__all__ = [
    "RECOVERY_KEYS",
    "contact_normal",
    "first_contact_normal",
    "onset_normal",
    "recovery_metrics",
]

RECOVERED_STAGE = 4

#: The fields of the summary's recovery part that the scenario or the run's end do not set
#: (:class:`quadimpact.results.summary_record.RecoveryPart`, where each is declared).
_SET_ELSEWHERE = (
    "pre_impact",
    "detection_threshold_m_s2",
    "final_altitude_m",
    "first_contact_bumper",
    "first_contact_normal",
)
RECOVERY_KEYS: tuple[str, ...] = tuple(
    f.name for f in fields(RecoveryPart) if f.name not in _SET_ELSEWHERE
)
"""The metric keys, in summary order."""


def _finite(v: float) -> float | None:
    return None if v is None or not math.isfinite(v) else float(v)


def contact_normal(
    x: np.ndarray,
    feat: np.ndarray,
    shapes: np.ndarray,
    feature: int,
    shape: int,
    C: np.ndarray | None = None,
) -> np.ndarray:
    """The contact normal (inertial, unit, out of the obstacle) of a feature-shape pair at ``x``.

    From the compiled contact geometry, whatever the kinds (``core.geometry``).
    ``C``: ``quat_to_matrix`` of ``x``'s quaternion, when the caller has it.
    """
    xq = np.ascontiguousarray(x, dtype=float)
    if C is None:
        C = quat_to_matrix(xq[L.X_QUAT : L.X_QUAT + 4])
    C = np.ascontiguousarray(C)
    rec = contact_record(xq, C, feat, shapes, int(feature), int(shape))
    return np.array(rec[8:11])


def first_obstacle_episode(
    episodes: Table, obstacle_names: Sequence[str]
) -> tuple[int, str] | None:
    """(bumper 1-4, surface name) of the first contact with an obstacle (not the ground)."""
    if n_rows(episodes) == 0:
        return None
    cols = episode_lists(episodes, ("bumper", "surface", "t_start_s"))
    names = set(obstacle_names)
    rows = [k for k, s in enumerate(cols["surface"]) if s in names]
    if not rows:
        return None
    start, bumper = cols["t_start_s"], cols["bumper"]
    first = min(rows, key=lambda k: (start[k], bumper[k]))  # ties: the first row
    return bumper[first], cols["surface"][first]


def first_contact_normal(
    st: np.ndarray,
    episodes: Table,
    feat: np.ndarray,
    shapes: np.ndarray,
    surface_names: Sequence[str],
    obstacle_names: Sequence[str],
) -> tuple[int, np.ndarray] | None:
    """The first contact with an obstacle: its bumper and the contact normal at the onset.

    Returns
    -------
    (int, numpy.ndarray (3,)) or None
        The bumper (feature, 1-based) and the contact normal (inertial NED,
        unit, out of the obstacle) at the state of the first onset
        (``ST_ONSET_X``); None when the run touched no obstacle.
    """
    return onset_normal(st, first_obstacle_episode(episodes, obstacle_names), feat, shapes,
                        surface_names)  # fmt: skip


def onset_normal(
    st: np.ndarray,
    first: tuple[int, str] | None,
    feat: np.ndarray,
    shapes: np.ndarray,
    surface_names: Sequence[str],
    C: np.ndarray | None = None,
) -> tuple[int, np.ndarray] | None:
    """:func:`first_contact_normal` given the first obstacle episode (bumper, surface) or None.

    ``C``: the attitude matrix at the onset, when the caller has it.
    """
    if first is None:
        return None
    bumper, surface = first
    s_index = list(surface_names).index(surface)
    x_onset = st[L.ST_ONSET_X : L.ST_ONSET_X + L.NX]
    return bumper, contact_normal(x_onset, feat, shapes, bumper - 1, s_index, C)


def recovery_metrics(
    st: np.ndarray,
    episodes: Table | None,
    *,
    feat: np.ndarray,
    shapes: np.ndarray,
    surface_names: Sequence[str],
    obstacle_names: Sequence[str],
    final_state: np.ndarray,
    first_obstacle_contact: tuple[int, np.ndarray] | None | str = "find",
    impacts: RunImpacts | None = None,
) -> dict[str, Any]:
    """The metrics of docs/RECOVERY.md section 6 from a run's record.

    Parameters
    ----------
    st : numpy.ndarray (NSTAT,)
        The kernel's stats (layout ``ST_*``).
    episodes : table or None
        The episodes (``simulation.record.episodes_frame`` or
        ``episode_columns``); not read (None) when ``first_obstacle_contact``
        and ``impacts`` are given.
    feat, shapes : numpy.ndarray
        The packed contact features and shapes (for the true contact normal).
    surface_names : sequence of str
        Names of the packed shapes, in order.
    obstacle_names : sequence of str
        The surfaces that count as obstacles (the ground does not).
    final_state : numpy.ndarray (NX,)
        The state at the end of the run.
    first_obstacle_contact : (int, numpy.ndarray) or None, optional
        The first contact with an obstacle, when the caller has it: (bumper
        1-based, contact normal there, inertial, unit), None where the run
        touched no obstacle; by default found from the episodes and the
        contact geometry (:func:`first_contact_normal`).
    impacts : RunImpacts, optional
        The run's impacts on the obstacles (grazes left out), when the caller
        has them; by default found from the episodes.

    Returns
    -------
    dict
        :data:`RECOVERY_KEYS`; floats are ``None`` where undefined (no
        detection, stage not reached...), booleans and counts always set.
    """
    out = _detection_metrics(st, final_state)
    if not out["detected"]:
        return out
    t_detect = float(st[L.ST_T_DETECT])
    first_contact = float(st[L.ST_ONSET_T])
    if math.isfinite(first_contact) and not out["false_detection"]:
        out["detection_latency_s"] = t_detect - first_contact
        first = first_obstacle_contact
        if isinstance(first, str):
            first = first_contact_normal(st, episodes, feat, shapes, surface_names, obstacle_names)
        out["normal_error_deg"] = _normal_error_deg(st, first)
    out.update(_stage_travel(st))
    if out["recovered"]:
        out["time_to_recover_s"] = float(st[L.ST_STAGE_T + RECOVERED_STAGE]) - t_detect
    t_hover = float(st[L.ST_HOVER + HV_T_HOVER])
    if math.isfinite(t_hover):
        out["time_to_hover_s"] = t_hover - t_detect
    out["max_tilt_deg"] = math.degrees(math.acos(min(max(float(st[L.ST_MIN_TILT_COS]), -1.0), 1.0)))
    out["max_rate_rad_s"] = float(st[L.ST_MAX_RATE])
    out["impacts_after_detection"] = _impacts_after(t_detect, episodes, obstacle_names, impacts)
    return out


def _detection_metrics(st: np.ndarray, final_state: np.ndarray) -> dict[str, Any]:
    """The metrics set whether or not the impact was detected, every other key None: the
    detection (detected, missed, false, how many, its time in s), the lowest altitude (m),
    the final speed (m/s), the time each stage 1-5 was entered (s), whether it recovered,
    and no impact after the detection (counted later where there was one)."""
    t_detect = float(st[L.ST_T_DETECT])
    detected = math.isfinite(t_detect)
    first_contact = float(st[L.ST_ONSET_T])
    contact = math.isfinite(first_contact)
    false_detection = detected and (not contact or t_detect < first_contact)
    out: dict[str, Any] = dict.fromkeys(RECOVERY_KEYS)
    out["detected"] = bool(detected)
    out["not_detected"] = bool(contact and not detected)
    out["false_detection"] = bool(false_detection)
    out["n_detections"] = int(st[L.ST_N_DETECTIONS])
    out["t_detect_s"] = _finite(t_detect)
    out["min_altitude_m"] = _finite(float(st[L.ST_MIN_ALT]))
    v = final_state[L.X_VEL : L.X_VEL + 3]
    out["final_speed_m_s"] = _finite(norm(v))
    stage_t = [float(st[L.ST_STAGE_T + k]) for k in range(L.N_STAGES)]
    for k in (1, 2, 3, 4, 5):
        out[f"t_stage{k}_s"] = _finite(stage_t[k])
    out["recovered"] = bool(math.isfinite(stage_t[RECOVERED_STAGE]))
    out["impacts_after_detection"] = 0
    out.update(held_hover_metrics(st))
    return out


def held_hover_metrics(st: np.ndarray) -> dict[str, Any]:
    """The held hover of the benchmark's suite 2 (``core/hover_tracking.py``) from the stats.

    Returns
    -------
    dict
        ``held_hover`` (bool), ``time_to_held_hover_s`` (s, from the first
        obstacle contact), ``held_hover_distance_m`` (m, horizontal, from the CM
        at the first obstacle contact to the hover point) and
        ``touched_after_hover`` (bool: a contact onset at or after the hover's
        start); the floats None without a held hover.
    """
    t_held = float(st[L.ST_HELD + HH_T_HELD])
    if not math.isfinite(t_held):
        return {"held_hover": False, "time_to_held_hover_s": None,
                "held_hover_distance_m": None, "touched_after_hover": False}  # fmt: skip
    onset = st[L.ST_ONSET_X + L.X_POS : L.ST_ONSET_X + L.X_POS + 2]
    held = st[L.ST_HELD + HH_HELD_X : L.ST_HELD + HH_HELD_X + 2]
    last_onset = float(st[L.ST_LAST_ONSET_T])
    return {
        "held_hover": True,
        "time_to_held_hover_s": t_held - float(st[L.ST_ONSET_T]),
        "held_hover_distance_m": math.hypot(held[0] - onset[0], held[1] - onset[1]),
        "touched_after_hover": bool(math.isfinite(last_onset) and last_onset >= t_held),
    }


def _normal_error_deg(st: np.ndarray, first: tuple[int, np.ndarray] | None) -> float | None:
    """The angle (deg) between the detector's normal estimate and the true normal of the
    first contact with an obstacle (``first``: bumper, normal; inertial); None without a
    contact or an estimate."""
    if first is None:
        return None
    n_true = first[1]
    n_est = st[L.ST_DETECT_NORMAL : L.ST_DETECT_NORMAL + 3]
    if not norm(n_est) > 0:
        return None
    c = min(max(float(dot(n_est, n_true) / norm(n_true)), -1.0), 1.0)
    return math.degrees(math.acos(c))


def _stage_travel(st: np.ndarray) -> dict[str, float]:
    """The height lost (altitude at the detection minus at the entry, m) and the horizontal
    drift (m) from the detection to the entry into stages 2, 3 and 4 (keys
    ``height_loss_stage2_m``... and ``height_loss_m`` for stage 4), those entered."""
    travel: dict[str, float] = {}
    p_detect = st[L.ST_DETECT_X + L.X_POS : L.ST_DETECT_X + L.X_POS + 3]
    for k, name in ((2, "stage2"), (3, "stage3"), (4, None)):
        if not math.isfinite(float(st[L.ST_STAGE_T + k])):
            continue
        p = st[L.ST_STAGE_X + 3 * k : L.ST_STAGE_X + 3 * k + 3]
        loss = -p_detect[2] - (-p[2])  # altitude at detection minus altitude at entry
        drift = math.hypot(p[0] - p_detect[0], p[1] - p_detect[1])
        suffix = f"_{name}" if name else ""
        travel[f"height_loss{suffix}_m"] = float(loss)
        travel[f"horizontal_drift{suffix}_m"] = float(drift)
    return travel


def _impacts_after(
    t_detect: float,
    episodes: Table | None,
    obstacle_names: Sequence[str],
    impacts: RunImpacts | None,
) -> int:
    """The impacts on the obstacles (grazes left out) that start after the detection at
    ``t_detect`` (s): of ``impacts`` when given, else found from the ``episodes``."""
    if impacts is None and n_rows(episodes):
        others = sorted(set(episode_lists(episodes, ("surface",))["surface"]) - set(obstacle_names))
        impacts = impacts_of_table(episodes, others, GRAZE_IMPULSE_FRACTION)
    starts = impacts.start_s if impacts is not None else []
    return sum(1 for t in starts if t > t_detect)
