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

from quadimpact.linalg import dot, inverse, matvec, matvec_t, norm, solve


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
