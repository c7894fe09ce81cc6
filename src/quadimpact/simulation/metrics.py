"""Metrics of a run from its tables: impact grouping, initial-impact metrics,
attitude excursion and the response type.

Everything here is a pure function of tables or plain lists, so it can be
tested on hand-made inputs. A "table" is anything whose columns are read
with ``table[name]``: a pandas DataFrame (the episodes and time series of
:mod:`quadimpact.simulation.tables`) or a plain mapping of NumPy arrays (what
``simulate`` uses, so that a summary needs no DataFrame). Definitions follow
docs/STUDIES.md sections 2 and 3; frames and units docs/MODEL.md section 1
(inertial NED, body FRD, SI).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from quadimpact import libm
from quadimpact.linalg import dot
from quadimpact.results.files import BUMPERS
from quadimpact.rotations import (
    euler_zyx_to_quat,
    quat_to_matrix,
    wrap_angle_rad,
)

__all__ = [
    "GRAZE_IMPULSE_FRACTION",
    "attitude_excursion_deg",
    "EpisodeLists",
    "episode_lists",
    "impact_rows",
    "impacts_in",
    "impacts_of",
    "RunImpacts",
    "graze_mask",
    "group_impacts",
    "impact_metrics",
    "impact_metrics_of",
    "impacts_of_table",
    "impulse_scale",
    "short_impacts",
    "short_impacts_of",
]


Table = Any
"""A DataFrame or a mapping of equal-length NumPy arrays (columns by name)."""


def column(table: Table, name: str, dtype: Any = np.float64) -> np.ndarray:
    """Column ``name`` of a table as a NumPy array."""
    values = table[name]
    if hasattr(values, "to_numpy"):
        return values.to_numpy(dtype=dtype)
    return np.asarray(values, dtype=dtype)


def has_column(table: Table, name: str) -> bool:
    """Whether the table has column ``name``."""
    columns = getattr(table, "columns", None)
    return name in (columns if columns is not None else table)


def n_rows(table: Table) -> int:
    """Number of rows of a table."""
    if hasattr(table, "shape"):
        return int(table.shape[0])
    return len(next(iter(table.values()))) if len(table) else 0


def select(table: Table, rows: np.ndarray, names: Sequence[str]) -> dict[str, np.ndarray]:
    """The columns ``names`` of a table at ``rows`` (a mask or positions), as arrays."""
    out = {}
    for name in names:
        values = table[name]
        values = values.to_numpy() if hasattr(values, "to_numpy") else np.asarray(values)
        out[name] = values[rows]
    return out


IMPACT_COLUMNS = ("bumper", "surface", "t_start_s", "t_end_s", "peak_delta_m", "peak_force_n")
"""The episode columns the impacts and their metrics are found from."""


class EpisodeLists(dict):
    """A run's episodes as Python lists, columns by name, in the table's order.

    What :func:`episode_lists` gives for any table, built once for a run's
    summary (``simulation.record.episode_lists_of``): the impacts found in it
    are kept (:func:`impacts_in`), so the summary's metrics, its warnings and
    the recovery metrics group the episodes once per set of excluded surfaces.
    Not to be changed once built.
    """

    def __init__(self, columns: Mapping[str, list[Any]]) -> None:
        super().__init__(columns)
        self.impacts: dict[tuple[frozenset[str], float], Any] = {}


def episode_lists(table: Table, names: Sequence[str]) -> dict[str, list[Any]]:
    """Columns of a table as Python lists (``surface`` as str): a run has a handful of
    episodes, and plain Python on a few values is faster than NumPy's calls on them
    (the same IEEE operations, so the same results). An :class:`EpisodeLists` is
    returned as it is (it has every column)."""
    if type(table) is EpisodeLists:
        return table
    out: dict[str, list[Any]] = {}
    for name in names:
        if name == "surface":
            out[name] = [str(v) for v in column(table, name, dtype=object).tolist()]
        elif name == "bumper":
            out[name] = [int(v) for v in column(table, name, dtype=np.int64).tolist()]
        else:
            out[name] = column(table, name).tolist()
    return out


def _group(start: list[float], end: list[float], bumper: list[int] | None) -> list[list[int]]:
    """:func:`group_impacts` on plain lists (positions into them)."""
    if not start:
        return []
    if not all(math.isfinite(t) for t in start) or any(math.isnan(t) for t in end):
        raise ValueError("episodes: t_start_s must be finite and t_end_s not NaN")
    if bumper is not None:  # by start, ties by bumper, then as given (stable)
        order = sorted(range(len(start)), key=lambda i: (start[i], bumper[i]))
    else:
        order = sorted(range(len(start)), key=start.__getitem__)
    groups: list[list[int]] = []
    current: list[int] = []
    group_end = -math.inf
    for i in order:
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


def group_impacts(episodes: Table) -> list[list[int]]:
    """Group contact episodes into impacts (docs/STUDIES.md section 2).

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
    episodes : table
        With at least ``t_start_s``, ``t_end_s`` (s) and ``bumper``.

    Returns
    -------
    list of list of int
        Row positions (``iloc``) in ``episodes``, one list per impact, impacts
        in time order and members in start order.
    """
    if n_rows(episodes) == 0:
        return []
    names = ("t_start_s", "t_end_s", "bumper")[: 3 if has_column(episodes, "bumper") else 2]
    cols = episode_lists(episodes, names)
    return _group(cols["t_start_s"], cols["t_end_s"], cols.get("bumper"))


def impulse_scale(episodes: Table) -> np.ndarray:
    """Each episode's impulse scale, N s: peak normal force times duration.

    An upper bound of the episode's normal impulse (the integral of the
    force over the episode, since the force never exceeds its peak), from the
    episode record alone (docs/STUDIES.md 2.2).
    """
    if n_rows(episodes) == 0:
        return np.zeros(0)
    duration = column(episodes, "t_end_s") - column(episodes, "t_start_s")
    return column(episodes, "peak_force_n") * np.maximum(duration, 0.0)


def _grazes(cols: dict[str, list[Any]], exclude: Sequence[str], fraction: float) -> list[bool]:
    """:func:`graze_mask` on the lists of :func:`episode_lists` (surface, times, peak force)."""
    n = len(cols["t_start_s"])
    if n == 0 or fraction <= 0.0:
        return [False] * n
    excluded = {str(s) for s in exclude}
    obstacle = [s not in excluded for s in cols["surface"]]
    if not any(obstacle):
        return [False] * n
    scale = [
        f * max(e - s, 0.0)
        for f, s, e in zip(cols["peak_force_n"], cols["t_start_s"], cols["t_end_s"], strict=True)
    ]
    limit = fraction * max(x for x, o in zip(scale, obstacle, strict=True) if o)
    return [o and x < limit for x, o in zip(scale, obstacle, strict=True)]


def graze_mask(
    episodes: Table,
    exclude_surfaces: Sequence[str] = ("ground",),
    fraction: float = 0.0,
) -> np.ndarray:
    """Which episodes are grazes (docs/STUDIES.md 2.2).

    An episode on an obstacle (a surface not in ``exclude_surfaces``) is a
    graze when its impulse scale (:func:`impulse_scale`) is below
    ``fraction`` times the largest impulse scale among the run's obstacle
    episodes (the impact's): its velocity change is small relative to the
    impact's, whatever the bumpers' stiffness. Episodes on excluded surfaces
    are never grazes (they are left out of the impacts anyway). ``fraction``
    0 (the default): no grazes.
    """
    n = n_rows(episodes)
    if n == 0 or fraction <= 0.0:
        return np.zeros(n, dtype=bool)
    cols = episode_lists(episodes, ("surface", "t_start_s", "t_end_s", "peak_force_n"))
    return np.array(_grazes(cols, exclude_surfaces, fraction), dtype=bool)


def impact_rows(
    cols: dict[str, list[Any]], exclude: Sequence[str], graze_fraction: float
) -> tuple[list[int], int]:
    """Rows that make impacts (not on an excluded surface, not grazes), and the rows on
    surfaces not excluded (grazes included)."""
    excluded = {str(s) for s in exclude}
    counted = [k for k, s in enumerate(cols["surface"]) if s not in excluded]
    if counted and graze_fraction > 0.0:
        grazes = _grazes(cols, exclude, graze_fraction)
        return [k for k in counted if not grazes[k]], len(counted)
    return counted, len(counted)


def impacts_of(cols: dict[str, list[Any]], rows: list[int]) -> list[list[int]]:
    """The impacts (:func:`group_impacts`) of these rows, as rows of ``cols``."""
    start = [cols["t_start_s"][k] for k in rows]
    end = [cols["t_end_s"][k] for k in rows]
    bumper = [cols["bumper"][k] for k in rows]
    return [[rows[i] for i in g] for g in _group(start, end, bumper)]


def impacts_in(
    cols: dict[str, list[Any]], exclude: Sequence[str], graze_fraction: float
) -> tuple[list[int], int, list[list[int]]]:
    """:func:`impact_rows` and :func:`impacts_of` of the lists of :func:`episode_lists`.

    Returns the impact rows, the count of rows on surfaces not excluded and the
    impacts (rows of ``cols``); kept in an :class:`EpisodeLists` for the next caller.
    """
    memo = cols.impacts if type(cols) is EpisodeLists else None
    if memo is not None:  # kept by the surfaces excluded among those touched: the same rows
        touched = set(cols["surface"])
        key = (frozenset(str(s) for s in exclude if str(s) in touched), float(graze_fraction))
        if key in memo:
            return memo[key]
    rows, n_all = impact_rows(cols, exclude, graze_fraction)
    found = (rows, n_all, impacts_of(cols, rows))
    if memo is not None:
        memo[key] = found
    return found


def short_impacts(
    episodes: Table,
    period_s: float,
    exclude_surfaces: Sequence[str] = ("ground",),
    graze_fraction: float = 0.0,
) -> tuple[int, float]:
    """The impacts (grazes and excluded surfaces left out) lasting less than ``period_s``.

    Returns
    -------
    (int, float)
        Their number and the shortest impact's duration, s (NaN when none).
    """
    if n_rows(episodes) == 0 or not period_s > 0.0:
        return 0, math.nan
    return short_impacts_of(impacts_of_table(episodes, exclude_surfaces, graze_fraction), period_s)


def short_impacts_of(impacts: RunImpacts, period_s: float) -> tuple[int, float]:
    """:func:`short_impacts` of a run's :class:`RunImpacts`: their number and the shortest, s."""
    if not period_s > 0.0:
        return 0, math.nan
    durations = [e - s for s, e in zip(impacts.start_s, impacts.end_s, strict=True)]
    short = [d for d in durations if d < period_s]
    return len(short), (min(short) if short else math.nan)


@dataclass(frozen=True)
class RunImpacts:
    """A run's impacts: its episodes grouped (:func:`group_impacts`), some surfaces and the
    grazes left out, what the summary's metrics are computed from.

    Found from a table by :func:`impacts_of_table` (the reference), or from the
    loop's raw episodes by the compiled pass of ``core/impacts.py``
    (``simulation.impacts``): the same numbers, bit for bit. Impacts in time
    order; times in s.
    """

    n_episodes: int
    """Episodes on the surfaces not left out (grazes included)."""
    n_grazes: int
    """Of those, the grazes (:func:`graze_mask`)."""
    bumpers: list[list[int]]
    """Each impact's episodes' features (1-based), in start order."""
    start_s: list[float]
    """Each impact's earliest episode start."""
    end_s: list[float]
    """Each impact's latest episode end (an open episode's: the run's end)."""
    peak_delta_m: list[float]
    """Each impact's largest peak deflection, m."""
    peak_force_n: list[float]
    """Each impact's largest peak normal force, N."""


NO_IMPACTS = RunImpacts(0, 0, [], [], [], [], [])
"""The :class:`RunImpacts` of a run without episodes."""


def impacts_of_table(
    episodes: Table, exclude_surfaces: Sequence[str] = ("ground",), graze_fraction: float = 0.0
) -> RunImpacts:
    """The :class:`RunImpacts` of an episodes table (Python; the compiled pass's reference).

    Episodes on ``exclude_surfaces`` and grazes (``graze_fraction``,
    :func:`graze_mask`) are left out; the rest are grouped by :func:`group_impacts`.
    """
    if n_rows(episodes) == 0:
        return NO_IMPACTS
    cols = episode_lists(episodes, IMPACT_COLUMNS)
    rows, n_all, groups = impacts_in(cols, exclude_surfaces, graze_fraction)
    start, end = cols["t_start_s"], cols["t_end_s"]
    delta, force, bumper = cols["peak_delta_m"], cols["peak_force_n"], cols["bumper"]
    return RunImpacts(
        n_episodes=n_all,
        n_grazes=n_all - len(rows),
        bumpers=[[bumper[k] for k in g] for g in groups],
        start_s=[min(start[k] for k in g) for g in groups],
        end_s=[max(end[k] for k in g) for g in groups],
        peak_delta_m=[max(delta[k] for k in g) for g in groups],
        peak_force_n=[max(force[k] for k in g) for g in groups],
    )


def impact_metrics(
    episodes: Table,
    exclude_surfaces: Sequence[str] = ("ground",),
    graze_fraction: float = 0.0,
    n_features: int = len(BUMPERS),
) -> dict[str, Any]:
    """Initial-impact metrics and counts of subsequent impacts (docs/STUDIES.md section 2).

    Parameters
    ----------
    episodes : table
        Episodes (:func:`~quadimpact.simulation.tables.episodes_frame`, or its
        columns as arrays: :func:`~quadimpact.simulation.tables.episode_columns`).
    exclude_surfaces : sequence of str
        Surfaces whose episodes are ignored (by default the ground, when it is
        a contact surface: touching down is not an impact with the obstacle).
    graze_fraction : float
        Episodes whose impulse scale is below this fraction of the run's
        largest are grazes (:func:`graze_mask`): left out of the impacts and
        their counts (``GRAZE_IMPULSE_FRACTION`` in the summary; 0: none).
    n_features : int
        The vehicle's contact features (numbered 1..n in ``bumper``; four
        bumper rings by default).

    Returns
    -------
    dict
        ``delta_init_m`` (m): largest peak deflection in the initial impact.
        ``peak_force_n`` (N): largest peak normal force in the initial impact.
        ``initial_impact_start_s``, ``initial_impact_end_s``,
        ``initial_impact_duration_s`` (s).
        ``leading_bumpers``: sorted bumper numbers of the initial impact.
        ``aft_bumpers``: the other bumpers (features) among 1..n (empty when
        there is no impact at all).
        ``n_episodes``: episodes on non-excluded surfaces.
        ``n_subsequent_impacts``: impacts (groups) after the initial one.
        ``n_subsequent_episodes``: episodes in those impacts.
        ``subsequent_impacts``: one list per subsequent impact with the bumper
        numbers of its episodes in start order (a bumper appears twice if it
        has two episodes in that impact).
        Floats are NaN and lists empty when there is no episode.
    """
    impacts = impacts_of_table(episodes, exclude_surfaces, graze_fraction)
    return impact_metrics_of(impacts, n_features)


def impact_metrics_of(impacts: RunImpacts, n_features: int = len(BUMPERS)) -> dict[str, Any]:
    """:func:`impact_metrics` of a run's :class:`RunImpacts` (the same dict)."""
    out: dict[str, Any] = {
        "delta_init_m": math.nan,
        "peak_force_n": math.nan,
        "initial_impact_start_s": math.nan,
        "initial_impact_end_s": math.nan,
        "initial_impact_duration_s": math.nan,
        "leading_bumpers": [],
        "aft_bumpers": [],
        "n_episodes": impacts.n_episodes,
        "n_grazes": impacts.n_grazes,
        "n_subsequent_impacts": 0,
        "n_subsequent_episodes": 0,
        "subsequent_impacts": [],
    }
    groups = impacts.bumpers
    if not groups:
        return out
    start = impacts.start_s[0]
    end = max(impacts.end_s[0], start)
    leading = sorted(set(groups[0]))
    out.update(
        {
            "delta_init_m": impacts.peak_delta_m[0],
            "peak_force_n": impacts.peak_force_n[0],
            "initial_impact_start_s": start,
            "initial_impact_end_s": end,
            "initial_impact_duration_s": end - start,
            "leading_bumpers": leading,
            "aft_bumpers": [b for b in range(1, n_features + 1) if b not in leading],
            "n_subsequent_impacts": len(groups) - 1,
            "n_subsequent_episodes": sum(len(g) for g in groups[1:]),
            "subsequent_impacts": [list(g) for g in groups[1:]],
        }
    )
    return out


def attitude_excursion_deg(ts: Table, refs: Mapping[str, float]) -> dict[str, float]:
    """Largest attitude departure from the reference over a run (degrees).

    Parameters
    ----------
    ts : table
        Time series (:func:`~quadimpact.simulation.tables.timeseries_frame` or
        its columns :func:`~quadimpact.simulation.tables.timeseries_columns`):
        uses ``roll_deg``, ``pitch_deg``, ``yaw_deg`` and, for the tilt,
        ``q0..q3`` (falling back to the Euler angles when the quaternion
        columns are absent). A run's summary has the same numbers from its
        loop (``core/excursion.py``).
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
    if n_rows(ts) == 0:
        return dict.fromkeys(keys, math.nan)
    roll_ref = float(refs["roll_rad"])
    pitch_ref = float(refs["pitch_rad"])
    yaw_ref = float(refs["yaw_rad"])
    if all(has_column(ts, c) for c in ("q0", "q1", "q2", "q3")):
        from quadimpact.packing.controller_block import reference_z_axis
        from quadimpact.simulation.attitude import excursion_from_quaternions

        quat = np.ascontiguousarray(
            np.stack([column(ts, c) for c in ("q0", "q1", "q2", "q3")], axis=1)
        )
        z_ref = reference_z_axis({"roll_rad": roll_ref, "pitch_rad": pitch_ref, "yaw_rad": yaw_ref})
        values = excursion_from_quaternions(
            quat, roll_ref, pitch_ref, yaw_ref, np.ascontiguousarray(z_ref)
        )
        return {k: float(v) for k, v in zip(keys, values, strict=True)}
    roll = np.radians(column(ts, "roll_deg"))
    pitch = np.radians(column(ts, "pitch_deg"))
    yaw = np.radians(column(ts, "yaw_deg"))
    d_roll = np.abs(wrap_angle_rad(roll - roll_ref))
    d_pitch = np.abs(pitch - pitch_ref)
    d_yaw = np.abs(wrap_angle_rad(yaw - yaw_ref))
    quat = euler_zyx_to_quat(roll, pitch, yaw)
    z_body = quat_to_matrix(quat)[:, :, 2]
    z_ref = quat_to_matrix(euler_zyx_to_quat(roll_ref, pitch_ref, yaw_ref))[:, 2]
    tilt = libm.arccos(np.clip(dot(z_body, z_ref), -1.0, 1.0))
    return {
        "roll_excursion_deg": float(np.degrees(np.max(d_roll))),
        "pitch_excursion_deg": float(np.degrees(np.max(d_pitch))),
        "yaw_excursion_deg": float(np.degrees(np.max(d_yaw))),
        "tilt_max_deg": float(np.degrees(np.max(tilt))),
    }


# ------------------------------------------------------------ response types
#: An obstacle episode whose impulse scale (peak force x duration, an upper bound
#: of its impulse) is below this fraction of the run's largest is a graze, not an
#: impact: it does not start, join or count as an impact for the metrics and the
#: response type (docs/STUDIES.md 2.2). A fraction, not a depth: the same
#: contacts are grazes whatever the bumpers' stiffness.
GRAZE_IMPULSE_FRACTION = 0.01
