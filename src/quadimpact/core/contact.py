"""The contact law: Hunt-Crossley normal force, friction, and the contact wrench.

This is the paper's contact law (its section III), applied per contact pair
(a feature of the vehicle against a shape of the world) with the feature's
own parameters (layout ``F_K``, ``F_N``, ``F_E``, ``F_MU``). The geometry of a
pair (depth, rate, point, normal) comes from ``geometry/`` as a contact
record; this module turns records into forces and never reads a shape:

* normal force, Hunt-Crossley with Herbert-McWhannell damping,
  ``F_n = max(0, k delta^n + lambda delta^n delta_dot)`` while ``delta > 0``,
  ``lambda = 6 (1 - e) k / (((2e - 1)^2 + 3) v_i)``, where ``v_i`` is
  ``delta_dot`` at the located onset of this pair's contact (floored at ``v_min``);
* optional regularised Coulomb friction ``-mu F_n v_t / sqrt(|v_t|^2 + v_reg^2)``
  opposing the contact point's sliding velocity ``v_t``;
* the wrench of all active pairs about the CM (body axes), with the paper
  replica's error of counting the first feature's (bumper 1's) yaw moment
  twice as a switch, and a per-feature factor on the normal force
  (``F_FORCE_SCALE``, 1 by default: the authors' hand modification of one
  crash run doubled bumper 2's force);
* the contact *gap* that the event locator watches: ``delta`` itself, or, with
  the recovery replica's broad-phase gate, ``min(delta, gate - d_CM)`` so that
  the force switches on only once the CM is within ``gate`` of the shape.

All functions are Numba ``njit`` and allocation free.
"""

import math

import numpy as np
from numba import njit

from quadimpact.core.compiled import compiled
from quadimpact.core.contact_slots import CS_ACTIVE, CS_LAMBDA
from quadimpact.core.feature_slots import (
    F_E,
    F_FORCE_SCALE,
    F_K,
    F_MU,
    F_N,
)
from quadimpact.core.geometry import PR_FEATURE, PR_SHAPE, pair_contact, shape_distance
from quadimpact.core.layout import (
    O_CONTACT_GATE,
    O_DOUBLE_BUMPER1_YAW,
    O_V_REG,
    X_POS,
)
from quadimpact.core.records import Model


@compiled
def damping_coefficient(k: float, e: float, v_i: float, v_min: float) -> float:
    """Herbert-McWhannell damping ``lambda`` (N s/m^(n+1)) for onset rate ``v_i`` (m/s).

    ``k``: stiffness (N/m^n); ``e``: coefficient of restitution.
    """
    v = max(v_i, v_min)
    return 6.0 * (1.0 - e) * k / (((2.0 * e - 1.0) ** 2 + 3.0) * v)


@compiled
def normal_force(k: float, n: float, delta: float, delta_dot: float, lam: float) -> float:
    """Hunt-Crossley normal force (N): ``max(0, k d^n + lambda d^n d_dot)``, zero for d <= 0."""
    if delta <= 0.0:
        return 0.0
    dn = delta**n
    f = k * dn + lam * dn * delta_dot
    return f if f > 0.0 else 0.0


@njit(cache=True, inline="always")
def pair_normal_force(m: Model, c: int, delta: float, delta_dot: float, lam: float) -> float:
    """:func:`normal_force` of pair ``c`` with its feature's parameters.

    Times the feature's factor ``F_FORCE_SCALE`` (1, or 0 in a row written
    without it: the law itself; the authors' hand modification of one crash
    run doubled bumper 2's force).
    """
    f = m.pairs[c, PR_FEATURE]
    fn = normal_force(m.feat[f, F_K], m.feat[f, F_N], delta, delta_dot, lam)
    scale = m.feat[f, F_FORCE_SCALE]
    return fn * scale if scale > 0.0 else fn


@compiled
def pair_damping(m: Model, c: int, v_i: float, v_min: float) -> float:
    """:func:`damping_coefficient` of pair ``c`` with its feature's parameters."""
    f = m.pairs[c, PR_FEATURE]
    return damping_coefficient(m.feat[f, F_K], m.feat[f, F_E], v_i, v_min)


@compiled
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
def contact_gap(x: np.ndarray, delta: float, m: Model, c: int) -> float:
    """The function whose rise through 0 starts pair ``c``'s episode (and whose fall ends it).

    ``delta`` without a gate; with the gate ``g = opts[O_CONTACT_GATE] > 0`` (the
    recovery replica), ``min(delta, g - d)`` with ``d`` the CM's distance from
    the pair's shape, so a feature already ``delta`` deep gets its force at
    once when the CM crosses into the gate.
    """
    gate = m.opts[O_CONTACT_GATE]
    if gate <= 0.0:
        return delta
    d = shape_distance(x[X_POS], x[X_POS + 1], x[X_POS + 2], m.shapes, m.pairs[c, PR_SHAPE])
    return min(delta, gate - d)


@compiled(inline="always")
def contact_wrench(
    x: np.ndarray, C: np.ndarray, m: Model, cs: np.ndarray
) -> tuple[float, float, float, float, float, float]:
    """Sum of the contact forces and moments of all active pairs.

    ``cs[c, CS_ACTIVE]`` says whether pair ``c`` is in an episode (set at the
    located onset); ``cs[c, CS_LAMBDA]`` holds its damping coefficient, fixed
    at that onset. ``C`` is the rotation of ``x``. Returns force and moment
    about the CM, body frame (N, N m).
    """
    fx = 0.0
    fy = 0.0
    fz = 0.0
    mx = 0.0
    my = 0.0
    mz = 0.0
    v_reg = m.opts[O_V_REG]
    double_first = m.opts[O_DOUBLE_BUMPER1_YAW] > 0.5
    for c in range(cs.shape[0]):
        if cs[c, CS_ACTIVE] < 0.5:
            continue
        d, dd, rx, ry, rz, vcx, vcy, vcz, nx, ny, nz = pair_contact(
            x, C, m.feat, m.shapes, m.pairs, c
        )
        fn = pair_normal_force(m, c, d, dd, cs[c, CS_LAMBDA])
        if fn <= 0.0:
            continue
        gx = fn * nx
        gy = fn * ny
        gz = fn * nz
        f = m.pairs[c, PR_FEATURE]
        mu = m.feat[f, F_MU]
        if mu > 0.0:
            tx, ty, tz = friction_force(fn, mu, v_reg, vcx, vcy, vcz, nx, ny, nz)
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
        if double_first and f == 0:
            mz += mzj  # paper replica: bumper 1's yaw moment counted twice
    return fx, fy, fz, mx, my, mz
