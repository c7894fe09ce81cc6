"""The paper's post-impact response types (docs/STUDIES.md 3, the paper's Table II).

Pure functions of a run's impacts (:mod:`quadimpact.simulation.metrics`) and
its crash: :func:`classify_response` sorts a run into A-D or Other,
:func:`response_type_applies` says where the types are defined, and
:func:`closest_chaining` finds the grouping decision that came closest to
going the other way (and the type it would have given).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from quadimpact.simulation.metrics import (
    GRAZE_IMPULSE_FRACTION,
    IMPACT_COLUMNS,
    Table,
    column,
    graze_mask,
    impact_metrics,
    n_rows,
    select,
)

__all__ = [
    "RESPONSE_TYPES",
    "RESPONSE_TYPE_MEANINGS",
    "classify_response",
    "closest_chaining",
    "response_type_applies",
]

RESPONSE_TYPES: tuple[str, ...] = ("A", "B", "C", "D", "Other")

#: What each response type says, in a few words (docs/STUDIES.md 3).
RESPONSE_TYPE_MEANINGS: dict[str, str] = {
    "A": "no crash before the end of the run; says nothing of the attitude or speed then",
    "B": "crashed with no impact after the initial one",
    "C": "another impact on the leading bumper(s), then the D pattern, then a crash",
    "D": "flipped toward the wall, hit it with the aft bumper(s), then crashed",
    "Other": "crashed, in none of the patterns B-D",
}


def response_type_applies(kind: str | None, ground: str | None) -> bool:
    """Whether the paper's response types (docs/STUDIES.md 3) are defined for a run.

    Only for the paper's wall approach (``kind = "wall-approach"``) with a
    crash rule, i.e. a ground that can end the run (``ground`` not
    ``"none"``): the types sort what follows an approach's first impact by
    how it ends in a crash. An impact trial or a flight also gets a
    ``response_type`` in its summary (the same rules), but it is not printed
    as one.
    """
    return kind in (None, "wall-approach") and ground != "none"


def classify_response(
    leading_bumpers: Sequence[int],
    subsequent_impacts: Sequence[Sequence[int]],
    crashed: bool,
) -> str:
    """Post-impact response type (docs/STUDIES.md section 3, the paper's Table II).

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


def closest_chaining(episodes: Table, crashed: bool) -> dict[str, Any] | None:
    """The chaining decision of the impact grouping that came closest to going the other way.

    Impacts are chained episodes (:func:`group_impacts`): an episode that
    starts before its group has ended joins it. For every episode after the
    first (obstacles only, grazes left out, as in the summary), its start
    minus the end of the group before it so far is its *margin*: negative,
    it joined that group by that overlap; positive, it started a new impact
    after that gap. The response type can hinge on a margin of a few
    milliseconds (an aft bumper touching just before the leading one leaves
    the wall makes one impact of two, and a D a B).

    Parameters
    ----------
    episodes : table
        The run's episodes (``bumper``, ``surface``, ``t_start_s``,
        ``t_end_s``, ``peak_delta_m``, ``peak_force_n``).
    crashed : bool
        Whether the run crashed.

    Returns
    -------
    dict or None
        ``margin_s`` (the smallest in size), ``bumper`` (that episode's),
        ``joined`` (its margin <= 0), ``type`` (the response type as grouped)
        and ``type_flipped`` (the type with that one episode on the other side
        of the group's end); None with fewer than two episodes.
    """
    n = n_rows(episodes)
    if n < 2:
        return None
    surface = column(episodes, "surface", dtype=object).astype(str)
    keep = (surface != "ground") & ~graze_mask(episodes, ("ground",), GRAZE_IMPULSE_FRACTION)
    eps = select(episodes, keep, IMPACT_COLUMNS)
    order = np.lexsort((np.asarray(eps["bumper"], float), eps["t_start_s"]))
    if len(order) < 2:
        return None
    best: tuple[float, int, float] | None = None  # (margin, episode, group end)
    group_end = -math.inf
    for k, pos in enumerate(order):
        i = int(pos)
        start, end = float(eps["t_start_s"][i]), float(eps["t_end_s"][i])
        if k > 0:
            margin = start - group_end
            if best is None or abs(margin) < abs(best[0]):
                best = (margin, i, group_end)
            group_end = max(group_end, end) if margin <= 0.0 else max(end, start)
        else:
            group_end = max(end, start)

    def response(table: dict[str, np.ndarray]) -> str:
        m = impact_metrics(table, exclude_surfaces=())
        return classify_response(m["leading_bumpers"], m["subsequent_impacts"], crashed)

    assert best is not None
    margin, i, end_before = best
    flipped = {k: np.array(v, dtype=float if k != "surface" else object) for k, v in eps.items()}
    # across the group's end: just after it (a new impact), or at it (chained: closed intervals)
    flipped["t_start_s"][i] = np.nextafter(end_before, math.inf) if margin <= 0.0 else end_before
    flipped["t_end_s"][i] = max(flipped["t_end_s"][i], flipped["t_start_s"][i])
    return {
        "margin_s": float(margin),
        "bumper": int(eps["bumper"][i]),
        "joined": bool(margin <= 0.0),
        "type": response(eps),
        "type_flipped": response(flipped),
    }
