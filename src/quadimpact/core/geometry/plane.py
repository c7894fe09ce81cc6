"""Contact geometry against a plane: the half-space behind a plane through a point.

The shape row (``shapes[s]``, layout ``SH_*``) holds a point ``p0`` on the
plane and its unit normal ``m`` pointing out of the obstacle into free space
(the paper's wall at ``X = d``: ``p0 = (d, 0, 0)``, ``m = -e_X``).

Ring feature (a bumper): a circle of radius ``R`` with centre ``c`` and
plane normal ``n`` (body frame, feature row ``feat[f]``, layout ``F_*``). In
inertial components the deepest rim point is found in closed form (the
paper's eqs. 10-15 without angles)::

    w     = m - (m . n) n              component of m in the circle's plane
    p_C   = c - R w / |w|              deepest rim point (c itself if |w| ~ 0)
    delta = -(p_C - p0) . m
    delta_dot = -(v + omega x r_C) . m   (inertial velocity of that rim point)

Exact (a closed form), continuous in time, and a few dozen flops. A point
feature (:func:`point_plane`) and a sphere (:func:`sphere_plane`: the point
``centre - R m``, depth ``R - distance(centre)``) are closed forms too.
"""

import math

import numpy as np
from numba import njit

from quadimpact.core.feature_slots import (
    F_CENTRE,
    F_NORMAL,
    F_RADIUS,
)
from quadimpact.core.geometry.contact_record import ContactRecord, feature_offset, material_record
from quadimpact.core.layout import (
    X_POS,
)
from quadimpact.core.shape_slots import (
    SH_NORMAL,
    SH_POINT,
)

PARALLEL_EPS = 1e-12  # |w| below this: the circle is parallel to the plane
BOUND_MARGIN = 1e-9  # m: added to the broad phase's depth bound (rounding), as ring.py's
RATE_MARGIN = 1e-9  # relative: added to its rate bound


@njit(cache=True, inline="always")
def plane_distance(px: float, py: float, pz: float, shapes: np.ndarray, s: int) -> float:
    """Signed distance (m) of the inertial point ``p`` from plane ``s``, positive in free space."""
    return (
        (px - shapes[s, SH_POINT]) * shapes[s, SH_NORMAL]
        + (py - shapes[s, SH_POINT + 1]) * shapes[s, SH_NORMAL + 1]
        + (pz - shapes[s, SH_POINT + 2]) * shapes[s, SH_NORMAL + 2]
    )


@njit(cache=True, inline="always")
def ring_plane(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, f: int, shapes: np.ndarray, s: int
) -> ContactRecord:
    """Deepest point of ring ``f`` against plane ``s`` (see the module docstring).

    Parameters
    ----------
    x : state vector (layout ``X_*``): position (inertial, m), velocity (body,
        m/s), quaternion, angular velocity (body, rad/s).
    C : body-to-inertial rotation matrix of ``x``'s quaternion.
    feat, f : the vehicle's features (layout ``F_*``) and the ring's row.
    shapes, s : the world's shapes (layout ``SH_*``) and the plane's row.

    Returns
    -------
    ContactRecord
        See ``record.py``: depth, depth rate, the point from the CM (body),
        its velocity (inertial) and the plane's normal.
    """
    mx = shapes[s, SH_NORMAL]
    my = shapes[s, SH_NORMAL + 1]
    mz = shapes[s, SH_NORMAL + 2]
    cb0 = feat[f, F_CENTRE]
    cb1 = feat[f, F_CENTRE + 1]
    cb2 = feat[f, F_CENTRE + 2]
    nb0 = feat[f, F_NORMAL]
    nb1 = feat[f, F_NORMAL + 1]
    nb2 = feat[f, F_NORMAL + 2]
    # centre offset and normal in inertial components
    ox = C[0, 0] * cb0 + C[0, 1] * cb1 + C[0, 2] * cb2
    oy = C[1, 0] * cb0 + C[1, 1] * cb1 + C[1, 2] * cb2
    oz = C[2, 0] * cb0 + C[2, 1] * cb1 + C[2, 2] * cb2
    nx = C[0, 0] * nb0 + C[0, 1] * nb1 + C[0, 2] * nb2
    ny = C[1, 0] * nb0 + C[1, 1] * nb1 + C[1, 2] * nb2
    nz = C[2, 0] * nb0 + C[2, 1] * nb1 + C[2, 2] * nb2
    mn = mx * nx + my * ny + mz * nz
    wx = mx - mn * nx
    wy = my - mn * ny
    wz = mz - mn * nz
    wn = math.sqrt(wx * wx + wy * wy + wz * wz)
    rb = feat[f, F_RADIUS]
    # contact point relative to the CM, inertial components
    if wn > PARALLEL_EPS:
        dx = ox - rb * wx / wn
        dy = oy - rb * wy / wn
        dz = oz - rb * wz / wn
    else:
        dx = ox
        dy = oy
        dz = oz
    px = x[X_POS] + dx
    py = x[X_POS + 1] + dy
    pz = x[X_POS + 2] + dz
    delta = -(
        (px - shapes[s, SH_POINT]) * mx
        + (py - shapes[s, SH_POINT + 1]) * my
        + (pz - shapes[s, SH_POINT + 2]) * mz
    )
    return material_record(x, C, delta, dx, dy, dz, mx, my, mz)


@njit(cache=True, inline="always")
def ring_reach(feat: np.ndarray, f: int) -> float:
    """An upper bound (m) on the distance of ring ``f``'s points from the CM, without a
    square root: ``|c_b|_1 + R`` (at least ``|c_b| + R``)."""
    return (
        abs(feat[f, F_CENTRE]) + abs(feat[f, F_CENTRE + 1]) + abs(feat[f, F_CENTRE + 2])
        + feat[f, F_RADIUS]
    )  # fmt: skip


@njit(cache=True, inline="always")
def ring_plane_bound(
    x: np.ndarray, speed: float, spin: float, feat: np.ndarray, f: int, shapes: np.ndarray, s: int
) -> tuple[float, float]:
    """Certified bounds on ring ``f``'s record against plane ``s``: the broad phase.

    Every point of the ring lies within ``|c_b| + R`` of the CM, so its depth
    (:func:`ring_plane`'s ``delta``) is at most ``|c_b| + R - d``, with ``d``
    the CM's distance from the plane, and its rate at most that point's speed,
    ``speed + spin (|c_b| + R)``. ``speed`` (m/s) and ``spin`` (rad/s) are the
    norms of ``x``'s velocity and angular velocity. Returns ``(depth bound
    (m), rate bound (m/s))``, each with a margin for rounding
    (:data:`BOUND_MARGIN`, :data:`RATE_MARGIN`). No rotation is needed: a
    handful of flops against the closed form's few dozen.
    """
    cb0 = feat[f, F_CENTRE]
    cb1 = feat[f, F_CENTRE + 1]
    cb2 = feat[f, F_CENTRE + 2]
    reach = math.sqrt(cb0 * cb0 + cb1 * cb1 + cb2 * cb2) + feat[f, F_RADIUS]
    d = plane_distance(x[X_POS], x[X_POS + 1], x[X_POS + 2], shapes, s)
    return reach - d + BOUND_MARGIN, (speed + spin * reach) * (1.0 + RATE_MARGIN)


@njit(cache=True, inline="always")
def plane_depth(
    px: float, py: float, pz: float, shapes: np.ndarray, s: int
) -> tuple[float, float, float, float, int]:
    """Depth (m, > 0 behind the plane) of the inertial point ``p``, its normal, piece -1."""
    return (
        -plane_distance(px, py, pz, shapes, s),
        shapes[s, SH_NORMAL],
        shapes[s, SH_NORMAL + 1],
        shapes[s, SH_NORMAL + 2],
        -1,
    )


@njit(cache=True, inline="always")
def point_plane(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, f: int, shapes: np.ndarray, s: int
) -> ContactRecord:
    """Point feature ``f`` (position ``F_CENTRE``, body) against plane ``s``: exact."""
    dx, dy, dz = feature_offset(C, feat, f)
    g = -plane_distance(x[X_POS] + dx, x[X_POS + 1] + dy, x[X_POS + 2] + dz, shapes, s)
    mx = shapes[s, SH_NORMAL]
    my = shapes[s, SH_NORMAL + 1]
    mz = shapes[s, SH_NORMAL + 2]
    return material_record(x, C, g, dx, dy, dz, mx, my, mz)


@njit(cache=True, inline="always")
def sphere_plane(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, f: int, shapes: np.ndarray, s: int
) -> ContactRecord:
    """Sphere feature ``f`` (centre ``F_CENTRE``, radius ``F_RADIUS``) against plane ``s``: exact.

    The deepest point is ``centre - R m``; its depth ``R - distance(centre)``.
    """
    ox, oy, oz = feature_offset(C, feat, f)
    r = feat[f, F_RADIUS]
    g = r - plane_distance(x[X_POS] + ox, x[X_POS + 1] + oy, x[X_POS + 2] + oz, shapes, s)
    mx = shapes[s, SH_NORMAL]
    my = shapes[s, SH_NORMAL + 1]
    mz = shapes[s, SH_NORMAL + 2]
    return material_record(x, C, g, ox - r * mx, oy - r * my, oz - r * mz, mx, my, mz)
