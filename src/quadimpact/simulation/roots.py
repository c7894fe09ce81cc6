"""A scalar root in a bracket: Brent's method, step for step as SciPy's ``brentq``.

The late start of the wall approach (``approach.py``) finds the start time at
which a contact-free run arrives at the wall with the required speed. It used
SciPy's ``optimize.brentq``, whose import alone costs about 0.25 s in a fresh
process (more than the whole run). :func:`brentq` here takes the same steps
(Brent's method with inverse quadratic extrapolation, as SciPy implements it in
C), so every start time, and every result computed from it, is the same to
the bit; ``tests/simulation/test_roots.py`` checks that against SciPy.
"""

from __future__ import annotations

from collections.abc import Callable

__all__ = ["brentq"]


def brentq(
    f: Callable[[float], float],
    a: float,
    b: float,
    xtol: float = 2e-12,
    rtol: float = 8.881784197001252e-16,
    maxiter: int = 100,
) -> float:
    """A root of ``f`` in ``[a, b]`` where ``f(a)`` and ``f(b)`` differ in sign.

    Parameters
    ----------
    f : callable
        The function (float -> float).
    a, b : float
        The bracket.
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
    x_prev, x_cur = float(a), float(b)
    f_prev, f_cur = f(x_prev), f(x_cur)
    if f_prev * f_cur > 0.0:
        raise ValueError("brentq: f(a) and f(b) must have different signs")
    if f_prev == 0.0:
        return x_prev
    if f_cur == 0.0:
        return x_cur
    x_blk = f_blk = 0.0  # the far end of the bracket and f there
    s_prev = s_cur = 0.0  # the step before last and the last step
    for _ in range(maxiter):
        if f_prev != 0.0 and f_cur != 0.0 and (f_prev < 0.0) != (f_cur < 0.0):
            x_blk, f_blk = x_prev, f_prev  # the root lies between x_cur and x_prev
            s_prev = s_cur = x_cur - x_prev
        if abs(f_blk) < abs(f_cur):  # x_cur the best estimate so far
            x_prev, x_cur, x_blk = x_cur, x_blk, x_cur
            f_prev, f_cur, f_blk = f_cur, f_blk, f_cur
        delta = (xtol + rtol * abs(x_cur)) / 2.0
        s_bis = (x_blk - x_cur) / 2.0
        if f_cur == 0.0 or abs(s_bis) < delta:
            return x_cur
        if abs(s_prev) > delta and abs(f_cur) < abs(f_prev):
            if x_prev == x_blk:  # secant
                s_try = -f_cur * (x_cur - x_prev) / (f_cur - f_prev)
            else:  # inverse quadratic extrapolation
                d_prev = (f_prev - f_cur) / (x_prev - x_cur)
                d_blk = (f_blk - f_cur) / (x_blk - x_cur)
                s_try = (
                    -f_cur * (f_blk * d_blk - f_prev * d_prev) / (d_blk * d_prev * (f_blk - f_prev))
                )
            if 2.0 * abs(s_try) < min(abs(s_prev), 3.0 * abs(s_bis) - delta):
                s_prev, s_cur = s_cur, s_try  # a good short step
            else:
                s_prev = s_cur = s_bis  # bisect
        else:
            s_prev = s_cur = s_bis  # bisect
        x_prev, f_prev = x_cur, f_cur
        x_cur += s_cur if abs(s_cur) > delta else (delta if s_bis > 0.0 else -delta)
        f_cur = f(x_cur)
    return x_cur
