"""The late start's root finder (``core/roots.py``, compiled steps) takes SciPy's
``brentq`` steps exactly: the same points evaluated, the same root, to the bit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadimpact.core.roots import brentq

optimize = pytest.importorskip("scipy.optimize")

EPS = np.finfo(float).eps
FUNCTIONS = [
    (lambda x: x**3 - 2.0 * x - 5.0, 2.0, 3.0),
    (lambda x: math.cos(x) - x, 0.0, 1.0),
    (lambda x: math.exp(x) - 10.0, -3.0, 5.0),
    (lambda x: (x - 0.3) ** 9, 0.0, 1.0),  # a flat root: many bisections
    (lambda x: math.atan(50.0 * (x - 0.123)), -1.0, 1.0),  # a steep one
    (lambda x: x - 1e-300, 0.0, 1.0),
    (lambda x: 1.0 / (x - 0.5) if x != 0.5 else 0.0, 0.0, 1.0),  # a pole, no root
    (lambda x: math.tanh(x) - 0.4 + 1e-3 * math.sin(40.0 * x), -2.0, 3.0),
]


def _traced(f):
    calls: list[float] = []

    def g(x: float) -> float:
        calls.append(x)
        return f(x)

    return g, calls


@pytest.mark.parametrize("k", range(len(FUNCTIONS)))
@pytest.mark.parametrize("xtol, rtol", [(2e-12, 4 * EPS), (1e-14, 4 * EPS), (1e-6, 1e-6)])
def test_the_same_steps_and_root_as_scipy(k, xtol, rtol):
    f, a, b = FUNCTIONS[k]
    ours, our_calls = _traced(f)
    theirs, their_calls = _traced(f)
    x = brentq(ours, a, b, xtol=xtol, rtol=rtol)
    y = optimize.brentq(theirs, a, b, xtol=xtol, rtol=rtol, disp=False)
    assert our_calls == their_calls and x == y  # bit for bit, every evaluation
    assert abs(f(x)) <= abs(f(a)) and abs(f(x)) <= abs(f(b))


def test_an_end_that_is_a_root_and_a_bad_bracket():
    assert brentq(lambda x: x - 1.0, 1.0, 2.0) == 1.0
    assert brentq(lambda x: x - 2.0, 1.0, 2.0) == 2.0
    with pytest.raises(ValueError, match="different signs"):
        brentq(lambda x: x * x + 1.0, -1.0, 1.0)


def test_the_iteration_limit_returns_the_last_estimate_as_scipy():
    f = FUNCTIONS[3][0]
    ours, our_calls = _traced(f)
    theirs, their_calls = _traced(f)
    x = brentq(ours, 0.0, 1.0, xtol=1e-300, rtol=4 * EPS, maxiter=5)
    y = optimize.brentq(theirs, 0.0, 1.0, xtol=1e-300, rtol=4 * EPS, maxiter=5, disp=False)
    assert our_calls == their_calls and x == y
