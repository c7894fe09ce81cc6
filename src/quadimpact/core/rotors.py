"""Rotor forces and moments (docs/MODEL.md section 2, paper eqs. 5-7).

Physically consistent form (the default):

* thrust of rotor j: ``F_Tj = -kt_j Omega_j^2 e_z`` (body);
* moments ``sum_j r_Tj x F_Tj - s_j (dt_j Omega_j^2 + Jr Omega_dot_j) e_z``;
* gyroscopic moment ``-Jr (sum_j s_j Omega_j) (omega x e_z)``.

The authors' codes got the yaw reaction wrong in two separable ways, each a
switch: the drag torque with the rotor's own sense, ``+s_j dt Omega_j^2``
(``drag_paper``; both the paper's code and the later recovery code), and the
spin-up term without the spin sign, ``-Jr sum_j Omega_dot_j``
(``spinup_paper``; the paper's code only).

The sums run over the vehicle's ``n`` rotors in order (``veh[V_N_ROTORS]``).
``Jr = 0`` (a model without rotor gyroscopics) leaves no gyroscopic or
spin-up moment.
"""

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import MAX_ROTORS, N_RIGID, X_OMEGA, X_ROTOR, Block
from quadimpact.core.vehicle_slots import V_DT, V_JR, V_KT, V_N_ROTORS, V_ROTOR_POS, V_SPIN

# ---- the rotor inputs over the current sub-interval rin (NRIN), a field of Data: the
# actuators write them at each tick and power-off segment (core/actuators.py), the
# right-hand side reads the rotors' rates and reaction-torque Omega_dot from them
_rin = Block("rin", "RIN_")
RIN_CMD = _rin.slot("RIN_CMD", MAX_ROTORS)  # speed command in force (rad/s)
RIN_RATE = _rin.slot("RIN_RATE", MAX_ROTORS)  # prescribed d(Omega)/dt of the rotor states
RIN_FF = _rin.slot("RIN_FF", MAX_ROTORS)  # Omega_dot used in the reaction torque
RIN_FIRST_ORDER = _rin.slot("RIN_FIRST_ORDER")  # 1: rotor states follow (cmd - Omega) / tau
RIN_PREV_CMD = _rin.slot("RIN_PREV_CMD", MAX_ROTORS)  # the previous tick's command, limited
NRIN = _rin.end("NRIN")


@compiled(inline="always")
def active_states(veh: np.ndarray) -> int:
    """The state's components in use: the rigid body's and the vehicle's ``n`` rotor speeds.

    The rotor slots beyond ``n`` (up to ``MAX_ROTORS``) stay 0; the integrator
    runs over the first ``N_RIGID + n`` components only.
    """
    return N_RIGID + int(veh[V_N_ROTORS])


@compiled
def rotor_wrench(
    x: np.ndarray, omega_dot: np.ndarray, veh: np.ndarray, drag_paper: bool, spinup_paper: bool
) -> tuple[float, float, float, float]:
    """Total rotor thrust and moments, body frame.

    Parameters
    ----------
    x : state; rotor speeds ``Omega_j`` (rad/s) at ``X_ROTOR``.
    omega_dot : rotor accelerations ``Omega_dot_j`` (rad/s^2), one per rotor.
    veh : packed vehicle: its rotor count ``n`` (``V_N_ROTORS``) and, per rotor
        ``j``, its position, spin sense and coefficients ``kt_j``, ``dt_j``.
    drag_paper : drag torque ``+s_j dt Omega_j^2`` (authors' sense) instead of ``-s_j ...``.
    spinup_paper : spin-up reaction ``-Jr Omega_dot_j`` without the spin sign.

    Returns
    -------
    fz : thrust force along z_B (N, negative = up).
    mx, my, mz : moment about the CM (N m).
    """
    n = int(veh[V_N_ROTORS])
    if n == 4:  # a quadrotor: the loop's count known to the compiler (unrolled, as before)
        return _rotor_sums(x, omega_dot, veh, 4, drag_paper, spinup_paper)
    return _rotor_sums(x, omega_dot, veh, n, drag_paper, spinup_paper)


@compiled(inline="always")
def _rotor_sums(
    x: np.ndarray,
    omega_dot: np.ndarray,
    veh: np.ndarray,
    n: int,
    drag_paper: bool,
    spinup_paper: bool,
) -> tuple[float, float, float, float]:
    """:func:`rotor_wrench` over rotors ``0..n-1``, summed in rotor order."""
    jr = veh[V_JR]
    fz = 0.0
    mx = 0.0
    my = 0.0
    mz = 0.0
    spin_sum = 0.0
    for j in range(n):
        w = x[X_ROTOR + j]
        s = veh[V_SPIN + j]
        dt = veh[V_DT + j]
        t = veh[V_KT + j] * w * w
        fz -= t
        # r_Tj x (0, 0, -t)
        mx -= veh[V_ROTOR_POS + 3 * j + 1] * t
        my += veh[V_ROTOR_POS + 3 * j] * t
        if drag_paper and spinup_paper:
            mz += s * dt * w * w - jr * omega_dot[j]
        elif drag_paper:
            mz += s * (dt * w * w - jr * omega_dot[j])
        elif spinup_paper:
            mz -= s * dt * w * w + jr * omega_dot[j]
        else:
            mz -= s * (dt * w * w + jr * omega_dot[j])
        spin_sum += s * w
    # gyroscopic: -Jr S (omega x e_z) = -Jr S (q, -p, 0)
    mx -= jr * spin_sum * x[X_OMEGA + 1]
    my += jr * spin_sum * x[X_OMEGA]
    return fz, mx, my, mz
