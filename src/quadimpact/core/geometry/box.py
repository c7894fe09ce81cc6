"""Contact geometry against a box: a finite, oriented obstacle with faces, edges and corners.

The shape row (``shapes[s]``, layout ``SH_*``) holds the centre ``o``
(``SH_POINT``), the half-extents ``h`` along the box's own axes
(``SH_HALF``) and those axes in inertial components (``SH_ROT``, row ``i``
is axis ``e_i``). A point ``p`` has box coordinates ``q_i = e_i . (p - o)``.

**Depth of a point** (the negative of the signed distance, exact, closed form):

* inside (every ``|q_i| <= h_i``): the distance to the nearest face,
  ``min_i (h_i - |q_i|)``, and the normal of that face (the shortest way
  out; where two faces tie, the lower axis index, positive side first);
* outside: minus the distance to the box, ``-|d|`` with ``d_i = q_i -
  clamp(q_i, -h_i, h_i)``, and the normal ``d / |d|`` expressed in inertial
  axes: a face's normal in front of a face, the direction from the edge in
  an edge's region, from the corner in a corner's region.

This is the function :func:`box_depth`; it is concave (a box is convex) and
1-Lipschitz in ``p``, continuous everywhere, smooth outside, and inside its
pieces (:func:`box_piece`: face ``k = 2 i + side``) meet along the box's
medial planes.

**Pairs.** A point feature's record is the point's depth
(:func:`point_box`); a sphere's is ``R - dist(centre)`` at
``centre - R m`` (:func:`sphere_box`): both exact, a few dozen flops. A ring
against a box has no closed form: ``ring.ring_box`` searches the circle.
"""

import math

import numpy as np
from numba import njit

from quadimpact.core.feature_slots import (
    F_RADIUS,
)
from quadimpact.core.geometry.contact_record import ContactRecord, feature_offset, material_record
from quadimpact.core.layout import (
    X_POS,
)
from quadimpact.core.shape_slots import (
    SH_HALF,
    SH_POINT,
    SH_ROT,
)

OUTSIDE = -1  # the piece id of a point outside (the depth is smooth there)


@njit(cache=True, inline="always")
def box_depth(
    px: float, py: float, pz: float, shapes: np.ndarray, s: int
) -> tuple[float, float, float, float, int]:
    """Depth (m, > 0 inside) of the inertial point ``p`` in box ``s``, the normal, the piece.

    Returns ``(depth, mx, my, mz, piece)``: ``m`` is the unit outward normal
    of the shortest way out (inside) or from the box to ``p`` (outside);
    ``piece`` is the face ``2 i + (0 if q_i >= 0 else 1)`` inside, ``OUTSIDE``
    outside.
    """
    rx = px - shapes[s, SH_POINT]
    ry = py - shapes[s, SH_POINT + 1]
    rz = pz - shapes[s, SH_POINT + 2]
    worst = -math.inf
    k = 0
    dx = 0.0
    dy = 0.0
    dz = 0.0
    d2 = 0.0
    for i in range(3):
        ex = shapes[s, SH_ROT + 3 * i]
        ey = shapes[s, SH_ROT + 3 * i + 1]
        ez = shapes[s, SH_ROT + 3 * i + 2]
        q = ex * rx + ey * ry + ez * rz
        a = abs(q) - shapes[s, SH_HALF + i]
        sign = 1.0 if q >= 0.0 else -1.0
        if a > worst:
            worst = a
            k = 2 * i + (0 if q >= 0.0 else 1)
        if a > 0.0:
            dx += sign * a * ex
            dy += sign * a * ey
            dz += sign * a * ez
            d2 += a * a
    if worst <= 0.0:
        i = k // 2
        sign = 1.0 if k % 2 == 0 else -1.0
        return (
            -worst,
            sign * shapes[s, SH_ROT + 3 * i],
            sign * shapes[s, SH_ROT + 3 * i + 1],
            sign * shapes[s, SH_ROT + 3 * i + 2],
            k,
        )
    dist = math.sqrt(d2)
    return -dist, dx / dist, dy / dist, dz / dist, OUTSIDE


@njit(cache=True, inline="always")
def box_piece(
    px: float, py: float, pz: float, shapes: np.ndarray, s: int, k: int
) -> tuple[float, float, float, float]:
    """Face ``k``'s depth of ``p`` (``h_i - side q_i``, extended beyond the face) and its normal."""
    i = k // 2
    sign = 1.0 if k % 2 == 0 else -1.0
    ex = shapes[s, SH_ROT + 3 * i]
    ey = shapes[s, SH_ROT + 3 * i + 1]
    ez = shapes[s, SH_ROT + 3 * i + 2]
    q = (
        ex * (px - shapes[s, SH_POINT])
        + ey * (py - shapes[s, SH_POINT + 1])
        + ez * (pz - shapes[s, SH_POINT + 2])
    )
    return shapes[s, SH_HALF + i] - sign * q, sign * ex, sign * ey, sign * ez


@njit(cache=True, inline="always")
def box_distance(px: float, py: float, pz: float, shapes: np.ndarray, s: int) -> float:
    """Signed distance (m) of the inertial point ``p`` from box ``s``, positive outside."""
    return -box_depth(px, py, pz, shapes, s)[0]


@njit(cache=True, inline="always")
def point_box(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, f: int, shapes: np.ndarray, s: int
) -> ContactRecord:
    """Point feature ``f`` (position ``F_CENTRE``, body) against box ``s``: exact."""
    dx, dy, dz = feature_offset(C, feat, f)
    g, mx, my, mz, _ = box_depth(x[X_POS] + dx, x[X_POS + 1] + dy, x[X_POS + 2] + dz, shapes, s)
    return material_record(x, C, g, dx, dy, dz, mx, my, mz)


@njit(cache=True, inline="always")
def sphere_box(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, f: int, shapes: np.ndarray, s: int
) -> ContactRecord:
    """Sphere feature ``f`` (centre ``F_CENTRE``, radius ``F_RADIUS``) against box ``s``: exact.

    The sphere's deepest point is ``centre - R m`` with ``m`` the box's normal
    at the centre, and its depth ``R + depth(centre)``.
    """
    ox, oy, oz = feature_offset(C, feat, f)
    g, mx, my, mz, _ = box_depth(x[X_POS] + ox, x[X_POS + 1] + oy, x[X_POS + 2] + oz, shapes, s)
    r = feat[f, F_RADIUS]
    return material_record(x, C, g + r, ox - r * mx, oy - r * my, oz - r * mz, mx, my, mz)
