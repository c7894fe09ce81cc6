"""The one place where validated inputs become the compiled core's flat arrays.

Slots are named in ``quadimpact.core.layout``. Nothing here integrates.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from quadimpact.core import layout as L
from quadimpact.core.controllers.common import P_GAINS, P_THRUST_COS_FLOOR
from quadimpact.inputs.vehicle import Vehicle
from quadimpact.inputs.world import Plane

# Paper gains (MODEL.md 6.1): (P, I, D) for altitude, climb rate, heading,
# roll/pitch and yaw rate, in the order of the G_* blocks.
PAPER_GAINS = np.array(
    [
        2.0, 0.0, 0.4,  # altitude h -> climb-rate reference
        1.6, 60.0, 0.0,  # climb rate -> vertical acceleration
        1.2, 1.0, 0.2,  # heading -> yaw-rate reference
        7.2, 4.0, 4.2,  # roll and pitch -> angular acceleration
        1.8, 2.0, 0.0,  # yaw rate -> yaw acceleration
    ]
)  # fmt: skip

# cascade-pid gains: the paper's, retuned where a running integral changes the
# loop (linearised analysis in docs/CONTROLLERS.md): climb rate P 4, I 4 (the
# paper's 1.6 and 60 give damping 0.05 with a true integral); heading I 0 (the
# yaw-rate integral already removes steady yaw errors; paper 1) and yaw rate
# P 3, I 1 (paper 1.8, 2: damping 0.26 with running integrals). Every loop then
# has damping >= 0.7.
CASCADE_GAINS = np.array(
    [
        2.0, 0.0, 0.4,  # altitude h -> climb-rate reference
        4.0, 4.0, 0.0,  # climb rate -> vertical acceleration
        1.2, 0.0, 0.2,  # heading -> yaw-rate reference
        7.2, 4.0, 4.2,  # roll and pitch -> angular acceleration
        3.0, 1.0, 0.0,  # yaw rate -> yaw acceleration
    ]
)  # fmt: skip
DEFAULT_GAINS = {L.CTRL_PAPER: PAPER_GAINS, L.CTRL_CASCADE_PID: CASCADE_GAINS}

CONTROL_RATE_HZ = 200.0
CASCADE_THRUST_COS_FLOOR = 0.5
RPM = 2.0 * np.pi / 60.0  # rad/s per rpm

# Integrator defaults, chosen by measurement (docs/NUMERICS.md,
# benchmarks/bench_tolerance.py): tightening both tenfold changes delta_init
# of the paper example by far less than 1e-4 relative.
DEFAULT_RTOL = 1e-8
DEFAULT_ATOL = 1e-10
EVENT_TOL_S = 1e-12
V_MIN_M_S = 1e-3  # floor of v_i in the damping coefficient (MODEL.md 4)
FRICTION_V_REG_M_S = 1e-2  # friction regularisation velocity
MAX_STEPS_PER_S = 2_000_000


def pack_vehicle(v: Vehicle) -> np.ndarray:
    """Vehicle parameters as the ``V_*`` vector (SI, body frame)."""
    veh = np.zeros(L.NVEH)
    inertia = v.inertia
    veh[L.V_MASS] = v.mass_kg
    veh[L.V_INERTIA : L.V_INERTIA + 9] = inertia.ravel()
    veh[L.V_INERTIA_INV : L.V_INERTIA_INV + 9] = np.linalg.inv(inertia).ravel()
    veh[L.V_ROTOR_POS : L.V_ROTOR_POS + 12] = v.rotor_positions.ravel()
    veh[L.V_SPIN : L.V_SPIN + 4] = v.spins
    veh[L.V_KT] = v.thrust_coefficient
    veh[L.V_DT] = v.drag_torque_coefficient
    veh[L.V_JR] = v.rotor_inertia_kg_m2
    veh[L.V_GRAVITY] = v.gravity_m_s2
    veh[L.V_RB] = v.bumper_radius_m
    centres, _, n = v.bumper_frames()
    veh[L.V_BUMP_C : L.V_BUMP_C + 12] = centres.ravel()
    veh[L.V_BUMP_N : L.V_BUMP_N + 12] = n.ravel()
    veh[L.V_K] = v.contact_stiffness
    veh[L.V_N] = v.contact_exponent
    veh[L.V_E] = v.restitution
    veh[L.V_TAU_M] = v.motor_time_constant_s
    return veh


def pack_surfaces(surfaces: Sequence[Plane]) -> np.ndarray:
    """Surfaces as an (n, NSURF) array; normals normalised."""
    surf = np.zeros((len(surfaces), L.NSURF))
    for i, s in enumerate(surfaces):
        n = np.asarray(s.normal, dtype=float)
        surf[i, L.S_P0 : L.S_P0 + 3] = s.point_m
        surf[i, L.S_NORMAL : L.S_NORMAL + 3] = n / np.linalg.norm(n)
        surf[i, L.S_IS_GROUND] = 1.0 if s.is_ground else 0.0
        surf[i, L.S_KIND] = L.SURF_PLANE
    return surf


def allocation_matrix(v: Vehicle, yaw_paper: bool) -> np.ndarray:
    """``A`` with ``[T, tau_x, tau_y, tau_z] = A [Omega_1^2 .. Omega_4^2]`` (MODEL.md 6.1).

    Rows: ``kt``, ``-kt y_j``, ``kt x_j`` and the yaw row of the rotor-torque
    model in use: ``-s_j dt`` (physical) or ``+s_j dt`` (paper replica).
    """
    kt = v.thrust_coefficient
    r = v.rotor_positions
    yaw = v.drag_torque_coefficient * v.spins * (1.0 if yaw_paper else -1.0)
    return np.vstack([np.full(4, kt), -kt * r[:, 1], kt * r[:, 0], yaw])


def trim_rotor_speeds(v: Vehicle, thrust_n: float, yaw_paper: bool) -> np.ndarray:
    """Rotor speeds (rad/s) giving total thrust ``thrust_n`` (N) and zero torques."""
    w2 = np.linalg.solve(allocation_matrix(v, yaw_paper), [thrust_n, 0.0, 0.0, 0.0])
    return np.sqrt(np.clip(w2, 0.0, None))


def pack_controller(
    kind: int,
    v: Vehicle,
    refs: dict[str, float],
    yaw_paper: bool,
    gains: np.ndarray | None = None,
) -> np.ndarray:
    """Controller settings as the ``C_*`` vector.

    ``refs`` holds ``altitude_m``, ``roll_rad``, ``pitch_rad``, ``yaw_rad``.
    """
    ctrl = np.zeros(L.NCTRL)
    ctrl[L.C_KIND] = kind
    ctrl[L.C_H_REF] = refs["altitude_m"]
    ctrl[L.C_PHI_REF] = refs["roll_rad"]
    ctrl[L.C_THETA_REF] = refs["pitch_rad"]
    ctrl[L.C_PSI_REF] = refs["yaw_rad"]
    if gains is None:
        gains = DEFAULT_GAINS.get(kind, PAPER_GAINS)
    ctrl[L.C_PARAMS + P_GAINS : L.C_PARAMS + P_GAINS + 15] = gains
    ctrl[L.C_PARAMS + P_THRUST_COS_FLOOR] = CASCADE_THRUST_COS_FLOOR
    ctrl[L.C_ALLOC_INV : L.C_ALLOC_INV + 16] = np.linalg.inv(
        allocation_matrix(v, yaw_paper)
    ).ravel()
    lo, hi = v.rotor_speed_range_rpm
    ctrl[L.C_OMEGA_MIN] = lo * RPM
    ctrl[L.C_OMEGA_MAX] = hi * RPM
    return ctrl


def pack_options(
    *,
    yaw_paper: bool,
    bumper1_yaw_twice: bool,
    crash_rule: int,
    crash_altitude_m: float,
    stop_on_crash: bool,
    first_order_rotors: bool,
    omega_limits_rad_s: tuple[float, float] | None,
    slew_limit_rad_s2: float | None,
    friction_coefficient: float,
    rtol: float | None,
    atol: float | None,
    duration_s: float,
) -> np.ndarray:
    """Model switches and integrator settings as the ``O_*`` vector."""
    opts = np.zeros(L.NOPT)
    opts[L.O_YAW_REACTION_PAPER] = float(yaw_paper)
    opts[L.O_SPINUP_PAPER] = float(yaw_paper)
    opts[L.O_DOUBLE_BUMPER1_YAW] = float(bumper1_yaw_twice)
    opts[L.O_CRASH_RULE] = crash_rule
    opts[L.O_CRASH_ALTITUDE] = crash_altitude_m
    opts[L.O_STOP_ON_CRASH] = float(stop_on_crash)
    opts[L.O_ROTOR_MODE] = L.ROTOR_FIRST_ORDER if first_order_rotors else L.ROTOR_IDEAL
    if omega_limits_rad_s is not None:
        opts[L.O_OMEGA_MIN], opts[L.O_OMEGA_MAX] = omega_limits_rad_s
    opts[L.O_SLEW_MAX] = slew_limit_rad_s2 or 0.0
    opts[L.O_MU] = friction_coefficient
    opts[L.O_V_REG] = FRICTION_V_REG_M_S
    opts[L.O_V_MIN] = V_MIN_M_S
    opts[L.O_DT_CONTROL] = 1.0 / CONTROL_RATE_HZ
    opts[L.O_RTOL] = DEFAULT_RTOL if rtol is None else rtol
    opts[L.O_ATOL] = DEFAULT_ATOL if atol is None else atol
    opts[L.O_H_MAX] = 0.0
    opts[L.O_MAX_STEPS] = max(100_000, MAX_STEPS_PER_S * duration_s)
    opts[L.O_EVENT_TOL] = EVENT_TOL_S
    opts[L.O_POWER_OFF_T] = np.inf
    return opts
