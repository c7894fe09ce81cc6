"""A run, one control tick at a time: the pipeline of every tick.

Per control tick ``t_k = t0 + k dt`` (``dt = opts[O_DT_CONTROL]``, 5 ms),
:func:`tick` chains the stages, each a small function:

1. the end of the run and the crash test at the tick (the replica's rules,
   from the first tick after the start); the quaternion renormalised;
2. estimation: the state estimate into the measurement record
   (``estimators``; the IMU samples up to and including ``t_k`` are already in
   it, taken and filtered by the sensor stage ``sensors/stage.py`` during the
   last interval); the hover tests on the true state (``hover_tracking.py``);
3. the controller (``controllers/``), or an external command set in
   ``ls[LS_EXT_CMD]`` (from Python, a learning agent...); its stage is recorded;
4. actuators: limits, slew, the rotor inputs of the interval, then the
   one-tick motor cut of the authors' crash runs (``actuators.py``);
5. integration to ``t_{k+1}`` with located events, output rows, IMU samples
   and episode peaks (``interval.py``).

Everything that survives from one tick to the next is in the run's records
(``records.py``): the constant :class:`Model` ``m``, the carried :class:`Data`
``d`` and the :class:`Output` ``o`` (counters are live in ``o.stats``, so a
run stopped after any tick can be read). :func:`start` initialises ``d`` and
``o``, :func:`advance` runs ``n`` ticks (or to the end) and :func:`finish`
closes the open episodes; ``kernel.run`` is ``start`` + ``advance`` to the end.
A run advanced tick by tick is the same computation as one advanced all at
once, bit for bit.
"""

import math

import numpy as np

from quadimpact.core.actuators import apply_command, cut_step
from quadimpact.core.compiled import allocating, compiled
from quadimpact.core.contact_slots import CS_ACTIVE, CS_EPISODE, CS_LAMBDA
from quadimpact.core.controller_slots import C_KIND, C_PHI_REF, C_PSI_REF, C_STEP, C_THETA_REF
from quadimpact.core.controllers import builtin_step
from quadimpact.core.estimators import at_tick, init_estimate
from quadimpact.core.excursion import excursion_start
from quadimpact.core.excursion_slots import NEX
from quadimpact.core.hover_tracking import start_hover_tracking, track_held_hover, track_hover
from quadimpact.core.interval import FAILED, RUNNING, contact_values, integrate_interval
from quadimpact.core.layout import (
    CRASH_PAPER_TICKS,
    CTRL_USER,
    LS_DONE,
    LS_EXT,
    LS_EXT_CMD,
    LS_H,
    LS_K,
    LS_PO_ACTIVE,
    LS_PO_T,
    LS_STAGE,
    LS_T,
    LS_T0,
    LS_T_SCHED,
    LS_TF,
    MEM_STAGE,
    N_STAGES,
    O_CRASH_ALTITUDE,
    O_CRASH_RULE,
    O_DT_CONTROL,
    O_END_AFTER_RECOVERY,
    O_H_MAX,
    O_POWER_OFF_T,
    O_ROTOR_MODE,
    ROTOR_FIRST_ORDER,
    SPAN_T0,
    SPAN_TF,
    ST_CRASH_T,
    ST_EXCURSION,
    ST_IMPACT_T,
    ST_LAST_ONSET_T,
    ST_MAX_DELTA,
    ST_MIN_ALT,
    ST_MIN_TILT_COS,
    ST_N_EPISODES,
    ST_N_OUT,
    ST_N_TICKS,
    ST_ONSET_T,
    ST_POWER_OFF_T,
    ST_STAGE_T,
    ST_STAGE_X,
    ST_STATUS,
    ST_T_DETECT,
    ST_T_END,
    STATUS_COMPLETED,
    STATUS_CRASHED,
    STATUS_FAILED,
    X_POS,
    X_QUAT,
    X_ROTOR,
)
from quadimpact.core.plugin_call import call_controller
from quadimpact.core.quaternion import normalise_quaternion
from quadimpact.core.recording import record_crash, write_sample
from quadimpact.core.recording_slots import E_OPEN, E_PEAK_DELTA, E_T_END
from quadimpact.core.records import Data, Model, Output, Work, new_work
from quadimpact.core.rotors import RIN_CMD, RIN_FIRST_ORDER, RIN_PREV_CMD
from quadimpact.core.sensing import sample_at
from quadimpact.core.sensors.imu_slots import (
    SC_RATE,
    SS_NEXT_T,
)
from quadimpact.core.sensors.measurement_slots import MS_IMU_T, MS_T_DETECT
from quadimpact.core.vehicle_slots import V_N_ROTORS

STAGE_RECOVERED = 4  # controllers/recovery.py's stage 4
controller_step = builtin_step  # rebound by kernel.make_kernel(step=...) (a loop of its own)


@allocating
def start(m: Model, d: Data, o: Output) -> None:
    """Initialise ``d`` and ``o`` for the run ``m`` from ``(t0, x0)``.

    Writes the output rows and the IMU sample at ``t0``.
    """
    t0 = m.span[SPAN_T0]
    x = d.x
    x[:] = m.x0
    stats = o.stats
    stats[:] = 0.0
    for i in (ST_CRASH_T, ST_ONSET_T, ST_POWER_OFF_T, ST_T_DETECT):
        stats[i] = np.nan
    for i in (ST_IMPACT_T, ST_LAST_ONSET_T):
        stats[i] = np.nan
    start_hover_tracking(stats)
    stats[ST_STAGE_T : ST_STAGE_T + N_STAGES] = np.nan
    stats[ST_T_END] = t0
    stats[ST_MIN_ALT] = -x[X_POS + 2]
    stats[ST_MIN_TILT_COS] = 1.0
    excursion_start(
        m.ctrl[C_PHI_REF], m.ctrl[C_THETA_REF], m.ctrl[C_PSI_REF],
        stats[ST_EXCURSION : ST_EXCURSION + NEX],
    )  # fmt: skip
    dt_c = m.opts[O_DT_CONTROL]
    h_max = m.opts[O_H_MAX] if m.opts[O_H_MAX] > 0.0 else dt_c
    ls = d.ls
    ls[:] = 0.0
    ls[LS_T] = t0
    ls[LS_T0] = t0
    ls[LS_TF] = m.span[SPAN_TF]
    ls[LS_H] = 0.1 * min(h_max, dt_c)
    ls[LS_PO_T] = math.inf
    ls[LS_T_SCHED] = math.inf
    if m.opts[O_POWER_OFF_T] >= 0.0:
        ls[LS_T_SCHED] = max(m.opts[O_POWER_OFF_T], t0)
    d.rin[:] = 0.0
    for j in range(int(m.veh[V_N_ROTORS])):
        d.rin[RIN_CMD + j] = x[X_ROTOR + j]
        d.rin[RIN_PREV_CMD + j] = x[X_ROTOR + j]
    d.rin[RIN_FIRST_ORDER] = 1.0 if int(m.opts[O_ROTOR_MODE]) == ROTOR_FIRST_ORDER else 0.0
    d.cs[:, CS_ACTIVE] = 0.0
    d.cs[:, CS_LAMBDA] = 0.0
    d.cs[:, CS_EPISODE] = -1.0
    d.mem[:] = 0.0
    d.meas[:] = 0.0
    d.meas[MS_IMU_T] = np.nan
    d.meas[MS_T_DETECT] = np.nan
    init_estimate(m, d)
    at_tick(t0, m, d)
    d.sst[:] = 0.0
    d.sst[SS_NEXT_T] = t0 if m.scfg[SC_RATE] > 0.0 else math.inf
    w = new_work(m.pairs.shape[0])
    i_out = 0
    while i_out < m.t_out.shape[0] and m.t_out[i_out] <= t0:
        write_sample(i_out, m.t_out[i_out], x, m, d, o, w)
        i_out += 1
    stats[ST_N_OUT] = i_out
    if d.sst[SS_NEXT_T] <= t0:
        sample_at(t0, x, m, d, o, w)


@compiled
def _crash_at_tick(t: float, m: Model, d: Data, o: Output) -> bool:
    """The replica's crash rules: ``h <= level`` tested at the control ticks after the start.

    The start tick is not tested: a run may start on the ground (the authors'
    crash run of I-11 starts at altitude 0).
    """
    if int(m.opts[O_CRASH_RULE]) != CRASH_PAPER_TICKS or d.ls[LS_K] < 0.5:
        return False
    if not -d.x[X_POS + 2] <= m.opts[O_CRASH_ALTITUDE]:
        return False
    record_crash(t, d.x, o.stats)
    return True


@compiled
def _ended_after_recovery(t: float, m: Model, o: Output) -> bool:
    """Whether the run ends at the tick ``t`` (s): ``O_END_AFTER_RECOVERY`` after stage 4."""
    delay = m.opts[O_END_AFTER_RECOVERY]
    if not delay > 0.0:
        return False
    t4 = o.stats[ST_STAGE_T + STAGE_RECOVERED]
    return not np.isnan(t4) and t >= t4 + delay - 1e-9


@compiled
def _command(t: float, m: Model, d: Data, o: Output, w: Work) -> None:
    """The tick's rotor command into ``w.cmd``: the controller's, or the external one.

    Records the controller's stage and the tick of each stage's first entry.
    """
    ls = d.ls
    if ls[LS_EXT] > 0.5:
        for j in range(int(m.veh[V_N_ROTORS])):
            w.cmd[j] = ls[LS_EXT_CMD + j]
        ls[LS_EXT] = 0.0
    elif int(m.ctrl[C_KIND]) == CTRL_USER and m.ctrl[C_STEP] != 0.0:  # a plug-in, by address
        call_controller(
            np.int64(m.ctrl[C_STEP]), t, d.meas, m.ctrl, d.mem, m.veh, m.opts[O_DT_CONTROL], w.cmd
        )
    else:
        controller_step(t, d.meas, m.ctrl, d.mem, m.veh, m.opts[O_DT_CONTROL], w.cmd)
    stats = o.stats
    stats[ST_N_TICKS] += 1.0
    stage = d.mem[MEM_STAGE]
    ls[LS_STAGE] = stage
    si = int(stage)
    if 0 <= si < N_STAGES and np.isnan(stats[ST_STAGE_T + si]):
        stats[ST_STAGE_T + si] = t
        for i in range(3):
            stats[ST_STAGE_X + 3 * si + i] = d.x[X_POS + i]


@compiled
def tick(m: Model, d: Data, o: Output, w: Work) -> None:
    """One control tick and the interval after it (``w``: work space)."""
    ls = d.ls
    dt_c = m.opts[O_DT_CONTROL]
    k = int(ls[LS_K])
    t0 = ls[LS_T0]
    tf = ls[LS_TF]
    t_k = t0 + k * dt_c
    if t_k >= tf - 1e-12 * max(1.0, abs(tf)):
        ls[LS_DONE] = 1.0
        return
    t_next = min(t0 + (k + 1) * dt_c, tf)
    normalise_quaternion(d.x, X_QUAT)
    if _ended_after_recovery(t_k, m, o):
        ls[LS_DONE] = 1.0
        return
    if _crash_at_tick(t_k, m, d, o):
        ls[LS_DONE] = 1.0
        return
    at_tick(t_k, m, d)
    track_hover(t_k, d.x, o.stats)
    track_held_hover(t_k, d.x, d.cs, o.stats)
    _command(t_k, m, d, o, w)
    apply_command(w.cmd, d.x, d.rin, m.opts, dt_c, ls[LS_PO_ACTIVE] > 0.5, int(m.veh[V_N_ROTORS]))
    cut_step(m, d)
    contact_values(d.x, m, d, w, w.g_a, w.gd_a, w.bnd_a)
    result = integrate_interval(t_k, t_next, m, d, o, w)
    if result == FAILED:
        ls[LS_DONE] = 1.0
        return
    ls[LS_K] = k + 1
    if result != RUNNING:
        ls[LS_DONE] = 1.0


@compiled
def finish(d: Data, o: Output) -> None:
    """Close the episodes still open at the time reached; deepest penetration of the run.

    Idempotent, and harmless before the end: an episode closed here is
    reopened in effect by the loop (its end is overwritten when it ends).
    """
    stats = o.stats
    episodes = o.episodes
    for e in range(int(stats[ST_N_EPISODES])):
        if episodes[e, E_PEAK_DELTA] > stats[ST_MAX_DELTA]:
            stats[ST_MAX_DELTA] = episodes[e, E_PEAK_DELTA]
    for c in range(d.cs.shape[0]):
        e = int(d.cs[c, CS_EPISODE])
        if e >= 0:
            episodes[e, E_T_END] = d.ls[LS_T]
            episodes[e, E_OPEN] = 1.0
    if stats[ST_STATUS] != STATUS_FAILED and not np.isnan(stats[ST_CRASH_T]):
        stats[ST_STATUS] = STATUS_CRASHED
    elif stats[ST_STATUS] != STATUS_FAILED:
        stats[ST_STATUS] = STATUS_COMPLETED


@allocating
def advance(n_ticks: int, m: Model, d: Data, o: Output) -> int:
    """Run up to ``n_ticks`` control ticks (``n_ticks < 0``: to the end); return the ticks run.

    ``d`` and ``o`` were initialised by :func:`start`. When the run ends
    (``d.ls[LS_DONE]``), :func:`finish` has been applied.
    """
    w = new_work(m.pairs.shape[0])
    n = 0
    while d.ls[LS_DONE] < 0.5 and (n_ticks < 0 or n < n_ticks):
        k = d.ls[LS_K]
        tick(m, d, o, w)
        if d.ls[LS_K] != k:
            n += 1
    if d.ls[LS_DONE] > 0.5:
        finish(d, o)
    return n
