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

The environments' record and slots (``env_layout``), the action maps
(``env_actions``), the observations (``env_observation``) and the reward and
envelope (``env_reward``) have modules of their own; their names are
re-exported here (``batch.B_OUTCOME``, ``batch.observe``...).

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

import numpy as np

from quadimpact.core.compiled import allocating, compiled
from quadimpact.core.controller_slots import C_PARAMS
from quadimpact.core.controllers.recovery import (
    R_FIRST_TICK_LEVEL,
    R_Q_TOL,
    R_RATE_TOL,
    R_W_TOL,
    law_references,
    recovery_step,
    staged_references,
)
from quadimpact.core.envs.actions import (
    action_command,
    affine_inverse,
    affine_map,
    max_thrust,
    rotor_range,
)
from quadimpact.core.envs.episode_layout import (
    ACT_CTBR,
    ACT_ROTORS,
    B_ACTIVE,
    B_H_REF,
    B_HOLD,
    B_HOLD_P,
    B_HOLD_T,
    B_INEXACT,
    B_LEVEL_N,
    B_LEVEL_P,
    B_LEVEL_T,
    B_OUTCOME,
    B_POLICY,
    B_RETURN,
    B_STAGE,
    B_STEPS,
    B_X_REF,
    B_Y_REF,
    ENV_ROTORS,
    EP_ACTION,
    EP_END_ON_RECOVERY,
    EP_FAIL_REMAINING,
    EP_GROUND,
    EP_HOLD_TICKS,
    EP_MAX_DIST,
    EP_MAX_DROP,
    EP_MAX_RATE,
    EP_MAX_TILT_COS,
    EP_OBS_CLIP,
    EP_OBS_F,
    EP_OBS_POS,
    EP_OBS_T,
    EP_OBS_V,
    EP_OBS_W,
    EP_OBSERVE,
    EP_RATE_MAX,
    EP_S_HEIGHT,
    EP_S_RATE,
    EP_S_VZ,
    EP_W_EFFORT,
    EP_W_FAILURE,
    EP_W_HEIGHT,
    EP_W_RATE,
    EP_W_RECOVERY,
    EP_W_TILT,
    EP_W_VZ,
    EP_ZERO_LOW,
    N_OBS_ESTIMATE,
    N_OBS_IMU,
    N_OBS_STATE,
    NB,
    NPAR,
    OBS_EST_BIAS,
    OBS_EST_F,
    OBS_EST_POS,
    OBS_EST_RATE,
    OBS_EST_ROTOR,
    OBS_EST_VEL,
    OBS_ESTIMATE,
    OBS_IMU,
    OBS_STATE,
    OC_ALTITUDE,
    OC_DISTANCE,
    OC_FAILED,
    OC_GROUND,
    OC_RATE,
    OC_RECOVERED,
    OC_RUNNING,
    OC_TILT,
    OC_TIME_LIMIT,
    Env,
    n_observations,
)
from quadimpact.core.envs.observation import (
    measurement_from_estimate,
    observe,
    observe_estimate,
    tick_measurement,
)
from quadimpact.core.envs.reward import (
    cost_rate,
    envelope_outcome,
    max_cost_rate,
)
from quadimpact.core.integrator import all_finite, copy_into
from quadimpact.core.layout import (
    LS_DONE,
    LS_EXT,
    LS_EXT_CMD,
    LS_T,
    LS_TF,
    MAX_ROTORS,
    MEM_STAGE,
    NX,
    O_DT_CONTROL,
    O_SLEW_MAX,
    ST_CRASH_T,
    ST_STAGE_T,
    ST_STAGE_X,
    ST_STATUS,
    STAGE_DETECTED,
    STAGE_PRE_IMPACT,
    STAGE_RECOVERED,
    STAGE_TILTED,
    STATUS_FAILED,
    X_POS,
    X_ROTOR,
    X_VEL,
)
from quadimpact.core.records import (
    Data,
    Model,
    Output,
    Work,
    data_row,
    model_row,
    new_work,
    output_row,
)
from quadimpact.core.sensors.measurement_slots import MS_DETECTED, MS_NORMAL, MS_T, MS_W_HAT, MS_X
from quadimpact.core.step import finish, start, tick

__all__ = [
    "ACT_CTBR",
    "ACT_ROTORS",
    "B_ACTIVE",
    "B_HOLD",
    "B_HOLD_P",
    "B_HOLD_T",
    "B_H_REF",
    "B_INEXACT",
    "B_LEVEL_N",
    "B_LEVEL_P",
    "B_LEVEL_T",
    "B_OUTCOME",
    "B_POLICY",
    "B_RETURN",
    "B_STAGE",
    "B_STEPS",
    "B_X_REF",
    "B_Y_REF",
    "EP_ACTION",
    "EP_END_ON_RECOVERY",
    "EP_FAIL_REMAINING",
    "EP_GROUND",
    "EP_HOLD_TICKS",
    "EP_MAX_DIST",
    "EP_MAX_DROP",
    "EP_MAX_RATE",
    "EP_MAX_TILT_COS",
    "EP_OBSERVE",
    "EP_OBS_CLIP",
    "EP_OBS_F",
    "EP_OBS_POS",
    "EP_OBS_T",
    "EP_OBS_V",
    "EP_OBS_W",
    "EP_RATE_MAX",
    "EP_S_HEIGHT",
    "EP_S_RATE",
    "EP_S_VZ",
    "EP_W_EFFORT",
    "EP_W_FAILURE",
    "EP_W_HEIGHT",
    "EP_W_RATE",
    "EP_W_RECOVERY",
    "EP_W_TILT",
    "EP_W_VZ",
    "EP_ZERO_LOW",
    "Env",
    "NB",
    "NPAR",
    "N_OBS_ESTIMATE",
    "N_OBS_IMU",
    "N_OBS_STATE",
    "OBS_ESTIMATE",
    "OBS_EST_BIAS",
    "OBS_EST_F",
    "OBS_EST_POS",
    "OBS_EST_RATE",
    "OBS_EST_ROTOR",
    "OBS_EST_VEL",
    "OBS_IMU",
    "OBS_STATE",
    "OC_ALTITUDE",
    "OC_DISTANCE",
    "OC_FAILED",
    "OC_GROUND",
    "OC_RATE",
    "OC_RECOVERED",
    "OC_RUNNING",
    "OC_TILT",
    "OC_TIME_LIMIT",
    "action_command",
    "affine_inverse",
    "affine_map",
    "cost_rate",
    "envelope_outcome",
    "level_and_recovered",
    "level_test",
    "max_cost_rate",
    "max_thrust",
    "measurement_from_estimate",
    "n_observations",
    "observe",
    "observe_estimate",
    "recovered_condition",
    "reset_slot",
    "rotor_range",
    "staged_actions",
    "staged_policy",
    "step_batch",
    "takeover_stage",
    "tick_measurement",
]


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
    copy_into(d.ls[LS_EXT_CMD : LS_EXT_CMD + MAX_ROTORS], w.cmd)
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
    cmd = np.zeros(MAX_ROTORS)
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
        for j in range(ENV_ROTORS):
            a, exact = affine_inverse(cmd[j], lo, hi)
            actions[k, j] = a
            prev = tmeas[MS_X + X_ROTOR + j]
            if not exact and (slew <= 0.0 or abs(cmd[j] - prev) <= slew):
                inexact[k] += 1.0
