"""What the learning environments' agent sees: the measurement of the next tick and the
normalised observation of each mode (``OBS_*``; layouts in docs/LEARNING.md).

Frames and units: inertial NED, body FRD, SI; every observed value divided by
its scale (``EP_OBS_*``) and clipped to ``EP_OBS_CLIP``.
"""

import numpy as np

from quadimpact.core.compiled import allocating, compiled
from quadimpact.core.envs.actions import rotor_range
from quadimpact.core.envs.episode_layout import (
    B_H_REF,
    B_Y_REF,
    ENV_ROTORS,
    EP_OBS_CLIP,
    EP_OBS_F,
    EP_OBS_POS,
    EP_OBS_T,
    EP_OBS_V,
    EP_OBS_W,
    EP_OBSERVE,
    OBS_EST_BIAS,
    OBS_EST_F,
    OBS_EST_POS,
    OBS_EST_RATE,
    OBS_EST_ROTOR,
    OBS_EST_VEL,
    OBS_ESTIMATE,
    OBS_STATE,
)
from quadimpact.core.estimators import write_estimate
from quadimpact.core.layout import (
    LS_K,
    LS_T0,
    NX,
    O_DT_CONTROL,
    X_OMEGA,
    X_POS,
    X_QUAT,
    X_ROTOR,
    X_VEL,
)
from quadimpact.core.quaternion import normalise_quaternion, rotation_matrix
from quadimpact.core.records import Data, Model
from quadimpact.core.rotors import RIN_CMD
from quadimpact.core.sensors.measurement_slots import (
    MS_BIAS_HAT,
    MS_DETECTED,
    MS_IMU_F,
    MS_IMU_W,
    MS_NORMAL,
    MS_T,
    MS_T_DETECT,
    MS_W_HAT,
    MS_X,
)


@allocating
def tick_measurement(m: Model, d: Data, tmeas: np.ndarray) -> None:
    """What a controller sees at the next tick: ``d.meas`` with the estimate of that tick.

    The state is renormalised on a copy, as ``step.tick`` renormalises it
    before the estimator runs (the same arithmetic, so the same bits), and the
    estimate written by the estimator stage (``estimators.write_estimate``, through
    the one writer of the measurement record).
    """
    tmeas[:] = d.meas
    x = d.x.copy()
    normalise_quaternion(x, X_QUAT)
    write_estimate(d.ls[LS_T0] + int(d.ls[LS_K]) * m.opts[O_DT_CONTROL], x, m, d, tmeas)


# ---------------------------------------------------------------- observation, reward
@compiled
def _clip(v: float, c: float) -> float:
    if not v == v:  # NaN (a failed run)
        return 0.0
    return min(max(v, -c), c)


@allocating
def observe(
    tmeas: np.ndarray,
    rin: np.ndarray,
    ctrl: np.ndarray,
    par: np.ndarray,
    env: np.ndarray,
    obs: np.ndarray,
) -> None:
    """The normalised observation of a tick (layouts in docs/LEARNING.md)."""
    x = tmeas[MS_X : MS_X + NX]
    C = np.empty((3, 3))
    rotation_matrix(x[X_QUAT : X_QUAT + 4], C)
    clip = par[EP_OBS_CLIP]
    vz = C[2, 0] * x[X_VEL] + C[2, 1] * x[X_VEL + 1] + C[2, 2] * x[X_VEL + 2]
    detected = tmeas[MS_DETECTED] > 0.5
    since = tmeas[MS_T] - tmeas[MS_T_DETECT] if detected else 0.0
    lo, hi = rotor_range(ctrl, par)
    h = 0.5 * (hi - lo)
    if int(par[EP_OBSERVE]) == OBS_ESTIMATE:
        observe_estimate(tmeas, par, obs)
        return
    if int(par[EP_OBSERVE]) == OBS_STATE:
        obs[0] = _clip(x[X_POS] / par[EP_OBS_POS], clip)
        obs[1] = _clip((x[X_POS + 1] - env[B_Y_REF]) / par[EP_OBS_POS], clip)
        obs[2] = _clip((-x[X_POS + 2] - env[B_H_REF]) / par[EP_OBS_POS], clip)
        for i in range(3):
            obs[3 + i] = _clip(x[X_VEL + i] / par[EP_OBS_V], clip)
        sign = -1.0 if x[X_QUAT] < 0.0 else 1.0
        for i in range(4):
            obs[6 + i] = _clip(sign * x[X_QUAT + i], clip)
        for i in range(3):
            obs[10 + i] = _clip(x[X_OMEGA + i] / par[EP_OBS_W], clip)
        for j in range(ENV_ROTORS):
            obs[13 + j] = _clip((x[X_ROTOR + j] - lo) / h - 1.0, clip)
        obs[17] = _clip(since / par[EP_OBS_T], clip)
        obs[18] = 1.0 if detected else 0.0
        return
    for i in range(3):
        obs[i] = _clip(tmeas[MS_IMU_F + i] / par[EP_OBS_F], clip)
        obs[3 + i] = _clip(tmeas[MS_IMU_W + i] / par[EP_OBS_W], clip)
    for r in range(3):
        for c in range(3):
            obs[6 + 3 * r + c] = _clip(C[r, c], clip)
    obs[15] = _clip(-vz / par[EP_OBS_V], clip)
    obs[16] = _clip(since / par[EP_OBS_T], clip)
    obs[17] = 1.0 if detected else 0.0
    obs[18] = _clip(tmeas[MS_NORMAL], clip)
    obs[19] = _clip(tmeas[MS_NORMAL + 1], clip)
    for j in range(ENV_ROTORS):
        obs[20 + j] = _clip((rin[RIN_CMD + j] - lo) / h - 1.0, clip)


@compiled
def observe_estimate(tmeas: np.ndarray, par: np.ndarray, obs: np.ndarray) -> None:
    """The estimate mode's observation: what an on-board controller sees (docs/LEARNING.md).

    The estimator's output (attitude, body velocity, position, rates, gyro
    bias), the IMU sample, the detector, the rotor speeds; every value divided
    by a power of two (so exactly recoverable from the float64 observation),
    then clipped.
    """
    x = tmeas[MS_X : MS_X + NX]
    clip = par[EP_OBS_CLIP]
    for i in range(4):
        obs[i] = _clip(x[X_QUAT + i], clip)
    for i in range(3):
        obs[4 + i] = _clip(x[X_VEL + i] / OBS_EST_VEL, clip)
        obs[7 + i] = _clip(x[X_POS + i] / OBS_EST_POS, clip)
        obs[10 + i] = _clip(tmeas[MS_W_HAT + i] / OBS_EST_RATE, clip)
        obs[13 + i] = _clip(tmeas[MS_IMU_F + i] / OBS_EST_F, clip)
        obs[16 + i] = _clip(tmeas[MS_IMU_W + i] / OBS_EST_RATE, clip)
        obs[19 + i] = _clip(tmeas[MS_BIAS_HAT + i] / OBS_EST_BIAS, clip)
    detected = tmeas[MS_DETECTED] > 0.5
    obs[22] = 1.0 if detected else 0.0
    obs[23] = _clip(tmeas[MS_T] - tmeas[MS_T_DETECT] if detected else 0.0, clip)
    obs[24] = _clip(tmeas[MS_NORMAL], clip)
    obs[25] = _clip(tmeas[MS_NORMAL + 1], clip)
    for j in range(4):
        obs[26 + j] = _clip(x[X_ROTOR + j] / OBS_EST_ROTOR, clip)


@compiled
def measurement_from_estimate(obs: np.ndarray, meas: np.ndarray) -> None:
    """The measurement record an estimate-mode observation stands for (its inverse).

    Fills what the staged controller reads: the state estimate, the estimated
    rates and bias, the IMU sample, the detector's verdict and normal.
    """
    meas[:] = 0.0
    for i in range(4):
        meas[MS_X + X_QUAT + i] = obs[i]
    for i in range(3):
        meas[MS_X + X_VEL + i] = obs[4 + i] * OBS_EST_VEL
        meas[MS_X + X_POS + i] = obs[7 + i] * OBS_EST_POS
        meas[MS_X + X_OMEGA + i] = obs[10 + i] * OBS_EST_RATE
        meas[MS_W_HAT + i] = obs[10 + i] * OBS_EST_RATE
        meas[MS_IMU_F + i] = obs[13 + i] * OBS_EST_F
        meas[MS_IMU_W + i] = obs[16 + i] * OBS_EST_RATE
        meas[MS_BIAS_HAT + i] = obs[19 + i] * OBS_EST_BIAS
    meas[MS_DETECTED] = obs[22]
    meas[MS_T_DETECT] = 0.0 if obs[22] > 0.5 else np.nan
    meas[MS_T] = obs[23]
    meas[MS_NORMAL] = obs[24]
    meas[MS_NORMAL + 1] = obs[25]
    for j in range(4):
        meas[MS_X + X_ROTOR + j] = obs[26 + j] * OBS_EST_ROTOR
