"""A run's episodes as its summary reads them: the impacts, found by one compiled pass.

The summary needs of a run's episodes its impacts twice over (on every
surface but the one named ``"ground"``, for the impact metrics and the
short-impact warning; on the obstacles, for the impacts after a detection:
the same sets unless a surface other than the ground is flagged as one) and
the first episode on an obstacle. :func:`run_episodes` finds them from the
loop's raw episode rows with ``core/impacts.py`` (sort, grazes, grouping in
compiled code) and makes :class:`~quadimpact.simulation.metrics.RunImpacts`
of them: the same numbers, bit for bit, as the Python reference
(:func:`~quadimpact.simulation.metrics.impacts_of_table` of the episodes
table), which takes over for a record the compiled pass leaves to it (a
start that is not finite, an index out of range: see ``core/impacts.py``).
No table is built unless asked for (:meth:`RunEpisodes.table`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from quadimpact.core import shape_slots as SHP
from quadimpact.core.impacts import (
    GRAZE,
    IM_END,
    IM_PEAK_DELTA,
    IM_PEAK_FORCE,
    IM_START,
    NIM,
    find_impacts,
    sort_and_find_impacts,
)
from quadimpact.core.recording_slots import E_FEATURE, E_SHAPE
from quadimpact.simulation.metrics import (
    GRAZE_IMPULSE_FRACTION,
    IMPACT_COLUMNS,
    NO_IMPACTS,
    RunImpacts,
    Table,
    episode_lists,
    impacts_of_table,
    n_rows,
)
from quadimpact.simulation.recovery_metrics import first_obstacle_episode
from quadimpact.simulation.tables import episode_lists_of

__all__ = ["GROUND_NAME", "RunEpisodes", "run_episodes"]

GROUND_NAME = "ground"
"""The surface the summary's impact metrics leave out (docs/STUDIES.md 2)."""


@dataclass
class RunEpisodes:
    """A run's episodes as its summary reads them.

    ``impacts``: the impacts on every surface but :data:`GROUND_NAME`
    (grazes left out); ``obstacle_impacts``: those on the obstacles (the
    surfaces not flagged as the ground); ``first_obstacle``: ``(bumper,
    surface)`` of the first episode on an obstacle (None: none). The episodes
    table itself (:meth:`table`) is built when first asked for.
    """

    impacts: RunImpacts
    obstacle_impacts: RunImpacts
    first_obstacle: tuple[int, str] | None
    make_table: Callable[[], Table] = field(repr=False)
    _table: Table | None = field(default=None, repr=False)

    def table(self) -> Table:
        """The episodes (columns by name, in time order), built on first use."""
        if self._table is None:
            self._table = self.make_table()
        return self._table

    @classmethod
    def of_table(cls, episodes: Table, obstacle_names: Sequence[str]) -> RunEpisodes:
        """The same from an episodes table, by the Python reference."""
        if n_rows(episodes) == 0:
            return cls(NO_IMPACTS, NO_IMPACTS, None, lambda: episodes)
        cols = episode_lists(episodes, IMPACT_COLUMNS)
        others = sorted(set(cols["surface"]) - set(obstacle_names))
        return cls(
            impacts=impacts_of_table(cols, (GROUND_NAME,), GRAZE_IMPULSE_FRACTION),
            obstacle_impacts=impacts_of_table(cols, others, GRAZE_IMPULSE_FRACTION),
            first_obstacle=first_obstacle_episode(cols, obstacle_names),
            make_table=lambda: episodes,
        )


def run_episodes(
    raw: np.ndarray,
    n: int,
    surface_names: Sequence[str],
    n_features: int,
    shapes: np.ndarray,
) -> RunEpisodes:
    """The :class:`RunEpisodes` of a run from the loop's raw episode rows.

    Parameters
    ----------
    raw : numpy.ndarray (max_episodes, NEP)
        The loop's episodes (``E_*``), the first ``n`` recorded.
    n : int
        Episodes recorded.
    surface_names : sequence of str
        The packed shapes' names, in order.
    n_features : int
        The vehicle's contact features.
    shapes : numpy.ndarray (n_shapes, NSH)
        The packed shapes (``SH_IS_GROUND`` says which are not obstacles).
    """
    names = list(surface_names)
    not_obstacle = [float(not flag < 0.5) for flag in shapes[:, SHP.SH_IS_GROUND].tolist()]

    def table() -> Table:
        return episode_lists_of(raw, n, names, n_features)

    if n == 0:
        return RunEpisodes(NO_IMPACTS, NO_IMPACTS, None, table)
    ground = [1.0 if name == GROUND_NAME else 0.0 for name in names]
    order = np.empty(n, dtype=np.int64)
    impact_of = np.empty(n, dtype=np.int64)
    found = np.empty((n, NIM))
    excluded = np.array(ground)
    count = sort_and_find_impacts(
        raw, n, n_features, excluded, GRAZE_IMPULSE_FRACTION, order, impact_of, found
    )
    if count < 0:  # the reference's path (it may raise)
        obstacles = [name for name, flag in zip(names, not_obstacle, strict=True) if not flag]
        return RunEpisodes.of_table(table(), obstacles)
    rows = raw[:n].tolist()
    sorted_rows = [rows[k] for k in order.tolist()]
    impacts = _impacts(sorted_rows, impact_of, found, count)
    if ground == not_obstacle:  # the obstacles are every surface but the ground
        obstacle_impacts = impacts
    else:
        excluded = np.array(not_obstacle)
        count = find_impacts(raw, order, n, excluded, GRAZE_IMPULSE_FRACTION, impact_of, found)
        obstacle_impacts = _impacts(sorted_rows, impact_of, found, count)
    first = None
    for row in sorted_rows:
        shape = round(row[E_SHAPE])
        if not not_obstacle[shape]:
            first = (round(row[E_FEATURE]) + 1, names[shape])
            break
    return RunEpisodes(impacts, obstacle_impacts, first, table)


def _impacts(
    sorted_rows: list[Any], impact_of: np.ndarray, found: np.ndarray, count: int
) -> RunImpacts:
    """A :class:`RunImpacts` of what the compiled pass wrote (``impact_of``, ``count`` rows of
    ``found``) for the episodes in order (``sorted_rows``)."""
    groups: list[list[int]] = [[] for _ in range(count)]
    n_all = n_grazes = 0
    for g, row in zip(impact_of.tolist(), sorted_rows, strict=True):
        if g >= 0:
            groups[g].append(round(row[E_FEATURE]) + 1)
            n_all += 1
        elif g == GRAZE:
            n_all += 1
            n_grazes += 1
    table = found[:count].T.tolist()  # one list per IM_ column
    return RunImpacts(
        n_episodes=n_all,
        n_grazes=n_grazes,
        bumpers=groups,
        start_s=table[IM_START],
        end_s=table[IM_END],
        peak_delta_m=table[IM_PEAK_DELTA],
        peak_force_n=table[IM_PEAK_FORCE],
    )
