"""Small dense linear algebra in a fixed order of operations: the same bits on every machine.

NumPy's ``@``, ``dot``, ``linalg.inv``, ``linalg.solve`` and ``linalg.norm``
call BLAS and LAPACK, whose kernels are chosen for the CPU at run time
(OpenBLAS has SkylakeX, Haswell, Zen... kernels). Their results differ in the
last bits from one machine to another, and a run through an impact amplifies
such a difference (a 1e-16 change of the inverse allocation moves
``delta_init_m`` by 1e-12, the response of a later impact by more). Every
number that feeds a run, its summary or a study's table is computed with
these functions instead: plain IEEE multiplications and additions in index
order (NumPy's element-wise ufuncs, or Python floats), which every machine
rounds alike.

The sizes here are tiny (3x3 and 4x4). One vector, or one matrix and one vector,
of floats take a path with Python floats (the same operations; a run's summary
calls them a few times).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "LU",
    "dot",
    "inverse",
    "lstsq",
    "lu_factor",
    "lu_solve",
    "matvec",
    "matvec_t",
    "norm",
    "pseudo_inverse",
    "solve",
]


def solve(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """``x`` with ``A x = b`` (A square), by Gaussian elimination with partial pivoting.

    The same operations as :func:`lu_solve` of :func:`lu_factor` (which see).

    Raises
    ------
    ValueError
        ``A`` is singular (a zero pivot).
    """
    return lu_solve(lu_factor(a), b)


class LU(NamedTuple):
    """``A`` eliminated by :func:`lu_factor`: what :func:`lu_solve` applies to a right-hand side."""

    pivots: tuple[int, ...]
    """The row swapped with row ``k`` at step ``k``."""
    factors: tuple[tuple[float, ...], ...]
    """At step ``k``, the multiples of row ``k`` taken from rows ``k+1..n-1``."""
    upper: tuple[tuple[float, ...], ...]
    """The eliminated matrix (its upper triangle is used)."""


def lu_factor(a: ArrayLike) -> LU:
    """Gaussian elimination with partial pivoting of a square ``A`` (for :func:`lu_solve`).

    Raises
    ------
    ValueError
        ``A`` is singular (a zero pivot).
    """
    m = [[float(v) for v in row] for row in np.asarray(a, dtype=np.float64)]
    n = len(m)
    pivots: list[int] = []
    factors: list[tuple[float, ...]] = []
    for k in range(n):
        p = max(range(k, n), key=lambda i: abs(m[i][k]))
        if m[p][k] == 0.0:
            raise ValueError("solve: the matrix is singular")
        if p != k:
            m[k], m[p] = m[p], m[k]
        pivots.append(p)
        fs = []
        for i in range(k + 1, n):
            f = m[i][k] / m[k][k]
            for j in range(k, n):
                m[i][j] -= f * m[k][j]
            fs.append(f)
        factors.append(tuple(fs))
    return LU(tuple(pivots), tuple(factors), tuple(tuple(row) for row in m))


def lu_solve(lu: LU, b: ArrayLike) -> np.ndarray:
    """``x`` with ``A x = b`` from ``lu = lu_factor(A)``: the row operations of the
    elimination applied to ``b`` in the same order, then back substitution (the
    bits of eliminating ``[A | b]`` at once). ``b``: shape (n,) or (n, k)."""
    m = lu.upper
    n = len(m)
    rhs = np.asarray(b, dtype=np.float64)
    if rhs.ndim == 1:
        return _lu_solve_vector(lu, rhs.tolist())
    cols = rhs.shape[1]
    r = rhs.reshape(n, cols).tolist()  # Python floats
    for k in range(n):
        p = lu.pivots[k]
        if p != k:
            r[k], r[p] = r[p], r[k]
        for i, f in zip(range(k + 1, n), lu.factors[k], strict=True):
            for j in range(cols):
                r[i][j] -= f * r[k][j]
    x = [[0.0] * cols for _ in range(n)]
    for i in reversed(range(n)):
        for j in range(cols):
            s = r[i][j]
            for k in range(i + 1, n):
                s -= m[i][k] * x[k][j]
            x[i][j] = s / m[i][i]
    return np.array(x, dtype=np.float64)


def _lu_solve_vector(lu: LU, r: list[float]) -> np.ndarray:
    """:func:`lu_solve` of one right-hand side (a list, changed): the same operations in the
    same order on plain floats, without the columns' loops (a run's trim solves one)."""
    m = lu.upper
    n = len(m)
    for k in range(n):
        p = lu.pivots[k]
        if p != k:
            r[k], r[p] = r[p], r[k]
        rk = r[k]
        for i, f in zip(range(k + 1, n), lu.factors[k], strict=True):
            r[i] -= f * rk
    x = [0.0] * n
    for i in reversed(range(n)):
        row = m[i]
        s = r[i]
        for k in range(i + 1, n):
            s -= row[k] * x[k]
        x[i] = s / row[i]
    return np.array(x, dtype=np.float64)


def inverse(a: ArrayLike) -> np.ndarray:
    """The inverse of a square matrix (:func:`solve` with the identity)."""
    n = np.asarray(a).shape[0]
    return solve(a, np.eye(n))


def pseudo_inverse(a: ArrayLike) -> np.ndarray:
    """The Moore-Penrose pseudo-inverse ``A^T (A A^T)^-1`` of a full-row-rank ``A`` (r x c, r <= c).

    ``A A^T`` and the product are summed in index order (:func:`dot`), the
    inverse is :func:`inverse`: the same bits on every machine.
    """
    a = np.asarray(a, dtype=np.float64)
    gram = dot(a[:, None, :], a[None, :, :])  # (r, r): sum_j a[i, j] a[k, j]
    g_inv = inverse(gram)
    return dot(a.T[:, None, :], g_inv.T[None, :, :])  # (c, r): sum_k a[k, j] g_inv[k, i]


def dot(a: ArrayLike, b: ArrayLike) -> np.ndarray | float:
    """``sum_k a[..., k] b[..., k]`` over the last axis, summed in index order."""
    if _vector(a) and _vector(b) and len(a) == len(b):
        # two vectors of floats: the same products and sums with Python floats (about
        # 5x faster; IEEE multiplications and additions round as NumPy's do)
        return _float_dot(a.tolist(), b.tolist())
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    s = a[..., 0] * b[..., 0]
    for k in range(1, a.shape[-1]):
        s = s + a[..., k] * b[..., k]
    return float(s) if np.ndim(s) == 0 else s


def _float_dot(xs: list[float], ys: list[float]) -> float:
    """``sum_k xs[k] ys[k]`` of Python floats, summed in index order (:func:`dot`'s order)."""
    s = xs[0] * ys[0]
    for k in range(1, len(xs)):
        s = s + xs[k] * ys[k]
    return s


def _vector(a: object) -> bool:
    """Whether ``a`` is a non-empty 1-D float64 array (the fast path of :func:`dot`)."""
    return type(a) is np.ndarray and a.ndim == 1 and a.dtype == np.float64 and len(a) > 0


def norm(a: ArrayLike) -> np.ndarray | float:
    """Euclidean norm over the last axis (``sqrt(dot(a, a))``)."""
    s = dot(a, a)
    return math.sqrt(s) if isinstance(s, float) else np.sqrt(s)


def matvec(m: ArrayLike, v: ArrayLike) -> np.ndarray:
    """``M v`` for matrices ``(..., r, c)`` and vectors ``(..., c)``, rows summed in index order."""
    if (
        type(m) is np.ndarray
        and m.ndim == 2
        and m.dtype == np.float64
        and _vector(v)
        and m.shape[1] == len(v)
    ):  # one matrix and one vector: :func:`dot`'s Python floats, row by row
        vs = v.tolist()
        return np.array([_float_dot(row, vs) for row in m.tolist()], dtype=np.float64)
    m = np.asarray(m, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    return dot(m, v[..., None, :])


def matvec_t(m: ArrayLike, v: ArrayLike) -> np.ndarray:
    """``M^T v`` for matrices ``(..., r, c)`` and vectors ``(..., r)``."""
    return matvec(np.swapaxes(np.asarray(m, dtype=np.float64), -1, -2), v)


def lstsq(a: ArrayLike, y: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Least squares ``min |A c - y|`` and ``(A^T A)^-1``, by modified Gram-Schmidt.

    For the small fits of the flight logs (``m`` samples of a few columns):
    the columns of ``A`` are orthogonalised one after the other (``A = Q R``),
    ``y`` is projected on them in the same order, and ``R c = Q^T y`` is solved
    by back substitution, every sum in index order. A column that is (to
    ``max(m, n) * eps`` of its norm) a combination of the earlier ones is
    left out, its coefficient 0, as LAPACK's minimum-norm solution does for an
    exactly dependent column (for instance a column of zeros).

    Parameters
    ----------
    a : array_like, shape (m, n)
        The design matrix.
    y : array_like, shape (m,)
        The observations.

    Returns
    -------
    coef : numpy.ndarray, shape (n,)
        The coefficients.
    gram_inverse : numpy.ndarray, shape (n, n)
        ``(A^T A)^-1`` (``R^-1 R^-T``), rows and columns of left-out columns 0;
        times the residual variance it is the coefficients' covariance.
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.array(y, dtype=np.float64)
    m, n = a.shape
    q = np.zeros((n, m))
    r = np.zeros((n, n))
    kept: list[int] = []
    for j in range(n):
        v = a[:, j].copy()
        size = math.sqrt(_sum_sq(v))
        for i in kept:
            r[i, j] = _sum_prod(q[i], v)
            v = v - r[i, j] * q[i]
        r_jj = math.sqrt(_sum_sq(v))
        if r_jj <= max(m, n) * np.finfo(np.float64).eps * size or r_jj == 0.0:
            continue  # dependent on the earlier columns: left out
        r[j, j] = r_jj
        q[j] = v / r_jj
        kept.append(j)
    c = np.zeros(n)
    for i in kept:
        c[i] = _sum_prod(q[i], b)
        b = b - c[i] * q[i]
    coef = np.zeros(n)
    for i in reversed(kept):
        s = c[i]
        for k in kept:
            if k > i:
                s -= r[i, k] * coef[k]
        coef[i] = s / r[i, i]
    # R^-1 of the kept columns, then R^-1 R^-T
    r_inv = np.zeros((n, n))
    for col in kept:
        for i in reversed(kept):
            if i > col:
                continue
            s = 1.0 if i == col else 0.0
            for k in kept:
                if i < k <= col:
                    s -= r[i, k] * r_inv[k, col]
            r_inv[i, col] = s / r[i, i]
    gram_inverse = np.zeros((n, n))
    for i in range(n):
        for j in range(n):
            gram_inverse[i, j] = _float_dot(r_inv[i].tolist(), r_inv[j].tolist())
    return coef, gram_inverse


def _sum_prod(a: np.ndarray, b: np.ndarray) -> float:
    """``sum(a * b)`` of two float64 vectors: NumPy's pairwise sum, the same on every CPU."""
    return float(np.add.reduce(a * b))


def _sum_sq(a: np.ndarray) -> float:
    return _sum_prod(a, a)
