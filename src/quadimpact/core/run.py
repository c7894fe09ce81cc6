"""The run loop: control ticks, adaptive steps, events and output, all compiled.

``run_builtin`` (cached) runs one scenario with a built-in controller;
``make_kernel(step)`` compiles the same loop around a user's ``njit``
controller step (see ``control`` for its signature). Inputs are the packed
arrays of ``layout``; outputs are written into arrays the caller allocates:

* ``out`` (n_out, NOUT): samples at the times ``t_out`` from the dense output;
* ``episodes`` (max_episodes, NEP): one row per bumper-surface contact episode;
* ``stats`` (NSTAT): status, counters, crash and first-onset records.

Loop structure: at each control tick ``t0 + k dt`` the controller sees the
exact state and sets the rotor inputs (zero-order hold); the interval to the
next tick is integrated by Dormand-Prince 5(4) restarted there (the inputs
jump). After every accepted step the event functions are checked at its end
(and inside it for near-grazing contacts); the earliest onset, end or crash
is located on the dense output, the step is cut there, every contact is
re-examined at that instant (simultaneous onsets) and integration restarts.
"""

import math
import types
from collections.abc import Callable

import numpy as np
from numba import njit

from .contact import bumper_plane_contact, damping_coefficient, normal_force
from .control import builtin_step
from .dynamics import state_derivative
from .events import EV_ALTITUDE, EV_RATE, NO_EVENT, contact_event, locate
from .integrator import dense_coefficients, dense_eval, error_norm, stage_state, step_factor
from .layout import (
    CRASH_CM_GROUND,
    CRASH_PAPER_TICKS,
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
    NEP,
    NMEM,
    NOUT,
    NRIN,
    NSTAT,
    NX,
    O_ATOL,
    O_CRASH_ALTITUDE,
    O_CRASH_RULE,
    O_DT_CONTROL,
    O_EVENT_TOL,
    O_H_MAX,
    O_MAX_STEPS,
    O_OMEGA_MAX,
    O_OMEGA_MIN,
    O_POWER_OFF_T,
    O_ROTOR_MODE,
    O_RTOL,
    O_SLEW_MAX,
    O_STOP_ON_CRASH,
    O_V_MIN,
    OUT_CMD,
    OUT_DELTA,
    OUT_FORCE,
    OUT_T,
    OUT_X,
    REASON_MAX_STEPS,
    REASON_NOT_FINITE,
    REASON_STEP_TOO_SMALL,
    RIN_CMD,
    RIN_FF,
    RIN_FIRST_ORDER,
    RIN_RATE,
    ROTOR_FIRST_ORDER,
    S_IS_GROUND,
    ST_CRASH_T,
    ST_CRASH_X,
    ST_EPISODES_DROPPED,
    ST_MAX_DELTA,
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
    ST_STATUS,
    ST_T_END,
    STATUS_COMPLETED,
    STATUS_CRASHED,
    STATUS_FAILED,
    X_POS,
    X_QUAT,
    X_ROTOR,
)
from .quaternion import normalise_quaternion, rotation_matrix
from .schedule import apply_segment, next_boundary, segment_at

MISSED_ONSET_DEPTH = 1e-9  # m; deeper first sightings count as missed onsets


@njit(cache=True)
def _contact_values(
    x: np.ndarray, C: np.ndarray, veh: np.ndarray, surf: np.ndarray, g: np.ndarray, gd: np.ndarray
) -> None:
    """Penetration and its rate for every bumper-surface pair at state ``x``."""
    rotation_matrix(x[X_QUAT : X_QUAT + 4], C)
    for c in range(g.shape[0]):
        d, dd, _, _, _, _, _, _ = bumper_plane_contact(x, C, veh, c % 4, surf, c // 4)
        g[c] = d
        gd[c] = dd


@njit(cache=True)
def _write_sample(
    row: int,
    t: float,
    xs: np.ndarray,
    C: np.ndarray,
    veh: np.ndarray,
    surf: np.ndarray,
    c_active: np.ndarray,
    c_lam: np.ndarray,
    rin: np.ndarray,
    out: np.ndarray,
) -> None:
    """One output row: time, state, per-bumper deflection and force, command."""
    out[row, OUT_T] = t
    for i in range(NX):
        out[row, OUT_X + i] = xs[i]
    rotation_matrix(xs[X_QUAT : X_QUAT + 4], C)
    for j in range(4):
        out[row, OUT_DELTA + j] = 0.0
        out[row, OUT_FORCE + j] = 0.0
        out[row, OUT_CMD + j] = rin[RIN_CMD + j]
    for c in range(c_active.shape[0]):
        j = c % 4
        d, dd, _, _, _, _, _, _ = bumper_plane_contact(xs, C, veh, j, surf, c // 4)
        if d > out[row, OUT_DELTA + j]:
            out[row, OUT_DELTA + j] = d
        if c_active[c] > 0.5:
            out[row, OUT_FORCE + j] += normal_force(veh, d, dd, c_lam[c])


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
) -> float:
    """Track episode ``e``'s peaks with contact ``c`` at ``t_old + sigma h`` (dense output).

    Returns the penetration rate there.
    """
    dense_eval(x_old, Q, h, sigma, xs)
    rotation_matrix(xs[X_QUAT : X_QUAT + 4], C)
    d, dd, _, _, _, _, _, _ = bumper_plane_contact(xs, C, veh, c % 4, surf, c // 4)
    _track_peak(episodes, e, t_old + sigma * h, d, normal_force(veh, d, dd, lam))
    return dd


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


controller_step = builtin_step  # rebound by make_kernel for plug-in controllers


@njit(cache=True)
def integrate(
    x0: np.ndarray,
    t0: float,
    tf: float,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    ctrl: np.ndarray,
    mem: np.ndarray,
    sched_t: np.ndarray,
    sched_rate: np.ndarray,
    sched_stop: np.ndarray,
    t_out: np.ndarray,
    out: np.ndarray,
    episodes: np.ndarray,
    stats: np.ndarray,
) -> None:
    """Integrate one scenario from ``t0`` to ``tf`` (s); see the module docstring.

    ``sched_t`` (K,) and ``sched_rate`` (K, 4) are the power-off schedule
    (segment starts after the trigger, s; rates, rad/s^2); K = 0: none.
    ``sched_stop`` (4,): 1 for the motors that stall at the trigger (speed 0 at once).
    """
    nc = 4 * surf.shape[0]
    x = x0.copy()
    x_new = np.empty(NX)
    x_b = np.empty(NX)
    xs = np.empty(NX)
    K = np.zeros((7, NX))
    Q = np.zeros((NX, 4))
    C = np.zeros((3, 3))
    wdot = np.zeros(4)
    rin = np.zeros(NRIN)
    cmd = np.zeros(4)
    prev_cmd = np.empty(4)
    for j in range(4):
        prev_cmd[j] = x[X_ROTOR + j]
        rin[RIN_CMD + j] = x[X_ROTOR + j]
    c_active = np.zeros(nc)
    c_lam = np.zeros(nc)
    c_ep = -np.ones(nc, np.int64)
    g_a = np.zeros(nc)
    gd_a = np.zeros(nc)
    g_b = np.zeros(nc)
    gd_b = np.zeros(nc)
    ev_sig = np.zeros(nc)

    for i in range(stats.shape[0]):
        stats[i] = 0.0
    stats[ST_CRASH_T] = np.nan
    stats[ST_ONSET_T] = np.nan
    stats[ST_POWER_OFF_T] = np.nan

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
    first_order = int(opts[O_ROTOR_MODE]) == ROTOR_FIRST_ORDER
    rin[RIN_FIRST_ORDER] = 1.0 if first_order else 0.0
    w_lo = opts[O_OMEGA_MIN]
    w_hi = opts[O_OMEGA_MAX]
    slew = opts[O_SLEW_MAX]
    max_episodes = episodes.shape[0]
    n_out_max = t_out.shape[0]
    # power-off schedule: inactive until its trigger (a time, or the first contact)
    has_schedule = sched_t.shape[0] > 0
    po_active = False
    po_t = math.inf  # trigger time once known
    po_seg = 0
    t_sched = math.inf  # next instant the rotor inputs change
    if has_schedule and opts[O_POWER_OFF_T] >= 0.0:
        t_sched = max(opts[O_POWER_OFF_T], t0)

    status = STATUS_COMPLETED
    reason = 0
    n_ep = 0
    n_steps = 0
    n_rej = 0
    n_rhs = 0
    i_out = 0
    h = 0.1 * min(h_max, dt_c)
    t = t0
    done = False
    # samples at the start time
    while i_out < n_out_max and t_out[i_out] <= t0:
        _write_sample(i_out, t_out[i_out], x, C, veh, surf, c_active, c_lam, rin, out)
        i_out += 1

    k = 0
    while not done:
        t_k = t0 + k * dt_c
        if t_k >= tf - 1e-12 * max(1.0, abs(tf)):
            break
        t_next = min(t0 + (k + 1) * dt_c, tf)
        t = t_k
        normalise_quaternion(x, X_QUAT)
        if crash_rule == CRASH_PAPER_TICKS and -x[X_POS + 2] <= crash_level:
            stats[ST_CRASH_T] = t
            for i in range(3):
                stats[ST_CRASH_X + i] = x[X_POS + i]
            status = STATUS_CRASHED
            break
        # ---- controller tick (zero-order hold) ----
        controller_step(x, ctrl, mem, veh, dt_c, cmd)
        stats[ST_N_TICKS] += 1.0
        for j in range(4):
            w = cmd[j]
            if slew > 0.0:
                w = min(max(w, prev_cmd[j] - slew * dt_c), prev_cmd[j] + slew * dt_c)
            if w_lo > 0.0 and w < w_lo:
                w = w_lo
            if w_hi > 0.0 and w > w_hi:
                w = w_hi
            if w < 0.0:
                w = 0.0
            rin[RIN_CMD + j] = w
            if po_active:  # the schedule overrides the controller
                pass
            elif first_order:
                rin[RIN_RATE + j] = 0.0
                rin[RIN_FF + j] = 0.0
            else:
                rin[RIN_RATE + j] = 0.0
                rin[RIN_FF + j] = (w - prev_cmd[j]) / dt_c
                x[X_ROTOR + j] = w
            prev_cmd[j] = w
        _contact_values(x, C, veh, surf, g_a, gd_a)
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
                apply_segment(x, sched_rate, po_seg, rin)
                t_sched = next_boundary(t, x, po_t, sched_t, po_seg, rin)
                fsal = False
            t_stop = min(t_next, t_sched)
            # contacts already penetrating without a located onset
            for c in range(nc):
                if c_active[c] < 0.5 and g_a[c] > 0.0:
                    if g_a[c] > MISSED_ONSET_DEPTH:
                        stats[ST_MISSED_ONSETS] += 1.0
                    ev_sig[c] = 0.0
                else:
                    ev_sig[c] = NO_EVENT
            if n_steps + n_rej >= max_steps:
                status = STATUS_FAILED
                reason = REASON_MAX_STEPS
                break
            h_try = min(h, h_max, t_stop - t)
            if t + 1.01 * h_try >= t_stop:
                h_try = t_stop - t
            if h_try <= 16.0 * 2.2e-16 * max(1.0, abs(t)) and t_stop - t > h_try:
                status = STATUS_FAILED
                reason = REASON_STEP_TOO_SMALL
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
                    state_derivative(x, K[0], veh, surf, opts, rin, c_active, c_lam, C, wdot)
                    n_rhs += 1
                for stage in range(1, 6):
                    stage_state(x, K, h_try, stage, xs)
                    state_derivative(xs, K[stage], veh, surf, opts, rin, c_active, c_lam, C, wdot)
                stage_state(x, K, h_try, 6, x_new)
                state_derivative(x_new, K[6], veh, surf, opts, rin, c_active, c_lam, C, wdot)
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
                _contact_values(x_new, C, veh, surf, g_b, gd_b)
                sig_min = NO_EVENT
                for c in range(nc):
                    sig = contact_event(
                        c, c_active[c] > 0.5, g_a[c], g_b[c], gd_a[c], gd_b[c],
                        x, Q, h_try, ev_tol, xs, C, veh, surf,
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
                                           xs, C, veh, surf, crash_level)  # fmt: skip
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
                # ---- output samples in (t, t_b] ----
                while i_out < n_out_max and t_out[i_out] <= t_b:
                    sm = (t_out[i_out] - t) / h_try
                    dense_eval(x, Q, h_try, sm, xs)
                    _write_sample(i_out, t_out[i_out], xs, C, veh, surf, c_active, c_lam, rin, out)
                    i_out += 1
                # ---- peaks of the active contacts over (t, t_b] ----
                for c in range(nc):
                    if c_active[c] < 0.5 or c_ep[c] < 0:
                        continue
                    e = c_ep[c]
                    rate_end = _observe(episodes, e, c, sig_min, t, h_try, x, Q, xs, C, veh, surf,
                                        c_lam[c])  # fmt: skip
                    # the force peaks before the deflection: look half-way too
                    _observe(episodes, e, c, 0.5 * sig_min, t, h_try, x, Q, xs, C, veh, surf,
                             c_lam[c])  # fmt: skip
                    if gd_a[c] > 0.0 and rate_end <= 0.0 and sig_min > 0.0:
                        sp = locate(EV_RATE, c, x, Q, h_try, gd_a[c], rate_end, sig_min, ev_tol,
                                    xs, C, veh, surf, 0.0)  # fmt: skip
                        _observe(episodes, e, c, sp, t, h_try, x, Q, xs, C, veh, surf, c_lam[c])
                if sig_crash <= sig_min:
                    stats[ST_CRASH_T] = t_b
                    for i in range(3):
                        stats[ST_CRASH_X + i] = x_b[X_POS + i]
                    status = STATUS_CRASHED
                    if stop_on_crash:
                        done = True
            # ---- advance to t_b and process the events located there ----
            t = t_b
            for i in range(NX):
                x[i] = x_b[i]
            if not np.isfinite(x).all():
                status = STATUS_FAILED
                reason = REASON_NOT_FINITE
                break
            h = h_new
            _contact_values(x, C, veh, surf, g_a, gd_a)
            for c in range(nc):
                if ev_sig[c] >= NO_EVENT or ev_sig[c] > sig_min + tol_sig:
                    continue
                fsal = False
                s = c // 4
                if c_active[c] < 0.5:
                    # onset: capture v_i at the located instant
                    c_active[c] = 1.0
                    c_lam[c] = damping_coefficient(veh, gd_a[c], v_min)
                    if n_ep < max_episodes:
                        e = n_ep
                        episodes[e, E_BUMPER] = c % 4
                        episodes[e, E_SURFACE] = s
                        episodes[e, E_T_START] = t
                        episodes[e, E_T_END] = np.nan
                        episodes[e, E_V_I] = gd_a[c]
                        episodes[e, E_PEAK_DELTA] = max(g_a[c], 0.0)
                        episodes[e, E_T_PEAK] = t
                        episodes[e, E_PEAK_FORCE] = 0.0
                        episodes[e, E_T_PEAK_FORCE] = t
                        episodes[e, E_OPEN] = 1.0
                        c_ep[c] = e
                        n_ep += 1
                    else:
                        c_ep[c] = -1
                        stats[ST_EPISODES_DROPPED] += 1.0
                    if surf[s, S_IS_GROUND] > 0.5:
                        if np.isnan(stats[ST_CRASH_T]):
                            stats[ST_CRASH_T] = t
                            for i in range(3):
                                stats[ST_CRASH_X + i] = x[X_POS + i]
                            status = STATUS_CRASHED
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
                    c_active[c] = 0.0
                    c_lam[c] = 0.0
                    e = c_ep[c]
                    if e >= 0:
                        episodes[e, E_T_END] = t
                        episodes[e, E_OPEN] = 0.0
                    c_ep[c] = -1
        if status == STATUS_FAILED:
            break
        k += 1

    # close the episodes still open; deepest penetration of the run
    for e in range(n_ep):
        if episodes[e, E_PEAK_DELTA] > stats[ST_MAX_DELTA]:
            stats[ST_MAX_DELTA] = episodes[e, E_PEAK_DELTA]
    for c in range(nc):
        e = c_ep[c]
        if e >= 0:
            episodes[e, E_T_END] = t
            episodes[e, E_OPEN] = 1.0
    stats[ST_STATUS] = status
    stats[ST_REASON] = reason
    stats[ST_T_END] = t
    stats[ST_N_STEPS] = n_steps
    stats[ST_N_REJECTED] = n_rej
    stats[ST_N_RHS] = n_rhs
    stats[ST_N_OUT] = i_out
    stats[ST_N_EPISODES] = n_ep


run_builtin = integrate  # the cached kernel with the built-in controllers


def make_kernel(step: Callable) -> Callable:
    """Compile the run loop around a user's ``njit`` controller ``step``.

    The loop's source is reused as it is, with its global ``controller_step``
    bound to ``step`` instead of the built-in dispatcher (Numba resolves
    globals at compile time). The result has the signature of
    ``run_builtin``; it is compiled on first call and not cached on disk.
    """
    py = integrate.py_func
    scope = dict(py.__globals__)
    scope["controller_step"] = step
    fn = types.FunctionType(py.__code__, scope, "integrate_" + step.__name__, py.__defaults__)
    return njit(fn)


def execute(
    x0: np.ndarray,
    t0: float,
    tf: float,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    ctrl: np.ndarray,
    t_out: np.ndarray,
    max_episodes: int = 1024,
    kernel: Callable | None = None,
    sched_t: np.ndarray | None = None,
    sched_rate: np.ndarray | None = None,
    sched_stop: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Allocate the outputs, run the compiled loop, return the filled parts.

    Returns ``(out[:n_out], episodes[:n_episodes], stats)`` (layout ``OUT_*``,
    ``E_*``, ``ST_*``). ``sched_t``/``sched_rate``: the power-off schedule
    (``core/schedule.py``), triggered at ``opts[O_POWER_OFF_T]`` (< 0: the first
    contact).
    """
    out = np.zeros((t_out.shape[0], NOUT))
    episodes = np.zeros((max_episodes, NEP))
    stats = np.zeros(NSTAT)
    mem = np.zeros(NMEM)
    (kernel or run_builtin)(
        np.ascontiguousarray(x0, dtype=np.float64),
        float(t0),
        float(tf),
        veh,
        surf,
        opts,
        ctrl,
        mem,
        np.zeros(0) if sched_t is None else np.ascontiguousarray(sched_t, dtype=np.float64),
        np.zeros((0, 4)) if sched_rate is None else np.ascontiguousarray(sched_rate, np.float64),
        np.zeros(4) if sched_stop is None else np.ascontiguousarray(sched_stop, np.float64),
        np.ascontiguousarray(t_out, dtype=np.float64),
        out,
        episodes,
        stats,
    )
    return out[: int(stats[ST_N_OUT])], episodes[: int(stats[ST_N_EPISODES])], stats
