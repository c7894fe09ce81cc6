"""Layout of the flat arrays exchanged between the Python layer and the compiled core.

The compiled kernel takes no Python objects: vehicles, surfaces, options and
controller settings are packed into ``float64`` arrays whose slots are named
here. Numba treats these module-level integers as compile-time constants.

Everything is SI; frames as in docs/MODEL.md section 1 (inertial NED, body FRD).
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
S_KIND = 7  # SURF_* below: which geometry (core/geometry.py dispatches on it)
NSURF = 8

SURF_PLANE = 0  # half-space: a plane through S_P0 with outward unit normal S_NORMAL

# --------------------------------------------------------------------------
# Options vector opts (length NOPT): model switches, integrator settings
# --------------------------------------------------------------------------
O_YAW_REACTION_PAPER = 0  # 1: replica rotor drag torque +s dt W^2 (and the allocation's yaw row)
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
O_SPINUP_PAPER = 19  # 1: spin-up reaction -Jr sum_j Omega_dot_j (no spin sign; paper replica)
O_CONTACT_GATE = 20  # m; > 0: contact forces act only while the CM is within this of the plane
O_CUT_STEP_MOTORS = 21  # bit j-1 set: a power-off schedule cuts motor j at the first tick after
#                         its trigger, as a one-tick command step (actuators.cut_step)
O_BUMPER_FORCE_SCALE = 22  # 4: per-bumper factor on the contact force (<= 0: 1, unscaled)
NOPT = 26

CRASH_CM_GROUND = 0  # event: CM altitude crosses O_CRASH_ALTITUDE (default 0)
CRASH_PAPER_TICKS = 1  # h <= O_CRASH_ALTITUDE tested at the control ticks after the start
CRASH_NONE = 2  # no crash plane (ground may be a contact surface)

ROTOR_IDEAL = 0
ROTOR_FIRST_ORDER = 1

# --------------------------------------------------------------------------
# Controller vector ctrl (length NCTRL) and its memory (length NMEM)
#
# A common head (kind, references, allocation, rotor range) followed by a
# block of NPARAM slots that each controller lays out for itself (see its
# module in core/controllers/). Memory slot MEM_STAGE (the last) is reserved:
# a controller with discrete stages writes its current stage there, and the
# loop records it per output sample and the tick at which each stage was
# first entered (ST_STAGE_T). Controllers written for the earlier 24-slot
# memory never touch it.
# --------------------------------------------------------------------------
C_KIND = 0  # CTRL_* below
C_H_REF = 1  # m, altitude reference
C_PHI_REF = 2  # rad
C_THETA_REF = 3  # rad
C_PSI_REF = 4  # rad
C_ALLOC_INV = 5  # 16: inverse allocation matrix, row-major
C_OMEGA_MIN = 21  # rad/s, the vehicle's rotor speed range (controllers that limit themselves)
C_OMEGA_MAX = 22
C_PARAMS = 23  # start of the controller's own parameters
NPARAM = 64
NCTRL = C_PARAMS + NPARAM

CTRL_NONE = 0  # rotors held at their initial speeds (no controller)
CTRL_PAPER = 1
CTRL_CASCADE_PID = 2
CTRL_RECOVERY = 3
CTRL_USER = 99  # a plug-in controller compiled with run.make_kernel

NMEM = 64  # controller memory (previous errors, integrals, flags), zeroed at the start
MEM_STAGE = NMEM - 1  # reserved: the controller's current stage (0 when it has none)
N_STAGES = 8  # stages 0..7 have recorded entry ticks

# --------------------------------------------------------------------------
# Rotor input over the current sub-interval (array rin of length NRIN)
# --------------------------------------------------------------------------
RIN_CMD = 0  # 4: speed command in force (rad/s)
RIN_RATE = 4  # 4: prescribed d(Omega)/dt of the rotor states (ideal: 0; power-off: rate)
RIN_FF = 8  # 4: Omega_dot used in the reaction torque (ideal: finite difference)
RIN_FIRST_ORDER = 12  # 1: rotor states follow (cmd - Omega) / tau instead
RIN_PREV_CMD = 13  # 4: the command of the previous tick, after limits (rad/s)
NRIN = 17

# --------------------------------------------------------------------------
# Loop state (array ls of length NLS): what the run loop carries from one
# control tick to the next besides the state, the rotor inputs, the contact
# pairs and the controller memory. Counters live in stats (ST_*).
# --------------------------------------------------------------------------
LS_T = 0  # s, time reached
LS_T0 = 1  # s, start of the run (tick k is at t0 + k dt)
LS_TF = 2  # s, end of the run
LS_K = 3  # index of the next control tick
LS_H = 4  # s, step-size proposal for the next step
LS_DONE = 5  # 1: the run has ended (final time, crash with stop, failure)
LS_PO_ACTIVE = 6  # 1: the power-off schedule is in force
LS_PO_T = 7  # s, its trigger time
LS_PO_SEG = 8  # its segment in force
LS_T_SCHED = 9  # s, next instant the scheduled rotor inputs change (inf: none)
LS_STAGE = 10  # the controller's stage in force (from MEM_STAGE at the last tick)
LS_EXT = 11  # 1: the next tick applies LS_EXT_CMD instead of the controller's command
LS_EXT_CMD = 12  # 4: external rotor speed command (rad/s), e.g. from Python
NLS = 16

# --------------------------------------------------------------------------
# Contact pairs (array cs of shape (4 n_surfaces, NCS)); pair c = 4 s + j is
# bumper j against surface s. Changed only at located events.
# --------------------------------------------------------------------------
CS_ACTIVE = 0  # 1 while the pair is in a contact episode (force applied)
CS_LAMBDA = 1  # damping coefficient fixed at the episode's onset
CS_EPISODE = 2  # row of its episode in `episodes` (-1: none / beyond the buffer)
NCS = 3

# --------------------------------------------------------------------------
# Measurement record (array meas of length NMEAS): what a controller sees at
# a control tick (core/sensors). The state estimate is the true state (an
# ideal estimator); the IMU fields hold the latest sample and the detector's
# verdict (zero / NaN until there is one).
# --------------------------------------------------------------------------
MS_X = 0  # NX: state estimate (today the true state at the tick)
MS_T = MS_X + NX  # s, time of the tick
MS_IMU_T = MS_T + 1  # s, time of the latest IMU sample (NaN: none yet)
MS_IMU_F = MS_IMU_T + 1  # 3: measured specific force, body FRD, m/s^2
MS_IMU_W = MS_IMU_F + 3  # 3: measured angular velocity, body FRD, rad/s
MS_DETECTED = MS_IMU_W + 3  # 1 once an impact has been detected
MS_T_DETECT = MS_DETECTED + 1  # s, time of the detecting sample (NaN: none)
MS_NORMAL = MS_T_DETECT + 1  # 3: wall-normal estimate at detection, inertial, unit (away)
NMEAS = MS_NORMAL + 3

# --------------------------------------------------------------------------
# Sensor configuration (array scfg of length NSCFG): the IMU and the impact
# detector (core/sensors/imu.py, core/sensors/detection.py). All noise,
# bias, saturation and filtering are off when their slots are 0.
# --------------------------------------------------------------------------
SC_RATE = 0  # Hz, IMU sample rate (0: no IMU, no detection)
SC_POS = 1  # 3: IMU position from the CM, body FRD, m
SC_NOISE_F = 4  # accelerometer white-noise standard deviation per axis, m/s^2
SC_NOISE_W = 5  # gyro white-noise standard deviation per axis, rad/s
SC_BIAS = 6  # 6: constant biases (f_x, f_y, f_z, w_x, w_y, w_z), drawn once per run
SC_RANGE_F = 12  # m/s^2, accelerometer range (saturation, per axis; <= 0: none)
SC_RANGE_W = 13  # rad/s, gyro range (<= 0: none)
SC_FILTER = 14  # FILTER_* below
SC_FILTER_PARAM = 15  # first-order: time constant, s; moving average: window, samples
SC_DET_THRESHOLD = 16  # m/s^2, horizontal specific force that detects an impact (<= 0: off)
SC_DET_WORLD = 17  # 1: world-horizontal |(C f)_XY| instead of body-horizontal |(f_x, f_y)|
SC_DET_PERSIST = 18  # consecutive samples at or above the threshold (>= 1)
NSCFG = 19

FILTER_NONE = 0
FILTER_FIRST_ORDER = 1
FILTER_MOVING_AVERAGE = 2
MAX_AVERAGE_WINDOW = 64  # samples

# --------------------------------------------------------------------------
# Sensor state (array sst of length NSST)
# --------------------------------------------------------------------------
SS_N = 0  # samples taken
SS_NEXT_T = 1  # s, time of the next sample
SS_COUNT = 2  # consecutive samples at or above the detection threshold
SS_FILT = 3  # 6: low-pass state (first-order) / running sum (moving average)
SS_RING = 9  # 6 * MAX_AVERAGE_WINDOW: moving-average window of the saturated samples
NSST = SS_RING + 6 * MAX_AVERAGE_WINDOW

# --------------------------------------------------------------------------
# IMU samples (array imu_out of shape (n_imu, NIMU))
# --------------------------------------------------------------------------
I_T = 0  # s
I_F = 1  # 3: measured specific force, body FRD, m/s^2
I_W = 4  # 3: measured angular velocity, body FRD, rad/s
I_F_TRUE = 7  # 3: true specific force at the IMU position, m/s^2
I_W_TRUE = 10  # 3: true angular velocity, rad/s
I_HORIZONTAL = 13  # the detector's horizontal measure of this sample, m/s^2
NIMU = 14

# --------------------------------------------------------------------------
# Output time series columns (array out of shape (n_out, NOUT))
# --------------------------------------------------------------------------
OUT_T = 0
OUT_X = 1  # NX state columns
OUT_DELTA = OUT_X + NX  # 4: per-bumper deflection, max over surfaces, >= 0 (m)
OUT_FORCE = OUT_DELTA + 4  # 4: per-bumper normal force, sum over surfaces (N)
OUT_CMD = OUT_FORCE + 4  # 4: rotor speed command in force (rad/s)
OUT_STAGE = OUT_CMD + 4  # the controller's stage in force (MEM_STAGE)
NOUT = OUT_STAGE + 1

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
ST_T_DETECT = ST_ONSET_X + NX  # s, first impact detection (NaN: none)
ST_DETECT_X = ST_T_DETECT + 1  # NX: state at that detection sample
ST_DETECT_NORMAL = ST_DETECT_X + NX  # 3: wall-normal estimate, inertial
ST_N_DETECTIONS = ST_DETECT_NORMAL + 3  # rising edges of the detection condition
ST_N_IMU = ST_N_DETECTIONS + 1  # IMU samples taken (also beyond the buffer)
ST_STAGE_T = ST_N_IMU + 1  # N_STAGES: tick at which each stage was first entered (NaN)
ST_STAGE_X = ST_STAGE_T + N_STAGES  # 3 N_STAGES: CM position there, inertial
ST_MIN_ALT = ST_STAGE_X + 3 * N_STAGES  # m, lowest CM altitude (step ends and events)
ST_MIN_TILT_COS = ST_MIN_ALT + 1  # after detection: lowest cos(tilt from vertical) (1: none)
ST_MAX_RATE = ST_MIN_TILT_COS + 1  # after detection: largest |omega|, rad/s (0: none)
NSTAT = ST_MAX_RATE + 1

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
