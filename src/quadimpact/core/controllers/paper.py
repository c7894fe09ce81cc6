"""The ``paper`` controller: the authors' discrete PID exactly as they ran it.

Runs at the control ticks (200 Hz, zero-order hold), reads the state
estimate of the measurement record. Quirks kept on purpose (the published
results depend on them; docs/CONTROLLERS.md): the "integral" terms use only
the last two errors, ``Ki dt (e_k + e_{k-1}) / 2``; the heading "integral" has
no 1/2; derivatives are ``Kd (e_k - e_{k-1}) / dt``, both zero on the first
tick; roll and pitch errors are not wrapped; the collective thrust is
``m (g + a) cos(phi) cos(theta)`` (multiplied by the cosines); no rotor limits.

Parameters (``ctrl[C_PARAMS + P_GAINS ...]``) and memory follow the PID layout
of ``common.py``.
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.controller_slots import C_H_REF, C_PARAMS, C_PHI_REF, C_PSI_REF, C_THETA_REF
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
    M_STARTED,
    P_GAINS,
    allocate,
    attitude_altitude,
    linearised_torques,
)
from quadimpact.core.layout import NX, X_OMEGA
from quadimpact.core.quaternion import wrap_pi
from quadimpact.core.sensors.measurement_slots import MS_X
from quadimpact.core.vehicle_slots import V_GRAVITY, V_MASS


@compiled
def paper_step(
    t: float,
    meas: np.ndarray,
    ctrl: np.ndarray,
    mem: np.ndarray,
    veh: np.ndarray,
    dt: float,
    cmd: np.ndarray,
) -> None:
    """One tick of the authors' controller; writes the rotor speeds (rad/s) into ``cmd``."""
    x = meas[MS_X : MS_X + NX]
    g = ctrl[C_PARAMS + P_GAINS : C_PARAMS + P_GAINS + 15]
    roll, pitch, yaw, h, hdot = attitude_altitude(x)
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
    tx, ty, tz = linearised_torques(x[X_OMEGA : X_OMEGA + 3], veh, a_phi, a_theta, a_r)
    allocate(ctrl, thrust, tx, ty, tz, cmd)
    mem[M_E_H] = e_h
    mem[M_E_V] = e_v
    mem[M_E_PSI] = e_psi
    mem[M_E_PHI] = e_phi
    mem[M_E_THETA] = e_theta
    mem[M_E_R] = e_r
    mem[M_STARTED] = 1.0
