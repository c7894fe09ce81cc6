"""Many runs stepped together under external rotor commands: the learning environments' core.

The records of :mod:`records` for N runs are stacked along a first axis
(``M.x0`` is (N, NX), ``D.cs`` (N, n_pairs, NCS), ``M.noise`` (N, n, 6) ...;
``model_row(M, k)`` is run ``k``'s model, as ``step.tick`` takes it); the
environments' own arrays are the record :class:`Env`. All runs of a batch
have the same features, shapes, output grid and buffer sizes; a run whose IMU
draws no noise (an ideal IMU) has its noise rows padded with zeros, which the
IMU multiplies by a zero standard deviation: the same arithmetic as no rows
at all.

Per control tick and run, :func:`step_batch` maps the agent's normalised
action to a rotor command, sets the run's stage in force (reported by the
policy, or from the observer below), runs one tick of ``step.tick`` with that
command in ``ls[LS_EXT_CMD]`` (so the loop's slew limit, range and zero floor
apply), then computes the run's next observation, reward and termination (all in compiled code).
:func:`reset_slot` starts a run and, in detection mode, runs its pre-impact
behaviour with the built-in controller until the detector fires.

Frames and units: inertial NED, body FRD, SI, rotor speeds in rad/s.

Action maps (``a`` clipped to [-1, 1]):

* rotors: ``omega_j = lo + (a_j + 1) h``, ``h = (hi - lo)/2``, with ``[lo, hi]``
  the vehicle's rotor range (or ``[0, hi]``), evaluated by :func:`affine_map`;
* ctbr: collective thrust ``T = T_max (a_0 + 1)/2`` (``T_max = 4 kt hi^2``), body
  rate references ``a_1..3 * rate_max`` (rad/s), then the staged controller's
  inner loop ``recovery.rate_loop`` (``K_rate`` feedback on the gyro,
  feedback-linearised torques, allocation, rotor range).

Observer (the stage record for a policy that reports no stages): stage 1 at
the first tick at which the detector has fired (the takeover); then, over the
ticks after it, the *level test* (the tilt error toward level of
``recovery.staged_references`` in stage 2, ``|q_e,x|, |q_e,y| < q_tol``, and the
gyro's ``|p|, |q| < rate_tol``) and the *recovered condition* (the level test
and body z velocity ``w < w_tol``) must each hold for a confirmation window of
``EP_HOLD_TICKS`` ticks: stages 2 and 3 are entered at the first tick of the
first window of the level test, stage 4 at the first tick of the first window
of the recovered condition (written into the run's stage record once the
window is complete). A policy that reports its stages (``staged_policy``) has
its own stage record; with either, the episode ends as recovered once stage 4
is reached and the recovered condition has held for the window.
"""

import math
from typing import NamedTuple

import numpy as np

from .compiled import allocating, compiled
from .controller_layout import (
    R_FIRST_TICK_LEVEL,
    R_Q_TOL,
    R_RATE_TOL,
    R_W_TOL,
    STAGE_DETECTED,
    STAGE_PRE_IMPACT,
    STAGE_RECOVERED,
    STAGE_TILTED,
)
from .controllers.recovery import (
    law_references,
    rate_loop,
    recovery_step,
    staged_references,
)
from .estimators import write_estimate
from .integrator import all_finite, copy_into
from .layout import (
    C_OMEGA_MAX,
    C_OMEGA_MIN,
    C_PARAMS,
    LS_DONE,
    LS_EXT,
    LS_EXT_CMD,
    LS_K,
    LS_T,
    LS_T0,
    LS_TF,
    MEM_STAGE,
    MS_BIAS_HAT,
    MS_DETECTED,
    MS_IMU_F,
    MS_IMU_W,
    MS_NORMAL,
    MS_T,
    MS_T_DETECT,
    MS_W_HAT,
    MS_X,
    N_ROTORS,
    NX,
    O_DT_CONTROL,
    O_SLEW_MAX,
    RIN_CMD,
    ST_CRASH_T,
    ST_STAGE_T,
    ST_STAGE_X,
    ST_STATUS,
    STATUS_FAILED,
    V_GRAVITY,
    V_KT,
    V_MASS,
    X_OMEGA,
    X_POS,
    X_QUAT,
    X_ROTOR,
    X_VEL,
    Block,
)
from .quaternion import normalise_quaternion, rotation_matrix
from .records import Data, Model, Output, Work, data_row, model_row, new_work, output_row
from .step import finish, start, tick


# ---------------------------------------------------------------- records
class Env(NamedTuple):
    """The environments' own arrays, stacked like the runs' records (row ``k``: run ``k``)."""

    state: np.ndarray  # (N, NB) per-run episode state (B_*)
    par: np.ndarray  # (NPAR,) parameters shared by the runs (EP_*)
    tmeas: np.ndarray  # (N, NMEAS) the measurement record of each run's next tick
    reported: np.ndarray  # (N,) the stage the policy reports for this tick (< 0: none)
    obs: np.ndarray  # (N, n_obs) float32 observations
    reward: np.ndarray  # (N,)
    terminated: np.ndarray  # (N,) bool
    truncated: np.ndarray  # (N,) bool


# ---------------------------------------------------------------- per-run env state (N, NB)
_b = Block("env.state", "B_")
B_ACTIVE = _b.slot("B_ACTIVE")  # 1 while the episode runs
B_STAGE = _b.slot("B_STAGE")  # stage in force (the policy's or the observer's)
B_POLICY = _b.slot("B_POLICY")  # 1 once the policy has reported a stage this episode
B_HOLD = _b.slot("B_HOLD")  # consecutive ticks (after the takeover) the recovered condition held
B_H_REF = _b.slot("B_H_REF")  # m, altitude at the takeover (height-loss reference)
B_X_REF = _b.slot("B_X_REF")  # m, CM X and Y at the takeover (distance reference)
B_Y_REF = _b.slot("B_Y_REF")
B_STEPS = _b.slot("B_STEPS")  # steps taken this episode
B_OUTCOME = _b.slot("B_OUTCOME")  # OC_* below
B_RETURN = _b.slot("B_RETURN")  # sum of the rewards of the episode
B_INEXACT = _b.slot("B_INEXACT")  # policy commands the action map could not give exactly
B_LEVEL_N = _b.slot("B_LEVEL_N")  # consecutive ticks (after the takeover) the level test held
B_LEVEL_T = _b.slot("B_LEVEL_T")  # s, first tick of that run
B_LEVEL_P = _b.slot("B_LEVEL_P", 3)  # CM position there, inertial, m
B_HOLD_T = _b.slot("B_HOLD_T")  # s, first tick of the recovered condition's run
B_HOLD_P = _b.slot("B_HOLD_P", 3)  # CM position there, inertial, m
NB = _b.end("NB")

OC_RUNNING = 0
OC_RECOVERED = 1
OC_GROUND = 2
OC_TILT = 3
OC_ALTITUDE = 4
OC_DISTANCE = 5
OC_RATE = 6
OC_TIME_LIMIT = 7
OC_FAILED = 8

# ---------------------------------------------------------------- parameters (NPAR)
_ep = Block("env.par", "EP_")
EP_ACTION = _ep.slot("EP_ACTION")  # ACT_* below
EP_OBSERVE = _ep.slot("EP_OBSERVE")  # OBS_* below
EP_ZERO_LOW = _ep.slot("EP_ZERO_LOW")  # 1: rotor actions map onto [0, hi], not [lo, hi]
EP_RATE_MAX = _ep.slot("EP_RATE_MAX", 3)  # ctbr rate reference scale (p, q, r), rad/s
EP_W_TILT = _ep.slot("EP_W_TILT")  # reward weights per second of simulated time
EP_W_RATE = _ep.slot("EP_W_RATE")
EP_W_VZ = _ep.slot("EP_W_VZ")
EP_W_HEIGHT = _ep.slot("EP_W_HEIGHT")
EP_W_EFFORT = _ep.slot("EP_W_EFFORT")
EP_W_RECOVERY = _ep.slot("EP_W_RECOVERY")  # bonus on the recovered termination
EP_W_FAILURE = _ep.slot("EP_W_FAILURE")  # penalty on a failure termination (ground, envelope)
EP_FAIL_REMAINING = _ep.slot("EP_FAIL_REMAINING")  # 1: a failure costs the top rate to the end
EP_S_RATE = _ep.slot("EP_S_RATE")  # rad/s, scale of the rate cost
EP_S_VZ = _ep.slot("EP_S_VZ")  # m/s, scale of the vertical-speed cost
EP_S_HEIGHT = _ep.slot("EP_S_HEIGHT")  # m, scale of the height-loss cost
EP_MAX_TILT_COS = _ep.slot("EP_MAX_TILT_COS")  # envelope: cos of the largest tilt from vertical
EP_MAX_DROP = _ep.slot("EP_MAX_DROP")  # m, envelope: altitude below the takeover altitude
EP_MAX_DIST = _ep.slot("EP_MAX_DIST")  # m, envelope: horizontal distance from the takeover
EP_MAX_RATE = _ep.slot("EP_MAX_RATE")  # rad/s, envelope: |omega|
EP_HOLD_TICKS = _ep.slot("EP_HOLD_TICKS")  # confirmation window of the level test, ticks
EP_GROUND = _ep.slot("EP_GROUND")  # 1: the first ground contact ends the episode
EP_OBS_F = _ep.slot("EP_OBS_F")  # observation scales: specific force m/s^2, rates rad/s,
EP_OBS_W = _ep.slot("EP_OBS_W")  # speed m/s, time s, position m; observations are
EP_OBS_V = _ep.slot("EP_OBS_V")  # clipped to +-EP_OBS_CLIP
EP_OBS_T = _ep.slot("EP_OBS_T")
EP_OBS_POS = _ep.slot("EP_OBS_POS")
EP_OBS_CLIP = _ep.slot("EP_OBS_CLIP")
EP_END_ON_RECOVERY = _ep.slot("EP_END_ON_RECOVERY")  # 1: the episode ends once recovered
NPAR = _ep.end("NPAR")

ACT_ROTORS = 0
ACT_CTBR = 1
OBS_IMU = 0
OBS_STATE = 1
OBS_ESTIMATE = 2
N_OBS_IMU = 24
N_OBS_STATE = 19
N_OBS_ESTIMATE = 30
# the estimate mode's scales: powers of two, so that value = observation * scale exactly
# (observations float64): the staged controller can act on its observation alone
OBS_EST_VEL = 2.0  # m/s
OBS_EST_POS = 8.0  # m
OBS_EST_RATE = 8.0  # rad/s
OBS_EST_F = 16.0  # m/s^2
OBS_EST_BIAS = 0.125  # rad/s
OBS_EST_ROTOR = 1024.0  # rad/s


def n_observations(mode: int) -> int:
    """The observation length of a mode (``OBS_*``)."""
    if mode == OBS_STATE:
        return N_OBS_STATE
    if mode == OBS_ESTIMATE:
        return N_OBS_ESTIMATE
    return N_OBS_IMU


# ---------------------------------------------------------------- action maps
@compiled
def affine_map(a: float, lo: float, hi: float) -> float:
    """``lo + (a + 1) (hi - lo)/2`` for ``a`` in [-1, 1], rounded as finely as floats allow.

    Evaluated from the nearer end (``lo + (1 + a) h`` for ``a < -1/2``,
    ``hi - (1 - a) h`` for ``a > 1/2``) or from the middle (``m + a h``), so that
    ``1 + a`` and ``1 - a`` are exact: every float command from
    ``lo + (hi - lo)/4`` to ``hi`` is the map of some float ``a``. Below, only a
    part is (near ``a = -1`` floats are ``2^-53`` apart, which the map spreads
    over more commands than there are floats ``a``). ``a = -1`` gives ``lo`` and
    ``a = 1`` gives ``hi`` exactly.
    """
    h = 0.5 * (hi - lo)
    if a < -0.5:
        return lo + (1.0 + a) * h
    if a > 0.5:
        return hi - (1.0 - a) * h
    return (lo + h) + a * h


@compiled
def affine_inverse(w: float, lo: float, hi: float) -> tuple[float, bool]:
    """The ``a`` in [-1, 1] whose :func:`affine_map` is ``w``; False if none (the nearest then).

    Newton steps on the map, then a walk with ``nextafter`` to the exact value.
    """
    h = 0.5 * (hi - lo)
    if w <= lo:
        return -1.0, w == lo
    if w >= hi:
        return 1.0, w == hi
    a = min(max((w - lo) / h - 1.0, -1.0), 1.0)
    for _ in range(3):
        a = min(max(a + (w - affine_map(a, lo, hi)) / h, -1.0), 1.0)
    best = a
    best_err = abs(affine_map(a, lo, hi) - w)
    for _ in range(64):
        m = affine_map(a, lo, hi)
        if m == w:
            return a, True
        err = abs(m - w)
        if err < best_err:
            best = a
            best_err = err
        a = np.nextafter(a, 2.0) if m < w else np.nextafter(a, -2.0)
        if a < -1.0 or a > 1.0:
            break
    return best, False


@compiled
def rotor_range(ctrl: np.ndarray, par: np.ndarray) -> tuple[float, float]:
    """The rotor-speed range (rad/s) that rotor actions map onto."""
    lo = 0.0 if par[EP_ZERO_LOW] > 0.5 else ctrl[C_OMEGA_MIN]
    return lo, ctrl[C_OMEGA_MAX]


@compiled
def max_thrust(veh: np.ndarray, ctrl: np.ndarray) -> float:
    """``4 kt hi^2`` (N): all rotors at the top of the range."""
    hi = ctrl[C_OMEGA_MAX]
    return 4.0 * veh[V_KT] * hi * hi


@allocating
def action_command(
    action: np.ndarray,
    meas: np.ndarray,
    veh: np.ndarray,
    ctrl: np.ndarray,
    par: np.ndarray,
    cmd: np.ndarray,
) -> None:
    """Rotor speed commands (rad/s) of a normalised action, into ``cmd``.

    ``meas``: the tick's measurement record (the gyro for the ctbr rate loop).
    """
    a = np.empty(4)
    for j in range(N_ROTORS):
        v = action[j]
        a[j] = -1.0 if not v >= -1.0 else (1.0 if v > 1.0 else v)  # NaN -> -1
    if int(par[EP_ACTION]) == ACT_CTBR:
        thrust = affine_map(a[0], 0.0, max_thrust(veh, ctrl))
        rates = (a[1] * par[EP_RATE_MAX], a[2] * par[EP_RATE_MAX + 1], a[3] * par[EP_RATE_MAX + 2])
        rate_loop(
            thrust, rates[0], rates[1], rates[2], meas[MS_W_HAT : MS_W_HAT + 3], ctrl, veh, cmd
        )
    else:
        lo, hi = rotor_range(ctrl, par)
        for j in range(N_ROTORS):
            cmd[j] = affine_map(a[j], lo, hi)


# ---------------------------------------------------------------- observer
@compiled
def level_test(
    tmeas: np.ndarray, ctrl: np.ndarray, veh: np.ndarray
) -> tuple[float, float, float, float, float]:
    """``(q_e,x, q_e,y, p, q, w)`` of the tick: tilt error toward level, gyro rates, body w."""
    x = tmeas[MS_X : MS_X + NX]
    _, _, _, qex, qey = staged_references(
        STAGE_TILTED, False, x, tmeas[MS_NORMAL : MS_NORMAL + 3], ctrl, veh
    )
    return qex, qey, tmeas[MS_W_HAT], tmeas[MS_W_HAT + 1], x[X_VEL + 2]


@compiled
def takeover_stage(stage: int, tmeas: np.ndarray) -> int:
    """The observer's stage at a tick before its stage 2: 1 once the detector has fired."""
    if stage == STAGE_PRE_IMPACT and tmeas[MS_DETECTED] > 0.5:
        return STAGE_DETECTED
    return stage


@compiled
def level_and_recovered(tmeas: np.ndarray, ctrl: np.ndarray, veh: np.ndarray) -> tuple[bool, bool]:
    """The level test of the tick, and the recovered condition (level and ``w < w_tol``)."""
    qex, qey, p, q, w = level_test(tmeas, ctrl, veh)
    p0 = C_PARAMS
    qt = ctrl[p0 + R_Q_TOL]
    rt = ctrl[p0 + R_RATE_TOL]
    level = abs(qex) < qt and abs(qey) < qt and abs(p) < rt and abs(q) < rt
    return level, level and w < ctrl[p0 + R_W_TOL]


@compiled
def recovered_condition(tmeas: np.ndarray, ctrl: np.ndarray, veh: np.ndarray) -> bool:
    """Level, slow (|p|, |q|) and body z velocity below ``w_tol``, all at this tick."""
    return level_and_recovered(tmeas, ctrl, veh)[1]


@compiled
def _enter(stats: np.ndarray, stage: int, t: float, p: np.ndarray) -> None:
    """Write a stage entry (tick, CM position) into a run's stage record."""
    stats[ST_STAGE_T + stage] = t
    for i in range(3):
        stats[ST_STAGE_X + 3 * stage + i] = p[i]


@compiled
def _track_windows(
    env: np.ndarray, tmeas: np.ndarray, x: np.ndarray, ctrl: np.ndarray, veh: np.ndarray
) -> None:
    """Runs of the level test and of the recovered condition at the tick ``tmeas[MS_T]``."""
    if env[B_STAGE] < STAGE_DETECTED:
        env[B_LEVEL_N] = 0.0
        env[B_HOLD] = 0.0
        return
    level, rec = level_and_recovered(tmeas, ctrl, veh)
    _count(env, level, B_LEVEL_N, B_LEVEL_T, B_LEVEL_P, tmeas[MS_T], x)
    _count(env, rec, B_HOLD, B_HOLD_T, B_HOLD_P, tmeas[MS_T], x)


@compiled
def _count(
    env: np.ndarray, ok: bool, n_slot: int, t_slot: int, p_slot: int, t: float, x: np.ndarray
) -> None:
    """One tick of a run: its length, and its first tick and position."""
    if not ok:
        env[n_slot] = 0.0
        return
    if env[n_slot] == 0.0:
        env[t_slot] = t
        for i in range(3):
            env[p_slot + i] = x[X_POS + i]
    env[n_slot] += 1.0


@compiled
def _observe_stages(env: np.ndarray, stats: np.ndarray, mem: np.ndarray, par: np.ndarray) -> None:
    """The observer's stages 2-4, entered at the start of their completed windows."""
    window = par[EP_HOLD_TICKS]
    stage = int(env[B_STAGE])
    if stage == STAGE_DETECTED and env[B_LEVEL_N] >= window:
        _enter(stats, STAGE_TILTED, env[B_LEVEL_T], env[B_LEVEL_P : B_LEVEL_P + 3])
        _enter(stats, STAGE_TILTED + 1, env[B_LEVEL_T], env[B_LEVEL_P : B_LEVEL_P + 3])
        stage = STAGE_TILTED + 1
    if stage == STAGE_TILTED + 1 and env[B_HOLD] >= window:
        _enter(stats, STAGE_RECOVERED, env[B_HOLD_T], env[B_HOLD_P : B_HOLD_P + 3])
        stage = STAGE_RECOVERED
    env[B_STAGE] = stage
    mem[MEM_STAGE] = stage


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
        for j in range(N_ROTORS):
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
    for j in range(N_ROTORS):
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
    for j in range(N_ROTORS):
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


# ---------------------------------------------------------------- reset and step
@compiled
def _begin_episode(k: int, m: Model, d: Data, E: Env) -> None:
    env = E.state[k]
    env[:] = 0.0
    env[B_ACTIVE] = 1.0
    env[B_H_REF] = -d.x[X_POS + 2]
    env[B_X_REF] = d.x[X_POS]
    env[B_Y_REF] = d.x[X_POS + 1]
    tick_measurement(m, d, E.tmeas[k])
    observe(E.tmeas[k], d.rin, m.ctrl, E.par, env, E.obs[k])


@compiled
def _tick(m: Model, d: Data, o: Output, w: Work) -> None:
    """``step.advance(1, ...)`` of one run with preallocated work space."""
    tick(m, d, o, w)
    if d.ls[LS_DONE] > 0.5:
        finish(d, o)


@allocating
def reset_slot(k: int, until_detection: bool, M: Model, D: Data, O: Output, E: Env) -> bool:
    """Start run ``k`` of the stacked records from its model and begin its episode.

    ``until_detection``: first run the built-in controller (its pre-impact
    behaviour) tick by tick until the detector has fired, so that the agent's
    first action is applied at the tick where the built-in law would start.
    Returns False if the run ended first (no detection): the episode is then
    not begun.
    """
    m = model_row(M, k)
    d = data_row(D, k)
    o = output_row(O, k)
    start(m, d, o)
    if until_detection:
        w = new_work(m.pairs.shape[0])
        while d.meas[MS_DETECTED] < 0.5:
            if d.ls[LS_DONE] > 0.5:
                E.state[k, B_ACTIVE] = 0.0
                return False
            _tick(m, d, o, w)
        if d.ls[LS_DONE] > 0.5:
            E.state[k, B_ACTIVE] = 0.0
            return False
    _begin_episode(k, m, d, E)
    return True


@compiled
def _outcome(m: Model, d: Data, o: Output, env: np.ndarray, par: np.ndarray, finite: bool) -> int:
    """``OC_*`` of a run after its tick: recovered and held, the ground, the envelope, its end."""
    stage = int(env[B_STAGE])
    outcome = OC_RUNNING
    if not finite:
        outcome = OC_FAILED
    elif (
        par[EP_END_ON_RECOVERY] > 0.5
        and stage >= STAGE_RECOVERED
        and env[B_HOLD] >= par[EP_HOLD_TICKS]
    ):
        outcome = OC_RECOVERED
    elif par[EP_GROUND] > 0.5 and not np.isnan(o.stats[ST_CRASH_T]):
        outcome = OC_GROUND
    else:
        outcome = envelope_outcome(d.x, env, par)
    if outcome == OC_RUNNING and d.ls[LS_DONE] > 0.5:
        outcome = OC_FAILED if o.stats[ST_STATUS] == STATUS_FAILED else OC_TIME_LIMIT
    return outcome


@compiled
def _step_one(k: int, actions: np.ndarray, m: Model, d: Data, o: Output, E: Env, w: Work) -> None:
    """One control tick of run ``k`` under its action; its reward, termination, observation."""
    veh = m.veh
    ctrl = m.ctrl
    par = E.par
    tmeas = E.tmeas[k]
    env = E.state[k]
    action_command(actions[k], tmeas, veh, ctrl, par, w.cmd)
    # the stage in force at this tick
    if E.reported[k] >= 0.0:
        env[B_STAGE] = E.reported[k]
        env[B_POLICY] = 1.0
    elif env[B_POLICY] < 0.5:
        env[B_STAGE] = takeover_stage(int(env[B_STAGE]), tmeas)
    d.mem[MEM_STAGE] = env[B_STAGE]
    d.ls[LS_EXT] = 1.0
    copy_into(d.ls[LS_EXT_CMD : LS_EXT_CMD + N_ROTORS], w.cmd)
    t_before = d.ls[LS_T]
    _tick(m, d, o, w)
    d.ls[LS_EXT] = 0.0
    tick_measurement(m, d, tmeas)
    env[B_STEPS] += 1.0
    r = -(d.ls[LS_T] - t_before) * cost_rate(d.x, d.rin, veh, ctrl, par, env[B_H_REF])
    # termination: recovered and held, the ground, the envelope; truncation: the run's end
    finite = all_finite(d.x)
    if finite:
        _track_windows(env, tmeas, d.x, ctrl, veh)
        if env[B_POLICY] < 0.5:
            _observe_stages(env, o.stats, d.mem, par)
    outcome = _outcome(m, d, o, env, par, finite)
    term = outcome != OC_RUNNING and outcome != OC_TIME_LIMIT and outcome != OC_FAILED
    if outcome == OC_RECOVERED:
        r += par[EP_W_RECOVERY]
    elif term:
        r -= par[EP_W_FAILURE]
        if par[EP_FAIL_REMAINING] > 0.5:
            r -= max_cost_rate(par) * max(d.ls[LS_TF] - d.ls[LS_T], 0.0)
    E.reward[k] = r
    env[B_RETURN] += r
    E.terminated[k] = term
    E.truncated[k] = outcome == OC_TIME_LIMIT or outcome == OC_FAILED
    observe(tmeas, d.rin, ctrl, par, env, E.obs[k])
    if outcome != OC_RUNNING:
        env[B_OUTCOME] = outcome
        env[B_ACTIVE] = 0.0
        finish(d, o)


@allocating
def step_batch(actions: np.ndarray, M: Model, D: Data, O: Output, E: Env) -> None:
    """One control tick of every active run under the actions ``actions`` (N, 4).

    ``E.reported`` (N,): the stage the policy reports for this tick (< 0:
    none; the observer's stage is used unless the policy has reported one this
    episode). Writes ``E.obs`` (N, n_obs), ``E.reward``, ``E.terminated`` and
    ``E.truncated`` (N,) of the active runs; a run that ends becomes inactive.
    """
    w = new_work(M.pairs.shape[1])
    for k in range(actions.shape[0]):
        if E.state[k, B_ACTIVE] < 0.5:
            continue
        _step_one(k, actions, model_row(M, k), data_row(D, k), output_row(O, k), E, w)


# ---------------------------------------------------------------- the built-in law as a policy
@compiled
def staged_policy(
    active: np.ndarray,
    M: Model,
    E: Env,
    pmem: np.ndarray,
    actions: np.ndarray,
    stages: np.ndarray,
) -> None:
    """The ``recovery`` controller as a policy: actions (N, 4) and stages (N,) of each active run.

    Runs ``recovery_step`` on the tick's measurement record (``E.tmeas``, the
    policy's observation of the state) with the policy's own memory ``pmem``
    (N, NMEM), then chooses the action whose map gives its command exactly when
    one exists (rotors), or its thrust and rate references (ctbr). Counts in
    ``E.state[:, B_INEXACT]`` the commands inside the slew window that the
    rotor map cannot give exactly.
    """
    staged_actions(active, E.tmeas, M, E.par, pmem, actions, stages, E.state[:, B_INEXACT])


@allocating
def staged_actions(
    active: np.ndarray,
    TMEAS: np.ndarray,
    M: Model,
    par: np.ndarray,
    pmem: np.ndarray,
    actions: np.ndarray,
    stages: np.ndarray,
    inexact: np.ndarray,
) -> None:
    """:func:`staged_policy` on given measurement records ``TMEAS`` (N, NMEAS).

    ``M`` gives each run's controller parameters, vehicle and options (the
    policy's own configuration); ``inexact`` (N,) counts the commands the
    rotor map cannot give exactly.
    """
    cmd = np.zeros(N_ROTORS)
    for k in range(TMEAS.shape[0]):
        if not active[k]:
            continue
        tmeas = TMEAS[k]
        ctrl = M.ctrl[k]
        veh = M.veh[k]
        opts = M.opts[k]
        mem = pmem[k]
        before = int(mem[MEM_STAGE])
        recovery_step(tmeas[MS_T], tmeas, ctrl, mem, veh, opts[O_DT_CONTROL], cmd)
        stage = int(mem[MEM_STAGE])
        stages[k] = stage
        if int(par[EP_ACTION]) == ACT_CTBR:
            if stage == STAGE_PRE_IMPACT:
                actions[k, 0] = -1.0
                for i in range(1, 4):
                    actions[k, i] = 0.0
                continue
            first = before == STAGE_PRE_IMPACT
            a_ref_on = not (first and ctrl[C_PARAMS + R_FIRST_TICK_LEVEL] > 0.5)
            x = tmeas[MS_X : MS_X + NX]
            thrust, p_des, q_des, r_des, _, _ = law_references(
                stage, a_ref_on, x, tmeas[MS_NORMAL : MS_NORMAL + 3], ctrl, veh, mem
            )
            actions[k, 0], _ = affine_inverse(thrust, 0.0, max_thrust(veh, ctrl))
            actions[k, 1] = min(max(p_des / par[EP_RATE_MAX], -1.0), 1.0)
            actions[k, 2] = min(max(q_des / par[EP_RATE_MAX + 1], -1.0), 1.0)
            actions[k, 3] = min(max(r_des / par[EP_RATE_MAX + 2], -1.0), 1.0)
            continue
        lo, hi = rotor_range(ctrl, par)
        slew = opts[O_SLEW_MAX] * opts[O_DT_CONTROL]
        for j in range(N_ROTORS):
            a, exact = affine_inverse(cmd[j], lo, hi)
            actions[k, j] = a
            prev = tmeas[MS_X + X_ROTOR + j]
            if not exact and (slew <= 0.0 or abs(cmd[j] - prev) <= slew):
                inexact[k] += 1.0
