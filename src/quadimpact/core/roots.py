"""A scalar root in a bracket: Brent's method, step for step as SciPy's ``brentq``.

The wall approach's late start (``core/approach.py``) finds the start time at
which a contact-free run arrives at the wall with the required speed, inside
its compiled solve. Brent's method is written here as steps that ask for the
function's value at one point at a time (reverse communication): the caller
evaluates the function wherever it can (compiled code, or Python through
:func:`brentq`) and hands the value back. The steps are those of SciPy's
``optimize.brentq`` (Brent's method with inverse quadratic extrapolation, as
SciPy implements it in C), so the points asked for and the root are the same
to the bit (``tests/core/test_roots.py`` checks that against SciPy).

The search's state is one float array of ``NBR`` slots (``BR_*``); its units
are the function argument's.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from quadimpact.core.compiled import compiled

__all__ = [
    "BRENT_ASK",
    "BRENT_NO_BRACKET",
    "BRENT_ROOT",
    "NBR",
    "BR_X",
    "brent_next",
    "brent_start",
    "brentq",
]

# the search's state br (NBR)
BR_X = 0  # the point asked for next, or the root once found
BR_X_PREV = 1  # the previous estimate and f there
BR_F_PREV = 2
BR_X_CUR = 3  # the current (best) estimate and f there
BR_F_CUR = 4
BR_X_BLK = 5  # the far end of the bracket and f there
BR_F_BLK = 6
BR_S_PREV = 7  # the step before last and the last step
BR_S_CUR = 8
BR_XTOL = 9
BR_RTOL = 10
BR_ITER = 11  # iterations done
BR_MAXITER = 12
BR_PHASE = 13  # what the value handed back is: f(a), f(b), or f at an iterate
NBR = 14

BRENT_ASK = 0  # evaluate the function at br[BR_X] and call brent_next again
BRENT_ROOT = 1  # br[BR_X] is the root (or the last estimate at the iteration limit)
BRENT_NO_BRACKET = -1  # f(a) and f(b) have the same sign

_PHASE_A = 0.0
_PHASE_B = 1.0
_PHASE_ITERATE = 2.0


@compiled
def brent_start(br: np.ndarray, a: float, b: float, xtol: float, rtol: float, maxiter: int) -> None:
    """Start a search in ``[a, b]`` to ``xtol + rtol |x|``: the first point asked is ``a``."""
    br[:] = 0.0
    br[BR_X_PREV] = a
    br[BR_X_CUR] = b
    br[BR_XTOL] = xtol
    br[BR_RTOL] = rtol
    br[BR_MAXITER] = maxiter
    br[BR_PHASE] = _PHASE_A
    br[BR_X] = a


@compiled
def brent_next(br: np.ndarray, fx: float) -> int:
    """Take ``fx = f(br[BR_X])``; return ``BRENT_ASK``, ``BRENT_ROOT`` or ``BRENT_NO_BRACKET``."""
    phase = br[BR_PHASE]
    if phase == _PHASE_A:
        br[BR_F_PREV] = fx
        br[BR_PHASE] = _PHASE_B
        br[BR_X] = br[BR_X_CUR]
        return BRENT_ASK
    x_prev = br[BR_X_PREV]
    f_prev = br[BR_F_PREV]
    x_cur = br[BR_X_CUR]
    f_cur = fx
    if phase == _PHASE_B:
        if f_prev * f_cur > 0.0:
            return BRENT_NO_BRACKET
        if f_prev == 0.0:
            br[BR_X] = x_prev
            return BRENT_ROOT
        if f_cur == 0.0:
            br[BR_X] = x_cur
            return BRENT_ROOT
    if br[BR_ITER] >= br[BR_MAXITER]:
        br[BR_X] = x_cur
        return BRENT_ROOT
    x_blk = br[BR_X_BLK]
    f_blk = br[BR_F_BLK]
    s_prev = br[BR_S_PREV]
    s_cur = br[BR_S_CUR]
    xtol = br[BR_XTOL]
    rtol = br[BR_RTOL]
    if f_prev != 0.0 and f_cur != 0.0 and (f_prev < 0.0) != (f_cur < 0.0):
        x_blk, f_blk = x_prev, f_prev  # the root lies between x_cur and x_prev
        s_prev = s_cur = x_cur - x_prev
    if abs(f_blk) < abs(f_cur):  # x_cur the best estimate so far
        x_prev, x_cur, x_blk = x_cur, x_blk, x_cur
        f_prev, f_cur, f_blk = f_cur, f_blk, f_cur
    delta = (xtol + rtol * abs(x_cur)) / 2.0
    s_bis = (x_blk - x_cur) / 2.0
    if f_cur == 0.0 or abs(s_bis) < delta:
        br[BR_X] = x_cur
        return BRENT_ROOT
    if abs(s_prev) > delta and abs(f_cur) < abs(f_prev):
        if x_prev == x_blk:  # secant
            s_try = -f_cur * (x_cur - x_prev) / (f_cur - f_prev)
        else:  # inverse quadratic extrapolation
            d_prev = (f_prev - f_cur) / (x_prev - x_cur)
            d_blk = (f_blk - f_cur) / (x_blk - x_cur)
            s_try = -f_cur * (f_blk * d_blk - f_prev * d_prev) / (d_blk * d_prev * (f_blk - f_prev))
        if 2.0 * abs(s_try) < min(abs(s_prev), 3.0 * abs(s_bis) - delta):
            s_prev, s_cur = s_cur, s_try  # a good short step
        else:
            s_prev = s_cur = s_bis  # bisect
    else:
        s_prev = s_cur = s_bis  # bisect
    x_prev, f_prev = x_cur, f_cur
    if abs(s_cur) > delta:
        x_cur += s_cur
    elif s_bis > 0.0:
        x_cur += delta
    else:
        x_cur -= delta
    br[BR_X_PREV] = x_prev
    br[BR_F_PREV] = f_prev
    br[BR_X_CUR] = x_cur
    br[BR_X_BLK] = x_blk
    br[BR_F_BLK] = f_blk
    br[BR_S_PREV] = s_prev
    br[BR_S_CUR] = s_cur
    br[BR_ITER] += 1.0
    br[BR_PHASE] = _PHASE_ITERATE
    br[BR_X] = x_cur
    return BRENT_ASK


def brentq(
    f: Callable[[float], float],
    a: float,
    b: float,
    xtol: float = 2e-12,
    rtol: float = 8.881784197001252e-16,
    maxiter: int = 100,
) -> float:
    """A root of the Python function ``f`` in ``[a, b]`` (the compiled steps driven from Python).

    Parameters
    ----------
    f : callable
        The function (float -> float).
    a, b : float
        The bracket; ``f(a)`` and ``f(b)`` must differ in sign.
    xtol, rtol : float
        The root is found to ``xtol + rtol * |x|`` (SciPy's defaults).
    maxiter : int
        Most iterations.

    Returns
    -------
    float
        The root (the last estimate when ``maxiter`` is reached, as SciPy
        returns with ``disp=False``).

    Raises
    ------
    ValueError
        If ``f(a)`` and ``f(b)`` have the same sign.
    """
    br = np.zeros(NBR)
    brent_start(br, float(a), float(b), float(xtol), float(rtol), int(maxiter))
    while True:
        code = brent_next(br, float(f(float(br[BR_X]))))
        if code == BRENT_ROOT:
            return float(br[BR_X])
        if code == BRENT_NO_BRACKET:
            raise ValueError("brentq: f(a) and f(b) must have different signs")
