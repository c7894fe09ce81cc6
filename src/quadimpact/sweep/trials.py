"""Random trials drawn one at a time: a sweep's ``trials`` (each trial its own random stream).

A sweep's ``sample`` draws every value at once from one generator; its
``trials`` give trial ``i`` a random stream of its own, seeded with the
sweep's seed and ``i`` (NumPy's PCG64 with ``SeedSequence(seed,
spawn_key=(i,))``). Trial ``i`` is then computed from ``(seed, i)`` alone, when
it is needed: a study of a million trials holds none of them in memory, and the
first thousand trials of a study are the same whatever its size. The
recovery study's Monte Carlo (the authors' distribution) is such a sweep.

Each trial draws one uniform number per field of ``ranges``, in their order
(``low + (high - low) u``), then, with a ``seed_field``, an integer in
``[0, 2**53)`` for it (a run's own seed: IMU noise and the like, exact as
the float the sweep stores).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from itertools import product
from typing import Any

import numpy as np

__all__ = ["SEED_LIMIT", "trial_corners", "trial_draws", "trial_rng"]

#: Drawn seeds are below 2**53, so that they are exact as the sweep's float inputs.
SEED_LIMIT = 2**53
#: Up to this many fields, every corner of the ranges' box is validated; beyond, each
#: field's own low and high (with the other fields at their lows).
ALL_CORNERS_UP_TO = 10


def trial_rng(seed: int, index: int) -> np.random.Generator:
    """Trial ``index``'s own random stream (PCG64) of trials seeded with ``seed``."""
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed, spawn_key=(index,))))


def trial_draws(
    seed: int,
    index: int,
    ranges: Mapping[str, tuple[float, float] | list[float]],
    seed_field: str | None = None,
) -> dict[str, Any]:
    """The values of trial ``index``: each field of ``ranges`` uniform in ``[low, high)``.

    Parameters
    ----------
    seed : int
        The trials' seed, >= 0.
    index : int
        The trial, >= 0.
    ranges : mapping
        Field -> (low, high), in the order the fields are drawn.
    seed_field : str, optional
        A field given an integer in ``[0, SEED_LIMIT)``, drawn after the ranges.

    Returns
    -------
    dict
        Field -> value (floats; the seed field an int).
    """
    rng = trial_rng(seed, index)
    u = rng.random(len(ranges))
    values: dict[str, Any] = {
        name: float(lo + (hi - lo) * x)
        for (name, (lo, hi)), x in zip(ranges.items(), u, strict=True)
    }
    if seed_field is not None:
        values[seed_field] = int(rng.integers(0, SEED_LIMIT))
    return values


def trial_corners(
    ranges: Mapping[str, tuple[float, float] | list[float]], seed_field: str | None = None
) -> Iterator[dict[str, Any]]:
    """The bounds every trial's values lie within, as value sets to validate.

    Every corner of the ranges' box (each field at its low or its high) up to
    :data:`ALL_CORNERS_UP_TO` fields, each field's low and high alone beyond;
    the seed field at 0 and at its largest value.
    """
    names = list(ranges)
    if len(names) <= ALL_CORNERS_UP_TO:
        choices = product(*[(0, 1)] * len(names))
    else:
        choices = iter(
            [tuple(0 for _ in names)]
            + [tuple(int(j == k) for j in range(len(names))) for k in range(len(names))]
        )
    for i, pick in enumerate(choices):
        values: dict[str, Any] = {
            name: float(ranges[name][p]) for name, p in zip(names, pick, strict=True)
        }
        if seed_field is not None:
            values[seed_field] = 0 if i % 2 == 0 else SEED_LIMIT - 1
        yield values
