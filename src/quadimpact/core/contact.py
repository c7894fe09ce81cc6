"""The contact law: Hunt-Crossley normal force, friction, and the contact wrench.

This is the paper's contact law (its section III). The geometry of a bumper
against a surface (depth, rate, point, normal) comes from ``geometry.py``;
this module turns those records into forces:

* normal force, Hunt-Crossley with Herbert-McWhannell damping,
  ``F_n = max(0, k delta^n + lambda delta^n delta_dot)`` while ``delta > 0``,
  ``lambda = 6 (1 - e) k / (((2e - 1)^2 + 3) v_i)``, where ``v_i`` is
  ``delta_dot`` at the located onset of this contact (floored at ``v_min``);
* optional regularised Coulomb friction ``-mu F_n v_t / sqrt(|v_t|^2 + v_reg^2)``
  opposing the contact point's sliding velocity ``v_t``;
* the wrench of all active bumper-surface pairs about the CM (body axes), with
  the paper replica's error of counting bumper 1's yaw moment twice as a switch,
  and a per-bumper factor on the normal force (``O_BUMPER_FORCE_SCALE``: the
  authors' hand modification of one crash run, bumper 2's force doubled);
* the contact *gap* that the event locator watches: ``delta`` itself, or, with
  the recovery replica's broad-phase gate, ``min(delta, gate - d_CM)`` so that
  the force switches on only once the CM is within ``gate`` of the surface.

All functions are Numba ``njit`` and allocation free.
"""

import math

import numpy as np
from numba import njit

from .geometry import bumper_contact, surface_distance
from .layout import (
    CS_ACTIVE,
    CS_LAMBDA,
    O_BUMPER_FORCE_SCALE,
    O_CONTACT_GATE,
    O_DOUBLE_BUMPER1_YAW,
    O_MU,
    O_V_REG,
    V_E,
    V_K,
    V_N,
    X_POS,
)


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
def bumper_force(
    veh: np.ndarray, opts: np.ndarray, j: int, delta: float, delta_dot: float, lam: float
) -> float:
    """Normal force (N) of bumper ``j``: :func:`normal_force` times the bumper's factor
    ``opts[O_BUMPER_FORCE_SCALE + j]`` (``<= 0``: 1, the law unchanged)."""
    s = opts[O_BUMPER_FORCE_SCALE + j]
    return normal_force(veh, delta, delta_dot, lam) * (s if s > 0.0 else 1.0)


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
    the contact-point velocity ``v_c`` along the surface of normal ``m``.
    """
    vn = vcx * mx + vcy * my + vcz * mz
    tx = vcx - vn * mx
    ty = vcy - vn * my
    tz = vcz - vn * mz
    scale = -mu * fn / math.sqrt(tx * tx + ty * ty + tz * tz + v_reg * v_reg)
    return scale * tx, scale * ty, scale * tz


@njit(cache=True, inline="always")
def contact_gap(x: np.ndarray, delta: float, surf: np.ndarray, s: int, opts: np.ndarray) -> float:
    """The function whose rise through 0 starts a contact episode (and whose fall ends it).

    ``delta`` without a gate; with the gate ``g = opts[O_CONTACT_GATE] > 0`` (the
    recovery replica), ``min(delta, g - d)`` with ``d`` the CM's distance from
    the surface, so a bumper already ``delta`` deep gets its force at once when
    the CM crosses into the gate.
    """
    gate = opts[O_CONTACT_GATE]
    if gate <= 0.0:
        return delta
    d = surface_distance(x[X_POS], x[X_POS + 1], x[X_POS + 2], surf, s)
    return min(delta, gate - d)


@njit(cache=True)
def contact_wrench(
    x: np.ndarray,
    C: np.ndarray,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    cs: np.ndarray,
) -> tuple[float, float, float, float, float, float]:
    """Sum of the contact forces and moments of all active bumper-surface pairs.

    ``cs[4 s + j, CS_ACTIVE]`` says whether bumper ``j`` is in an episode with
    surface ``s`` (set at the located onset); ``cs[., CS_LAMBDA]`` holds its
    damping coefficient, fixed at that onset. Returns force and moment about
    the CM, body frame (N, N m).
    """
    fx = 0.0
    fy = 0.0
    fz = 0.0
    mx = 0.0
    my = 0.0
    mz = 0.0
    mu = opts[O_MU]
    double_b1 = opts[O_DOUBLE_BUMPER1_YAW] > 0.5
    for c in range(cs.shape[0]):
        if cs[c, CS_ACTIVE] < 0.5:
            continue
        j = c % 4
        d, dd, rx, ry, rz, vcx, vcy, vcz, nx, ny, nz = bumper_contact(x, C, veh, j, surf, c // 4)
        fn = bumper_force(veh, opts, j, d, dd, cs[c, CS_LAMBDA])
        if fn <= 0.0:
            continue
        gx = fn * nx
        gy = fn * ny
        gz = fn * nz
        if mu > 0.0:
            tx, ty, tz = friction_force(fn, mu, opts[O_V_REG], vcx, vcy, vcz, nx, ny, nz)
            gx += tx
            gy += ty
            gz += tz
        # inertial -> body: C^T g
        bx = C[0, 0] * gx + C[1, 0] * gy + C[2, 0] * gz
        by = C[0, 1] * gx + C[1, 1] * gy + C[2, 1] * gz
        bz = C[0, 2] * gx + C[1, 2] * gy + C[2, 2] * gz
        fx += bx
        fy += by
        fz += bz
        mx += ry * bz - rz * by
        my += rz * bx - rx * bz
        mzj = rx * by - ry * bx
        mz += mzj
        if double_b1 and j == 0:
            mz += mzj  # paper replica: bumper 1's yaw moment counted twice
    return fx, fy, fz, mx, my, mz
