"""What every built-in controller shares: the measured attitude, torques, allocation.

Frames: inertial NED, body FRD; angles in rad; rotor speeds in rad/s.
"""

import math

import numpy as np
from numba import njit

from ..layout import C_ALLOC_INV, V_INERTIA, X_OMEGA, X_POS, X_QUAT, X_VEL
from ..quaternion import euler_zyx


@njit(cache=True)
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


@njit(cache=True)
def allocate(
    ctrl: np.ndarray, thrust: float, tx: float, ty: float, tz: float, cmd: np.ndarray
) -> bool:
    """Solve ``[T, tx, ty, tz] = A Omega^2`` with the packed inverse; clip negative squares.

    ``thrust`` in N, torques in N m (body FRD); writes rotor speeds (rad/s) into
    ``cmd``. Returns True if any square was clipped.
    """
    clipped = False
    for j in range(4):
        a = ctrl[C_ALLOC_INV + 4 * j]
        b = ctrl[C_ALLOC_INV + 4 * j + 1]
        c = ctrl[C_ALLOC_INV + 4 * j + 2]
        d = ctrl[C_ALLOC_INV + 4 * j + 3]
        w2 = a * thrust + b * tx + c * ty + d * tz
        if w2 < 0.0:
            w2 = 0.0
            clipped = True
        cmd[j] = math.sqrt(w2)
    return clipped


@njit(cache=True)
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


@njit(cache=True)
def body_rates(x: np.ndarray) -> np.ndarray:
    """The body angular velocity slice ``(p, q, r)`` of a state (a view)."""
    return x[X_OMEGA : X_OMEGA + 3]


# ---------------------------------------------------------------- PID layout
# The two PID controllers (paper, cascade-pid) and the recovery controller's
# nominal pre-impact behaviour share this parameter and memory layout.
# Parameters, at ctrl[C_PARAMS + ...]:
P_GAINS = 0  # 15 gains: (P, I, D) for altitude, climb, heading, roll/pitch, yaw rate
P_THRUST_COS_FLOOR = 15  # cascade-pid: floor of cos(phi) cos(theta)
N_PID_PARAMS = 16

G_ALT = 0  # gain block offsets inside P_GAINS: P, I, D at +0, +1, +2
G_CLIMB = 3
G_HEADING = 6
G_ATT = 9
G_YAWRATE = 12

# Memory slots (the last, layout.MEM_STAGE, is reserved):
M_STARTED = 1  # 1 after the first tick
M_E_H = 2  # previous errors
M_E_V = 3
M_E_PSI = 4
M_E_PHI = 5
M_E_THETA = 6
M_E_R = 7
M_I_H = 8  # running integrals (cascade-pid)
M_I_V = 9
M_I_PSI = 10
M_I_PHI = 11
M_I_THETA = 12
M_I_R = 13
M_SATURATED = 14  # 1 if the last command saturated (cascade-pid)
N_PID_MEM = 15
