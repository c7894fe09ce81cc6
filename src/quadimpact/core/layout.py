"""Layout of the flat arrays exchanged between the Python layer and the compiled core.

The compiled kernel takes no Python objects: vehicles, surfaces, options and
controller settings are packed into ``float64`` arrays whose slots are named
here. Numba treats these module-level integers as compile-time constants.

Everything is SI; frames as in MODEL.md section 1 (inertial NED, body FRD).
"""

# --------------------------------------------------------------------------
# State vector x (length NX). Rotor speeds are always part of the state: in
# ideal and power-off modes their derivative is prescribed (zero or a
# schedule rate), in first-order mode it is (cmd - Omega) / tau.
# --------------------------------------------------------------------------
X_POS = 0  # p, CM position, inertial (3)
X_VEL = 3  # v, CM velocity, body (3)
X_QUAT = 6  # q = [q0, q1, q2, q3], scalar first, body -> inertial (4)
X_OMEGA = 10  # omega = [p, q, r], body angular velocity (3)
X_ROTOR = 13  # Omega_1..4, rotor speeds in rad/s (4)
NX = 17
N_RIGID = 13

# --------------------------------------------------------------------------
# Vehicle vector veh (length NVEH)
# --------------------------------------------------------------------------
V_MASS = 0
V_INERTIA = 1  # 9, row-major
V_INERTIA_INV = 10  # 9, row-major
V_ROTOR_POS = 19  # 12, rotor j at V_ROTOR_POS + 3 j (body, m)
V_SPIN = 31  # 4, +-1, spin sense about +z_B
V_KT = 35  # thrust coefficient, N/(rad/s)^2
V_DT = 36  # drag-torque coefficient, N m/(rad/s)^2
V_JR = 37  # rotor inertia about its axis, kg m^2
V_GRAVITY = 38  # m/s^2
V_RB = 39  # bumper circle radius, m
V_BUMP_C = 40  # 12, bumper centre j (body, m)
V_BUMP_N = 52  # 12, circle plane unit normal n_j (body)
V_K = 64  # contact stiffness, N/m^n
V_N = 65  # contact exponent
V_E = 66  # coefficient of restitution
V_TAU_M = 67  # motor time constant, s (first-order rotor mode)
NVEH = 68

# --------------------------------------------------------------------------
# Surfaces: array surf of shape (n_surfaces, NSURF). A plane through p0 with
# unit normal m pointing out of the obstacle into free space.
# --------------------------------------------------------------------------
S_P0 = 0  # 3
S_NORMAL = 3  # 3
S_IS_GROUND = 6  # 1.0 if this surface is the ground (first onset = crash)
NSURF = 7

# --------------------------------------------------------------------------
# Options vector opts (length NOPT): model switches, integrator settings
# --------------------------------------------------------------------------
O_YAW_REACTION_PAPER = 0  # 1: replica rotor yaw reaction (+s dt W^2, -Jr sum Wdot)
O_DOUBLE_BUMPER1_YAW = 1  # 1: replica counts bumper 1's contact yaw moment twice
O_CRASH_RULE = 2  # CRASH_* below
O_CRASH_ALTITUDE = 3  # m; crash when h <= this (paper-ticks rule) or crosses it
O_ROTOR_MODE = 4  # ROTOR_* below
O_OMEGA_MIN = 5  # rad/s, command lower limit (<= 0: none)
O_OMEGA_MAX = 6  # rad/s, command upper limit (<= 0: none)
O_SLEW_MAX = 7  # rad/s^2, command slew limit (<= 0: none)
O_MU = 8  # friction coefficient (0: frictionless, the paper)
O_V_REG = 9  # m/s, friction regularisation velocity
O_V_MIN = 10  # m/s, floor of v_i in the damping coefficient
O_DT_CONTROL = 11  # s, control period
O_RTOL = 12
O_ATOL = 13
O_H_MAX = 14  # s, largest step (<= 0: the control period)
O_MAX_STEPS = 15  # total accepted+rejected step budget
O_EVENT_TOL = 16  # s, event time tolerance
O_POWER_OFF_T = 17  # s, power-off trigger time (< 0: at the first contact; inf: never)
O_STOP_ON_CRASH = 18  # 1: end the run at the crash
NOPT = 19

CRASH_CM_GROUND = 0  # event: CM altitude crosses O_CRASH_ALTITUDE (default 0)
CRASH_PAPER_TICKS = 1  # h <= O_CRASH_ALTITUDE tested at control ticks only
CRASH_NONE = 2  # no crash plane (ground may be a contact surface)

ROTOR_IDEAL = 0
ROTOR_FIRST_ORDER = 1

# --------------------------------------------------------------------------
# Controller vector ctrl (length NCTRL) and its memory (length NMEM)
# --------------------------------------------------------------------------
C_KIND = 0  # CTRL_* below
C_H_REF = 1  # m, altitude reference
C_PHI_REF = 2  # rad
C_THETA_REF = 3  # rad
C_PSI_REF = 4  # rad
C_GAINS = 5  # 15 gains: (P, I, D) for altitude, climb, heading, roll/pitch, yaw rate
C_THRUST_COS_FLOOR = 20  # cascade-pid: floor of cos(phi) cos(theta)
C_ALLOC_INV = 21  # 16: inverse allocation matrix, row-major
C_OMEGA_MIN = 37  # rad/s, controller's own rotor limits (cascade-pid)
C_OMEGA_MAX = 38
NCTRL = 39

CTRL_NONE = 0  # rotors held at their initial speeds (no controller)
CTRL_PAPER = 1
CTRL_CASCADE_PID = 2

G_ALT = 0  # gain block offsets inside C_GAINS: P, I, D at +0, +1, +2
G_CLIMB = 3
G_HEADING = 6
G_ATT = 9
G_YAWRATE = 12

NMEM = 24  # controller memory (previous errors, integrals, flags)

# --------------------------------------------------------------------------
# Rotor input over the current sub-interval (array rin of length NRIN)
# --------------------------------------------------------------------------
RIN_CMD = 0  # 4: speed command in force (rad/s)
RIN_RATE = 4  # 4: prescribed d(Omega)/dt of the rotor states (ideal: 0; power-off: rate)
RIN_FF = 8  # 4: Omega_dot used in the reaction torque (ideal: finite difference)
RIN_FIRST_ORDER = 12  # 1: rotor states follow (cmd - Omega) / tau instead
NRIN = 13

# --------------------------------------------------------------------------
# Output time series columns (array out of shape (n_out, NOUT))
# --------------------------------------------------------------------------
OUT_T = 0
OUT_X = 1  # NX state columns
OUT_DELTA = OUT_X + NX  # 4: per-bumper deflection, max over surfaces, >= 0 (m)
OUT_FORCE = OUT_DELTA + 4  # 4: per-bumper normal force, sum over surfaces (N)
OUT_CMD = OUT_FORCE + 4  # 4: rotor speed command in force (rad/s)
NOUT = OUT_CMD + 4

# --------------------------------------------------------------------------
# Contact episodes (array episodes of shape (max_episodes, NEP))
# --------------------------------------------------------------------------
E_BUMPER = 0  # 0..3
E_SURFACE = 1  # index into surf
E_T_START = 2  # s, located onset
E_T_END = 3  # s, located end (run end if still open)
E_V_I = 4  # m/s, penetration rate at onset (before the v_min floor)
E_PEAK_DELTA = 5  # m
E_T_PEAK = 6  # s
E_PEAK_FORCE = 7  # N
E_T_PEAK_FORCE = 8  # s
E_OPEN = 9  # 1 if the episode had not ended when the run stopped
NEP = 10

# --------------------------------------------------------------------------
# Run statistics (array stats of length NSTAT)
# --------------------------------------------------------------------------
ST_STATUS = 0  # STATUS_* below
ST_REASON = 1  # REASON_* below
ST_T_END = 2  # s, time reached
ST_N_STEPS = 3  # accepted steps
ST_N_REJECTED = 4
ST_N_RHS = 5  # right-hand-side evaluations
ST_N_OUT = 6  # output rows written
ST_N_EPISODES = 7
ST_CRASH_T = 8  # s, NaN when none
ST_CRASH_X = 9  # m, CM position at the crash
ST_CRASH_Y = 10
ST_CRASH_Z = 11
ST_MAX_DELTA = 12  # m, largest penetration of any bumper on any surface
ST_MISSED_ONSETS = 13  # contacts found already penetrating at a step start
ST_EPISODES_DROPPED = 14  # episodes beyond the buffer
ST_POWER_OFF_T = 15  # s, when the power-off schedule started (NaN: never)
ST_N_TICKS = 16  # controller updates
ST_ONSET_T = 17  # s, first contact onset on a non-ground surface (NaN: none)
ST_ONSET_X = 18  # NX: full state at that onset
NSTAT = ST_ONSET_X + NX

STATUS_COMPLETED = 0
STATUS_CRASHED = 1
STATUS_FAILED = 2

REASON_NONE = 0
REASON_STEP_TOO_SMALL = 1
REASON_MAX_STEPS = 2
REASON_NOT_FINITE = 3
REASON_TEXT = {
    REASON_NONE: "",
    REASON_STEP_TOO_SMALL: "step size fell below the floor (stiff or singular dynamics)",
    REASON_MAX_STEPS: "step budget exhausted",
    REASON_NOT_FINITE: "state became NaN or infinite",
}
