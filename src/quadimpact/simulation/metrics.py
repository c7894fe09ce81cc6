"""Metrics of a run from its tables: impact grouping, initial-impact metrics,
attitude excursion and the response type.

Everything here is a pure function of pandas tables (the episodes and time
series of :mod:`quadimpact.simulation.record`) or plain lists, so it can be
tested on hand-made inputs. Definitions follow STUDIES.md sections 2 and 3;
frames and units follow MODEL.md section 1 (inertial NED, body FRD, SI).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from quadimpact.results.files import BUMPERS
from quadimpact.rotations import (
    euler_zyx_to_quat,
    quat_to_matrix,
    wrap_angle_rad,
)

__all__ = [
    "GRAZE_DELTA_M",
    "RESPONSE_TYPES",
    "attitude_excursion_deg",
    "classify_response",
    "group_impacts",
    "impact_metrics",
]


def group_impacts(episodes: pd.DataFrame) -> list[list[int]]:
    """Group contact episodes into impacts (STUDIES.md section 2).

    Episodes are taken in order of ``t_start_s`` (ties by ``bumper``). An
    impact starts with the earliest episode not yet grouped; every following
    episode that starts no later than the group's end so far (the largest
    ``t_end_s`` of its members) joins it, and may extend that end, so a chain
    of overlapping episodes is one impact even when a member starts after the
    first one ended. Open episodes count as lasting to their ``t_end_s`` (the
    run end).

    Intervals are closed: an episode starting exactly when the group ends
    (``t_start_s == end``) joins it, so a zero-length grazing contact still
    groups with an episode starting at the same instant.

    Parameters
    ----------
    episodes : pandas.DataFrame
        Table with at least ``t_start_s``, ``t_end_s`` (s) and ``bumper``.

    Returns
    -------
    list of list of int
        Row positions (``iloc``) in ``episodes``, one list per impact, impacts
        in time order and members in start order.
    """
    if len(episodes) == 0:
        return []
    start = episodes["t_start_s"].to_numpy(dtype=np.float64)
    end = episodes["t_end_s"].to_numpy(dtype=np.float64)
    if np.any(~np.isfinite(start)) or np.any(np.isnan(end)):
        raise ValueError("episodes: t_start_s must be finite and t_end_s not NaN")
    if "bumper" in episodes.columns:
        bumper = episodes["bumper"].to_numpy(dtype=np.float64)
        order = np.lexsort((bumper, start))
    else:
        order = np.argsort(start, kind="stable")
    groups: list[list[int]] = []
    current: list[int] = []
    group_end = -math.inf
    for pos in order:
        i = int(pos)
        if current and start[i] <= group_end:
            current.append(i)
            group_end = max(group_end, end[i])
        else:
            if current:
                groups.append(current)
            current = [i]
            group_end = max(end[i], start[i])
    groups.append(current)
    return groups


def impact_metrics(
    episodes: pd.DataFrame,
    exclude_surfaces: Sequence[str] = ("ground",),
    min_peak_delta_m: float = 0.0,
) -> dict[str, Any]:
    """Initial-impact metrics and counts of subsequent impacts (STUDIES.md section 2).

    Parameters
    ----------
    episodes : pandas.DataFrame
        Episodes table (:func:`~quadimpact.simulation.record.episodes_frame`).
    exclude_surfaces : sequence of str
        Surfaces whose episodes are ignored (by default the ground, when it is
        a contact surface: touching down is not an impact with the obstacle).
    min_peak_delta_m : float
        Episodes whose peak deflection is below this (m) are grazes: left out
        of the impacts and their counts (``GRAZE_DELTA_M`` in the summary).

    Returns
    -------
    dict
        ``delta_init_m`` (m): largest peak deflection in the initial impact.
        ``peak_force_n`` (N): largest peak normal force in the initial impact.
        ``initial_impact_start_s``, ``initial_impact_end_s``,
        ``initial_impact_duration_s`` (s).
        ``leading_bumpers``: sorted bumper numbers of the initial impact.
        ``aft_bumpers``: the other bumpers among 1-4 (empty when there is no
        impact at all).
        ``n_episodes``: episodes on non-excluded surfaces.
        ``n_subsequent_impacts``: impacts (groups) after the initial one.
        ``n_subsequent_episodes``: episodes in those impacts.
        ``subsequent_impacts``: one list per subsequent impact with the bumper
        numbers of its episodes in start order (a bumper appears twice if it
        has two episodes in that impact).
        Floats are NaN and lists empty when there is no episode.
    """
    if len(episodes) and len(exclude_surfaces):
        keep = ~episodes["surface"].astype(str).isin([str(s) for s in exclude_surfaces])
        eps = episodes.loc[keep.to_numpy()].reset_index(drop=True)
    else:
        eps = episodes.reset_index(drop=True)
    n_all = len(eps)
    if n_all and min_peak_delta_m > 0.0:
        eps = eps.loc[(eps["peak_delta_m"] >= min_peak_delta_m).to_numpy()].reset_index(drop=True)
    groups = group_impacts(eps)
    out: dict[str, Any] = {
        "delta_init_m": math.nan,
        "peak_force_n": math.nan,
        "initial_impact_start_s": math.nan,
        "initial_impact_end_s": math.nan,
        "initial_impact_duration_s": math.nan,
        "leading_bumpers": [],
        "aft_bumpers": [],
        "n_episodes": n_all,
        "n_grazes": n_all - len(eps),
        "n_subsequent_impacts": 0,
        "n_subsequent_episodes": 0,
        "subsequent_impacts": [],
    }
    if not groups:
        return out
    first = eps.iloc[groups[0]]
    start = float(first["t_start_s"].min())
    end = float(max(first["t_end_s"].max(), start))
    leading = sorted({int(b) for b in first["bumper"]})
    bumper_col = eps["bumper"].to_numpy()
    out.update(
        {
            "delta_init_m": float(first["peak_delta_m"].max()),
            "peak_force_n": float(first["peak_force_n"].max()),
            "initial_impact_start_s": start,
            "initial_impact_end_s": end,
            "initial_impact_duration_s": end - start,
            "leading_bumpers": leading,
            "aft_bumpers": [b for b in BUMPERS if b not in leading],
            "n_subsequent_impacts": len(groups) - 1,
            "n_subsequent_episodes": sum(len(g) for g in groups[1:]),
            "subsequent_impacts": [[int(bumper_col[i]) for i in g] for g in groups[1:]],
        }
    )
    return out


def attitude_excursion_deg(ts: pd.DataFrame, refs: Mapping[str, float]) -> dict[str, float]:
    """Largest attitude departure from the reference over a run (degrees).

    Parameters
    ----------
    ts : pandas.DataFrame
        Time-series table (:func:`~quadimpact.simulation.record.timeseries_frame`):
        uses ``roll_deg``, ``pitch_deg``, ``yaw_deg`` and, for the tilt,
        ``q0..q3`` (falling back to the Euler angles when the quaternion
        columns are absent).
    refs : mapping
        ``roll_rad``, ``pitch_rad``, ``yaw_rad`` (ZYX reference attitude,
        radians); other keys (``altitude_m``) are ignored.

    Returns
    -------
    dict
        ``roll_excursion_deg``: max ``|wrap(roll - roll_ref)|``;
        ``pitch_excursion_deg``: max ``|pitch - pitch_ref|``;
        ``yaw_excursion_deg``: max ``|wrap(yaw - yaw_ref)|``;
        ``tilt_max_deg``: max angle between the body z axis and the reference
        body z axis (both in the inertial frame), in [0, 180].
        Roll and yaw differences are wrapped to (-180, 180] since both angles
        are reported wrapped. All NaN for an empty table.
    """
    keys = ("roll_excursion_deg", "pitch_excursion_deg", "yaw_excursion_deg", "tilt_max_deg")
    if len(ts) == 0:
        return dict.fromkeys(keys, math.nan)
    roll_ref = float(refs["roll_rad"])
    pitch_ref = float(refs["pitch_rad"])
    yaw_ref = float(refs["yaw_rad"])
    roll = np.radians(ts["roll_deg"].to_numpy(dtype=np.float64))
    pitch = np.radians(ts["pitch_deg"].to_numpy(dtype=np.float64))
    yaw = np.radians(ts["yaw_deg"].to_numpy(dtype=np.float64))
    d_roll = np.abs(wrap_angle_rad(roll - roll_ref))
    d_pitch = np.abs(pitch - pitch_ref)
    d_yaw = np.abs(wrap_angle_rad(yaw - yaw_ref))
    if all(c in ts.columns for c in ("q0", "q1", "q2", "q3")):
        quat = ts[["q0", "q1", "q2", "q3"]].to_numpy(dtype=np.float64)
    else:
        quat = euler_zyx_to_quat(roll, pitch, yaw)
    z_body = quat_to_matrix(quat)[:, :, 2]
    z_ref = quat_to_matrix(euler_zyx_to_quat(roll_ref, pitch_ref, yaw_ref))[:, 2]
    tilt = np.arccos(np.clip(z_body @ z_ref, -1.0, 1.0))
    return {
        "roll_excursion_deg": float(np.degrees(np.max(d_roll))),
        "pitch_excursion_deg": float(np.degrees(np.max(d_pitch))),
        "yaw_excursion_deg": float(np.degrees(np.max(d_yaw))),
        "tilt_max_deg": float(np.degrees(np.max(tilt))),
    }


# ------------------------------------------------------------ response types
#: Contacts shallower than this (m) are grazes, not impacts: they do not start,
#: join or count as impacts for the metrics and the response type.
GRAZE_DELTA_M = 1e-3

RESPONSE_TYPES: tuple[str, ...] = ("A", "B", "C", "D", "Other")


def classify_response(
    leading_bumpers: Sequence[int],
    subsequent_impacts: Sequence[Sequence[int]],
    crashed: bool,
) -> str:
    """Post-impact response type (STUDIES.md section 3, the paper's Table II).

    A pure function of the impacts (:func:`impact_metrics`) and the crash.

    Parameters
    ----------
    leading_bumpers : sequence of int
        Bumpers of the initial impact (empty: the obstacle was never hit).
    subsequent_impacts : sequence of sequence of int
        For each later impact, its episodes' bumpers in start order.
    crashed : bool
        Whether a crash was recorded before the final time.

    Returns
    -------
    str
        ``"A"``: no crash (bounces away and stays up, whatever else happened).
        ``"B"``: crash with no subsequent impact.
        ``"C"``: crash; the first subsequent impact involves a leading bumper
        and an aft-bumper episode starts after that leading bumper's (in the
        same impact or a later one): the D pattern after an extra
        leading-bumper hit.
        ``"D"``: crash; the first subsequent impact involves only aft bumpers
        and there are at least two subsequent episodes.
        ``"Other"``: any other crash, including a crash without any impact.
    """
    if not crashed:
        return "A"
    if len(leading_bumpers) == 0:
        return "Other"
    if len(subsequent_impacts) == 0:
        return "B"
    leading = set(int(b) for b in leading_bumpers)
    first = [int(b) for b in subsequent_impacts[0]]
    later = [int(b) for impact in subsequent_impacts for b in impact]  # start order
    if any(b in leading for b in first):
        k = next(i for i, b in enumerate(later) if b in leading)
        return "C" if any(b not in leading for b in later[k + 1 :]) else "Other"
    return "D" if len(later) >= 2 else "Other"
