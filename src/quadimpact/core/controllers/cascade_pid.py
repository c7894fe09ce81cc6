"""The ``cascade-pid`` controller: the paper's loop structure done properly.

Running trapezoidal integrals, conditional integration (anti-windup) while
the rotors saturate, thrust divided by ``cos(phi) cos(theta)`` down to a floor
and faded to zero beyond it (:func:`tilt_compensation`), rotor speeds limited
to the vehicle's range (``C_OMEGA_MIN``, ``C_OMEGA_MAX``). Gains and memory
follow the PID layout of ``common.py``; the retuned default gains and their
analysis are in docs/CONTROLLERS.md.
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.controller_slots import (
    C_H_REF,
    C_OMEGA_MAX,
    C_OMEGA_MIN,
    C_PARAMS,
    C_PHI_REF,
    C_PSI_REF,
    C_THETA_REF,
    C_WAYPOINT_ON,
)
from quadimpact.core.controllers.common import (
    G_ALT,
    G_ATT,
    G_CLIMB,
    G_HEADING,
    G_YAWRATE,
    M_E_H,
    M_E_PHI,
    M_E_PSI,
    M_E_R,
    M_E_THETA,
    M_E_V,
    M_I_H,
    M_I_PHI,
    M_I_PSI,
    M_I_R,
    M_I_THETA,
    M_I_V,
    M_SATURATED,
    M_STARTED,
    P_GAINS,
    P_THRUST_COS_FLOOR,
    allocate,
    attitude_altitude,
    linearised_torques,
)
from quadimpact.core.controllers.waypoint import waypoint_references
from quadimpact.core.layout import NX, X_OMEGA
from quadimpact.core.quaternion import wrap_pi
from quadimpact.core.sensors.measurement_slots import MS_X
from quadimpact.core.vehicle_slots import V_GRAVITY, V_MASS, V_N_ROTORS

FADE_POWER = 4.0  # thrust fade beyond the tilt floor (tilt_compensation)


@compiled
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


@compiled
def tilt_compensation(c: float, floor: float) -> float:
    """Collective-thrust factor for ``c = cos(phi) cos(theta)``.

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


@compiled
def cascade_pid_step(
    t: float,
    meas: np.ndarray,
    ctrl: np.ndarray,
    mem: np.ndarray,
    veh: np.ndarray,
    dt: float,
    cmd: np.ndarray,
) -> None:
    """One tick of the cascade PID; writes the rotor speeds (rad/s) into ``cmd``."""
    x = meas[MS_X : MS_X + NX]
    g = ctrl[C_PARAMS + P_GAINS : C_PARAMS + P_GAINS + 15]
    floor = ctrl[C_PARAMS + P_THRUST_COS_FLOOR]
    roll, pitch, yaw, h, hdot = attitude_altitude(x)
    started = mem[M_STARTED] > 0.5
    # conditional integration: frozen while the rotors saturated at the last
    # tick (anti-windup); the altitude loop's also while the tilt is beyond the
    # compensation floor (its output is faded out then)
    integrate = mem[M_SATURATED] < 0.5
    roll_pitch_c = math.cos(roll) * math.cos(pitch)
    integrate_alt = integrate and roll_pitch_c >= floor
    v_des = _pid(ctrl[C_H_REF] - h, M_E_H, M_I_H, mem, g, G_ALT, dt, started, integrate_alt, False)
    acc = _pid(v_des - hdot, M_E_V, M_I_V, mem, g, G_CLIMB, dt, started, integrate_alt, False)
    fade = tilt_compensation(roll_pitch_c, floor)
    thrust = veh[V_MASS] * (veh[V_GRAVITY] + acc) * fade
    e_psi = wrap_pi(ctrl[C_PSI_REF] - yaw)
    r_des = _pid(e_psi, M_E_PSI, M_I_PSI, mem, g, G_HEADING, dt, started, integrate, True)
    phi_ref = ctrl[C_PHI_REF]
    theta_ref = ctrl[C_THETA_REF]
    if ctrl[C_WAYPOINT_ON] > 0.5:
        phi_ref, theta_ref = waypoint_references(t, x, yaw, ctrl, veh[V_GRAVITY])
    e_phi = wrap_pi(phi_ref - roll)
    e_theta = theta_ref - pitch
    a_phi = _pid(e_phi, M_E_PHI, M_I_PHI, mem, g, G_ATT, dt, started, integrate, True)
    a_theta = _pid(e_theta, M_E_THETA, M_I_THETA, mem, g, G_ATT, dt, started, integrate, False)
    a_r = _pid(
        r_des - x[X_OMEGA + 2], M_E_R, M_I_R, mem, g, G_YAWRATE, dt, started, integrate, False
    )
    tx, ty, tz = linearised_torques(x[X_OMEGA : X_OMEGA + 3], veh, a_phi, a_theta, a_r)
    saturated = allocate(ctrl, thrust, tx, ty, tz, cmd)
    lo = ctrl[C_OMEGA_MIN]
    hi = ctrl[C_OMEGA_MAX]
    for j in range(int(veh[V_N_ROTORS])):
        if cmd[j] < lo:
            cmd[j] = lo
            saturated = True
        elif cmd[j] > hi:
            cmd[j] = hi
            saturated = True
    mem[M_SATURATED] = 1.0 if saturated else 0.0
    mem[M_STARTED] = 1.0
