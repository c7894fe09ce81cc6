"""Small linear algebra with a fixed order of operations (``quadimpact.linalg``).

Exact to rounding against NumPy/LAPACK, and the same bits whatever BLAS
kernels the machine picks (a run's inputs must not depend on the CPU).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from quadimpact.linalg import (
    dot,
    inverse,
    lstsq,
    lu_factor,
    lu_solve,
    matvec,
    matvec_t,
    norm,
    solve,
)

pytestmark = pytest.mark.pinned  # CI runs these again under NumPy's AVX2 dispatch


def test_solve_and_inverse_agree_with_lapack_to_rounding():
    rng = np.random.default_rng(3)
    for _ in range(200):
        a = rng.standard_normal((4, 4)) + 4.0 * np.eye(4)
        b = rng.standard_normal(4)
        assert np.allclose(solve(a, b), np.linalg.solve(a, b), rtol=1e-13, atol=1e-13)
        assert np.allclose(inverse(a) @ a, np.eye(4), atol=1e-13)


def test_solve_pivots_and_refuses_a_singular_matrix():
    # a zero leading pivot needs the row exchange
    a = np.array([[0.0, 1.0], [1.0, 0.0]])
    assert solve(a, [2.0, 3.0]).tolist() == [3.0, 2.0]
    with pytest.raises(ValueError, match="singular"):
        solve(np.ones((3, 3)), np.ones(3))


def _eliminate_augmented(a: np.ndarray, b: np.ndarray) -> list[float]:
    """The textbook form: ``[A | b]`` eliminated with partial pivoting, then back-substituted."""
    n = len(a)
    m = [[float(v) for v in a[i]] + [float(b[i])] for i in range(n)]
    for k in range(n):
        p = max(range(k, n), key=lambda i: abs(m[i][k]))
        m[k], m[p] = m[p], m[k]
        for i in range(k + 1, n):
            f = m[i][k] / m[k][k]
            for j in range(k, n + 1):
                m[i][j] -= f * m[k][j]
    x = [0.0] * n
    for i in reversed(range(n)):
        s = m[i][n]
        for k in range(i + 1, n):
            s -= m[i][k] * x[k]
        x[i] = s / m[i][i]
    return x


def test_a_factorisation_reused_gives_the_bits_of_eliminating_each_system():
    """``lu_solve(lu_factor(A), b)`` (A eliminated once, e.g. per vehicle) is, bit for bit,
    the elimination of ``[A | b]`` for every ``b``."""
    rng = np.random.default_rng(11)
    for n in (1, 2, 4, 5):
        for _ in range(100):
            a = rng.standard_normal((n, n)) * 10.0 ** rng.integers(-4, 5)
            a[0, 0] *= 1e-3  # pivoting needed
            lu = lu_factor(a)
            for _ in range(5):
                b = rng.standard_normal(n)
                assert lu_solve(lu, b).tolist() == _eliminate_augmented(a, b)
                assert lu_solve(lu, b[:, None])[:, 0].tolist() == _eliminate_augmented(a, b)
                assert solve(a, b).tolist() == _eliminate_augmented(a, b)


def test_products_sum_in_index_order():
    a = np.array([1e16, 1.0, -1e16])
    b = np.ones(3)
    assert dot(a, b) == (1e16 + 1.0) - 1e16  # not a pairwise or FMA-reordered sum
    m = np.arange(9.0).reshape(3, 3)
    v = np.array([1.0, -2.0, 0.5])
    assert matvec(m, v).tolist() == [sum(m[i, k] * v[k] for k in range(3)) for i in range(3)]
    assert matvec_t(m, v).tolist() == [sum(m[k, i] * v[k] for k in range(3)) for i in range(3)]
    assert norm([3.0, 4.0]) == 5.0
    stacked = matvec(np.stack([m, 2 * m]), np.stack([v, v]))
    assert stacked.shape == (2, 3) and stacked[1].tolist() == (2 * matvec(m, v)).tolist()


def test_one_vector_products_with_python_floats_are_the_array_path_bit_for_bit():
    """A vector (dot) or a matrix and a vector (matvec) of floats take the Python-float path;
    stacked inputs the array path: the same bits."""
    rng = np.random.default_rng(11)
    a = rng.standard_normal((3000, 4)) * rng.uniform(1e-8, 1e8, size=(3000, 1))
    b = rng.standard_normal((3000, 4))
    a[:100, 1] = -0.0
    for n in (1, 3, 4):
        stacked = dot(a[:, :n], b[:, :n])  # the array path
        for i in range(len(a)):
            single = dot(a[i, :n].copy(), b[i, :n].copy())
            assert type(single) is float and single == stacked[i]
            assert np.float64(single).tobytes() == stacked[i].tobytes()
    assert norm(np.array([3.0, 4.0])) == 5.0 and dot(np.array([np.nan]), np.ones(1)) != 0.0
    m = rng.standard_normal((500, 3, 4)) * 1e3
    stacked = matvec(m, b[:500])  # the array path
    for i in range(500):
        single = matvec(m[i].copy(), b[i].copy())
        assert single.shape == (3,) and single.tobytes() == stacked[i].tobytes()


def test_least_squares_fits_exact_data_exactly_and_agrees_with_lapack():
    """Exact data give the polynomial back; noisy data the LAPACK solution and
    ``(A^T A)^-1`` to rounding; a dependent column (all zeros: the fit's
    change-point column before the change) gets 0, as LAPACK's minimum-norm solution."""
    t = np.linspace(-0.3, 0.0, 31)
    a = np.vander(t, 3)
    coef, _ = lstsq(a, 2.0 * t**2 - 0.5 * t + 1.25)
    assert np.allclose(coef, [2.0, -0.5, 1.25], rtol=1e-12, atol=1e-12)
    rng = np.random.default_rng(5)
    for _ in range(50):
        tt = np.sort(rng.uniform(-0.4, 0.0, 40))
        a = np.vander(tt, 4)
        y = rng.standard_normal(40)
        coef, g = lstsq(a, y)
        assert np.allclose(coef, np.linalg.lstsq(a, y, rcond=None)[0], rtol=1e-9, atol=1e-9)
        assert np.allclose(g, np.linalg.inv(a.T @ a), rtol=1e-7, atol=1e-9)
    a = np.column_stack([np.ones(20), t[:20], np.zeros(20)])
    coef, g = lstsq(a, rng.standard_normal(20))
    assert coef[2] == 0.0 and (g[2] == 0.0).all() and (g[:, 2] == 0.0).all()


_SUMMARY = """
import json
from quadimpact import WallApproach, simulate
s = simulate(WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75)).summary
s.pop("integrator")
s.pop("cost")  # CPU times: the only numbers that differ from one run to the next
print(json.dumps(s))
"""


@pytest.mark.parametrize("core", ["Nehalem", "Haswell"])
def test_a_run_does_not_depend_on_the_blas_kernels(core):
    """The paper example's summary with OpenBLAS forced onto other kernels: the same bits."""
    env = dict(os.environ)
    runs = []
    for coretype in (None, core):
        if coretype is None:
            env.pop("OPENBLAS_CORETYPE", None)
        else:
            env["OPENBLAS_CORETYPE"] = coretype
        out = subprocess.run(
            [sys.executable, "-c", _SUMMARY], env=env, capture_output=True, text=True, timeout=300
        )
        assert out.returncode == 0, out.stderr
        runs.append(json.loads(out.stdout))
    assert runs[0] == runs[1]
