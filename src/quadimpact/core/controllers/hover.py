"""Stage 5 of the staged recovery law: return to hover and hold the position.

After stage 4 (recovered: level, not descending) the ``recovery`` controller
holds a position set-point ``p_set`` (by default where the vehicle stops: it
brakes, holding wherever it is, until its speed estimate falls below 0.2 m/s;
or the position estimate at which stage 4 was entered, or a given one) and
the yaw ``psi_set`` it had on entering stage 4. Its outer
loop is a cascade on the estimate, position to velocity to acceleration,
with limits (so a fast vehicle brakes at the limit and comes back at a
bounded speed, without the overshoot of a saturated PD)::

    v_des = K_p (p_set - p_hat),   |v_des,XY| <= v_max, |v_des,Z| <= v_max
    a     = K_v (v_des - v_hat),   |a_XY| <= a_max,     |a_Z| <= a_max   (inertial, NED)
    f_des = -g e_Z + a                                  desired thrust per unit mass
    r_des = K_psi wrap(psi_set - psi_hat)               yaw-rate reference

then the staged law's thrust and tilt error toward ``f_des`` and its rate
loop (``recovery.thrust_and_tilt``, ``recovery.rate_loop``). Defaults
(``inputs/controllers.py``): ``K_p = 1.5 1/s``, ``K_v = 4 1/s`` (well below
the attitude loop's 20 1/s), ``v_max = 1 m/s``, ``a_max = g/2`` (tilts of at
most about 27 deg), ``K_psi = 2 1/s``.
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import X_POS, X_QUAT, X_VEL
from quadimpact.core.quaternion import wrap_pi


@compiled
def yaw_of(q: np.ndarray) -> float:
    """ZYX yaw (rad) of the scalar-first quaternion ``q`` (body to inertial)."""
    return math.atan2(2.0 * (q[0] * q[3] + q[1] * q[2]), 1.0 - 2.0 * (q[2] * q[2] + q[3] * q[3]))


@compiled
def _limit(x: float, y: float, z: float, lim: float) -> tuple[float, float, float]:
    """``(x, y)`` scaled to a norm of at most ``lim``, ``z`` clipped to ``+-lim``."""
    h = math.sqrt(x * x + y * y)
    if h > lim:
        x *= lim / h
        y *= lim / h
    return x, y, min(max(z, -lim), lim)


@compiled
def hover_acceleration(
    x: np.ndarray,
    C: np.ndarray,
    p_set: np.ndarray,
    psi_set: float,
    gains: np.ndarray,
    g: float,
) -> tuple[float, float, float, float]:
    """Stage 5's desired thrust per unit mass ``f_des`` (inertial, m/s^2) and ``r_des`` (rad/s).

    ``x``: the state estimate (position inertial, velocity body); ``C``: its
    rotation; ``p_set`` (m), ``psi_set`` (rad): the set-points; ``gains``:
    ``(K_p, K_v, v_max, a_max, K_psi)``.
    """
    kp, kv, v_max, a_max, k_yaw = gains[0], gains[1], gains[2], gains[3], gains[4]
    vx = C[0, 0] * x[X_VEL] + C[0, 1] * x[X_VEL + 1] + C[0, 2] * x[X_VEL + 2]
    vy = C[1, 0] * x[X_VEL] + C[1, 1] * x[X_VEL + 1] + C[1, 2] * x[X_VEL + 2]
    vz = C[2, 0] * x[X_VEL] + C[2, 1] * x[X_VEL + 1] + C[2, 2] * x[X_VEL + 2]
    dx, dy, dz = _limit(
        kp * (p_set[0] - x[X_POS]),
        kp * (p_set[1] - x[X_POS + 1]),
        kp * (p_set[2] - x[X_POS + 2]),
        v_max,
    )
    ax, ay, az = _limit(kv * (dx - vx), kv * (dy - vy), kv * (dz - vz), a_max)
    r_des = k_yaw * wrap_pi(psi_set - yaw_of(x[X_QUAT : X_QUAT + 4]))
    return ax, ay, -g + az, r_des
