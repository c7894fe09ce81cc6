"""Element-wise transcendental functions through the C library: the same bits on every machine.

NumPy picks the loop of a ufunc for the CPU it runs on. On a CPU with AVX-512,
``np.arctan2``, ``np.arccos``, ``np.arcsin``, ``np.arctan``, ``np.exp``,
``np.log``, ``np.power``, ``np.cbrt`` and a few more run vectorised
approximations (Intel's SVML) that differ from the C library's ``atan2``,
``acos``... in the last bits of about one result in ten; on a CPU with AVX2
only, NumPy calls the C library one element at a time. A number computed with
those ufuncs is therefore not the same on two x86-64 machines, and a summary
that pins it (the inclination at the first contact of a Figure 4 run) changes
in its last digit from one to the other.

The functions here call the C library's scalar routine (through :mod:`math`)
for every element, on every machine: the numbers of an AVX2 machine, and the
same numbers on an AVX-512 one. Every transcendental function whose result
reaches a run's summary, a table of a study or a pinned test goes through
them. ``np.sin``, ``np.cos``, ``np.hypot``, ``np.tanh``, ``np.sqrt`` and the
arithmetic ufuncs give the same bits under every dispatch NumPy has today
(``tests/test_libm.py`` checks this under the machine's own dispatch; CI runs
the suite again with NumPy limited to AVX2) and are used directly.

Outside the functions' domains they return what NumPy returns (``nan``,
``-inf``), never an exception. The cost is a Python call per element (about
0.1 us): fine for a run's few thousand samples and a study's thousands of rows.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["arccos", "arcsin", "arctan", "arctan2", "exp", "log"]


def _acos(x: float) -> float:
    return math.acos(x) if -1.0 <= x <= 1.0 else math.nan


def _asin(x: float) -> float:
    return math.asin(x) if -1.0 <= x <= 1.0 else math.nan


def _log(x: float) -> float:
    if x > 0.0:
        return math.log(x)  # inf -> inf
    if x == 0.0:
        return -math.inf
    return math.nan  # negative or NaN


def _exp(x: float) -> float:
    try:
        return math.exp(x)
    except OverflowError:
        return math.inf


def _unary(fn: Callable[[float], float], name: str, doc: str) -> Callable[[ArrayLike], Any]:
    """``fn`` applied to every element: a NumPy float for a scalar, float64 array otherwise."""
    ufunc = np.frompyfunc(lambda v: fn(float(v)), 1, 1)

    def apply(x: ArrayLike) -> Any:
        if type(x) in _SCALARS:
            return np.float64(fn(float(x)))
        a = np.asarray(x, dtype=np.float64)
        if a.ndim == 0:
            return np.float64(fn(float(a)))
        return ufunc(a).astype(np.float64)

    apply.__name__ = apply.__qualname__ = name
    apply.__doc__ = doc
    return apply


_SCALARS = (float, int, np.float64)
_atan2_ufunc = np.frompyfunc(lambda y, x: math.atan2(float(y), float(x)), 2, 1)


def arctan2(y: ArrayLike, x: ArrayLike) -> Any:
    """``atan2(y, x)`` element-wise (rad, in [-pi, pi]), broadcast as ``np.arctan2`` does.

    A NumPy float for scalar arguments, an array of float64 otherwise.
    """
    if type(y) in _SCALARS and type(x) in _SCALARS:
        return np.float64(math.atan2(float(y), float(x)))
    a, b = np.asarray(y, dtype=np.float64), np.asarray(x, dtype=np.float64)
    if a.ndim == 0 and b.ndim == 0:
        return np.float64(math.atan2(float(a), float(b)))
    return _atan2_ufunc(a, b).astype(np.float64)


arccos = _unary(_acos, "arccos", "``acos`` element-wise (rad, in [0, pi]); nan outside [-1, 1].")
arcsin = _unary(_asin, "arcsin", "``asin`` element-wise (rad, in [-pi/2, pi/2]); nan off [-1, 1].")
arctan = _unary(math.atan, "arctan", "``atan`` element-wise (rad, in [-pi/2, pi/2]).")
exp = _unary(_exp, "exp", "``exp`` element-wise; inf where it overflows.")
log = _unary(_log, "log", "Natural ``log`` element-wise; -inf at 0, nan below 0.")
