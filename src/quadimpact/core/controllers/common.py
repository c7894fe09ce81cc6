"""What every built-in controller shares: the measured attitude, torques, allocation.

Frames: inertial NED, body FRD; angles in rad; rotor speeds in rad/s.
"""

import math

import numpy as np

from quadimpact.core.compiled import allocating, compiled
from quadimpact.core.layout import (
    C_ALLOC_INV,
    C_N_ROTORS,
    N_WRENCH,
    V_INERTIA,
    X_OMEGA,
    X_POS,
    X_QUAT,
    X_VEL,
)
from quadimpact.core.quaternion import euler_zyx


@compiled
def attitude_altitude(x: np.ndarray) -> tuple[float, float, float, float, float]:
    """Roll, pitch, yaw (rad, ZYX), altitude ``h = -Z`` (m) and climb rate ``h_dot`` (m/s)."""
    roll, pitch, yaw = euler_zyx(x[X_QUAT : X_QUAT + 4])
    q0 = x[X_QUAT]
    q1 = x[X_QUAT + 1]
    q2 = x[X_QUAT + 2]
    q3 = x[X_QUAT + 3]
    n2 = q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3
    c20 = 2.0 * (q1 * q3 - q0 * q2) / n2
    c21 = 2.0 * (q2 * q3 + q0 * q1) / n2
    c22 = 1.0 - 2.0 * (q1 * q1 + q2 * q2) / n2
    zdot = c20 * x[X_VEL] + c21 * x[X_VEL + 1] + c22 * x[X_VEL + 2]
    return roll, pitch, yaw, -x[X_POS + 2], -zdot


@compiled
def allocate(
    ctrl: np.ndarray, thrust: float, tx: float, ty: float, tz: float, cmd: np.ndarray
) -> bool:
    """Solve ``[T, tx, ty, tz] = A Omega^2`` with the packed inverse; clip negative squares.

    ``A`` is the vehicle's 4 x n effectiveness matrix (docs/MODEL.md 6.1; ``n``
    rotors, ``ctrl[C_N_ROTORS]``). The packed inverse ``A^+`` (n x 4, row ``j``
    at ``C_ALLOC_INV + N_WRENCH j``) is ``A^-1`` for a quadrotor and the
    Moore-Penrose pseudo-inverse ``A^T (A A^T)^-1`` otherwise: the least-squares
    ``Omega^2`` of the smallest norm, so ``A Omega^2`` is the commanded wrench
    exactly while every square is >= 0. A negative square is clipped to 0 (a
    rotor cannot push): the wrench is then not reproduced, and this returns
    True. The other squares are not redistributed.

    ``thrust`` in N, torques in N m (body FRD); writes the ``n`` rotor speeds
    (rad/s) into ``cmd``. Returns True if any square was clipped.
    """
    clipped = False
    for j in range(int(ctrl[C_N_ROTORS])):
        a = ctrl[C_ALLOC_INV + N_WRENCH * j]
        b = ctrl[C_ALLOC_INV + N_WRENCH * j + 1]
        c = ctrl[C_ALLOC_INV + N_WRENCH * j + 2]
        d = ctrl[C_ALLOC_INV + N_WRENCH * j + 3]
        w2 = a * thrust + b * tx + c * ty + d * tz
        if w2 < 0.0:
            w2 = 0.0
            clipped = True
        cmd[j] = math.sqrt(w2)
    return clipped


@compiled
def linearised_torques(
    omega: np.ndarray, veh: np.ndarray, a_p: float, a_q: float, a_r: float
) -> tuple[float, float, float]:
    """Feedback-linearised torques (N m) from angular-acceleration commands (rad/s^2).

    ``tau_x = Ixx a_p - (Iyy - Izz) q r`` and cyclic; ``omega = (p, q, r)`` body rates.
    """
    ixx = veh[V_INERTIA]
    iyy = veh[V_INERTIA + 4]
    izz = veh[V_INERTIA + 8]
    p = omega[0]
    q = omega[1]
    r = omega[2]
    tx = ixx * a_p - (iyy - izz) * q * r
    ty = iyy * a_q - (izz - ixx) * p * r
    tz = izz * a_r - (ixx - iyy) * p * q
    return tx, ty, tz


@allocating
def body_rates(x: np.ndarray) -> np.ndarray:
    """The body angular velocity slice ``(p, q, r)`` of a state (a view)."""
    return x[X_OMEGA : X_OMEGA + 3]
