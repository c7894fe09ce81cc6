"""A run's impacts from its raw contact episodes, compiled: the summary's one pass over them.

An **impact** is a group of chained contact episodes (docs/STUDIES.md 2):
the episodes are taken in order of start (ties by feature, then as
recorded); an episode that starts no later than the latest end of the group
so far joins it, else it starts the next impact. Episodes on **excluded**
shapes (the ground, for the summary's metrics) are left out, and so are
**grazes**: an episode on a counted shape whose impulse scale (peak normal
force times duration) is below ``graze_fraction`` times the largest of the
counted episodes'.

:func:`find_impacts` does all of it over the raw episode rows the loop
recorded (layout ``E_*``) and writes one row per impact (``IM_*``, below): its
start, end, largest peak deflection and largest peak force. It is the same
computation, in the same order of the same IEEE operations, as the Python
reference of ``quadimpact.simulation.metrics`` (``impacts_in`` and
``impact_metrics``), so the two give the same numbers bit for bit
(``tests/simulation/test_impacts.py``): ``max``/``min`` keep the first
of equal values as Python's do, and a NaN where Python's comparisons keep it.

A record the reference would refuse or sort differently (a start that is not
finite, an end that is NaN, a feature or shape index out of range: the
reference raises or sorts NaNs as NumPy does) is not grouped here
(:func:`episodes_usable` is false): the caller takes the reference's path.
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import Block
from quadimpact.core.recording_slots import (
    E_FEATURE,
    E_PEAK_DELTA,
    E_PEAK_FORCE,
    E_SHAPE,
    E_T_END,
    E_T_START,
)

# ---- a run's impacts (n_impacts, NIM): one row per impact (a group of chained
# episodes, docs/STUDIES.md 2), members in start order
_im = Block("impacts", "IM_")
IM_START = _im.slot("IM_START")  # s, earliest start of its episodes
IM_END = _im.slot("IM_END")  # s, latest end of its episodes (run end if one is open)
IM_PEAK_DELTA = _im.slot("IM_PEAK_DELTA")  # m, largest peak deflection of its episodes
IM_PEAK_FORCE = _im.slot("IM_PEAK_FORCE")  # N, largest peak normal force of its episodes
NIM = _im.end("NIM")

EXCLUDED = -1
"""``impact_of[k]`` of an episode on an excluded shape."""
GRAZE = -2
"""``impact_of[k]`` of a graze."""
_INDEX_LIMIT = 2.0**62


@compiled(inline="always")
def _larger(a: float, b: float) -> float:
    """Python's ``max(a, b)``: ``b`` only if it is greater (the first of equals, NaN kept first)."""
    return b if b > a else a


@compiled(inline="always")
def _smaller(a: float, b: float) -> float:
    """Python's ``min(a, b)``: ``b`` only if it is smaller."""
    return b if b < a else a


@compiled(inline="always")
def _whole_index(value: float, count: int) -> bool:
    """Whether a raw index is a number whose nearest whole number is in ``0..count - 1``."""
    if not abs(value) < _INDEX_LIMIT:  # NaN fails too
        return False
    k = np.rint(value)
    return 0.0 <= k < count


@compiled
def episodes_usable(episodes: np.ndarray, n: int, n_features: int, n_shapes: int) -> bool:
    """Whether the first ``n`` raw episodes can be grouped here (see the module).

    Parameters
    ----------
    episodes : numpy.ndarray (max_episodes, NEP)
        The loop's episode rows (``E_*``; times in s).
    n : int
        Rows recorded.
    n_features, n_shapes : int
        The vehicle's contact features and the packed shapes (index ranges).
    """
    for i in range(n):
        if not math.isfinite(episodes[i, E_T_START]) or math.isnan(episodes[i, E_T_END]):
            return False
        if not _whole_index(episodes[i, E_FEATURE], n_features):
            return False
        if not _whole_index(episodes[i, E_SHAPE], n_shapes):
            return False
    return True


@compiled
def sort_episodes(episodes: np.ndarray, n: int, order: np.ndarray) -> None:
    """``order[:n]``: the rows by start, then feature; equal keys as recorded (a stable sort).

    An insertion sort: a run has a handful of episodes.
    """
    for i in range(n):
        order[i] = i
    for i in range(1, n):
        row = order[i]
        t = episodes[row, E_T_START]
        f = np.rint(episodes[row, E_FEATURE])
        j = i - 1
        while j >= 0:
            other = order[j]
            t_other = episodes[other, E_T_START]
            if t_other > t or (t_other == t and np.rint(episodes[other, E_FEATURE]) > f):
                order[j + 1] = other
                j -= 1
            else:
                break
        order[j + 1] = row


@compiled(inline="always")
def _impulse_scale(episodes: np.ndarray, row: int) -> float:
    """Peak normal force times duration (clamped at 0), N s."""
    return episodes[row, E_PEAK_FORCE] * _larger(
        episodes[row, E_T_END] - episodes[row, E_T_START], 0.0
    )


@compiled
def _mark_excluded_and_grazes(
    episodes: np.ndarray,
    order: np.ndarray,
    n: int,
    excluded: np.ndarray,
    graze_fraction: float,
    impact_of: np.ndarray,
) -> None:
    """``impact_of[k]``: :data:`EXCLUDED`, :data:`GRAZE`, or 0 (counted) for sorted row ``k``."""
    counted = False
    for k in range(n):
        shape = int(np.rint(episodes[order[k], E_SHAPE]))
        if excluded[shape] > 0.5:
            impact_of[k] = EXCLUDED
        else:
            impact_of[k] = 0
            counted = True
    if not (counted and graze_fraction > 0.0):
        return
    largest = 0.0
    first = True
    for k in range(n):
        if impact_of[k] != EXCLUDED:
            x = _impulse_scale(episodes, order[k])
            largest = x if first else _larger(largest, x)
            first = False
    limit = graze_fraction * largest
    for k in range(n):
        if impact_of[k] != EXCLUDED and _impulse_scale(episodes, order[k]) < limit:
            impact_of[k] = GRAZE


@compiled
def find_impacts(
    episodes: np.ndarray,
    order: np.ndarray,
    n: int,
    excluded: np.ndarray,
    graze_fraction: float,
    impact_of: np.ndarray,
    impacts: np.ndarray,
) -> int:
    """Group the sorted episodes into impacts; return how many (see the module).

    Parameters
    ----------
    episodes : numpy.ndarray (max_episodes, NEP)
        The loop's episode rows, usable (:func:`episodes_usable`).
    order : numpy.ndarray of int64 (>= n,)
        The rows in order (:func:`sort_episodes`).
    n : int
        Rows recorded.
    excluded : numpy.ndarray (n_shapes,)
        1 for a shape whose episodes are left out, else 0.
    graze_fraction : float
        Grazes: impulse scale below this fraction of the largest (0: none).
    impact_of : numpy.ndarray of int64 (>= n,)
        Out: for sorted row ``k``, its impact (0, 1, ... in time order),
        :data:`EXCLUDED` or :data:`GRAZE`.
    impacts : numpy.ndarray (>= n, NIM)
        Out: one row per impact (``IM_*``: s, s, m, N).
    """
    _mark_excluded_and_grazes(episodes, order, n, excluded, graze_fraction, impact_of)
    count = 0
    group_end = -math.inf
    for k in range(n):
        if impact_of[k] < 0:
            continue
        row = order[k]
        start = episodes[row, E_T_START]
        end = episodes[row, E_T_END]
        if count > 0 and start <= group_end:  # chained: joins the impact so far
            g = count - 1
            impact_of[k] = g
            group_end = _larger(group_end, end)
            impacts[g, IM_START] = _smaller(impacts[g, IM_START], start)
            impacts[g, IM_END] = _larger(impacts[g, IM_END], end)
            delta, force = episodes[row, E_PEAK_DELTA], episodes[row, E_PEAK_FORCE]
            impacts[g, IM_PEAK_DELTA] = _larger(impacts[g, IM_PEAK_DELTA], delta)
            impacts[g, IM_PEAK_FORCE] = _larger(impacts[g, IM_PEAK_FORCE], force)
        else:
            impact_of[k] = count
            impacts[count, IM_START] = start
            impacts[count, IM_END] = end
            impacts[count, IM_PEAK_DELTA] = episodes[row, E_PEAK_DELTA]
            impacts[count, IM_PEAK_FORCE] = episodes[row, E_PEAK_FORCE]
            group_end = _larger(end, start)
            count += 1
    return count


@compiled
def sort_and_find_impacts(
    episodes: np.ndarray,
    n: int,
    n_features: int,
    excluded: np.ndarray,
    graze_fraction: float,
    order: np.ndarray,
    impact_of: np.ndarray,
    impacts: np.ndarray,
) -> int:
    """:func:`episodes_usable`, :func:`sort_episodes` and :func:`find_impacts` in one call.

    Returns the number of impacts, or -1 (nothing written) when the record is
    not usable here (``excluded`` has one entry per shape). One call from
    Python instead of three: a summary's first calls after the loop run cold.
    """
    if not episodes_usable(episodes, n, n_features, excluded.shape[0]):
        return -1
    sort_episodes(episodes, n, order)
    return find_impacts(episodes, order, n, excluded, graze_fraction, impact_of, impacts)
