"""The studies' proportions: a share of trials with its 95 % Wilson interval, in words.

Every study reports success rates the same way: ``k / n`` with the Wilson
score interval (:func:`wilson_interval`), as a :class:`Rate` in its numbers
(``study.json``) and as ``k / n = p % [low %, high %]`` in its report and on
the command line (:func:`rate_text`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["Z_95", "Rate", "percent", "rate", "rate_text", "wilson_interval"]

#: Normal quantile of a two-sided 95 % interval.
Z_95 = 1.96


def wilson_interval(k: int, n: int, z: float = Z_95) -> tuple[float, float]:
    """The Wilson score interval of a binomial proportion ``k / n``.

    Parameters
    ----------
    k : int
        Successes, ``0 <= k <= n``.
    n : int
        Trials; ``n = 0`` gives ``(nan, nan)``.
    z : float
        Normal quantile (1.96: 95 %).

    Returns
    -------
    (low, high) : tuple of float
        ``centre -+ halfwidth`` with ``p = k/n``,
        ``centre = (p + z²/(2n)) / (1 + z²/n)`` and
        ``halfwidth = z sqrt(p(1-p)/n + z²/(4n²)) / (1 + z²/n)``; exactly 0
        (1) at ``k = 0`` (``k = n``), where the formula gives it but for rounding.
    """
    if n <= 0:
        return (math.nan, math.nan)
    if not 0 <= k <= n:
        raise ValueError(f"k must be in [0, n] (got k={k}, n={n})")
    p = k / n
    z2 = z * z
    denominator = 1.0 + z2 / n
    centre = (p + z2 / (2 * n)) / denominator
    half = z * math.sqrt(p * (1 - p) / n + z2 / (4 * n * n)) / denominator
    low = 0.0 if k == 0 else max(0.0, centre - half)
    high = 1.0 if k == n else min(1.0, centre + half)
    return (low, high)


@dataclass(frozen=True)
class Rate:
    """A proportion ``k / n`` with its 95 % Wilson interval ``[low, high]``."""

    k: int
    n: int
    value: float
    low: float
    high: float


def rate(k: int, n: int) -> Rate:
    """``k / n`` and its Wilson interval (NaN when ``n = 0``)."""
    low, high = wilson_interval(int(k), int(n))
    return Rate(int(k), int(n), k / n if n else math.nan, low, high)


def percent(x: float | None, digits: int = 1) -> str:
    """A share as a percentage (``–`` when undefined)."""
    return "–" if x is None or not math.isfinite(x) else f"{100 * x:.{digits}f} %"


def rate_text(r: Rate | Mapping[str, Any]) -> str:
    """``k / n = p % [low %, high %]`` (the 95 % Wilson interval); ``no trials`` when n = 0.

    ``r``: a :class:`Rate`, or its fields as a mapping (a study's numbers as
    ``study.json`` holds them).
    """
    if isinstance(r, Mapping):
        r = Rate(int(r["k"]), int(r["n"]), float(r["value"]), float(r["low"]), float(r["high"]))
    if r.n == 0:
        return "no trials"
    return f"{r.k} / {r.n} = {percent(r.value)} [{percent(r.low)}, {percent(r.high)}]"
