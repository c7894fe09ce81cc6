"""Contact geometry against a cylinder: a pole, a bar, a branch (any axis; finite or infinite).

The shape row (``shapes[s]``, layout ``SH_*``) holds a point ``o`` of the
axis (``SH_POINT``; the centre of a finite cylinder), the unit axis ``e``
(``SH_NORMAL``), the radius ``r`` (``SH_RADIUS``) and the length ``L``
(``SH_LENGTH``; ``inf``: unbounded, no end caps). A point ``p`` has the axial
coordinate ``z = e . (p - o)`` and the distance ``rho`` from the axis, with
the radial unit vector ``u``.

**Depth of a point** (the negative of the signed distance, exact, closed form):

* infinite: ``r - rho``, normal ``u``, inside and outside;
* finite, inside (``rho <= r``, ``|z| <= L/2``): the nearer of the side
  (``r - rho``, normal ``u``) and the flat caps (``L/2 - |z|``, normal
  ``+-e``): the shortest way out;
* finite, outside: minus the distance to the solid: to the side
  (``rho - r``) beside it, to a cap (``|z| - L/2``) above or below it, to the
  rim circle (``hypot(rho - r, |z| - L/2)``, normal from the rim) off both.

This is :func:`cylinder_depth`: concave (a cylinder is convex), 1-Lipschitz,
continuous, smooth outside; inside its pieces (:func:`cylinder_piece`: 0
the side, 1 the cap at ``+L/2``, 2 the cap at ``-L/2``) meet along the
medial surfaces. On the axis itself (``rho = 0``) the radial direction is
not defined and a fixed perpendicular of the axis is used.

**Pairs.** A point's record is its depth (:func:`point_cylinder`), a
sphere's ``R + depth(centre)`` at ``centre - R m`` (:func:`sphere_cylinder`):
both exact, a few dozen flops. A ring against a cylinder has no closed form
(the authors solved a quartic): ``ring.ring_cylinder`` searches the circle.
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
    SH_LENGTH,
    SH_NORMAL,
    SH_POINT,
    SH_RADIUS,
)

OUTSIDE = -1  # the piece id of a point outside (the depth is smooth there)
AXIS_EPS = 1e-300  # rho below this: the point is on the axis


@njit(cache=True, inline="always")
def _radial(
    px: float, py: float, pz: float, shapes: np.ndarray, s: int
) -> tuple[float, float, float, float, float]:
    """Axial coordinate ``z``, distance ``rho`` from the axis and the radial unit vector."""
    ex = shapes[s, SH_NORMAL]
    ey = shapes[s, SH_NORMAL + 1]
    ez = shapes[s, SH_NORMAL + 2]
    rx = px - shapes[s, SH_POINT]
    ry = py - shapes[s, SH_POINT + 1]
    rz = pz - shapes[s, SH_POINT + 2]
    z = ex * rx + ey * ry + ez * rz
    wx = rx - z * ex
    wy = ry - z * ey
    wz = rz - z * ez
    rho = math.sqrt(wx * wx + wy * wy + wz * wz)
    if rho > AXIS_EPS:
        return z, rho, wx / rho, wy / rho, wz / rho
    # on the axis: a fixed perpendicular (the axis crossed with its least aligned basis vector)
    ax = abs(ex)
    ay = abs(ey)
    az = abs(ez)
    if ax <= ay and ax <= az:
        ux, uy, uz = 0.0, ez, -ey
    elif ay <= az:
        ux, uy, uz = -ez, 0.0, ex
    else:
        ux, uy, uz = ey, -ex, 0.0
    n = math.sqrt(ux * ux + uy * uy + uz * uz)
    return z, 0.0, ux / n, uy / n, uz / n


@njit(cache=True, inline="always")
def cylinder_depth(
    px: float, py: float, pz: float, shapes: np.ndarray, s: int
) -> tuple[float, float, float, float, int]:
    """Depth (m, > 0 inside) of the inertial point ``p`` in cylinder ``s``, the normal, the piece.

    Returns ``(depth, mx, my, mz, piece)`` (see the module docstring; piece
    ``OUTSIDE`` outside, and for an infinite cylinder, whose depth is smooth).
    """
    z, rho, ux, uy, uz = _radial(px, py, pz, shapes, s)
    r = shapes[s, SH_RADIUS]
    a_r = rho - r
    length = shapes[s, SH_LENGTH]
    if not length < math.inf:
        return -a_r, ux, uy, uz, OUTSIDE
    a_z = abs(z) - 0.5 * length
    sz = 1.0 if z >= 0.0 else -1.0
    ex = sz * shapes[s, SH_NORMAL]
    ey = sz * shapes[s, SH_NORMAL + 1]
    ez = sz * shapes[s, SH_NORMAL + 2]
    if a_r <= 0.0 and a_z <= 0.0:
        if a_r >= a_z:
            return -a_r, ux, uy, uz, 0
        return -a_z, ex, ey, ez, 1 if z >= 0.0 else 2
    if a_z <= 0.0:
        return -a_r, ux, uy, uz, OUTSIDE
    if a_r <= 0.0:
        return -a_z, ex, ey, ez, OUTSIDE
    dist = math.sqrt(a_r * a_r + a_z * a_z)
    return (
        -dist,
        (a_r * ux + a_z * ex) / dist,
        (a_r * uy + a_z * ey) / dist,
        (a_r * uz + a_z * ez) / dist,
        OUTSIDE,
    )


@njit(cache=True, inline="always")
def cylinder_piece(
    px: float, py: float, pz: float, shapes: np.ndarray, s: int, k: int
) -> tuple[float, float, float, float]:
    """Piece ``k``'s depth of ``p`` (0 the side ``r - rho``, 1 and 2 the caps) and its normal."""
    z, rho, ux, uy, uz = _radial(px, py, pz, shapes, s)
    if k == 0:
        return shapes[s, SH_RADIUS] - rho, ux, uy, uz
    sign = 1.0 if k == 1 else -1.0
    return (
        0.5 * shapes[s, SH_LENGTH] - sign * z,
        sign * shapes[s, SH_NORMAL],
        sign * shapes[s, SH_NORMAL + 1],
        sign * shapes[s, SH_NORMAL + 2],
    )


@njit(cache=True, inline="always")
def cylinder_distance(px: float, py: float, pz: float, shapes: np.ndarray, s: int) -> float:
    """Signed distance (m) of the inertial point ``p`` from cylinder ``s``, positive outside."""
    return -cylinder_depth(px, py, pz, shapes, s)[0]


@njit(cache=True, inline="always")
def point_cylinder(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, f: int, shapes: np.ndarray, s: int
) -> ContactRecord:
    """Point feature ``f`` (position ``F_CENTRE``, body) against cylinder ``s``: exact."""
    dx, dy, dz = feature_offset(C, feat, f)
    g, mx, my, mz, _ = cylinder_depth(
        x[X_POS] + dx, x[X_POS + 1] + dy, x[X_POS + 2] + dz, shapes, s
    )
    return material_record(x, C, g, dx, dy, dz, mx, my, mz)


@njit(cache=True, inline="always")
def sphere_cylinder(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, f: int, shapes: np.ndarray, s: int
) -> ContactRecord:
    """Sphere feature ``f`` (centre ``F_CENTRE``, radius ``F_RADIUS``) against cylinder ``s``."""
    ox, oy, oz = feature_offset(C, feat, f)
    g, mx, my, mz, _ = cylinder_depth(
        x[X_POS] + ox, x[X_POS + 1] + oy, x[X_POS + 2] + oz, shapes, s
    )
    r = feat[f, F_RADIUS]
    return material_record(x, C, g + r, ox - r * mx, oy - r * my, oz - r * mz, mx, my, mz)
