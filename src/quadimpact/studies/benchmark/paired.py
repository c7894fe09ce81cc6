"""Paired differences of success between two rows flown on the same trials.

Every row of the benchmark flies the same seeded trials, so two rows are
compared trial by trial. Of the ``n`` trials valid in both, ``a`` succeed in
both, ``b`` in the first row only, ``c`` in the second only and ``d`` in
neither. The difference of the success shares is ``(b - c) / n``; its 95 %
interval is Newcombe's hybrid score interval for paired proportions (his
method 10: R. G. Newcombe, "Improved confidence intervals for the difference
between binomial proportions based on paired data", Statistics in Medicine 17,
1998), built from the Wilson intervals of the two shares and their
correlation. A difference whose interval contains 0 is one the suite cannot
resolve.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from quadimpact.studies.statistics import wilson_interval

__all__ = ["PairedDifference", "paired_difference"]


@dataclass(frozen=True)
class PairedDifference:
    """The difference of two rows' success shares on the same trials, with its interval.

    Attributes
    ----------
    n : int
        Trials valid in both rows.
    only_first, only_second : int
        Trials only the first (second) row succeeds on.
    difference, low, high : float
        The first share minus the second and its 95 % interval (fractions; NaN
        when ``n = 0``).
    """

    n: int
    only_first: int
    only_second: int
    difference: float
    low: float
    high: float

    @property
    def resolved(self) -> bool:
        """Whether the interval excludes 0 (the suite tells the two rows apart)."""
        return self.n > 0 and (self.low > 0.0 or self.high < 0.0)


def paired_difference(first: np.ndarray, second: np.ndarray) -> PairedDifference:
    """Newcombe's interval (module docstring) of ``mean(first) - mean(second)``.

    Parameters
    ----------
    first, second : numpy.ndarray of bool, same length
        Each trial's success in the two rows (only trials valid in both).
    """
    x = np.asarray(first, dtype=bool)
    y = np.asarray(second, dtype=bool)
    if x.shape != y.shape:
        raise ValueError(f"paired_difference: {x.shape} and {y.shape} trials differ")
    n = int(x.size)
    if n == 0:
        return PairedDifference(0, 0, 0, math.nan, math.nan, math.nan)
    a = int((x & y).sum())
    b = int((x & ~y).sum())
    c = int((~x & y).sum())
    d = n - a - b - c
    p1, p2 = (a + b) / n, (a + c) / n
    l1, u1 = wilson_interval(a + b, n)
    l2, u2 = wilson_interval(a + c, n)
    margins = (a + b) * (c + d) * (a + c) * (b + d)
    phi = (a * d - b * c) / math.sqrt(margins) if margins > 0 else 0.0
    diff = p1 - p2
    below = (p1 - l1) ** 2 - 2.0 * phi * (p1 - l1) * (u2 - p2) + (u2 - p2) ** 2
    above = (u1 - p1) ** 2 - 2.0 * phi * (u1 - p1) * (p2 - l2) + (p2 - l2) ** 2
    low = max(-1.0, diff - math.sqrt(max(below, 0.0)))
    high = min(1.0, diff + math.sqrt(max(above, 0.0)))
    return PairedDifference(n, b, c, diff, low, high)
