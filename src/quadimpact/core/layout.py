"""The slots of every array the compiled core exchanges: one checked contract.

The compiled loop takes no Python objects: it takes a few named records of
``float64`` arrays (``core/records.py``), and every slot of those arrays is
declared here or by its component, block by block, with :class:`Block`
(``core/block.py``). A block hands out
consecutive offsets in the order its slots are declared, so two slots of a
block cannot overlap and its size always covers them;
``tests/core/test_layout.py`` checks every registered block (the
learning environment's blocks, which are declared with their code,
included) and that no constant of a block's prefix escapes its
declaration. Only what belongs to no component is declared here: the
state (``x``), time (``ls``, ``span``), the run's options (``opts``) and
the run's own statistics (``stats``). A component declares its own blocks
in its own module, after the head it extends (the controllers' parameter
and memory blocks in ``core/controllers/``, the estimators' own
configuration and state in ``core/estimators/``, the detector's and the
sensor components' in ``core/sensors/``), and a stage that alone owns an
array declares it (the wall approach's record in ``core/approach.py``, the
impact rows in ``core/impacts.py``, the rotor inputs in ``core/rotors.py``,
the contact-pair table in ``core/geometry``). A component whose sizes
``records.py``, the packers or this module need declares its blocks in a
declaration module next to it, which holds no compiled code: the contact
pairs' ``cs`` (``core/contact_slots.py``), the output rows and episodes
(``core/recording_slots.py``), the IMU's ``scfg``, ``sst``, ``snoise`` and
``imu`` (``core/sensors/imu_slots.py``), the measurement record ``meas``
(``core/sensors/measurement_slots.py``), the controllers' ``ctrl``
(``core/controller_slots.py``), the estimators' ``ecfg`` and ``est``
(``core/estimator_slots.py``), the vehicle's ``veh``
(``core/vehicle_slots.py``), the features' ``feat``
(``core/feature_slots.py``), the shapes' ``shapes``
(``core/shape_slots.py``), and the parts of ``stats`` this module places
at addresses computed from their declared sizes (``ST_EXCURSION`` from
``core/excursion_slots.py``, ``ST_HOVER`` and ``ST_HELD`` from
``core/hover_slots.py``, ``ST_STEPS`` from ``core/interval_slots.py``).
docs/ARCHITECTURE.md section 10 says why each central block stays. Numba
reads these module-level integers as compile-time constants.

Kinds (feature, shape, controller, rotor mode, crash rule, filter, status,
reason) are plain integer constants for the compiled code (Numba cannot
store an ``IntEnum`` member in a float array) with an ``IntEnum`` of the
same values for the Python side (``FeatureKind``, ``ShapeKind``, ``Status``...).

Everything is SI; frames as in docs/MODEL.md section 1 (inertial NED, body FRD).
"""

from __future__ import annotations

import math
from enum import IntEnum

from quadimpact.core.block import Block
from quadimpact.core.excursion_slots import NEX
from quadimpact.core.hover_slots import NHELD, NHOVER
from quadimpact.core.interval_slots import NSTEPS

__all__ = ["Block"]  # and every slot constant below


# --------------------------------------------------------------------------
# Kinds
# --------------------------------------------------------------------------
MAX_ROTORS = 8  # the most rotors a vehicle may have: per-rotor slots have this many entries;
#   a run's own count is veh[V_N_ROTORS] (4 to MAX_ROTORS) and every compiled loop over the
#   rotors runs to it, so the entries beyond it stay 0 (no state, no thrust, no error norm)


class FeatureKind(IntEnum):
    """Contact features of a vehicle (rows of ``feat``)."""

    RING = 0  # a bumper ring: centre, plane normal, radius
    SPHERE = 1  # a spherical cage or ball: centre, radius
    POINT = 2  # a landing-gear foot, an arm tip, a body corner: a position


class ShapeKind(IntEnum):
    """Shapes of the world (rows of ``shapes``)."""

    PLANE = 0  # a half-space: a plane through a point, outward unit normal
    CYLINDER = 1  # a point on the axis (the centre), unit axis, radius, length (inf: unbounded)
    BOX = 2  # a centre, half-extents along its own axes, those axes (rows of SH_ROT)


class ControllerKind(IntEnum):
    """Built-in controllers (``ctrl[C_KIND]``)."""

    NONE = 0  # rotors held at their current speeds
    PAPER = 1
    CASCADE_PID = 2
    RECOVERY = 3
    USER = 99  # a plug-in, called by address from the one loop (core/plugin_call.py)


class EstimatorKind(IntEnum):
    """Built-in estimators (``ecfg[EC_KIND]``; core/estimators/)."""

    IDEAL = 0  # the true state (and the gyro as measured): every result as before estimators
    COMPLEMENTARY = 1  # Mahony-type nonlinear complementary filter
    EKF = 2  # multiplicative (error-state) extended Kalman filter
    EKF_ADDITIVE = 3  # the authors' 7-state additive-quaternion EKF (ekf_additive.py)
    NAV_EKF = 4  # the navigation filter: 16 error states, baro, range and flow (nav_ekf.py)
    USER = 99  # a plug-in, called by address from the one loop (core/plugin_call.py)


class RotorMode(IntEnum):
    IDEAL = 0
    FIRST_ORDER = 1


class CrashRule(IntEnum):
    CM_GROUND = 0  # event: the CM altitude crosses O_CRASH_ALTITUDE (default 0)
    PAPER_TICKS = 1  # h <= O_CRASH_ALTITUDE tested at the control ticks after the start
    NONE = 2  # no crash plane (the ground may be a contact shape)


class Filter(IntEnum):
    NONE = 0
    FIRST_ORDER = 1
    MOVING_AVERAGE = 2


class Status(IntEnum):
    COMPLETED = 0
    CRASHED = 1
    FAILED = 2


class Reason(IntEnum):
    NONE = 0
    STEP_TOO_SMALL = 1
    MAX_STEPS = 2
    NOT_FINITE = 3
    EVENT_STORM = 4


FEAT_RING = int(FeatureKind.RING)
FEAT_SPHERE = int(FeatureKind.SPHERE)
FEAT_POINT = int(FeatureKind.POINT)
SHAPE_PLANE = int(ShapeKind.PLANE)
SHAPE_CYLINDER = int(ShapeKind.CYLINDER)
SHAPE_BOX = int(ShapeKind.BOX)
CTRL_NONE = int(ControllerKind.NONE)
CTRL_PAPER = int(ControllerKind.PAPER)
CTRL_CASCADE_PID = int(ControllerKind.CASCADE_PID)
CTRL_RECOVERY = int(ControllerKind.RECOVERY)
CTRL_USER = int(ControllerKind.USER)
EST_IDEAL = int(EstimatorKind.IDEAL)
EST_COMPLEMENTARY = int(EstimatorKind.COMPLEMENTARY)
EST_EKF = int(EstimatorKind.EKF)
EST_EKF_ADDITIVE = int(EstimatorKind.EKF_ADDITIVE)
EST_NAV_EKF = int(EstimatorKind.NAV_EKF)
EST_USER = int(EstimatorKind.USER)
ROTOR_IDEAL = int(RotorMode.IDEAL)
ROTOR_FIRST_ORDER = int(RotorMode.FIRST_ORDER)
CRASH_CM_GROUND = int(CrashRule.CM_GROUND)
CRASH_PAPER_TICKS = int(CrashRule.PAPER_TICKS)
CRASH_NONE = int(CrashRule.NONE)
FILTER_NONE = int(Filter.NONE)
FILTER_FIRST_ORDER = int(Filter.FIRST_ORDER)
FILTER_MOVING_AVERAGE = int(Filter.MOVING_AVERAGE)
STATUS_COMPLETED = int(Status.COMPLETED)
STATUS_CRASHED = int(Status.CRASHED)
STATUS_FAILED = int(Status.FAILED)
REASON_NONE = int(Reason.NONE)
REASON_STEP_TOO_SMALL = int(Reason.STEP_TOO_SMALL)
REASON_MAX_STEPS = int(Reason.MAX_STEPS)
REASON_NOT_FINITE = int(Reason.NOT_FINITE)
REASON_EVENT_STORM = int(Reason.EVENT_STORM)
# contact events (onsets and ends, one per pair) one control
# interval may hold; one more fails the run (core/interval.py, docs/NUMERICS.md)
MAX_INTERVAL_EVENTS = 64
REASON_TEXT = {
    REASON_NONE: "",
    REASON_STEP_TOO_SMALL: "step size fell below the floor (stiff or singular dynamics)",
    REASON_MAX_STEPS: "step budget exhausted",
    REASON_NOT_FINITE: "state became NaN or infinite",
    REASON_EVENT_STORM: (
        f"event storm: more than {MAX_INTERVAL_EVENTS} events in one control interval"
        " (contact chattering)"
    ),
}

# ==========================================================================
# Model: per-run constants
# ==========================================================================

# ---- state vector x (NX). Rotor speeds are always states: in ideal and
# power-off modes their derivative is prescribed (zero or a schedule rate), in
# first-order mode it is (cmd - Omega) / tau.
_x = Block("x", "X_")
X_POS = _x.slot("X_POS", 3)  # p, CM position, inertial (m)
X_VEL = _x.slot("X_VEL", 3)  # v, CM velocity, body (m/s)
X_QUAT = _x.slot("X_QUAT", 4)  # q = [q0, q1, q2, q3], scalar first, body -> inertial
X_OMEGA = _x.slot("X_OMEGA", 3)  # omega = [p, q, r], body angular velocity (rad/s)
X_ROTOR = _x.slot("X_ROTOR", MAX_ROTORS)  # Omega_1..n, rotor speeds (rad/s); 0 beyond n
NX = _x.end("NX")
N_RIGID = X_ROTOR  # the rigid-body states come first

# ---- vehicle veh (NVEH): declared by the vehicle model in core/vehicle_slots.py

# ---- contact features feat (n_features, NFEAT): declared by the contact law in
# core/feature_slots.py

# ---- world shapes shapes (n_shapes, NSHAPE): declared by the obstacle geometry in
# core/shape_slots.py

# ---- options opts (NOPT): model switches, integrator settings
_opt = Block("opts", "O_")
O_YAW_REACTION_PAPER = _opt.slot("O_YAW_REACTION_PAPER")  # 1: replica drag +s dt W^2
O_DOUBLE_BUMPER1_YAW = _opt.slot("O_DOUBLE_BUMPER1_YAW")  # 1: feature 0's yaw moment twice
O_CRASH_RULE = _opt.slot("O_CRASH_RULE")  # CRASH_*
O_CRASH_ALTITUDE = _opt.slot("O_CRASH_ALTITUDE")  # m; crash when h <= this / crosses it
O_ROTOR_MODE = _opt.slot("O_ROTOR_MODE")  # ROTOR_*
O_OMEGA_MIN = _opt.slot("O_OMEGA_MIN")  # rad/s, command lower limit (<= 0: none)
O_OMEGA_MAX = _opt.slot("O_OMEGA_MAX")  # rad/s, command upper limit (<= 0: none)
O_SLEW_MAX = _opt.slot("O_SLEW_MAX")  # rad/s^2, command slew limit (<= 0: none)
O_V_REG = _opt.slot("O_V_REG")  # m/s, friction regularisation velocity
O_V_MIN = _opt.slot("O_V_MIN")  # m/s, floor of v_i in the damping coefficient
O_DT_CONTROL = _opt.slot("O_DT_CONTROL")  # s, control period
O_RTOL = _opt.slot("O_RTOL")
O_ATOL = _opt.slot("O_ATOL")
O_H_MAX = _opt.slot("O_H_MAX")  # s, largest step (<= 0: the control period)
O_MAX_STEPS = _opt.slot("O_MAX_STEPS")  # total accepted + rejected step budget
O_EVENT_TOL = _opt.slot("O_EVENT_TOL")  # s, event time tolerance
O_POWER_OFF_T = _opt.slot("O_POWER_OFF_T")  # s, power-off trigger (< 0: first contact; inf: never)
O_STOP_ON_CRASH = _opt.slot("O_STOP_ON_CRASH")  # 1: end the run at the crash
O_SPINUP_PAPER = _opt.slot("O_SPINUP_PAPER")  # 1: spin-up reaction -Jr sum Omega_dot (replica)
O_CONTACT_GATE = _opt.slot("O_CONTACT_GATE")  # m; > 0: forces only while the CM is this close
O_CUT_STEP_MOTORS = _opt.slot("O_CUT_STEP_MOTORS")  # bit j: motor j+1 cut at the first tick
#   after the power-off trigger as a one-tick command step (actuators.cut_step)
O_END_AFTER_RECOVERY = _opt.slot("O_END_AFTER_RECOVERY")  # s; > 0: the run ends this long
#   after the entry into stage 4 (recovered)
NOPT = _opt.end("NOPT")

# ---- controller ctrl (NCTRL): declared by the controllers in core/controller_slots.py

N_DETECTOR_CFG = 3  # the detector's config slots (core/sensors/detection.py)
# ---- sensors scfg (NSCFG), the IMU and the impact detector: declared by the IMU in
# core/sensors/imu_slots.py

# ---- the older sensors' standard normal draws snoise (n_imu, NSN): declared by the IMU in
# core/sensors/imu_slots.py

# ---- estimator ecfg (NECFG): declared by the estimators in core/estimator_slots.py

# ---- the span of the run: span (NSPAN)
_span = Block("span", "SPAN_")
SPAN_T0 = _span.slot("SPAN_T0")  # s, start
SPAN_TF = _span.slot("SPAN_TF")  # s, end
NSPAN = _span.end("NSPAN")

# ==========================================================================
# Data: what the loop carries from one control tick to the next
# ==========================================================================

# ---- loop scalars ls (NLS); counters live in stats (ST_*)
_ls = Block("ls", "LS_")
LS_T = _ls.slot("LS_T")  # s, time reached
LS_T0 = _ls.slot("LS_T0")  # s, start of the run (tick k is at t0 + k dt)
LS_TF = _ls.slot("LS_TF")  # s, end of the run
LS_K = _ls.slot("LS_K")  # index of the next control tick
LS_H = _ls.slot("LS_H")  # s, step-size proposal for the next step
LS_DONE = _ls.slot("LS_DONE")  # 1: the run has ended (final time, crash with stop, failure)
LS_PO_ACTIVE = _ls.slot("LS_PO_ACTIVE")  # 1: the power-off schedule is in force
LS_PO_T = _ls.slot("LS_PO_T")  # s, its trigger time
LS_PO_SEG = _ls.slot("LS_PO_SEG")  # its segment in force
LS_T_SCHED = _ls.slot("LS_T_SCHED")  # s, next instant the scheduled rotor inputs change
LS_STAGE = _ls.slot("LS_STAGE")  # the controller's stage in force (MEM_STAGE at the last tick)
LS_EXT = _ls.slot("LS_EXT")  # 1: the next tick applies LS_EXT_CMD instead of the controller
LS_EXT_CMD = _ls.slot("LS_EXT_CMD", MAX_ROTORS)  # external rotor speed command (rad/s)
NLS = _ls.end("NLS")

# ---- controller memory mem (NMEM), zeroed at the start; each controller
# lays out its slots with a Block of array "mem.<name>". The last slot is
# reserved: a controller with stages writes its current stage there.
NMEM = 64
MEM_STAGE = NMEM - 1
N_STAGES = 8  # stages 0..7 have recorded entry ticks
# the staged recovery law's stages (core/controllers/recovery.py), as the stats and the
# learning environment read them
STAGE_PRE_IMPACT = 0
STAGE_DETECTED = 1
STAGE_TILTED = 2
STAGE_LEVEL = 3
STAGE_RECOVERED = 4
STAGE_HOVER = 5

# ---- measurement record meas (NMEAS): declared by core/sensors/measurement_slots.py

# ---- sensor state sst (NSST): declared by the IMU in core/sensors/imu_slots.py

# ---- estimator state est (NEST): declared by the estimators in core/estimator_slots.py

# ==========================================================================
# Output: what a run returns
# ==========================================================================

# ---- IMU samples imu (n_imu, NIMU): declared by the IMU in core/sensors/imu_slots.py

# ---- run statistics stats (NSTAT)
_st = Block("stats", "ST_")
ST_STATUS = _st.slot("ST_STATUS")  # STATUS_*
ST_REASON = _st.slot("ST_REASON")  # REASON_*
ST_T_END = _st.slot("ST_T_END")  # s, time reached
ST_STEPS = _st.slot("ST_STEPS", NSTEPS)  # the integrator's step counts (core/interval.py
#   integrate_interval): its IS_* slots, declared by core/interval_slots.py
ST_N_OUT = _st.slot("ST_N_OUT")  # output rows written
ST_N_EPISODES = _st.slot("ST_N_EPISODES")
ST_CRASH_T = _st.slot("ST_CRASH_T")  # s, NaN when none
ST_CRASH_X = _st.slot("ST_CRASH_X", 3)  # m, CM position at the crash
ST_MAX_DELTA = _st.slot("ST_MAX_DELTA")  # m, deepest penetration of any pair
ST_MISSED_ONSETS = _st.slot("ST_MISSED_ONSETS")  # contacts found already penetrating
ST_EPISODES_DROPPED = _st.slot("ST_EPISODES_DROPPED")  # episodes beyond the buffer
ST_POWER_OFF_T = _st.slot("ST_POWER_OFF_T")  # s, when the power-off schedule started (NaN)
ST_N_TICKS = _st.slot("ST_N_TICKS")  # controller updates
ST_ONSET_T = _st.slot("ST_ONSET_T")  # s, first contact onset on a non-ground shape (NaN)
ST_ONSET_X = _st.slot("ST_ONSET_X", NX)  # full state at that onset
ST_T_DETECT = _st.slot("ST_T_DETECT")  # s, first impact detection (NaN: none)
ST_DETECT_X = _st.slot("ST_DETECT_X", NX)  # state at that detection sample
ST_DETECT_NORMAL = _st.slot("ST_DETECT_NORMAL", 3)  # wall-normal estimate, inertial
ST_N_DETECTIONS = _st.slot("ST_N_DETECTIONS")  # rising edges of the detection condition
ST_N_IMU = _st.slot("ST_N_IMU")  # IMU samples taken (also beyond the buffer)
ST_STAGE_T = _st.slot("ST_STAGE_T", N_STAGES)  # tick of each stage's first entry (NaN)
ST_STAGE_X = _st.slot("ST_STAGE_X", 3 * N_STAGES)  # CM position there, inertial
ST_MIN_ALT = _st.slot("ST_MIN_ALT")  # m, lowest CM altitude (step ends and events)
ST_MIN_TILT_COS = _st.slot("ST_MIN_TILT_COS")  # after detection: lowest cos(tilt) (1: none)
ST_MAX_RATE = _st.slot("ST_MAX_RATE")  # after detection: largest |omega|, rad/s (0: none)
ST_IMPACT_V = _st.slot("ST_IMPACT_V")  # sum over onsets of exp(-2 (ST_IMPACT_T - t_c) / tau)
ST_IMPACT_T = _st.slot("ST_IMPACT_T")  # s, the latest contact onset (NaN: none)
N_EST_ERR = 4  # estimation errors: attitude (deg), velocity (m/s), gyro bias (rad/s), position (m)
N_PHASES = 3  # before the first contact, the crash (to stage 4), after stage 4
ST_EST_ERR = _st.slot("ST_EST_ERR", 3 * N_EST_ERR * N_PHASES)  # (sum of squares, max, samples)
ST_HOVER = _st.slot("ST_HOVER", NHOVER)  # the time to hover's ticks (core/hover_tracking.py
#   track_hover): its HV_* slots, declared by core/hover_slots.py
ST_EXCURSION = _st.slot("ST_EXCURSION", NEX)  # the output samples' attitude excursion:
#   its EX_* slots, declared by core/excursion_slots.py
ST_X_LAST = _st.slot("ST_X_LAST", NX)  # the state of the last output sample
ST_HELD = _st.slot("ST_HELD", NHELD)  # the held hover of the benchmark's suite 2
#   (core/hover_tracking.py track_held_hover): its HH_* slots, declared by core/hover_slots.py
ST_LAST_ONSET_T = _st.slot("ST_LAST_ONSET_T")  # s, the latest contact onset, any shape (NaN)
NSTAT = _st.end("NSTAT")


# a power-off schedule's rate that switches the motor off (speed 0 from the segment's start)
MOTOR_OFF = -math.inf
