"""What every built-in controller shares: the measured attitude, torques, allocation.

It also declares the PID laws' blocks (the paper's and cascade-pid's, and the
recovery law's nominal pre-impact flight): their parameters at
``ctrl[C_PARAMS + P_*]`` and their memory ``mem[M_*]``.

Frames: inertial NED, body FRD; angles in rad; rotor speeds in rad/s.
"""

import math

import numpy as np

from quadimpact.core.compiled import allocating, compiled
from quadimpact.core.controller_slots import C_ALLOC_INV, C_N_ROTORS, N_WRENCH, NPARAM
from quadimpact.core.layout import MEM_STAGE, X_OMEGA, X_POS, X_QUAT, X_VEL, Block
from quadimpact.core.quaternion import euler_zyx
from quadimpact.core.vehicle_slots import V_INERTIA

# ---- the PID laws' blocks
# The two PID controllers (paper, cascade-pid) and the recovery controller's
# nominal pre-impact behaviour share this parameter and memory layout.
# Parameters, at ctrl[C_PARAMS + ...]:
_params = Block("ctrl.params", "P_", capacity=NPARAM)
P_GAINS = _params.slot(
    "P_GAINS", 15
)  # (P, I, D) for altitude, climb, heading, roll/pitch, yaw rate
P_THRUST_COS_FLOOR = _params.slot("P_THRUST_COS_FLOOR")  # cascade-pid: floor of cos(phi) cos(theta)
N_PID_PARAMS = _params.end("N_PID_PARAMS")

G_ALT = 0  # gain block offsets inside P_GAINS: P, I, D at +0, +1, +2
G_CLIMB = 3
G_HEADING = 6
G_ATT = 9
G_YAWRATE = 12

# Memory slots (slot 0 unused; the last, layout.MEM_STAGE, is reserved):
_mem = Block("mem", "M_", start=1, capacity=MEM_STAGE)
M_STARTED = _mem.slot("M_STARTED")  # 1 after the first tick
M_E_H = _mem.slot("M_E_H")  # previous errors
M_E_V = _mem.slot("M_E_V")
M_E_PSI = _mem.slot("M_E_PSI")
M_E_PHI = _mem.slot("M_E_PHI")
M_E_THETA = _mem.slot("M_E_THETA")
M_E_R = _mem.slot("M_E_R")
M_I_H = _mem.slot("M_I_H")  # running integrals (cascade-pid)
M_I_V = _mem.slot("M_I_V")
M_I_PSI = _mem.slot("M_I_PSI")
M_I_PHI = _mem.slot("M_I_PHI")
M_I_THETA = _mem.slot("M_I_THETA")
M_I_R = _mem.slot("M_I_R")
M_SATURATED = _mem.slot("M_SATURATED")  # 1 if the last command saturated (cascade-pid)
N_PID_MEM = _mem.end("N_PID_MEM")


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
