"""Bumper contact: circle-plane geometry and the Hunt-Crossley force law.

This is the contact law of the paper (section III) as restated in MODEL.md
section 4:

* bumper ``j`` is a circle of radius ``Rb`` centred on rotor ``j`` (body
  frame), tilted so that its outer rim is raised by ``alpha``; its plane
  normal is ``n_j``;
* against a plane through ``p0`` with unit normal ``m`` (pointing out of the
  obstacle into free space) the deepest rim point is found in closed form:
  ``w = m - (m.n) n``, ``p_C = c - Rb w/|w|``; the penetration is
  ``delta = -(p_C - p0).m`` and its rate ``delta_dot`` is the velocity of the
  material rim point at ``p_C`` projected on ``-m``;
* the normal force is Hunt-Crossley with Herbert-McWhannell damping,
  ``F_n = max(0, k delta^n + lambda delta^n delta_dot)``,
  ``lambda = 6 (1 - e) k / (((2e - 1)^2 + 3) v_i)``, where ``v_i`` is
  ``delta_dot`` at the located onset of this contact (floored at ``v_min``);
* optional regularised Coulomb friction ``-mu F_n v_t / sqrt(|v_t|^2 + v_reg^2)``
  opposes the contact point's sliding velocity ``v_t``.

All functions are Numba ``njit`` and allocation free.
"""

import math

import numpy as np
from numba import njit

from .layout import (
    S_NORMAL,
    S_P0,
    V_BUMP_C,
    V_BUMP_N,
    V_E,
    V_K,
    V_N,
    V_RB,
    X_OMEGA,
    X_POS,
    X_VEL,
)

PARALLEL_EPS = 1e-12  # |w| below this: the circle is parallel to the plane


@njit(cache=True)
def bumper_plane_contact(
    x: np.ndarray, C: np.ndarray, veh: np.ndarray, j: int, surf: np.ndarray, s: int
) -> tuple[float, float, float, float, float, float, float, float]:
    """Deepest point of bumper ``j`` against surface ``s``.

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
    return delta, delta_dot, rcx, rcy, rcz, vcx, vcy, vcz


@njit(cache=True)
def damping_coefficient(veh: np.ndarray, v_i: float, v_min: float) -> float:
    """Herbert-McWhannell damping ``lambda`` (N s/m^(n+1)) for onset rate ``v_i`` (m/s)."""
    e = veh[V_E]
    v = max(v_i, v_min)
    return 6.0 * (1.0 - e) * veh[V_K] / (((2.0 * e - 1.0) ** 2 + 3.0) * v)


@njit(cache=True)
def normal_force(veh: np.ndarray, delta: float, delta_dot: float, lam: float) -> float:
    """Hunt-Crossley normal force (N): ``max(0, k d^n + lambda d^n d_dot)``, zero for d <= 0."""
    if delta <= 0.0:
        return 0.0
    dn = delta ** veh[V_N]
    f = veh[V_K] * dn + lam * dn * delta_dot
    return f if f > 0.0 else 0.0


@njit(cache=True)
def friction_force(
    fn: float,
    mu: float,
    v_reg: float,
    vcx: float,
    vcy: float,
    vcz: float,
    mx: float,
    my: float,
    mz: float,
) -> tuple[float, float, float]:
    """Regularised Coulomb friction (N, inertial) opposing the sliding velocity.

    ``F_t = -mu F_n v_t / sqrt(|v_t|^2 + v_reg^2)`` with ``v_t`` the component of
    the contact-point velocity along the plane.
    """
    vn = vcx * mx + vcy * my + vcz * mz
    tx = vcx - vn * mx
    ty = vcy - vn * my
    tz = vcz - vn * mz
    scale = -mu * fn / math.sqrt(tx * tx + ty * ty + tz * tz + v_reg * v_reg)
    return scale * tx, scale * ty, scale * tz
