"""Element-wise math with the same bits on every x86-64 machine (``quadimpact.libm``).

NumPy runs some float64 ufuncs through SVML on AVX-512 CPUs and through the C
library elsewhere; ``quadimpact.libm`` always takes the C library's scalar
routine. These tests check that it does (element by element, against
:mod:`math`), that the ufuncs the project still calls directly agree with the C
library under this machine's dispatch (CI runs the suite once more with NumPy
limited to AVX2, so both dispatches are checked), that no module of the package
calls a CPU-dependent ufunc or BLAS/LAPACK routine on numbers that reach a
result, and that a run's summary is the same whatever NumPy dispatches to.
"""

from __future__ import annotations

import ast
import ctypes
import ctypes.util
import json
import math
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import quadimpact
from quadimpact import libm

from cpu_dispatch import avx2_limit

pytestmark = pytest.mark.pinned  # CI runs these again under NumPy's AVX2 dispatch
ROOT = Path(quadimpact.__file__).resolve().parent
RNG = np.random.default_rng(20261205)
X = RNG.standard_normal(20_000) * 10.0 ** RNG.integers(-3, 3, 20_000)
Y = RNG.standard_normal(20_000)
U = RNG.uniform(-1.0, 1.0, 20_000)


@pytest.mark.parametrize(
    ("fn", "ref", "args"),
    [
        (libm.arctan2, math.atan2, (Y, X)),
        (libm.arccos, math.acos, (U,)),
        (libm.arcsin, math.asin, (U,)),
        (libm.arctan, math.atan, (X,)),
        (libm.exp, math.exp, (Y,)),
        (libm.log, math.log, (np.abs(X),)),
    ],
    ids=["arctan2", "arccos", "arcsin", "arctan", "exp", "log"],
)
def test_each_element_is_the_c_library_result(fn, ref, args):
    got = fn(*args)
    assert got.dtype == np.float64 and got.shape == args[0].shape
    want = np.array([ref(*(float(a[i]) for a in args)) for i in range(len(args[0]))])
    assert got.tobytes() == want.tobytes()
    # shapes kept, scalars give a NumPy float of the same bits
    assert fn(*(a.reshape(100, 200) for a in args)).tobytes() == want.tobytes()
    assert type(fn(*(float(a[7]) for a in args))) is np.float64
    assert fn(*(a[7] for a in args)) == want[7]
    assert fn(*(np.asarray(a[7]) for a in args)) == want[7]


def test_outside_the_domain_the_answer_is_numpys_and_nothing_is_raised():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.isnan(libm.arccos(1.5)) and np.isnan(libm.arcsin(np.array([-2.0]))).all()
        assert libm.log(0.0) == -np.inf and np.isnan(libm.log(-1.0)) and np.isnan(libm.log(np.nan))
        assert libm.exp(1000.0) == np.inf and libm.exp(-1000.0) == 0.0
        assert np.isnan(libm.arctan2(np.nan, 1.0)) and libm.arctan2(0.0, -1.0) == math.pi
    assert libm.arctan2(np.ones((2, 1)), np.ones(3)).shape == (2, 3)  # broadcasting


def _c_hypot() -> object:
    name = ctypes.util.find_library("m")
    if name is None:
        pytest.skip("no C math library found by ctypes")
    fn = ctypes.CDLL(name).hypot
    fn.restype, fn.argtypes = ctypes.c_double, [ctypes.c_double, ctypes.c_double]
    return fn


def test_the_ufuncs_used_directly_are_the_c_library_under_this_dispatch():
    """``np.sin``, ``np.cos`` and ``np.hypot`` are called directly (rotations, vehicles):
    under this machine's dispatch they give the C library's bits, as under AVX2. If a
    NumPy release vectorises them per CPU, this fails, and they must go through libm."""
    assert np.sin(X).tobytes() == np.array([math.sin(v) for v in X]).tobytes()
    assert np.cos(X).tobytes() == np.array([math.cos(v) for v in X]).tobytes()
    c_hypot = _c_hypot()
    want = np.array([c_hypot(a, b) for a, b in zip(X, Y, strict=True)])
    assert np.hypot(X, Y).tobytes() == want.tobytes()


#: Calls whose float64 results depend on the CPU: NumPy ufuncs with SVML loops on
#: AVX-512, and BLAS/LAPACK (kernels chosen per CPU).
CPU_DEPENDENT = {
    "arctan2", "arccos", "arcsin", "arctan", "arccosh", "arcsinh", "arctanh", "exp", "exp2",
    "expm1", "log", "log2", "log10", "log1p", "power", "float_power", "cbrt", "tan", "sinh",
    "cosh", "dot", "vdot", "inner", "matmul", "tensordot", "polyfit", "cov", "corrcoef",
    "correlate", "convolve",
}  # fmt: skip
#: Where such calls stay, and why (none of them reaches a result a test pins or a table holds).
ALLOWED = {
    # validity tests of a vehicle: an eigenvalue's sign, a condition number above 1e12
    ("inputs/vehicle.py", "linalg.eigvalsh"),
    ("inputs/vehicle.py", "linalg.cond"),
}
#: Packages of pictures only: pixel positions, never a number of a table.
PICTURES = ("viz/",)


def _cpu_dependent_calls() -> list[str]:
    found = []
    for path in sorted(ROOT.rglob("*.py")):
        rel = path.relative_to(ROOT).as_posix()
        if rel.startswith(("core/", *PICTURES)):  # core: compiled by Numba, no SVML, no BLAS
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.BinOp) and isinstance(node.op, ast.MatMult):
                if (rel, "@") not in ALLOWED:
                    found.append(f"{rel}:{node.lineno}: @")
            if not isinstance(node, ast.Attribute):
                continue
            name = ast.unparse(node)
            for prefix in ("np.", "numpy."):
                if not name.startswith(prefix):
                    continue
                attr = name[len(prefix) :]
                bad = attr in CPU_DEPENDENT or attr.startswith("linalg.")
                if bad and (rel, attr) not in ALLOWED:
                    found.append(f"{rel}:{node.lineno}: {name}")
    return found


def test_no_module_computes_a_result_with_a_cpu_dependent_call():
    """Results go through ``quadimpact.libm`` and ``quadimpact.linalg`` (a new ``np.arctan2``
    or ``@`` in a module fails here, naming the line)."""
    assert _cpu_dependent_calls() == []


_SUMMARIES = """
import json
from quadimpact import WallApproach, simulate
out = []
for model, heading, incl, speed in (("paper-replica", 0, 15, 0.5), ("default", 45, 20, 1.0)):
    s = simulate(WallApproach(heading_deg=heading, inclination_deg=incl, speed_m_s=speed,
                              model=model)).summary
    s.pop("integrator"); s.pop("cost")  # times, not results
    out.append(s)
print(json.dumps(out))
"""


def test_a_run_does_not_depend_on_numpys_simd_dispatch():
    """The two runs whose inclination at the contact once differed between an AVX-512 and
    an AVX2 machine: the same summaries, bit for bit, with NumPy limited to AVX2."""
    runs = []
    for limit in (None, avx2_limit()):
        env = dict(os.environ)
        env.pop("NPY_DISABLE_CPU_FEATURES", None)
        if limit is not None:
            env["NPY_DISABLE_CPU_FEATURES"] = limit
        out = subprocess.run(
            [sys.executable, "-c", _SUMMARIES], env=env, capture_output=True, text=True, timeout=300
        )
        assert out.returncode == 0, out.stderr
        runs.append(json.loads(out.stdout))
    assert runs[0] == runs[1]
