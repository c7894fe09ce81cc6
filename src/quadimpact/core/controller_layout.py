"""The built-in controllers' parameter blocks and memory slots (``core/controllers/``).

Declared with :class:`~quadimpact.core.layout.Block` like every other slot,
in a module of their own that loads no compiled code, so that the Python
side (``inputs/controllers.py``) packs them without importing Numba. The
blocks live at ``ctrl[C_PARAMS + ...]`` (capacity ``NPARAM``) and in the
controller's memory ``mem`` (before ``MEM_STAGE``).
"""

from quadimpact.core.layout import MEM_STAGE, NPARAM, NPOLICY, Block

# ---- PID (controllers/common.py)
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

# ---- recovery (controllers/recovery.py)
# ---- parameters, at ctrl[C_PARAMS + ...] (after the PID block above)
_params = Block("ctrl.params", "R_", start=N_PID_PARAMS, capacity=NPARAM)
R_NOMINAL_KIND = _params.slot("R_NOMINAL_KIND")  # CTRL_PAPER or CTRL_CASCADE_PID (pre-impact)
R_PRE_IMPACT = _params.slot("R_PRE_IMPACT")  # PRE_* below
R_K_ATT = _params.slot("R_K_ATT")  # 1/s, tilt error -> rate reference
R_K_RATE = _params.slot("R_K_RATE", 3)  # 1/s, rate error -> angular acceleration (p, q, r)
R_A_MAG = _params.slot("R_A_MAG")  # m/s^2, stage 1 push away from the wall
R_K_Z = _params.slot("R_K_Z", 4)  # 1/s, vertical-velocity gain of stages 1-4
R_Q_TOL = _params.slot("R_Q_TOL")  # tilt-error tolerance of the stage 1 and 2 tests
R_RATE_TOL = _params.slot("R_RATE_TOL")  # rad/s, |p|, |q| tolerance of the stage 1 and 2 tests
R_W_TOL = _params.slot("R_W_TOL")  # m/s, body z velocity below which stage 3 ends
R_FIRST_TICK_LEVEL = _params.slot("R_FIRST_TICK_LEVEL")  # 1: a_ref = 0 at detection (replica)
R_HOVER = _params.slot("R_HOVER")  # 1: stage 5 (hold position and yaw) after stage 4
R_HOVER_GAINS = _params.slot("R_HOVER_GAINS", 5)  # K_p 1/s, K_v 1/s, v_max m/s, a_max m/s^2,
# K_psi 1/s (controllers/hover.py)
R_HOVER_MODE = _params.slot("R_HOVER_MODE")  # HOLD_* below: which position stage 5 holds
R_HOVER_SET = _params.slot("R_HOVER_SET", 3)  # m, the given set-point, inertial NED
R_LEVEL_TEST = _params.slot("R_LEVEL_TEST")  # LEVEL_* below: the stage 2 -> 3 tilt test
R_EULER_TOL = _params.slot("R_EULER_TOL")  # rad, |roll|, |pitch| tolerance of LEVEL_EULER
R_LEAN_CUT = _params.slot("R_LEAN_CUT")  # sine of the lean into the obstacle beyond which
# stage 1 idles its rotors (> 1: never; controllers/recovery.py's lean_cut)
R_LEAN_FORCE = _params.slot("R_LEAN_FORCE")  # m/s^2, the cut also needs a body-horizontal
# specific force at least this (the contact still pushing); 0: whatever it is
N_RECOVERY_PARAMS = _params.end("N_RECOVERY_PARAMS")

HOLD_ENTRY = 0  # the position estimate at stage 4's entry
HOLD_STOP = 1  # brake first; hold the position estimate where the speed fell below 0.2 m/s
HOLD_GIVEN = 2  # R_HOVER_SET
HOLD_CAPTURE_M_S = 0.2

LEVEL_TILT_ERROR = 0  # stage 2 -> 3 tests |q_e,x|, |q_e,y| < R_Q_TOL, as stage 1 -> 2
LEVEL_EULER = 1  # stage 2 -> 3 tests the ZYX Euler |roll|, |pitch| < R_EULER_TOL

PRE_NOMINAL = 0
PRE_HOLD = 1
PRE_SPIN_DOWN = 2
PRE_IMMEDIATE = 3

# ---- memory (after the PID slots of the nominal controller)
_mem = Block("mem", "RM_", start=N_PID_MEM, capacity=MEM_STAGE)
RM_QE_X = _mem.slot("RM_QE_X")  # previous tick's tilt error quaternion, x and y
RM_QE_Y = _mem.slot("RM_QE_Y")
RM_HOLD = _mem.slot("RM_HOLD", 3)  # m, stage 5's position set-point, inertial NED
RM_HOLD_PSI = _mem.slot("RM_HOLD_PSI")  # rad, stage 5's yaw set-point
RM_HOLD_SET = _mem.slot("RM_HOLD_SET")  # 1 once the position set-point is set (HOLD_STOP)
N_RECOVERY_MEM = _mem.end("N_RECOVERY_MEM")

STAGE_PRE_IMPACT = 0
STAGE_DETECTED = 1
STAGE_TILTED = 2
STAGE_LEVEL = 3
STAGE_RECOVERED = 4
STAGE_HOVER = 5

# ---- a learned residual on the recovery law, at ctrl[C_POLICY:] (controllers/residual.py)
PB_HIDDEN = 0  # hidden width (0: no policy)
PB_THRUST_SCALE = 1  # s_T: the largest thrust correction as a fraction of m g
PB_RATE_SCALE = 2  # s_w, rad/s: the largest roll and pitch rate-reference correction
PB_LAST_STAGE = 3  # the last stage it acts in: 4 (stages 1-4; 0 reads as 4) or 5 (the hover too)
PB_WEIGHTS = 4  # W1 (nh x N_FEATURES, row-major), b1 (nh), W2 (N_OUTPUTS x nh), b2 from here
N_FEATURES = 24  # what the network reads (residual.features)
N_OUTPUTS = 3  # thrust, p_des, q_des corrections
MAX_HIDDEN = 32  # the widest hidden layer a policy may have (fits in NPOLICY)
assert PB_WEIGHTS + MAX_HIDDEN * (N_FEATURES + 1 + N_OUTPUTS) + N_OUTPUTS <= NPOLICY
