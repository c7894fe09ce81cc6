"""Independent NumPy references for the contact geometry tests: shapes, depths, brute force.

Written from the definitions (docs/OBSTACLES.md), not from the compiled code:
the depth of a point in a plane, a cylinder or a box (minus its signed
distance, vectorised), and the deepest point of a ring by brute force (dense
sampling of the circle, then golden-section refinement around the best
samples, which converges on smooth maxima and on creases alike).
"""

from __future__ import annotations

import math

import numpy as np

from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP


def rotation(rng: np.random.Generator) -> np.ndarray:
    """A random rotation matrix (uniform quaternion)."""
    q = rng.standard_normal(4)
    a, b, c, d = q / np.linalg.norm(q)
    return np.array(
        [
            [a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)],
            [2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b)],
            [2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d],
        ]
    )


def plane_row(point, normal) -> np.ndarray:
    row = np.zeros(SHP.NSHAPE)
    row[SHP.SH_KIND] = L.SHAPE_PLANE
    row[SHP.SH_POINT : SHP.SH_POINT + 3] = point
    row[SHP.SH_NORMAL : SHP.SH_NORMAL + 3] = np.asarray(normal, float) / np.linalg.norm(normal)
    return row


def cylinder_row(point, axis, radius, length=math.inf) -> np.ndarray:
    row = np.zeros(SHP.NSHAPE)
    row[SHP.SH_KIND] = L.SHAPE_CYLINDER
    row[SHP.SH_POINT : SHP.SH_POINT + 3] = point
    row[SHP.SH_NORMAL : SHP.SH_NORMAL + 3] = np.asarray(axis, float) / np.linalg.norm(axis)
    row[SHP.SH_RADIUS] = radius
    row[SHP.SH_LENGTH] = length
    return row


def box_row(centre, half, axes) -> np.ndarray:
    row = np.zeros(SHP.NSHAPE)
    row[SHP.SH_KIND] = L.SHAPE_BOX
    row[SHP.SH_POINT : SHP.SH_POINT + 3] = centre
    row[SHP.SH_HALF : SHP.SH_HALF + 3] = half
    row[SHP.SH_ROT : SHP.SH_ROT + 9] = np.asarray(axes, float).ravel()
    return row


def depth(p: np.ndarray, row: np.ndarray) -> np.ndarray:
    """Depth (minus the signed distance, m) of the points ``p`` (..., 3) in the shape ``row``."""
    p = np.asarray(p, float)
    kind = int(row[SHP.SH_KIND])
    o = row[SHP.SH_POINT : SHP.SH_POINT + 3]
    if kind == L.SHAPE_PLANE:
        return -(p - o) @ row[SHP.SH_NORMAL : SHP.SH_NORMAL + 3]
    if kind == L.SHAPE_CYLINDER:
        e = row[SHP.SH_NORMAL : SHP.SH_NORMAL + 3]
        z = (p - o) @ e
        rho = np.linalg.norm((p - o) - z[..., None] * e, axis=-1)
        a_r = rho - row[SHP.SH_RADIUS]
        if not np.isfinite(row[SHP.SH_LENGTH]):
            return -a_r
        a_z = np.abs(z) - 0.5 * row[SHP.SH_LENGTH]
        inside = np.minimum(np.maximum(a_r, a_z), 0.0)
        outside = np.hypot(np.maximum(a_r, 0.0), np.maximum(a_z, 0.0))
        return -(inside + outside)
    axes = row[SHP.SH_ROT : SHP.SH_ROT + 9].reshape(3, 3)
    q = (p - o) @ axes.T
    a = np.abs(q) - row[SHP.SH_HALF : SHP.SH_HALF + 3]
    inside = np.minimum(a.max(axis=-1), 0.0)
    outside = np.linalg.norm(np.maximum(a, 0.0), axis=-1)
    return -(inside + outside)


def circle(ring, t) -> np.ndarray:
    c, a, b, r = (np.asarray(ring[0:3]), np.asarray(ring[3:6]), np.asarray(ring[6:9]), ring[9])
    t = np.asarray(t, float)
    return c + r * (np.cos(t)[..., None] * a + np.sin(t)[..., None] * b)


def ring_brute_force(ring, row, n: int = 20000, keep: int = 6) -> tuple[float, float]:
    """(deepest depth, its angle) of a ring: dense sampling, then golden-section refinement."""
    ts = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    vals = depth(circle(ring, ts), row)
    h = 2.0 * math.pi / n
    best, best_t = -math.inf, 0.0
    invphi = (math.sqrt(5.0) - 1.0) / 2.0

    def f(t):
        return float(depth(circle(ring, [t]), row)[0])

    for i in np.argsort(vals)[-keep:]:
        lo, hi = ts[i] - h, ts[i] + h
        x1 = hi - invphi * (hi - lo)
        x2 = lo + invphi * (hi - lo)
        f1, f2 = f(x1), f(x2)
        for _ in range(80):
            if f1 >= f2:
                hi, x2, f2 = x2, x1, f1
                x1 = hi - invphi * (hi - lo)
                f1 = f(x1)
            else:
                lo, x1, f1 = x1, x2, f2
                x2 = lo + invphi * (hi - lo)
                f2 = f(x2)
        for t, v in ((x1, f1), (x2, f2), (ts[i], vals[i])):
            if v > best:
                best, best_t = float(v), float(t)
    return best, best_t


def random_ring(rng, spread=0.3):
    """A random circle (centre within ``spread`` of the origin, radius 0.05-0.2 m)."""
    c = rng.uniform(-spread, spread, 3)
    n = rng.standard_normal(3)
    n /= np.linalg.norm(n)
    k = np.eye(3)[np.argmin(np.abs(n))]
    a = np.cross(n, k)
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    return (*c, *a, *b, float(rng.uniform(0.05, 0.2)))


def random_shape(rng, kind: str) -> np.ndarray:
    if kind == "box":
        return box_row(rng.uniform(-0.1, 0.1, 3), rng.uniform(0.02, 0.3, 3), rotation(rng))
    axis = rng.standard_normal(3)
    length = math.inf if kind == "infinite cylinder" else rng.uniform(0.05, 0.6)
    return cylinder_row(rng.uniform(-0.1, 0.1, 3), axis, rng.uniform(0.02, 0.2), length)
