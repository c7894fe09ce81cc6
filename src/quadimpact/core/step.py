"""Advance a run one control interval at a time; all loop state lives in arrays.

A run is a chain of stages at every control tick ``t_k = t0 + k dt``
(``dt = opts[O_DT_CONTROL]``, 5 ms):

1. crash test at the tick (the paper replica's rule), quaternion renormalised;
2. sensors: the measurement record (``sensors/record.py``; the IMU samples up
   to and including ``t_k`` are already in it);
3. controller (``controllers/``), or an external command set in
   ``ls[LS_EXT_CMD]`` (from Python, a learning agent...); its stage is recorded;
4. actuators: limits, slew, rotor inputs of the interval (``actuators.py``);
5. Dormand-Prince 5(4) steps to ``t_{k+1}`` (restarted at the tick: the inputs
   jump). After each accepted step the event functions (the contact gap of
   every bumper-surface pair, and the altitude for the crash) are checked at
   its end, and inside it for contacts within reach; the earliest onset, end
   or crash is located on the dense output, the step is cut there, every pair
   is re-examined at that instant (simultaneous onsets: at psi = 0 bumpers 1
   and 4 start together), ``v_i`` is captured, and integration restarts from
   the cut. Output rows and IMU samples falling inside the step are written
   from the dense output; episode peaks are tracked (the deflection at the
   located zero of ``delta_dot``, the force at step ends and mid-steps).

Everything that survives from one tick to the next is in the caller's arrays:

* ``x`` (NX) the state; ``ls`` (NLS) loop scalars (time, tick, step size,
  power-off schedule, stage, external command); ``cs`` (4 n_surf, NCS) the
  contact pairs; ``rin`` (NRIN) rotor inputs; ``mem`` (NMEM) controller
  memory; ``meas`` (NMEAS) the measurement record; ``sst`` (NSST) sensor state;
* outputs ``out``, ``imu_out``, ``episodes`` and ``stats`` (counters are live
  in ``stats``, so a run stopped after any tick can be read).

:func:`start` initialises them, :func:`advance` runs ``n`` ticks (or to the end)
and :func:`finish` closes the open episodes; ``run.run_builtin`` is
``start`` + ``advance`` to the end. A run advanced tick by tick is the same
computation as one advanced all at once, bit for bit.
"""

import math

import numpy as np
from numba import njit

from .actuators import apply_command, apply_segment, cut_step, next_boundary, segment_at
from .contact import bumper_force, contact_gap, damping_coefficient
from .controllers import builtin_step
from .dynamics import state_derivative
from .events import EV_ALTITUDE, EV_RATE, NO_EVENT, contact_event, locate
from .geometry import bumper_depth
from .integrator import dense_coefficients, dense_eval, error_norm, stage_state, step_factor
from .layout import (
    CRASH_CM_GROUND,
    CRASH_PAPER_TICKS,
    CS_ACTIVE,
    CS_EPISODE,
    CS_LAMBDA,
    E_BUMPER,
    E_OPEN,
    E_PEAK_DELTA,
    E_PEAK_FORCE,
    E_SURFACE,
    E_T_END,
    E_T_PEAK,
    E_T_PEAK_FORCE,
    E_T_START,
    E_V_I,
    LS_DONE,
    LS_EXT,
    LS_EXT_CMD,
    LS_H,
    LS_K,
    LS_PO_ACTIVE,
    LS_PO_SEG,
    LS_PO_T,
    LS_STAGE,
    LS_T,
    LS_T0,
    LS_T_SCHED,
    LS_TF,
    MEM_STAGE,
    MS_DETECTED,
    MS_IMU_T,
    MS_T_DETECT,
    N_STAGES,
    NX,
    O_ATOL,
    O_CRASH_ALTITUDE,
    O_CRASH_RULE,
    O_DT_CONTROL,
    O_EVENT_TOL,
    O_H_MAX,
    O_MAX_STEPS,
    O_POWER_OFF_T,
    O_ROTOR_MODE,
    O_RTOL,
    O_STOP_ON_CRASH,
    O_V_MIN,
    OUT_CMD,
    OUT_DELTA,
    OUT_FORCE,
    OUT_STAGE,
    OUT_T,
    OUT_X,
    REASON_MAX_STEPS,
    REASON_NOT_FINITE,
    REASON_STEP_TOO_SMALL,
    RIN_CMD,
    RIN_FIRST_ORDER,
    RIN_PREV_CMD,
    ROTOR_FIRST_ORDER,
    S_IS_GROUND,
    SC_RATE,
    SS_N,
    SS_NEXT_T,
    ST_CRASH_T,
    ST_CRASH_X,
    ST_EPISODES_DROPPED,
    ST_MAX_DELTA,
    ST_MAX_RATE,
    ST_MIN_ALT,
    ST_MIN_TILT_COS,
    ST_MISSED_ONSETS,
    ST_N_EPISODES,
    ST_N_OUT,
    ST_N_REJECTED,
    ST_N_RHS,
    ST_N_STEPS,
    ST_N_TICKS,
    ST_ONSET_T,
    ST_ONSET_X,
    ST_POWER_OFF_T,
    ST_REASON,
    ST_STAGE_T,
    ST_STAGE_X,
    ST_STATUS,
    ST_T_DETECT,
    ST_T_END,
    STATUS_COMPLETED,
    STATUS_CRASHED,
    STATUS_FAILED,
    X_OMEGA,
    X_POS,
    X_QUAT,
    X_ROTOR,
)
from .quaternion import normalise_quaternion, rotation_matrix
from .sensors.detection import detect
from .sensors.imu import imu_sample
from .sensors.record import observe_state

MISSED_ONSET_DEPTH = 1e-9  # m; deeper first sightings count as missed onsets

controller_step = builtin_step  # rebound by run.make_kernel for plug-in controllers


@njit(cache=True)
def _contact_values(
    x: np.ndarray,
    C: np.ndarray,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    g: np.ndarray,
    gd: np.ndarray,
) -> None:
    """Contact gap ``g`` and penetration rate ``gd`` of every bumper-surface pair at ``x``."""
    rotation_matrix(x[X_QUAT : X_QUAT + 4], C)
    for c in range(g.shape[0]):
        d, dd = bumper_depth(x, C, veh, c % 4, surf, c // 4)
        g[c] = contact_gap(x, d, surf, c // 4, opts)
        gd[c] = dd


@njit(cache=True)
def _write_sample(
    row: int,
    t: float,
    xs: np.ndarray,
    C: np.ndarray,
    veh: np.ndarray,
    surf: np.ndarray,
    cs: np.ndarray,
    rin: np.ndarray,
    stage: float,
    out: np.ndarray,
    opts: np.ndarray,
) -> None:
    """One output row: time, state, per-bumper deflection and force, command, stage."""
    out[row, OUT_T] = t
    for i in range(NX):
        out[row, OUT_X + i] = xs[i]
    rotation_matrix(xs[X_QUAT : X_QUAT + 4], C)
    for j in range(4):
        out[row, OUT_DELTA + j] = 0.0
        out[row, OUT_FORCE + j] = 0.0
        out[row, OUT_CMD + j] = rin[RIN_CMD + j]
    out[row, OUT_STAGE] = stage
    for c in range(cs.shape[0]):
        j = c % 4
        d, dd = bumper_depth(xs, C, veh, j, surf, c // 4)
        if d > out[row, OUT_DELTA + j]:
            out[row, OUT_DELTA + j] = d
        if cs[c, CS_ACTIVE] > 0.5:
            out[row, OUT_FORCE + j] += bumper_force(veh, opts, j, d, dd, cs[c, CS_LAMBDA])


@njit(cache=True)
def _track_peak(episodes: np.ndarray, e: int, t: float, d: float, f: float) -> None:
    """Update an episode's peak deflection and peak force with a new observation."""
    if e < 0:
        return
    if d > episodes[e, E_PEAK_DELTA]:
        episodes[e, E_PEAK_DELTA] = d
        episodes[e, E_T_PEAK] = t
    if f > episodes[e, E_PEAK_FORCE]:
        episodes[e, E_PEAK_FORCE] = f
        episodes[e, E_T_PEAK_FORCE] = t


@njit(cache=True)
def _observe(
    episodes: np.ndarray,
    e: int,
    c: int,
    sigma: float,
    t_old: float,
    h: float,
    x_old: np.ndarray,
    Q: np.ndarray,
    xs: np.ndarray,
    C: np.ndarray,
    veh: np.ndarray,
    surf: np.ndarray,
    lam: float,
    opts: np.ndarray,
) -> float:
    """Track episode ``e``'s peaks with pair ``c`` at ``t_old + sigma h`` (dense output).

    Returns the penetration rate there.
    """
    dense_eval(x_old, Q, h, sigma, xs)
    rotation_matrix(xs[X_QUAT : X_QUAT + 4], C)
    d, dd = bumper_depth(xs, C, veh, c % 4, surf, c // 4)
    _track_peak(episodes, e, t_old + sigma * h, d, bumper_force(veh, opts, c % 4, d, dd, lam))
    return dd


@njit(cache=True)
def _sample_imu(
    t: float,
    xs: np.ndarray,
    xd: np.ndarray,
    C: np.ndarray,
    wdot: np.ndarray,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    rin: np.ndarray,
    cs: np.ndarray,
    scfg: np.ndarray,
    sst: np.ndarray,
    noise: np.ndarray,
    meas: np.ndarray,
    imu_out: np.ndarray,
    stats: np.ndarray,
    t0: float,
) -> None:
    """IMU sample and detection at ``t`` from the state ``xs`` (inputs of the interval)."""
    state_derivative(xs, xd, veh, surf, opts, rin, cs, C, wdot)
    # (not counted in ST_N_RHS: that is the integrator's own count)
    imu_sample(t, xs, xd, C, veh, scfg, sst, noise, meas, imu_out, stats)
    detect(t, xs, C, veh, scfg, sst, meas, imu_out, stats)
    sst[SS_NEXT_T] = t0 + sst[SS_N] / scfg[SC_RATE]


@njit(cache=True)
def start(
    x: np.ndarray,
    t0: float,
    tf: float,
    ls: np.ndarray,
    cs: np.ndarray,
    rin: np.ndarray,
    mem: np.ndarray,
    meas: np.ndarray,
    sst: np.ndarray,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    scfg: np.ndarray,
    noise: np.ndarray,
    t_out: np.ndarray,
    out: np.ndarray,
    imu_out: np.ndarray,
    stats: np.ndarray,
) -> None:
    """Initialise the loop state for a run from ``(t0, x)`` to ``tf`` (s).

    ``x`` holds the initial state (it becomes the running state). Writes the
    output rows and the IMU sample at ``t0``.
    """
    for i in range(stats.shape[0]):
        stats[i] = 0.0
    stats[ST_CRASH_T] = np.nan
    stats[ST_ONSET_T] = np.nan
    stats[ST_POWER_OFF_T] = np.nan
    stats[ST_T_DETECT] = np.nan
    for s in range(N_STAGES):
        stats[ST_STAGE_T + s] = np.nan
    stats[ST_T_END] = t0
    stats[ST_MIN_ALT] = -x[X_POS + 2]
    stats[ST_MIN_TILT_COS] = 1.0
    dt_c = opts[O_DT_CONTROL]
    h_max = opts[O_H_MAX] if opts[O_H_MAX] > 0.0 else dt_c
    for i in range(ls.shape[0]):
        ls[i] = 0.0
    ls[LS_T] = t0
    ls[LS_T0] = t0
    ls[LS_TF] = tf
    ls[LS_H] = 0.1 * min(h_max, dt_c)
    ls[LS_PO_T] = math.inf
    ls[LS_T_SCHED] = math.inf
    if opts[O_POWER_OFF_T] >= 0.0:
        ls[LS_T_SCHED] = max(opts[O_POWER_OFF_T], t0)
    for i in range(rin.shape[0]):
        rin[i] = 0.0
    for j in range(4):
        rin[RIN_CMD + j] = x[X_ROTOR + j]
        rin[RIN_PREV_CMD + j] = x[X_ROTOR + j]
    rin[RIN_FIRST_ORDER] = 1.0 if int(opts[O_ROTOR_MODE]) == ROTOR_FIRST_ORDER else 0.0
    for c in range(cs.shape[0]):
        cs[c, CS_ACTIVE] = 0.0
        cs[c, CS_LAMBDA] = 0.0
        cs[c, CS_EPISODE] = -1.0
    for i in range(mem.shape[0]):
        mem[i] = 0.0
    for i in range(meas.shape[0]):
        meas[i] = 0.0
    meas[MS_IMU_T] = np.nan
    meas[MS_T_DETECT] = np.nan
    observe_state(t0, x, meas)
    for i in range(sst.shape[0]):
        sst[i] = 0.0
    sst[SS_NEXT_T] = t0 if scfg[SC_RATE] > 0.0 else math.inf
    C = np.zeros((3, 3))
    i_out = 0
    while i_out < t_out.shape[0] and t_out[i_out] <= t0:
        _write_sample(i_out, t_out[i_out], x, C, veh, surf, cs, rin, 0.0, out, opts)
        i_out += 1
    stats[ST_N_OUT] = i_out
    if sst[SS_NEXT_T] <= t0:
        _sample_imu(t0, x, np.empty(x.shape[0]), C, np.zeros(4), veh, surf, opts, rin, cs,
                    scfg, sst, noise, meas, imu_out, stats, t0)  # fmt: skip


@njit(cache=True)
def _open_episode(
    c: int, t: float, x: np.ndarray, C: np.ndarray, veh: np.ndarray, surf: np.ndarray,
    gd: float, v_min: float, cs: np.ndarray, episodes: np.ndarray, stats: np.ndarray,
) -> None:  # fmt: skip
    """Contact onset of pair ``c`` at ``t``: fix its damping, open an episode row."""
    cs[c, CS_ACTIVE] = 1.0
    cs[c, CS_LAMBDA] = damping_coefficient(veh, gd, v_min)
    n_ep = int(stats[ST_N_EPISODES])
    if n_ep < episodes.shape[0]:
        rotation_matrix(x[X_QUAT : X_QUAT + 4], C)
        d, _ = bumper_depth(x, C, veh, c % 4, surf, c // 4)
        e = n_ep
        episodes[e, E_BUMPER] = c % 4
        episodes[e, E_SURFACE] = c // 4
        episodes[e, E_T_START] = t
        episodes[e, E_T_END] = np.nan
        episodes[e, E_V_I] = gd
        episodes[e, E_PEAK_DELTA] = max(d, 0.0)
        episodes[e, E_T_PEAK] = t
        episodes[e, E_PEAK_FORCE] = 0.0
        episodes[e, E_T_PEAK_FORCE] = t
        episodes[e, E_OPEN] = 1.0
        cs[c, CS_EPISODE] = e
        stats[ST_N_EPISODES] = n_ep + 1
    else:
        cs[c, CS_EPISODE] = -1.0
        stats[ST_EPISODES_DROPPED] += 1.0


@njit(cache=True)
def _track_extremes(x: np.ndarray, detected: bool, stats: np.ndarray) -> None:
    """Lowest altitude; after detection the largest tilt and rate (exact at step ends)."""
    alt = -x[X_POS + 2]
    if alt < stats[ST_MIN_ALT]:
        stats[ST_MIN_ALT] = alt
    if detected:
        q1 = x[X_QUAT + 1]
        q2 = x[X_QUAT + 2]
        n2 = x[X_QUAT] ** 2 + q1 * q1 + q2 * q2 + x[X_QUAT + 3] ** 2
        c22 = 1.0 - 2.0 * (q1 * q1 + q2 * q2) / n2  # cos of the body z axis from vertical
        if c22 < stats[ST_MIN_TILT_COS]:
            stats[ST_MIN_TILT_COS] = c22
        w = math.sqrt(x[X_OMEGA] ** 2 + x[X_OMEGA + 1] ** 2 + x[X_OMEGA + 2] ** 2)
        if w > stats[ST_MAX_RATE]:
            stats[ST_MAX_RATE] = w


@njit(cache=True)
def _record_crash(t: float, x: np.ndarray, stats: np.ndarray) -> None:
    stats[ST_CRASH_T] = t
    for i in range(3):
        stats[ST_CRASH_X + i] = x[X_POS + i]
    stats[ST_STATUS] = STATUS_CRASHED


@njit(cache=True)
def tick(
    x: np.ndarray,
    ls: np.ndarray,
    cs: np.ndarray,
    rin: np.ndarray,
    mem: np.ndarray,
    meas: np.ndarray,
    sst: np.ndarray,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    ctrl: np.ndarray,
    scfg: np.ndarray,
    sched_t: np.ndarray,
    sched_rate: np.ndarray,
    sched_stop: np.ndarray,
    noise: np.ndarray,
    t_out: np.ndarray,
    out: np.ndarray,
    imu_out: np.ndarray,
    episodes: np.ndarray,
    stats: np.ndarray,
    x_new: np.ndarray,
    x_b: np.ndarray,
    xs: np.ndarray,
    xd: np.ndarray,
    K: np.ndarray,
    Q: np.ndarray,
    C: np.ndarray,
    wdot: np.ndarray,
    cmd: np.ndarray,
    g_a: np.ndarray,
    gd_a: np.ndarray,
    g_b: np.ndarray,
    gd_b: np.ndarray,
    ev_sig: np.ndarray,
) -> None:
    """One control tick and the interval after it (the arrays after ``stats`` are work space)."""
    nc = cs.shape[0]
    rtol = opts[O_RTOL]
    atol = opts[O_ATOL]
    dt_c = opts[O_DT_CONTROL]
    h_max = opts[O_H_MAX] if opts[O_H_MAX] > 0.0 else dt_c
    max_steps = int(opts[O_MAX_STEPS])
    ev_tol = opts[O_EVENT_TOL]
    v_min = opts[O_V_MIN]
    crash_rule = int(opts[O_CRASH_RULE])
    crash_level = opts[O_CRASH_ALTITUDE]
    stop_on_crash = opts[O_STOP_ON_CRASH] > 0.5
    n_out_max = t_out.shape[0]
    has_schedule = sched_t.shape[0] > 0
    t0 = ls[LS_T0]
    tf = ls[LS_TF]
    k = int(ls[LS_K])
    po_active = ls[LS_PO_ACTIVE] > 0.5
    po_t = ls[LS_PO_T]
    po_seg = int(ls[LS_PO_SEG])
    t_sched = ls[LS_T_SCHED]
    h = ls[LS_H]
    i_out = int(stats[ST_N_OUT])
    n_steps = int(stats[ST_N_STEPS])
    n_rej = int(stats[ST_N_REJECTED])
    n_rhs = int(stats[ST_N_RHS])
    done = False
    failed = False

    t_k = t0 + k * dt_c
    if t_k >= tf - 1e-12 * max(1.0, abs(tf)):
        ls[LS_DONE] = 1.0
        return
    t_next = min(t0 + (k + 1) * dt_c, tf)
    t = t_k
    normalise_quaternion(x, X_QUAT)
    if crash_rule == CRASH_PAPER_TICKS and k > 0 and -x[X_POS + 2] <= crash_level:
        _record_crash(t, x, stats)
        ls[LS_DONE] = 1.0
        return
    # ---- sensors, controller (or an external command), actuators ----
    observe_state(t, x, meas)
    if ls[LS_EXT] > 0.5:
        for j in range(4):
            cmd[j] = ls[LS_EXT_CMD + j]
        ls[LS_EXT] = 0.0
    else:
        controller_step(t, meas, ctrl, mem, veh, dt_c, cmd)
    stats[ST_N_TICKS] += 1.0
    stage = mem[MEM_STAGE]
    ls[LS_STAGE] = stage
    si = int(stage)
    if 0 <= si < N_STAGES and np.isnan(stats[ST_STAGE_T + si]):
        stats[ST_STAGE_T + si] = t
        for i in range(3):
            stats[ST_STAGE_X + 3 * si + i] = x[X_POS + i]
    apply_command(cmd, x, rin, opts, dt_c, po_active)
    cut_step(x, rin, opts, t0, k, dt_c, po_active, po_t)
    _contact_values(x, C, veh, surf, opts, g_a, gd_a)
    fsal = False
    # ---- integrate [t_k, t_next], cut at schedule boundaries ----
    tiny = 1e-12 * max(1.0, abs(t_next))  # boundaries closer than this coincide
    while not done:
        if t_next - t <= tiny:
            t = t_next
            break
        if t_sched - t <= tiny:
            # the rotor inputs change here: trigger, next segment or a motor stopping
            if not po_active:
                po_active = True
                po_t = t
                stats[ST_POWER_OFF_T] = t
                for j in range(4):
                    if sched_stop[j] > 0.5:
                        x[X_ROTOR + j] = 0.0
            po_seg = segment_at(t + tiny, po_t, sched_t)
            apply_segment(x, sched_rate, po_seg, rin, opts)
            t_sched = next_boundary(t, x, po_t, sched_t, po_seg, rin)
            fsal = False
        t_stop = min(t_next, t_sched)
        # contacts already penetrating without a located onset
        for c in range(nc):
            if cs[c, CS_ACTIVE] < 0.5 and g_a[c] > 0.0:
                if g_a[c] > MISSED_ONSET_DEPTH:
                    stats[ST_MISSED_ONSETS] += 1.0
                ev_sig[c] = 0.0
            else:
                ev_sig[c] = NO_EVENT
        if n_steps + n_rej >= max_steps:
            stats[ST_STATUS] = STATUS_FAILED
            stats[ST_REASON] = REASON_MAX_STEPS
            failed = True
            break
        h_try = min(h, h_max, t_stop - t)
        if t + 1.01 * h_try >= t_stop:
            h_try = t_stop - t
        if h_try <= 16.0 * 2.2e-16 * max(1.0, abs(t)) and t_stop - t > h_try:
            stats[ST_STATUS] = STATUS_FAILED
            stats[ST_REASON] = REASON_STEP_TOO_SMALL
            failed = True
            break
        has_pending = False
        for c in range(nc):
            if ev_sig[c] == 0.0:
                has_pending = True
        tol_sig = 0.0
        if has_pending:
            sig_min = 0.0
            for i in range(NX):
                x_b[i] = x[i]
            t_b = t
            h_new = h
        else:
            if not fsal:
                state_derivative(x, K[0], veh, surf, opts, rin, cs, C, wdot)
                n_rhs += 1
            for st in range(1, 6):
                stage_state(x, K, h_try, st, xs)
                state_derivative(xs, K[st], veh, surf, opts, rin, cs, C, wdot)
            stage_state(x, K, h_try, 6, x_new)
            state_derivative(x_new, K[6], veh, surf, opts, rin, cs, C, wdot)
            n_rhs += 6
            err = error_norm(x, x_new, K, h_try, rtol, atol)
            if not np.isfinite(err):
                n_rej += 1
                h = 0.2 * h_try
                fsal = True
                continue
            if err > 1.0:
                n_rej += 1
                h = h_try * step_factor(err, True)
                fsal = True
                continue
            n_steps += 1
            tol_sig = ev_tol / h_try
            h_new = h_try * step_factor(err, True)
            dense_coefficients(K, Q)
            # ---- events at the step end, or inside it for near grazes ----
            _contact_values(x_new, C, veh, surf, opts, g_b, gd_b)
            sig_min = NO_EVENT
            for c in range(nc):
                sig = contact_event(
                    c, cs[c, CS_ACTIVE] > 0.5, g_a[c], g_b[c], gd_a[c], gd_b[c],
                    x, Q, h_try, ev_tol, xs, C, veh, surf, opts,
                )  # fmt: skip
                ev_sig[c] = sig
                if sig < sig_min:
                    sig_min = sig
            sig_crash = NO_EVENT
            if crash_rule == CRASH_CM_GROUND:
                ha = -x[X_POS + 2] - crash_level
                hb = -x_new[X_POS + 2] - crash_level
                if ha > 0.0 and hb <= 0.0:
                    sig_crash = locate(EV_ALTITUDE, 0, x, Q, h_try, ha, hb, 1.0, ev_tol,
                                       xs, C, veh, surf, opts, crash_level)  # fmt: skip
                    if sig_crash < sig_min:
                        sig_min = sig_crash
            if sig_min <= 1.0:
                t_b = t + sig_min * h_try
                dense_eval(x, Q, h_try, sig_min, x_b)
                fsal = False
            else:
                sig_min = 1.0
                t_b = t + h_try
                for i in range(NX):
                    x_b[i] = x_new[i]
                K[0, :] = K[6, :]
                fsal = True
            if t_stop - t_b < tiny:
                t_b = t_stop
            # ---- output rows and IMU samples in (t, t_b] ----
            while i_out < n_out_max and t_out[i_out] <= t_b:
                sm = (t_out[i_out] - t) / h_try
                dense_eval(x, Q, h_try, sm, xs)
                _write_sample(i_out, t_out[i_out], xs, C, veh, surf, cs, rin, ls[LS_STAGE], out,
                              opts)  # fmt: skip
                i_out += 1
            while sst[SS_NEXT_T] <= t_b:
                ts = sst[SS_NEXT_T]
                if ts == t_b and fsal:
                    # at the end of an uncut step: its solution and derivative (FSAL)
                    rotation_matrix(x_b[X_QUAT : X_QUAT + 4], C)
                    imu_sample(ts, x_b, K[6], C, veh, scfg, sst, noise, meas, imu_out, stats)
                    detect(ts, x_b, C, veh, scfg, sst, meas, imu_out, stats)
                    sst[SS_NEXT_T] = t0 + sst[SS_N] / scfg[SC_RATE]
                    continue
                dense_eval(x, Q, h_try, (ts - t) / h_try, xs)
                _sample_imu(ts, xs, xd, C, wdot, veh, surf, opts, rin, cs, scfg, sst, noise,
                            meas, imu_out, stats, t0)  # fmt: skip
            # ---- peaks of the active contacts over (t, t_b] ----
            for c in range(nc):
                e = int(cs[c, CS_EPISODE])
                if cs[c, CS_ACTIVE] < 0.5 or e < 0:
                    continue
                lam = cs[c, CS_LAMBDA]
                rate_end = _observe(episodes, e, c, sig_min, t, h_try, x, Q, xs, C, veh, surf, lam,
                                    opts)  # fmt: skip
                # the force peaks before the deflection: look half-way too
                _observe(episodes, e, c, 0.5 * sig_min, t, h_try, x, Q, xs, C, veh, surf, lam, opts)
                if gd_a[c] > 0.0 and rate_end <= 0.0 and sig_min > 0.0:
                    sp = locate(EV_RATE, c, x, Q, h_try, gd_a[c], rate_end, sig_min, ev_tol,
                                xs, C, veh, surf, opts, 0.0)  # fmt: skip
                    _observe(episodes, e, c, sp, t, h_try, x, Q, xs, C, veh, surf, lam, opts)
            if sig_crash <= sig_min:
                _record_crash(t_b, x_b, stats)
                if stop_on_crash:
                    done = True
        # ---- advance to t_b and process the events located there ----
        t = t_b
        for i in range(NX):
            x[i] = x_b[i]
        if not np.isfinite(x).all():
            stats[ST_STATUS] = STATUS_FAILED
            stats[ST_REASON] = REASON_NOT_FINITE
            failed = True
            break
        _track_extremes(x, meas[MS_DETECTED] > 0.5, stats)
        h = h_new
        _contact_values(x, C, veh, surf, opts, g_a, gd_a)
        for c in range(nc):
            if ev_sig[c] >= NO_EVENT or ev_sig[c] > sig_min + tol_sig:
                continue
            fsal = False
            s = c // 4
            if cs[c, CS_ACTIVE] < 0.5:
                # onset: capture v_i at the located instant
                _open_episode(c, t, x, C, veh, surf, gd_a[c], v_min, cs, episodes, stats)
                if surf[s, S_IS_GROUND] > 0.5:
                    if np.isnan(stats[ST_CRASH_T]):
                        _record_crash(t, x, stats)
                        if stop_on_crash:
                            done = True
                elif np.isnan(stats[ST_ONSET_T]):
                    stats[ST_ONSET_T] = t
                    for i in range(NX):
                        stats[ST_ONSET_X + i] = x[i]
                    if has_schedule and opts[O_POWER_OFF_T] < 0.0 and not po_active:
                        t_sched = t  # power-off triggered by the first contact
            else:
                # end of the episode
                cs[c, CS_ACTIVE] = 0.0
                cs[c, CS_LAMBDA] = 0.0
                e = int(cs[c, CS_EPISODE])
                if e >= 0:
                    episodes[e, E_T_END] = t
                    episodes[e, E_OPEN] = 0.0
                cs[c, CS_EPISODE] = -1.0
    # ---- write the loop state back ----
    ls[LS_T] = t
    ls[LS_H] = h
    ls[LS_PO_ACTIVE] = 1.0 if po_active else 0.0
    ls[LS_PO_T] = po_t
    ls[LS_PO_SEG] = po_seg
    ls[LS_T_SCHED] = t_sched
    stats[ST_T_END] = t
    stats[ST_N_OUT] = i_out
    stats[ST_N_STEPS] = n_steps
    stats[ST_N_REJECTED] = n_rej
    stats[ST_N_RHS] = n_rhs
    if failed:
        ls[LS_DONE] = 1.0
        return
    ls[LS_K] = k + 1
    if done:
        ls[LS_DONE] = 1.0


@njit(cache=True)
def finish(ls: np.ndarray, cs: np.ndarray, episodes: np.ndarray, stats: np.ndarray) -> None:
    """Close the episodes still open at the time reached; deepest penetration of the run.

    Idempotent, and harmless before the end: an episode closed here is
    reopened in effect by the loop (its end is overwritten when it ends).
    """
    n_ep = int(stats[ST_N_EPISODES])
    for e in range(n_ep):
        if episodes[e, E_PEAK_DELTA] > stats[ST_MAX_DELTA]:
            stats[ST_MAX_DELTA] = episodes[e, E_PEAK_DELTA]
    for c in range(cs.shape[0]):
        e = int(cs[c, CS_EPISODE])
        if e >= 0:
            episodes[e, E_T_END] = ls[LS_T]
            episodes[e, E_OPEN] = 1.0
    if stats[ST_STATUS] != STATUS_FAILED and not np.isnan(stats[ST_CRASH_T]):
        stats[ST_STATUS] = STATUS_CRASHED
    elif stats[ST_STATUS] != STATUS_FAILED:
        stats[ST_STATUS] = STATUS_COMPLETED


@njit(cache=True)
def advance(
    n_ticks: int,
    x: np.ndarray,
    ls: np.ndarray,
    cs: np.ndarray,
    rin: np.ndarray,
    mem: np.ndarray,
    meas: np.ndarray,
    sst: np.ndarray,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    ctrl: np.ndarray,
    scfg: np.ndarray,
    sched_t: np.ndarray,
    sched_rate: np.ndarray,
    sched_stop: np.ndarray,
    noise: np.ndarray,
    t_out: np.ndarray,
    out: np.ndarray,
    imu_out: np.ndarray,
    episodes: np.ndarray,
    stats: np.ndarray,
) -> int:
    """Run up to ``n_ticks`` control ticks (``n_ticks < 0``: to the end); return the ticks run.

    The arrays are those of :func:`start` (initialised by it) plus the run's
    constant inputs: ``veh``, ``surf``, ``opts``, ``ctrl``, ``scfg`` (packed
    vehicle, surfaces, options, controller, sensors), the power-off schedule
    ``sched_t`` (K,) segment starts after the trigger (s), ``sched_rate``
    (K, 4) rates (rad/s^2), ``sched_stop`` (4,) motors stalling at the trigger,
    and ``noise`` (n_imu, 6) standard normal draws for the IMU. When the run
    ends (``ls[LS_DONE]``), :func:`finish` has been applied.
    """
    nc = cs.shape[0]
    x_new = np.empty(NX)
    x_b = np.empty(NX)
    xs = np.empty(NX)
    xd = np.empty(NX)
    K = np.zeros((7, NX))
    Q = np.zeros((NX, 4))
    C = np.zeros((3, 3))
    wdot = np.zeros(4)
    cmd = np.zeros(4)
    g_a = np.zeros(nc)
    gd_a = np.zeros(nc)
    g_b = np.zeros(nc)
    gd_b = np.zeros(nc)
    ev_sig = np.zeros(nc)
    n = 0
    while ls[LS_DONE] < 0.5 and (n_ticks < 0 or n < n_ticks):
        k = ls[LS_K]
        tick(x, ls, cs, rin, mem, meas, sst, veh, surf, opts, ctrl, scfg, sched_t, sched_rate,
             sched_stop, noise, t_out, out, imu_out, episodes, stats,
             x_new, x_b, xs, xd, K, Q, C, wdot, cmd, g_a, gd_a, g_b, gd_b, ev_sig)  # fmt: skip
        if ls[LS_K] != k:
            n += 1
    if ls[LS_DONE] > 0.5:
        finish(ls, cs, episodes, stats)
    return n
