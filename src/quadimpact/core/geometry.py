"""Contact geometry: a bumper against a surface, dispatched on the surface's kind.

A contact query returns a record, as in Drake's contact queries: the
penetration ``delta`` (m, positive in contact), its rate ``delta_dot``
(m/s), the contact point from the CM in body axes (m), that material
point's velocity in inertial axes (m/s) and the contact normal in inertial
axes (unit, pointing out of the obstacle into free space). The force law
(``contact.py``) consumes that record and never reads a surface itself.

Surface kinds (slot ``S_KIND`` of the packed surfaces, ``layout.SURF_*``):

* ``SURF_PLANE``: the half-space behind a plane through ``p0`` with unit
  normal ``m`` (the paper's wall at ``X = d``: ``p0 = (d, 0, 0)``,
  ``m = -e_X``). Bumper ``j`` is a circle of radius ``Rb`` with centre ``c_j``
  and plane normal ``n_j`` (body frame); in inertial components the deepest
  rim point is found in closed form (the paper's eqs. 10-15 without angles)::

      w     = m - (m . n) n              component of m in the circle's plane
      p_C   = c - Rb w / |w|             deepest rim point (c itself if |w| ~ 0)
      delta = -(p_C - p0) . m
      delta_dot = -(v + omega x r_C) . m   (inertial velocity of that rim point)

A new obstacle shape is a new ``SURF_*`` kind: a function with the same
record as :func:`bumper_plane`, a branch in :func:`bumper_contact` and one in
:func:`surface_distance`, and its packing on the Python side. Everything
else (events, forces, output) goes through these two functions.

All functions are Numba ``njit`` and allocation free.
"""

import math

import numpy as np
from numba import njit

from .layout import (
    S_KIND,
    S_NORMAL,
    S_P0,
    SURF_PLANE,
    V_BUMP_C,
    V_BUMP_N,
    V_RB,
    X_OMEGA,
    X_POS,
    X_VEL,
)

PARALLEL_EPS = 1e-12  # |w| below this: the circle is parallel to the plane

ContactRecord = tuple[float, float, float, float, float, float, float, float, float, float, float]
"""(delta, delta_dot, rcx, rcy, rcz, vcx, vcy, vcz, nx, ny, nz)."""


@njit(cache=True, inline="always")
def bumper_plane(
    x: np.ndarray, C: np.ndarray, veh: np.ndarray, j: int, surf: np.ndarray, s: int
) -> ContactRecord:
    """Deepest point of bumper ``j`` against the plane ``s`` (see the module docstring).

    Parameters
    ----------
    x : state vector (layout ``X_*``): position (inertial, m), velocity (body,
        m/s), quaternion, angular velocity (body, rad/s).
    C : body-to-inertial rotation matrix of ``x``'s quaternion.
    veh : packed vehicle (layout ``V_*``).
    j : bumper index, 0..3.
    surf : packed surfaces, shape (n_surfaces, NSURF); ``s`` selects one.

    Returns
    -------
    delta : penetration (m), positive in contact.
    delta_dot : penetration rate (m/s).
    rcx, rcy, rcz : contact point from the CM, body frame (m).
    vcx, vcy, vcz : contact point velocity, inertial frame (m/s).
    nx, ny, nz : contact normal, inertial frame, out of the obstacle (the plane's).
    """
    mx = surf[s, S_NORMAL]
    my = surf[s, S_NORMAL + 1]
    mz = surf[s, S_NORMAL + 2]
    cb0 = veh[V_BUMP_C + 3 * j]
    cb1 = veh[V_BUMP_C + 3 * j + 1]
    cb2 = veh[V_BUMP_C + 3 * j + 2]
    nb0 = veh[V_BUMP_N + 3 * j]
    nb1 = veh[V_BUMP_N + 3 * j + 1]
    nb2 = veh[V_BUMP_N + 3 * j + 2]
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
    rb = veh[V_RB]
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
        (px - surf[s, S_P0]) * mx + (py - surf[s, S_P0 + 1]) * my + (pz - surf[s, S_P0 + 2]) * mz
    )
    # contact point in body components: r_C = C^T d
    rcx = C[0, 0] * dx + C[1, 0] * dy + C[2, 0] * dz
    rcy = C[0, 1] * dx + C[1, 1] * dy + C[2, 1] * dz
    rcz = C[0, 2] * dx + C[1, 2] * dy + C[2, 2] * dz
    # material velocity of that point: v + omega x r_C (body), then inertial
    p = x[X_OMEGA]
    q = x[X_OMEGA + 1]
    r = x[X_OMEGA + 2]
    ub = x[X_VEL] + q * rcz - r * rcy
    vb = x[X_VEL + 1] + r * rcx - p * rcz
    wb = x[X_VEL + 2] + p * rcy - q * rcx
    vcx = C[0, 0] * ub + C[0, 1] * vb + C[0, 2] * wb
    vcy = C[1, 0] * ub + C[1, 1] * vb + C[1, 2] * wb
    vcz = C[2, 0] * ub + C[2, 1] * vb + C[2, 2] * wb
    delta_dot = -(vcx * mx + vcy * my + vcz * mz)
    return delta, delta_dot, rcx, rcy, rcz, vcx, vcy, vcz, mx, my, mz


@njit(cache=True, inline="always")
def bumper_contact(
    x: np.ndarray, C: np.ndarray, veh: np.ndarray, j: int, surf: np.ndarray, s: int
) -> ContactRecord:
    """Contact record of bumper ``j`` against surface ``s``, whatever its kind.

    Same arguments and record as :func:`bumper_plane`; dispatches on
    ``surf[s, S_KIND]``. Planes are the only kind today.
    """
    kind = int(surf[s, S_KIND])
    if kind == SURF_PLANE:
        return bumper_plane(x, C, veh, j, surf, s)
    return bumper_plane(x, C, veh, j, surf, s)  # unknown kinds are refused when packing


@njit(cache=True, inline="always")
def surface_distance(px: float, py: float, pz: float, surf: np.ndarray, s: int) -> float:
    """Signed distance (m) of the inertial point ``p`` from surface ``s``, positive in free space.

    Planes (the only kind today): ``(p - p0) . m``.
    """
    return (
        (px - surf[s, S_P0]) * surf[s, S_NORMAL]
        + (py - surf[s, S_P0 + 1]) * surf[s, S_NORMAL + 1]
        + (pz - surf[s, S_P0 + 2]) * surf[s, S_NORMAL + 2]
    )


@njit(cache=True, inline="always")
def bumper_depth(x: np.ndarray, C: np.ndarray, veh: np.ndarray, j: int, surf: np.ndarray, s: int):
    """Penetration ``delta`` (m) and its rate ``delta_dot`` (m/s) only."""
    rec = bumper_contact(x, C, veh, j, surf, s)
    return rec[0], rec[1]
