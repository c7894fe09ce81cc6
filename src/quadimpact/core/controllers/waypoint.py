"""The ``cascade-pid`` controller's position loop: a flight toward a waypoint.

Off unless ``ctrl[C_WAYPOINT_ON]`` (a flight scenario's ``waypoint``). Before
``C_WAYPOINT_T`` the loop holds ``C_HOLD_POS`` (the start: a hover), from it
on it flies to ``C_WAYPOINT``; the altitude stays the altitude loop's
(``C_H_REF``), the heading the heading loop's. In the horizontal plane
(inertial NED, X and Y)::

    v_des = K_p (p_ref - p), its magnitude limited to v_max
    a_des = K_v (v_des - v), its magnitude limited to g tan(tilt_max)

and the attitude references that tilt the thrust toward ``a_des`` at the
current heading ``psi`` with the vertical thrust ``m g`` (altitude held):
``a_f = cos(psi) a_X + sin(psi) a_Y`` (forward), ``a_r = -sin(psi) a_X +
cos(psi) a_Y`` (right), ``pitch = -atan(a_f / g)``,
``roll = atan(a_r cos(pitch) / g)``. Gains ``C_POS_GAINS``: ``K_p`` (1/s),
``K_v`` (1/s), ``v_max`` (m/s), ``tilt_max`` (rad).
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.controller_slots import C_HOLD_POS, C_POS_GAINS, C_WAYPOINT, C_WAYPOINT_T
from quadimpact.core.layout import X_POS, X_QUAT, X_VEL


@compiled
def _limit(ax: float, ay: float, limit: float) -> tuple[float, float]:
    """``(ax, ay)`` scaled down to the magnitude ``limit`` if it is larger."""
    n = math.sqrt(ax * ax + ay * ay)
    if n > limit and n > 0.0:
        return ax * limit / n, ay * limit / n
    return ax, ay


@compiled
def waypoint_references(
    t: float, x: np.ndarray, yaw: float, ctrl: np.ndarray, g: float
) -> tuple[float, float]:
    """Roll and pitch references (rad, ZYX) toward the waypoint at ``t`` (s).

    ``x``: the state (estimate) the controller reads; ``yaw``: its yaw (rad);
    ``g``: gravity (m/s^2).
    """
    k = C_WAYPOINT if t >= ctrl[C_WAYPOINT_T] else C_HOLD_POS
    q0, q1, q2, q3 = x[X_QUAT], x[X_QUAT + 1], x[X_QUAT + 2], x[X_QUAT + 3]
    n2 = q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3
    u, v, w = x[X_VEL], x[X_VEL + 1], x[X_VEL + 2]
    # inertial X and Y velocity: the first two rows of C v
    vx = ((1.0 - 2.0 * (q2 * q2 + q3 * q3) / n2) * u + 2.0 * (q1 * q2 - q0 * q3) / n2 * v
          + 2.0 * (q1 * q3 + q0 * q2) / n2 * w)  # fmt: skip
    vy = (2.0 * (q1 * q2 + q0 * q3) / n2 * u + (1.0 - 2.0 * (q1 * q1 + q3 * q3) / n2) * v
          + 2.0 * (q2 * q3 - q0 * q1) / n2 * w)  # fmt: skip
    kp = ctrl[C_POS_GAINS]
    kv = ctrl[C_POS_GAINS + 1]
    vdx, vdy = _limit(
        kp * (ctrl[k] - x[X_POS]), kp * (ctrl[k + 1] - x[X_POS + 1]), ctrl[C_POS_GAINS + 2]
    )
    ax, ay = _limit(kv * (vdx - vx), kv * (vdy - vy), g * math.tan(ctrl[C_POS_GAINS + 3]))
    c = math.cos(yaw)
    s = math.sin(yaw)
    pitch = -math.atan((c * ax + s * ay) / g)
    roll = math.atan((-s * ax + c * ay) * math.cos(pitch) / g)
    return roll, pitch
