"""The learning environments' reward and envelope: the cost per second of a state and the
command in force (each term in [0, 1], weighted by ``EP_W_*``), and the first
envelope limit a state breaks (``OC_*``). SI units, inertial NED.
"""

import math

import numpy as np

from quadimpact.core.compiled import allocating, compiled
from quadimpact.core.controller_slots import C_OMEGA_MAX, C_OMEGA_MIN
from quadimpact.core.envs.episode_layout import (
    B_H_REF,
    B_X_REF,
    B_Y_REF,
    ENV_ROTORS,
    EP_MAX_DIST,
    EP_MAX_DROP,
    EP_MAX_RATE,
    EP_MAX_TILT_COS,
    EP_S_HEIGHT,
    EP_S_RATE,
    EP_S_VZ,
    EP_W_EFFORT,
    EP_W_HEIGHT,
    EP_W_RATE,
    EP_W_TILT,
    EP_W_VZ,
    OC_ALTITUDE,
    OC_DISTANCE,
    OC_RATE,
    OC_RUNNING,
    OC_TILT,
)
from quadimpact.core.layout import X_OMEGA, X_POS, X_QUAT, X_VEL
from quadimpact.core.quaternion import rotation_matrix
from quadimpact.core.rotors import RIN_CMD
from quadimpact.core.vehicle_slots import V_GRAVITY, V_KT, V_MASS


@allocating
def cost_rate(
    x: np.ndarray,
    rin: np.ndarray,
    veh: np.ndarray,
    ctrl: np.ndarray,
    par: np.ndarray,
    h_ref: float,
) -> float:
    """Weighted cost per second of a state and the command in force (each term in [0, 1])."""
    q1 = x[X_QUAT + 1]
    q2 = x[X_QUAT + 2]
    n2 = x[X_QUAT] ** 2 + q1 * q1 + q2 * q2 + x[X_QUAT + 3] ** 2
    c22 = 1.0 - 2.0 * (q1 * q1 + q2 * q2) / n2  # cos of the tilt from vertical
    tilt = 0.5 * (1.0 - c22)
    w = math.sqrt(x[X_OMEGA] ** 2 + x[X_OMEGA + 1] ** 2 + x[X_OMEGA + 2] ** 2)
    rate = min(w / par[EP_S_RATE], 1.0)
    C = np.empty((3, 3))
    rotation_matrix(x[X_QUAT : X_QUAT + 4], C)
    vz = C[2, 0] * x[X_VEL] + C[2, 1] * x[X_VEL + 1] + C[2, 2] * x[X_VEL + 2]
    vert = min(abs(vz) / par[EP_S_VZ], 1.0)
    height = min(max(h_ref + x[X_POS + 2], 0.0) / par[EP_S_HEIGHT], 1.0)
    hover = math.sqrt(veh[V_MASS] * veh[V_GRAVITY] / (4.0 * veh[V_KT]))
    span = ctrl[C_OMEGA_MAX] - ctrl[C_OMEGA_MIN]
    effort = 0.0
    for j in range(ENV_ROTORS):
        d = (rin[RIN_CMD + j] - hover) / span
        effort += 0.25 * d * d
    effort = min(effort, 1.0)
    total = (
        par[EP_W_TILT] * tilt
        + par[EP_W_RATE] * rate
        + par[EP_W_VZ] * vert
        + par[EP_W_HEIGHT] * height
        + par[EP_W_EFFORT] * effort
    )
    return total if total == total else max_cost_rate(par)


@compiled
def max_cost_rate(par: np.ndarray) -> float:
    """The largest cost per second (every term at 1)."""
    return par[EP_W_TILT] + par[EP_W_RATE] + par[EP_W_VZ] + par[EP_W_HEIGHT] + par[EP_W_EFFORT]


@compiled
def envelope_outcome(x: np.ndarray, env: np.ndarray, par: np.ndarray) -> int:
    """``OC_*`` of the first envelope limit the state breaks (``OC_RUNNING``: none)."""
    q1 = x[X_QUAT + 1]
    q2 = x[X_QUAT + 2]
    n2 = x[X_QUAT] ** 2 + q1 * q1 + q2 * q2 + x[X_QUAT + 3] ** 2
    if 1.0 - 2.0 * (q1 * q1 + q2 * q2) / n2 < par[EP_MAX_TILT_COS]:
        return OC_TILT
    if -x[X_POS + 2] < env[B_H_REF] - par[EP_MAX_DROP]:
        return OC_ALTITUDE
    if math.hypot(x[X_POS] - env[B_X_REF], x[X_POS + 1] - env[B_Y_REF]) > par[EP_MAX_DIST]:
        return OC_DISTANCE
    w = math.sqrt(x[X_OMEGA] ** 2 + x[X_OMEGA + 1] ** 2 + x[X_OMEGA + 2] ** 2)
    if w > par[EP_MAX_RATE]:
        return OC_RATE
    return OC_RUNNING
