"""The ``recovery`` controller: a pre-impact behaviour, then a staged recovery law.

Before an impact is detected (stage 0) it runs a pre-impact behaviour:

* ``PRE_NOMINAL``: the nominal controller (``paper`` or ``cascade-pid``, with
  the scenario's references, as in the wall approach);
* ``PRE_HOLD``: the rotor speeds stay where they are (the initial trimmed speeds);
* ``PRE_SPIN_DOWN``: the rotor commands are zero, so the speeds fall at the
  loop's slew limit to zero (the authors' Monte Carlo). The rotor range
  applies only to the staged law's commands;
* ``PRE_IMMEDIATE``: none: the staged law runs from the first tick, as if an
  impact had been detected there (with no wall-normal estimate, stage 1's
  target is level). For exercising the law from any initial state.

From the tick at which the detector has fired (``meas[MS_DETECTED]``) it runs
the staged law until the end of the run. With ``u = -C e_z`` the body's up
axis (inertial components), ``V_Z`` the inertial vertical velocity (down
positive) and ``n`` the wall-normal estimate (``meas[MS_NORMAL]``)::

    f_des = -g e_Z + a_ref - k_z V_Z e_Z          desired thrust per unit mass (inertial)
    T     = m (f_des . u)  if positive, else 0    collective thrust
    theta = angle(u, f_des),  e = (u x f_des) / |u x f_des|
    q_e   = (cos theta/2, sin theta/2 C^T e)      tilt error quaternion, body axes
    p_des = K_att q_e,x,  q_des = K_att q_e,y,  r_des = 0
    nu    = K_rate * (omega_des - omega)          angular acceleration command
    tau   = I nu - (omega x I omega)_diag terms   feedback linearisation (common.py)

then the allocation (negative squares to zero) and the vehicle's rotor range.

Stages (checked at each tick, at most one stage per tick; the test uses the
error quaternion of the previous tick's law and the current rates, then the
law is computed for the stage now in force):

====  ==================  ==========  ====  =====================================
stage meaning             a_ref       k_z   leaves when
====  ==================  ==========  ====  =====================================
1     impact detected     a_mag n     0     |q_e,x|, |q_e,y| < q_tol and |p|, |q| < rate_tol
2     tilted away         0           0     the same test (now toward level), or with
                                            ``R_LEVEL_TEST = LEVEL_EULER`` the ZYX Euler
                                            |roll|, |pitch| < euler_tol and the same rates
3     level               0           10    body z velocity w < w_tol
4     recovered           0           10    stays (or 5 at the next tick)
5     hover (optional)    position    --    stays (``hover.py``: holds the position
                          hold                    estimate and yaw of the stage 4 entry)
====  ==================  ==========  ====  =====================================

With stage 5 on (``R_HOVER``, the default) stage 4 lasts one tick: at the next
tick the law brakes and holds a position estimate (where it stops, by
default; ``R_HOVER_MODE``) and the yaw at which stage 4 was entered, so a
recovered vehicle no longer drifts away;
stage 4's entry (``recovered``) and everything before it are unchanged.

At the detection tick the stage becomes 1 and the law runs at once (no test).
Rates are the estimator's (``meas[MS_W_HAT]``: the gyro as measured with the
ideal estimator, the gyro minus the estimated bias otherwise), attitude,
velocity and position come from the state estimate. Every gain, threshold,
``a_mag`` and ``k_z`` is a parameter (layout ``R_*`` below, at
``ctrl[C_PARAMS + ...]``); the recovery replica's "level target at the
detection tick" is the switch ``R_FIRST_TICK_LEVEL``, the pole replica's
Euler-angle test of stage 2 the switch ``R_LEVEL_TEST`` (:func:`stage_tilt`).

A learned residual (``ctrl[C_POLICY:]``, ``residual.py``) may correct the
outer loop's thrust and roll and pitch rate references from the detection to
the recovery (stages 1-4; stage 5's hover is the law's), or in every stage from
the detection on, the hover included (its block's ``PB_LAST_STAGE`` 5); with
none (the default) the law is as above.
"""

import math

import numpy as np

from quadimpact.core.compiled import allocating, compiled
from quadimpact.core.controller_slots import C_OMEGA_MAX, C_OMEGA_MIN, C_PARAMS, C_POLICY, NPARAM
from quadimpact.core.controllers.cascade_pid import cascade_pid_step
from quadimpact.core.controllers.common import (
    N_PID_MEM,
    N_PID_PARAMS,
    allocate,
    linearised_torques,
)
from quadimpact.core.controllers.hover import hover_acceleration, yaw_of
from quadimpact.core.controllers.paper import paper_step
from quadimpact.core.controllers.residual import (
    PB_HAND_OVER,
    PB_HIDDEN,
    residual_last_stage,
    residual_references,
)
from quadimpact.core.layout import (
    CTRL_CASCADE_PID,
    MEM_STAGE,
    NX,
    STAGE_DETECTED,
    STAGE_HOVER,
    STAGE_LEVEL,
    STAGE_PRE_IMPACT,
    STAGE_RECOVERED,
    STAGE_TILTED,
    X_POS,
    X_QUAT,
    X_ROTOR,
    X_VEL,
    Block,
)
from quadimpact.core.quaternion import euler_zyx, rotation_matrix
from quadimpact.core.sensors.measurement_slots import (
    MS_DETECTED,
    MS_IMU_F,
    MS_NORMAL,
    MS_W_HAT,
    MS_X,
)
from quadimpact.core.vehicle_slots import V_GRAVITY, V_MASS, V_N_ROTORS

# ---- the recovery law's blocks
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

#: the pre-impact behaviours by their names in scenario files (inputs/controllers.py)
PRE_IMPACT_KINDS = {
    "nominal": PRE_NOMINAL,
    "hold": PRE_HOLD,
    "spin-down": PRE_SPIN_DOWN,
    "immediate": PRE_IMMEDIATE,
}


@compiled
def next_stage(
    stage: int,
    qe_x: float,
    qe_y: float,
    p: float,
    q: float,
    w: float,
    q_tol: float,
    rate_tol: float,
    w_tol: float,
    hover: bool = False,
) -> int:
    """The stage machine: the stage after this tick's test (at most one step up).

    ``qe_x``, ``qe_y``: the tilt the stage's test reads, ``q_tol`` its tolerance
    (:func:`stage_tilt`: the previous tick's tilt error quaternion, body x and y,
    or in stage 2 with the Euler test the roll and pitch now, rad); ``p``, ``q``:
    body rates now (rad/s); ``w``: body z velocity now (m/s, down positive);
    ``hover``: stage 5 follows stage 4 at the next tick.
    """
    if stage == STAGE_DETECTED or stage == STAGE_TILTED:
        if abs(qe_x) < q_tol and abs(qe_y) < q_tol and abs(p) < rate_tol and abs(q) < rate_tol:
            return stage + 1
        return stage
    if stage == STAGE_LEVEL:
        if w < w_tol:
            return STAGE_RECOVERED
        return stage
    if stage == STAGE_RECOVERED and hover:
        return STAGE_HOVER
    return stage


@compiled
def stage_tilt(
    stage: int, x: np.ndarray, ctrl: np.ndarray, mem: np.ndarray
) -> tuple[float, float, float]:
    """The tilt that the stage test of ``stage`` reads, and its tolerance: ``(a, b, tol)``.

    By default the previous tick's tilt error quaternion, body x and y parts
    (``mem[RM_QE_X]``, ``mem[RM_QE_Y]``), against ``R_Q_TOL``. In stage 2 with
    ``R_LEVEL_TEST = LEVEL_EULER`` (the pole replica): the ZYX Euler roll and
    pitch (rad) of the state estimate ``x`` at this tick, against
    ``R_EULER_TOL`` (rad).
    """
    p0 = C_PARAMS
    if stage == STAGE_TILTED and int(ctrl[p0 + R_LEVEL_TEST]) == LEVEL_EULER:
        roll, pitch, _ = euler_zyx(x[X_QUAT : X_QUAT + 4])
        return roll, pitch, ctrl[p0 + R_EULER_TOL]
    return mem[RM_QE_X], mem[RM_QE_Y], ctrl[p0 + R_Q_TOL]


@allocating
def staged_references(
    stage: int,
    a_ref_on: bool,
    x: np.ndarray,
    normal: np.ndarray,
    ctrl: np.ndarray,
    veh: np.ndarray,
) -> tuple[float, float, float, float, float]:
    """The staged law's outer loop in ``stage`` (1-4): thrust, rate references, tilt error.

    Returns ``(thrust, p_des, q_des, qe_x, qe_y)``: the collective thrust (N),
    the body rate references (rad/s) and the tilt error quaternion's body x, y
    parts. ``x``: state estimate; ``normal``: wall-normal estimate (inertial,
    unit, away from the wall); ``a_ref_on``: whether stage 1's push away from
    the wall applies.
    """
    p0 = C_PARAMS
    C = np.empty((3, 3))
    rotation_matrix(x[X_QUAT : X_QUAT + 4], C)
    g = veh[V_GRAVITY]
    # the inertial vertical velocity V_Z = (C v)_Z
    vz = C[2, 0] * x[X_VEL] + C[2, 1] * x[X_VEL + 1] + C[2, 2] * x[X_VEL + 2]
    k_z = ctrl[p0 + R_K_Z + stage - 1]
    ax = 0.0
    ay = 0.0
    az = 0.0
    if stage == STAGE_DETECTED and a_ref_on:
        a_mag = ctrl[p0 + R_A_MAG]
        ax = a_mag * normal[0]
        ay = a_mag * normal[1]
        az = a_mag * normal[2]
    fx = ax
    fy = ay
    fz = -g + az - k_z * vz
    return thrust_and_tilt(fx, fy, fz, C, ctrl, veh)


@compiled
def thrust_and_tilt(
    fx: float, fy: float, fz: float, C: np.ndarray, ctrl: np.ndarray, veh: np.ndarray
) -> tuple[float, float, float, float, float]:
    """Thrust (N), rate references (rad/s) and tilt error toward ``f_des = (fx, fy, fz)``.

    ``f_des``: the desired thrust per unit mass, inertial (m/s^2); ``C``: the
    estimated attitude. Returns ``(thrust, p_des, q_des, qe_x, qe_y)``.
    """
    p0 = C_PARAMS
    ux = -C[0, 2]
    uy = -C[1, 2]
    uz = -C[2, 2]
    thrust = veh[V_MASS] * (fx * ux + fy * uy + fz * uz)
    if thrust < 0.0:
        thrust = 0.0
    # tilt error: rotation taking u onto f_des, as a quaternion in body axes
    fn = math.sqrt(fx * fx + fy * fy + fz * fz)
    cx = uy * fz - uz * fy
    cy = uz * fx - ux * fz
    cz = ux * fy - uy * fx
    cn = math.sqrt(cx * cx + cy * cy + cz * cz)
    qex = 0.0
    qey = 0.0
    if fn > 0.0 and cn > 0.0:
        cos_t = (ux * fx + uy * fy + uz * fz) / fn
        theta = math.atan2(cn / fn, cos_t)
        s = math.sin(0.5 * theta) / cn
        # C^T e (body components of the axis)
        qex = s * (C[0, 0] * cx + C[1, 0] * cy + C[2, 0] * cz)
        qey = s * (C[0, 1] * cx + C[1, 1] * cy + C[2, 1] * cz)
    k_att = ctrl[p0 + R_K_ATT]
    return thrust, k_att * qex, k_att * qey, qex, qey


@allocating
def law_references(
    stage: int,
    a_ref_on: bool,
    x: np.ndarray,
    normal: np.ndarray,
    ctrl: np.ndarray,
    veh: np.ndarray,
    mem: np.ndarray,
) -> tuple[float, float, float, float, float, float]:
    """The outer loop in ``stage`` (1-5): ``(thrust, p_des, q_des, r_des, qe_x, qe_y)``.

    Stages 1-4: :func:`staged_references` with ``r_des = 0``; stage 5: the
    position hold of ``hover.py`` toward the set-points in ``mem``.
    """
    if stage == STAGE_HOVER:
        p0 = C_PARAMS
        C = np.empty((3, 3))
        rotation_matrix(x[X_QUAT : X_QUAT + 4], C)
        if mem[RM_HOLD_SET] < 0.5:
            # HOLD_STOP: brake (hold wherever the vehicle is) until slow, then keep that point
            v2 = x[X_VEL] ** 2 + x[X_VEL + 1] ** 2 + x[X_VEL + 2] ** 2
            for i in range(3):
                mem[RM_HOLD + i] = x[X_POS + i]
            if v2 < HOLD_CAPTURE_M_S**2:
                mem[RM_HOLD_SET] = 1.0
        fx, fy, fz, r_des = hover_acceleration(
            x,
            C,
            mem[RM_HOLD : RM_HOLD + 3],
            mem[RM_HOLD_PSI],
            ctrl[p0 + R_HOVER_GAINS : p0 + R_HOVER_GAINS + 5],
            veh[V_GRAVITY],
        )
        thrust, p_des, q_des, qex, qey = thrust_and_tilt(fx, fy, fz, C, ctrl, veh)
        return thrust, p_des, q_des, r_des, qex, qey
    thrust, p_des, q_des, qex, qey = staged_references(stage, a_ref_on, x, normal, ctrl, veh)
    return thrust, p_des, q_des, 0.0, qex, qey


@compiled
def hold_set_point(x: np.ndarray, ctrl: np.ndarray, mem: np.ndarray) -> None:
    """Stage 5's set-points into ``mem`` at stage 4's entry: the yaw of ``x`` and, by the
    mode, the position estimate of ``x``, the given point, or (``HOLD_STOP``) none yet."""
    p0 = C_PARAMS
    mode = int(ctrl[p0 + R_HOVER_MODE])
    for i in range(3):
        if mode == HOLD_GIVEN:
            mem[RM_HOLD + i] = ctrl[p0 + R_HOVER_SET + i]
        else:
            mem[RM_HOLD + i] = x[X_POS + i]
    mem[RM_HOLD_SET] = 0.0 if mode == HOLD_STOP else 1.0
    mem[RM_HOLD_PSI] = yaw_of(x[X_QUAT : X_QUAT + 4])


@compiled
def rate_loop(
    thrust: float,
    p_des: float,
    q_des: float,
    r_des: float,
    omega: np.ndarray,
    ctrl: np.ndarray,
    veh: np.ndarray,
    cmd: np.ndarray,
) -> None:
    """The staged law's inner loop: thrust (N) and rate references (rad/s) to rotor speeds.

    ``nu = K_rate (omega_des - omega)``, feedback-linearised torques, the
    allocation (negative squares to zero) and the vehicle's rotor range
    (``ctrl[C_OMEGA_MIN]``, ``ctrl[C_OMEGA_MAX]``); writes rad/s into ``cmd``.
    ``omega``: estimated body rates (rad/s).
    """
    p0 = C_PARAMS
    nu_p = ctrl[p0 + R_K_RATE] * (p_des - omega[0])
    nu_q = ctrl[p0 + R_K_RATE + 1] * (q_des - omega[1])
    nu_r = ctrl[p0 + R_K_RATE + 2] * (r_des - omega[2])
    tx, ty, tz = linearised_torques(omega, veh, nu_p, nu_q, nu_r)
    allocate(ctrl, thrust, tx, ty, tz, cmd)
    lo = ctrl[C_OMEGA_MIN]
    hi = ctrl[C_OMEGA_MAX]
    for j in range(int(veh[V_N_ROTORS])):
        if cmd[j] < lo:
            cmd[j] = lo
        elif cmd[j] > hi:
            cmd[j] = hi


@compiled
def staged_law(
    stage: int,
    a_ref_on: bool,
    x: np.ndarray,
    omega: np.ndarray,
    normal: np.ndarray,
    ctrl: np.ndarray,
    veh: np.ndarray,
    cmd: np.ndarray,
) -> tuple[float, float]:
    """Rotor commands (rad/s) of the staged law in ``stage`` (1-4); returns ``(q_e,x, q_e,y)``.

    ``x``: state estimate; ``omega``: measured body rates (rad/s); ``normal``:
    wall-normal estimate (inertial, unit, away from the wall); ``a_ref_on``:
    whether stage 1's push away from the wall applies. The outer loop
    (:func:`staged_references`) then the inner loop (:func:`rate_loop`, with
    ``r_des = 0``).
    """
    thrust, p_des, q_des, qex, qey = staged_references(stage, a_ref_on, x, normal, ctrl, veh)
    rate_loop(thrust, p_des, q_des, 0.0, omega, ctrl, veh, cmd)
    return qex, qey


@compiled
def lean_cut(x: np.ndarray, normal: np.ndarray, meas: np.ndarray, ctrl: np.ndarray) -> bool:
    """Whether stage 1 idles its rotors at this tick (the lean cut, ``R_LEAN_*``).

    It does while the up axis leans toward the obstacle by more than the cut's
    angle (the up axis's component along ``-normal``, the opposite of the
    wall-normal estimate, above ``R_LEAN_CUT``, the angle's sine; above 1:
    never) and the body-horizontal specific force of the latest IMU sample is
    at least ``R_LEAN_FORCE`` (m/s^2; 0: whatever it is): the contact still
    pushes. ``x``: state estimate; ``normal``: inertial, unit, horizontal.
    """
    p0 = C_PARAMS
    sin_cut = ctrl[p0 + R_LEAN_CUT]
    if sin_cut > 1.0:
        return False
    f_min = ctrl[p0 + R_LEAN_FORCE]
    if meas[MS_IMU_F] ** 2 + meas[MS_IMU_F + 1] ** 2 < f_min * f_min:
        return False
    q0 = x[X_QUAT]
    q1 = x[X_QUAT + 1]
    q2 = x[X_QUAT + 2]
    q3 = x[X_QUAT + 3]
    # u = -C e_z: minus the third column of the rotation matrix
    ux = -2.0 * (q1 * q3 + q0 * q2)
    uy = -2.0 * (q2 * q3 - q0 * q1)
    return -(ux * normal[0] + uy * normal[1]) > sin_cut


@compiled
def recovery_step(
    t: float,
    meas: np.ndarray,
    ctrl: np.ndarray,
    mem: np.ndarray,
    veh: np.ndarray,
    dt: float,
    cmd: np.ndarray,
) -> None:
    """One tick of the recovery controller; writes the rotor speeds (rad/s) into ``cmd``."""
    p0 = C_PARAMS
    x = meas[MS_X : MS_X + NX]
    stage = int(mem[MEM_STAGE])
    if stage == STAGE_PRE_IMPACT:
        pre = int(ctrl[p0 + R_PRE_IMPACT])
        if meas[MS_DETECTED] < 0.5 and pre != PRE_IMMEDIATE:
            if pre == PRE_NOMINAL:
                if int(ctrl[p0 + R_NOMINAL_KIND]) == CTRL_CASCADE_PID:
                    cascade_pid_step(t, meas, ctrl, mem, veh, dt, cmd)
                else:
                    paper_step(t, meas, ctrl, mem, veh, dt, cmd)
            elif pre == PRE_HOLD:
                for j in range(int(veh[V_N_ROTORS])):
                    cmd[j] = x[X_ROTOR + j]
            else:
                for j in range(int(veh[V_N_ROTORS])):
                    cmd[j] = 0.0
            return
        stage = STAGE_DETECTED
        first_tick = True
    else:
        first_tick = False
        w_body = x[X_VEL + 2]
        before = stage
        tilt_a, tilt_b, tilt_tol = stage_tilt(stage, x, ctrl, mem)
        stage = next_stage(
            stage,
            tilt_a,
            tilt_b,
            meas[MS_W_HAT],
            meas[MS_W_HAT + 1],
            w_body,
            tilt_tol,
            ctrl[p0 + R_RATE_TOL],
            ctrl[p0 + R_W_TOL],
            ctrl[p0 + R_HOVER] > 0.5,
        )
        if stage == STAGE_RECOVERED and before != STAGE_RECOVERED:
            hold_set_point(x, ctrl, mem)
    a_ref_on = not (first_tick and ctrl[p0 + R_FIRST_TICK_LEVEL] > 0.5)
    normal = meas[MS_NORMAL : MS_NORMAL + 3]
    thrust, p_des, q_des, r_des, qex, qey = law_references(
        stage, a_ref_on, x, normal, ctrl, veh, mem
    )
    if (
        ctrl[C_POLICY + PB_HIDDEN] > 0.5
        and stage <= residual_last_stage(ctrl)
        and not (
            stage == STAGE_HOVER and ctrl[C_POLICY + PB_HAND_OVER] > 0.5 and mem[RM_HOLD_SET] > 0.5
        )
    ):
        thrust, p_des, q_des = residual_references(
            t, stage, (thrust, p_des, q_des), meas, ctrl, veh
        )
    if stage == STAGE_DETECTED and lean_cut(x, normal, meas, ctrl):
        for j in range(int(veh[V_N_ROTORS])):
            cmd[j] = ctrl[C_OMEGA_MIN]
    else:
        rate_loop(thrust, p_des, q_des, r_des, meas[MS_W_HAT : MS_W_HAT + 3], ctrl, veh, cmd)
    mem[RM_QE_X] = qex
    mem[RM_QE_Y] = qey
    mem[MEM_STAGE] = stage
