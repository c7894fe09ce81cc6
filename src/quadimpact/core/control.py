"""Controllers (MODEL.md section 6) and the rotor allocation, compiled.

Interface of a controller step (built-in or plugged in, all ``njit``)::

    step(x, ctrl, mem, veh, dt, cmd) -> None

``x`` is the state at the control tick, ``ctrl`` the packed settings
(layout ``C_*``: references, gains, allocation), ``mem`` a float64 array of
``NMEM`` slots the controller owns across ticks (zeroed at the start of a
run), ``veh`` the packed vehicle, ``dt`` the control period (s). It writes the
four rotor-speed commands (rad/s) into ``cmd``. The run loop applies the
generic speed and slew limits afterwards and holds the command for the period.

Built-ins:

* ``paper``: the authors' discrete law exactly, quirks included: the
  "integral" terms use only the last two errors, thrust is multiplied by
  ``cos(phi) cos(theta)``, no limits;
* ``cascade-pid``: the same loops with running trapezoidal integrals,
  conditional integration (anti-windup) while the rotors saturate, thrust
  divided by ``cos(phi) cos(theta)`` down to a floor and faded to zero beyond
  it (``tilt_compensation``), rotor speeds limited to the vehicle's range.
"""

import math

import numpy as np
from numba import njit

from .layout import (
    C_ALLOC_INV,
    C_GAINS,
    C_H_REF,
    C_KIND,
    C_OMEGA_MAX,
    C_OMEGA_MIN,
    C_PHI_REF,
    C_PSI_REF,
    C_THETA_REF,
    C_THRUST_COS_FLOOR,
    CTRL_CASCADE_PID,
    CTRL_PAPER,
    G_ALT,
    G_ATT,
    G_CLIMB,
    G_HEADING,
    G_YAWRATE,
    V_GRAVITY,
    V_INERTIA,
    V_MASS,
    X_OMEGA,
    X_POS,
    X_QUAT,
    X_ROTOR,
    X_VEL,
)
from .quaternion import euler_zyx, wrap_pi

# controller memory slots
M_STARTED = 0  # 1 after the first tick
M_E_H = 1  # previous errors
M_E_V = 2
M_E_PSI = 3
M_E_PHI = 4
M_E_THETA = 5
M_E_R = 6
M_I_H = 7  # running integrals (cascade-pid)
M_I_V = 8
M_I_PSI = 9
M_I_PHI = 10
M_I_THETA = 11
M_I_R = 12
M_SATURATED = 13  # 1 if the last command saturated (cascade-pid)

FADE_POWER = 4.0  # cascade-pid thrust fade beyond the tilt floor (tilt_compensation)


@njit(cache=True)
def _measure(x: np.ndarray) -> tuple[float, float, float, float, float]:
    """Roll, pitch, yaw (rad), altitude h = -Z (m) and climb rate h_dot (m/s)."""
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

    Returns True if any square was clipped.
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
def _torques(
    x: np.ndarray, veh: np.ndarray, a_phi: float, a_theta: float, a_r: float
) -> tuple[float, float, float]:
    """Feedback-linearised torques (N m) from angular-acceleration commands (rad/s^2)."""
    ixx = veh[V_INERTIA]
    iyy = veh[V_INERTIA + 4]
    izz = veh[V_INERTIA + 8]
    p = x[X_OMEGA]
    q = x[X_OMEGA + 1]
    r = x[X_OMEGA + 2]
    tx = ixx * a_phi - (iyy - izz) * q * r
    ty = iyy * a_theta - (izz - ixx) * p * r
    tz = izz * a_r - (ixx - iyy) * p * q
    return tx, ty, tz


@njit(cache=True)
def paper_step(
    x: np.ndarray, ctrl: np.ndarray, mem: np.ndarray, veh: np.ndarray, dt: float, cmd: np.ndarray
) -> None:
    """The authors' controller (MODEL.md 6.1), exactly as they ran it."""
    g = ctrl[C_GAINS : C_GAINS + 15]
    roll, pitch, yaw, h, hdot = _measure(x)
    started = mem[M_STARTED] > 0.5
    # altitude -> climb-rate reference (two-point "integral")
    e_h = ctrl[C_H_REF] - h
    v_des = g[G_ALT] * e_h
    if started:
        v_des += g[G_ALT + 1] * dt * (e_h + mem[M_E_H]) / 2.0
        v_des += g[G_ALT + 2] * (e_h - mem[M_E_H]) / dt
    e_v = v_des - hdot
    acc = g[G_CLIMB] * e_v
    if started:
        acc += g[G_CLIMB + 1] * dt * (e_v + mem[M_E_V]) / 2.0
        acc += g[G_CLIMB + 2] * (e_v - mem[M_E_V]) / dt
    thrust = veh[V_MASS] * (veh[V_GRAVITY] + acc) * math.cos(roll) * math.cos(pitch)
    # heading -> yaw-rate reference: this "integral" has no 1/2
    e_psi = wrap_pi(ctrl[C_PSI_REF] - yaw)
    r_des = g[G_HEADING] * e_psi
    if started:
        r_des += g[G_HEADING + 1] * dt * (e_psi + mem[M_E_PSI])
        r_des += g[G_HEADING + 2] * wrap_pi(e_psi - mem[M_E_PSI]) / dt
    # roll and pitch PID (errors not wrapped)
    e_phi = ctrl[C_PHI_REF] - roll
    e_theta = ctrl[C_THETA_REF] - pitch
    a_phi = g[G_ATT] * e_phi
    a_theta = g[G_ATT] * e_theta
    if started:
        a_phi += g[G_ATT + 1] * dt * (e_phi + mem[M_E_PHI]) / 2.0
        a_phi += g[G_ATT + 2] * (e_phi - mem[M_E_PHI]) / dt
        a_theta += g[G_ATT + 1] * dt * (e_theta + mem[M_E_THETA]) / 2.0
        a_theta += g[G_ATT + 2] * (e_theta - mem[M_E_THETA]) / dt
    # yaw rate PI
    e_r = r_des - x[X_OMEGA + 2]
    a_r = g[G_YAWRATE] * e_r
    if started:
        a_r += g[G_YAWRATE + 1] * dt * (e_r + mem[M_E_R]) / 2.0
        a_r += g[G_YAWRATE + 2] * (e_r - mem[M_E_R]) / dt
    tx, ty, tz = _torques(x, veh, a_phi, a_theta, a_r)
    allocate(ctrl, thrust, tx, ty, tz, cmd)
    mem[M_E_H] = e_h
    mem[M_E_V] = e_v
    mem[M_E_PSI] = e_psi
    mem[M_E_PHI] = e_phi
    mem[M_E_THETA] = e_theta
    mem[M_E_R] = e_r
    mem[M_STARTED] = 1.0


@njit(cache=True)
def _pid(
    e: float,
    slot_e: int,
    slot_i: int,
    mem: np.ndarray,
    gains: np.ndarray,
    k: int,
    dt: float,
    started: bool,
    integrate: bool,
    wrap: bool,
) -> float:
    """PID with a running trapezoidal integral held in ``mem[slot_i]``."""
    out = gains[k] * e
    if started:
        de = e - mem[slot_e]
        if wrap:
            de = wrap_pi(de)
        if integrate:
            mem[slot_i] += gains[k + 1] * dt * (e + mem[slot_e]) / 2.0
        out += mem[slot_i] + gains[k + 2] * de / dt
    mem[slot_e] = e
    return out


@njit(cache=True)
def tilt_compensation(c: float, floor: float) -> float:
    """Collective-thrust factor for ``c = cos(phi) cos(theta)`` (cascade-pid).

    ``1/c`` while ``c >= floor`` (the vertical thrust component stays
    ``m (g + a)``); below the floor it fades as ``(c/floor)^FADE_POWER / floor``
    (continuous at the floor) to zero at 90 deg of tilt, and stays zero upside
    down. A vehicle knocked onto its side gets almost no push from the altitude
    loop, so the attitude is recovered first instead of the thrust driving it
    into whatever it leans on. With a linear fade (power 1), 17 runs of the
    Figure 4 grid pushed a bumper beyond its radius; with power 4 only one run
    exceeds it, by an impact at 1.76 m/s that the bumper cannot absorb, not by
    a push (docs/CONTROLLERS.md).
    """
    if c >= floor:
        return 1.0 / c
    if c <= 0.0:
        return 0.0
    return (c / floor) ** FADE_POWER / floor


@njit(cache=True)
def cascade_pid_step(
    x: np.ndarray, ctrl: np.ndarray, mem: np.ndarray, veh: np.ndarray, dt: float, cmd: np.ndarray
) -> None:
    """Cascade PID done properly (MODEL.md 6.2): running integrals, anti-windup, limits."""
    g = ctrl[C_GAINS : C_GAINS + 15]
    roll, pitch, yaw, h, hdot = _measure(x)
    started = mem[M_STARTED] > 0.5
    # conditional integration: frozen while the rotors saturated at the last
    # tick (anti-windup); the altitude loop's also while the tilt is beyond the
    # compensation floor (its output is faded out then)
    integrate = mem[M_SATURATED] < 0.5
    roll_pitch_c = math.cos(roll) * math.cos(pitch)
    integrate_alt = integrate and roll_pitch_c >= ctrl[C_THRUST_COS_FLOOR]
    v_des = _pid(ctrl[C_H_REF] - h, M_E_H, M_I_H, mem, g, G_ALT, dt, started, integrate_alt, False)
    acc = _pid(v_des - hdot, M_E_V, M_I_V, mem, g, G_CLIMB, dt, started, integrate_alt, False)
    fade = tilt_compensation(roll_pitch_c, ctrl[C_THRUST_COS_FLOOR])
    thrust = veh[V_MASS] * (veh[V_GRAVITY] + acc) * fade
    e_psi = wrap_pi(ctrl[C_PSI_REF] - yaw)
    r_des = _pid(e_psi, M_E_PSI, M_I_PSI, mem, g, G_HEADING, dt, started, integrate, True)
    e_phi = wrap_pi(ctrl[C_PHI_REF] - roll)
    e_theta = ctrl[C_THETA_REF] - pitch
    a_phi = _pid(e_phi, M_E_PHI, M_I_PHI, mem, g, G_ATT, dt, started, integrate, True)
    a_theta = _pid(e_theta, M_E_THETA, M_I_THETA, mem, g, G_ATT, dt, started, integrate, False)
    a_r = _pid(
        r_des - x[X_OMEGA + 2], M_E_R, M_I_R, mem, g, G_YAWRATE, dt, started, integrate, False
    )
    tx, ty, tz = _torques(x, veh, a_phi, a_theta, a_r)
    saturated = allocate(ctrl, thrust, tx, ty, tz, cmd)
    lo = ctrl[C_OMEGA_MIN]
    hi = ctrl[C_OMEGA_MAX]
    for j in range(4):
        if cmd[j] < lo:
            cmd[j] = lo
            saturated = True
        elif cmd[j] > hi:
            cmd[j] = hi
            saturated = True
    mem[M_SATURATED] = 1.0 if saturated else 0.0
    mem[M_STARTED] = 1.0


@njit(cache=True)
def builtin_step(
    x: np.ndarray, ctrl: np.ndarray, mem: np.ndarray, veh: np.ndarray, dt: float, cmd: np.ndarray
) -> None:
    """Dispatch to the built-in controller named by ``ctrl[C_KIND]``; none holds the speeds."""
    kind = int(ctrl[C_KIND])
    if kind == CTRL_PAPER:
        paper_step(x, ctrl, mem, veh, dt, cmd)
    elif kind == CTRL_CASCADE_PID:
        cascade_pid_step(x, ctrl, mem, veh, dt, cmd)
    else:
        for j in range(4):
            cmd[j] = x[X_ROTOR + j]
