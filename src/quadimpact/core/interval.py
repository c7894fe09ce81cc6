"""Integration of one control interval: Dormand-Prince 5(4) with located events.

From the tick ``t_k`` to ``t_{k+1}`` the inputs are constant (zero-order
hold), so the integrator is restarted at the tick and steps to the next one,
also cut where the power-off schedule changes the rotor inputs. After each
accepted step the event functions (the contact gap of every pair, the
altitude for the crash) are checked at its end, and inside it for contacts
within reach; the earliest onset, end or crash is located on the dense
output, the step is cut there, every pair is re-examined at that instant
(simultaneous onsets: at psi = 0 bumpers 1 and 4 start together), ``v_i`` is
captured, and integration restarts from the cut. Output rows and IMU
samples falling inside the step are written from the dense output; episode
peaks are tracked (the deflection at the located zero of ``delta_dot``, the
force at step ends and mid-steps). Contact state changes only at located
events, so a trial step never integrates a force switched on mid-step.
"""

import math

import numpy as np

from quadimpact.core.actuators import apply_segment, next_boundary, segment_at
from quadimpact.core.compiled import compiled
from quadimpact.core.contact import contact_gap
from quadimpact.core.contact_slots import CS_ACTIVE, CS_EPISODE
from quadimpact.core.dynamics import state_derivative
from quadimpact.core.events import EV_ALTITUDE, EV_RATE, NO_EVENT, contact_event, locate
from quadimpact.core.geometry import (
    GEOM_RING_PLANE,
    PR_FEATURE,
    PR_GEOMETRY,
    PR_SHAPE,
    has_bound,
    pair_bound,
    pair_depth,
)
from quadimpact.core.geometry.plane import ring_plane, ring_plane_bound, ring_reach
from quadimpact.core.integrator import (
    all_finite,
    copy_into,
    dense_coefficients,
    dense_eval,
    dense_eval_part,
    error_norm,
    stage_state,
    step_factor,
)
from quadimpact.core.interval_slots import IS_N_REJECTED, IS_N_RHS, IS_N_STEPS
from quadimpact.core.layout import (
    CRASH_CM_GROUND,
    LS_H,
    LS_PO_ACTIVE,
    LS_PO_SEG,
    LS_PO_T,
    LS_T,
    LS_T_SCHED,
    MAX_INTERVAL_EVENTS,
    NX,
    O_ATOL,
    O_CRASH_ALTITUDE,
    O_CRASH_RULE,
    O_CUT_STEP_MOTORS,
    O_DT_CONTROL,
    O_EVENT_TOL,
    O_H_MAX,
    O_MAX_STEPS,
    O_POWER_OFF_T,
    O_RTOL,
    O_STOP_ON_CRASH,
    REASON_EVENT_STORM,
    REASON_MAX_STEPS,
    REASON_NOT_FINITE,
    REASON_STEP_TOO_SMALL,
    ST_CRASH_T,
    ST_MISSED_ONSETS,
    ST_N_OUT,
    ST_ONSET_T,
    ST_ONSET_X,
    ST_POWER_OFF_T,
    ST_REASON,
    ST_STATUS,
    ST_STEPS,
    ST_T_END,
    STATUS_FAILED,
    X_OMEGA,
    X_POS,
    X_QUAT,
    X_ROTOR,
    X_VEL,
)
from quadimpact.core.quaternion import rotation_matrix
from quadimpact.core.recording import (
    add_attitude,
    attitude_settled,
    close_episode,
    keep_last_state,
    observe_peak,
    open_episode,
    record_crash,
    track_extremes,
    write_sample,
)
from quadimpact.core.records import Data, Model, Output, Work
from quadimpact.core.rotors import active_states
from quadimpact.core.sensing import sample_at, take_sample
from quadimpact.core.sensors.imu_slots import SS_NEXT_T
from quadimpact.core.sensors.measurement_slots import MS_DETECTED
from quadimpact.core.shape_slots import (
    SH_IS_GROUND,
)
from quadimpact.core.vehicle_slots import V_N_ROTORS

MISSED_ONSET_DEPTH = 1e-9  # m; deeper first sightings count as missed onsets

RUNNING = 0  # what integrate_interval returns: the run goes on,
ENDED = 1  # it ended (a crash with stop-on-crash),
FAILED = 2  # or failed (status and reason in stats)


@compiled
def contact_values(
    x: np.ndarray, m: Model, d: Data, w: Work, g: np.ndarray, gd: np.ndarray, bnd: np.ndarray
):
    """Gap ``g`` and penetration rate ``gd`` of every pair at ``x`` (``w.C``: its rotation).

    The broad phase: a pair out of contact whose record is a search (a ring
    against a cylinder or a box, ``geometry.has_bound``) is first bounded
    (``geometry.pair_bound``, one point depth); when the bound proves it
    apart, ``g[c]`` and ``gd[c]`` hold the bounds (its gap is at most
    ``g[c] < 0``, its rate at most ``gd[c]`` in size) and ``bnd[c] = 1``.
    ``events.contact_event`` decides from them only what they prove and
    computes the values otherwise, so no result changes (bit for bit). A ring
    against a plane takes its depth and rate from the closed form inlined here
    (``geometry.plane.ring_plane``: the rest of its record is not computed),
    after a broad phase of its own out of contact (``geometry.plane.ring_plane_bound``:
    the CM's distance from the plane against the ring's reach), tried only where the
    last values in ``g``, ``bnd`` say it may succeed (near the plane it would only add
    to the closed form).
    """
    rotation_matrix(x[X_QUAT : X_QUAT + 4], w.C)
    speed = -1.0  # the norms of the velocity and the angular velocity, when first needed
    spin = 0.0
    for c in range(g.shape[0]):
        if m.pairs[c, PR_GEOMETRY] == GEOM_RING_PLANE:
            f = m.pairs[c, PR_FEATURE]
            s = m.pairs[c, PR_SHAPE]
            # bounded where the last values in these slots say it may prove the ring apart
            # (proved apart, or a gap below twice its reach); the closed form otherwise
            if d.cs[c, CS_ACTIVE] < 0.5 and (bnd[c] > 0.5 or g[c] < -2.0 * ring_reach(m.feat, f)):
                if speed < 0.0:
                    speed = math.sqrt(x[X_VEL] ** 2 + x[X_VEL + 1] ** 2 + x[X_VEL + 2] ** 2)
                    spin = math.sqrt(x[X_OMEGA] ** 2 + x[X_OMEGA + 1] ** 2 + x[X_OMEGA + 2] ** 2)
                gu, vu = ring_plane_bound(x, speed, spin, m.feat, f, m.shapes, s)
                if gu < 0.0:
                    g[c] = gu
                    gd[c] = vu
                    bnd[c] = 1.0
                    continue
            rec = ring_plane(x, w.C, m.feat, f, m.shapes, s)
            g[c] = contact_gap(x, rec[0], m, c)
            gd[c] = rec[1]
            bnd[c] = 0.0
            continue
        if d.cs[c, CS_ACTIVE] < 0.5 and has_bound(m.pairs, c):
            gu, vu = pair_bound(x, w.C, m.feat, m.shapes, m.pairs, c)
            if gu < 0.0:
                g[c] = gu
                gd[c] = vu
                bnd[c] = 1.0
                continue
        dp, dd = pair_depth(x, w.C, m.feat, m.shapes, m.pairs, c)
        g[c] = contact_gap(x, dp, m, c)
        gd[c] = dd
        bnd[c] = 0.0


@compiled
def _schedule_boundary(t: float, tiny: float, m: Model, d: Data, o: Output) -> None:
    """The rotor inputs change at ``t``: power-off trigger, next segment, a motor stopping."""
    ls = d.ls
    x = d.x
    n = int(m.veh[V_N_ROTORS])
    if ls[LS_PO_ACTIVE] < 0.5:
        ls[LS_PO_ACTIVE] = 1.0
        ls[LS_PO_T] = t
        o.stats[ST_POWER_OFF_T] = t
        for j in range(n):
            if m.sched_stop[j] > 0.5:
                x[X_ROTOR + j] = 0.0
    seg = segment_at(t + tiny, ls[LS_PO_T], m.sched_t)
    ls[LS_PO_SEG] = seg
    apply_segment(x, m.sched_rate, seg, d.rin, int(m.opts[O_CUT_STEP_MOTORS]), n)
    ls[LS_T_SCHED] = next_boundary(t, x, ls[LS_PO_T], m.sched_t, seg, d.rin, n)


@compiled
def _pending_onsets(d: Data, o: Output, w: Work) -> bool:
    """Mark pairs already penetrating without a located onset (``w.ev_sig = 0``); any?"""
    pending = False
    for c in range(d.cs.shape[0]):
        if d.cs[c, CS_ACTIVE] < 0.5 and w.g_a[c] > 0.0:
            if w.g_a[c] > MISSED_ONSET_DEPTH:
                o.stats[ST_MISSED_ONSETS] += 1.0
            w.ev_sig[c] = 0.0
            pending = True
        else:
            w.ev_sig[c] = NO_EVENT
    return pending


@compiled(inline="always")
def _trial_step(m: Model, d: Data, w: Work, h: float, fsal: bool) -> float:
    """A Dormand-Prince step of ``h`` (s) from ``d.x``: stages in ``w.K``, its end in ``w.x_new``.

    ``fsal``: ``w.K[0]`` already holds the derivative at ``d.x``. Returns the
    scaled error norm (<= 1: accept).
    """
    x = d.x
    K = w.K
    na = active_states(m.veh)
    for st in range(1 if fsal else 0, 7):
        # stage 0 at x (unless FSAL), 1-5 at w.xs, the last at the step's end w.x_new;
        # one call site, so the inlined right-hand side is compiled once
        xs = x if st == 0 else (w.x_new if st == 6 else w.xs)
        if st > 0:
            stage_state(x[:na], K, h, st, xs)
        state_derivative(xs, K[st], m, d, w)
    return error_norm(x[:na], w.x_new[:na], K, h, m.opts[O_RTOL], m.opts[O_ATOL])


@compiled(inline="always")
def _step_events(m: Model, d: Data, w: Work, h: float) -> tuple[float, float]:
    """Earliest event of the accepted step of ``h`` (s), and the crash's (fractions; NO_EVENT)."""
    contact_values(w.x_new, m, d, w, w.g_b, w.gd_b, w.bnd_b)
    sig_min = NO_EVENT
    for c in range(d.cs.shape[0]):
        sig = contact_event(c, m, d, w, h)
        w.ev_sig[c] = sig
        if sig < sig_min:
            sig_min = sig
    sig_crash = NO_EVENT
    if int(m.opts[O_CRASH_RULE]) == CRASH_CM_GROUND:
        level = m.opts[O_CRASH_ALTITUDE]
        ha = -d.x[X_POS + 2] - level
        hb = -w.x_new[X_POS + 2] - level
        if ha > 0.0 and hb <= 0.0:
            sig_crash = locate(EV_ALTITUDE, 0, level, m, d, w, h, ha, hb, 1.0)
            if sig_crash < sig_min:
                sig_min = sig_crash
    return sig_min, sig_crash


@compiled
def _rowless_samples(
    m: Model, d: Data, o: Output, w: Work, t: float, h: float, t_b: float, i_out: int
) -> int:
    """The samples in ``(t, t_b]`` of the step of ``h`` (s) that have no row; the next one.

    A sweep's run (``o.out`` has no rows). A sample that is not the step's last
    only joins the attitude excursion: its quaternion alone is interpolated
    (``recording.add_attitude``), and not even that where the step is proved
    unable to change the excursion (``recording.attitude_settled``: the same
    bits). The step's last sample is written in full, so the last state kept is
    the run's last sample's. Not inlined: the loop's own code stays as it was.
    """
    t_out = m.t_out
    n_out = t_out.shape[0]
    settled = False  # proved: no sample of the step changes the excursion
    if i_out + 1 < n_out and t_out[i_out + 1] <= t_b:
        settled = attitude_settled(d.x, w.Q, h, m, o, w)
    while i_out + 1 < n_out and t_out[i_out + 1] <= t_b:
        if not settled:
            dense_eval_part(d.x, w.Q, h, (t_out[i_out] - t) / h, w.xs, X_QUAT, X_QUAT + 4)
            add_attitude(w.xs, m, o, w)
        i_out += 1
    if i_out < n_out and t_out[i_out] <= t_b:
        dense_eval(d.x[: active_states(m.veh)], w.Q, h, (t_out[i_out] - t) / h, w.xs)
        if settled:
            keep_last_state(w.xs, o)
        else:
            write_sample(i_out, t_out[i_out], w.xs, m, d, o, w)
        i_out += 1
    return i_out


@compiled(inline="always")
def _dense_samples(
    m: Model, d: Data, o: Output, w: Work, t: float, h: float, t_b: float, fsal: bool, i_out: int
) -> int:
    """Output rows and IMU samples in ``(t, t_b]`` of the step of ``h`` (s); the next row.

    Samples without a row (a sweep's run): :func:`_rowless_samples`.
    """
    t_out = m.t_out
    if i_out >= o.out.shape[0]:
        i_out = _rowless_samples(m, d, o, w, t, h, t_b, i_out)
    while i_out < t_out.shape[0] and t_out[i_out] <= t_b:
        dense_eval(d.x[: active_states(m.veh)], w.Q, h, (t_out[i_out] - t) / h, w.xs)
        write_sample(i_out, t_out[i_out], w.xs, m, d, o, w)
        i_out += 1
    sst = d.sst
    while sst[SS_NEXT_T] <= t_b:
        ts = sst[SS_NEXT_T]
        if ts == t_b and fsal:
            # at the end of an uncut step: its solution and derivative (FSAL)
            rotation_matrix(w.x_b[X_QUAT : X_QUAT + 4], w.C)
            take_sample(ts, w.x_b, w.K[6], m, d, o, w)
            continue
        dense_eval(d.x[: active_states(m.veh)], w.Q, h, (ts - t) / h, w.xs)
        sample_at(ts, w.xs, m, d, o, w)
    return i_out


@compiled(inline="always")
def _track_peaks(m: Model, d: Data, o: Output, w: Work, t: float, h: float, sig: float) -> None:
    """Peaks of the active contacts over the step of ``h`` (s) from ``t`` up to fraction ``sig``."""
    for c in range(d.cs.shape[0]):
        e = int(d.cs[c, CS_EPISODE])
        if d.cs[c, CS_ACTIVE] < 0.5 or e < 0:
            continue
        rate_end = observe_peak(m, d, o, w, e, c, sig, t, h)
        # the force peaks before the deflection: look half-way too
        observe_peak(m, d, o, w, e, c, 0.5 * sig, t, h)
        if w.gd_a[c] > 0.0 and rate_end <= 0.0 and sig > 0.0:
            sp = locate(EV_RATE, c, 0.0, m, d, w, h, w.gd_a[c], rate_end, sig)
            observe_peak(m, d, o, w, e, c, sp, t, h)


@compiled(inline="always")
def _process_events(
    t: float, sig: float, tol_sig: float, m: Model, d: Data, o: Output, w: Work
) -> tuple[int, bool]:
    """Onsets and ends located at ``t`` (fraction ``sig`` of the step, within ``tol_sig``).

    ``d.x`` is the state there and ``w.g_a``, ``w.gd_a`` its gaps and rates.
    Returns (the number of events, one per pair; the run ends: a ground onset
    with stop-on-crash).
    """
    stats = o.stats
    n_events = 0
    ended = False
    for c in range(d.cs.shape[0]):
        if w.ev_sig[c] >= NO_EVENT or w.ev_sig[c] > sig + tol_sig:
            continue
        n_events += 1
        if d.cs[c, CS_ACTIVE] >= 0.5:
            close_episode(c, t, d, o)
            continue
        # onset: capture v_i at the located instant
        open_episode(c, t, w.gd_a[c], m, d, o, w)
        if m.shapes[m.pairs[c, PR_SHAPE], SH_IS_GROUND] > 0.5:
            if np.isnan(stats[ST_CRASH_T]):
                record_crash(t, d.x, stats)
                ended = ended or m.opts[O_STOP_ON_CRASH] > 0.5
        elif np.isnan(stats[ST_ONSET_T]):
            stats[ST_ONSET_T] = t
            for i in range(NX):
                stats[ST_ONSET_X + i] = d.x[i]
            first_contact = m.opts[O_POWER_OFF_T] < 0.0 and d.ls[LS_PO_ACTIVE] < 0.5
            if m.sched_t.shape[0] > 0 and first_contact:
                d.ls[LS_T_SCHED] = t  # power-off triggered by the first contact
    return n_events, ended


@compiled(inline="always")
def _arrive(
    uncut: bool, t: float, sig: float, tol_sig: float, m: Model, d: Data, o: Output, w: Work
) -> tuple[int, bool]:
    """At the new state ``d.x`` (time ``t``): extremes, the pairs' gaps, the events there.

    ``uncut``: ``d.x`` is the end of the step just accepted, bit for bit, and
    no contact changed state since the step's events computed its gaps
    (``w.g_b``): they are the gaps at ``d.x`` and are taken, not computed again.
    Returns :func:`_process_events`'s (number of events, the run ends).
    """
    track_extremes(d.x, d.meas[MS_DETECTED] > 0.5, o.stats)
    if uncut:
        copy_into(w.g_a, w.g_b)
        copy_into(w.gd_a, w.gd_b)
        copy_into(w.bnd_a, w.bnd_b)
    else:
        contact_values(d.x, m, d, w, w.g_a, w.gd_a, w.bnd_a)
    return _process_events(t, sig, tol_sig, m, d, o, w)


@compiled
def _fail(stats: np.ndarray, reason: int) -> int:
    stats[ST_STATUS] = STATUS_FAILED
    stats[ST_REASON] = reason
    return FAILED


@compiled(inline="always")
def _after_events(result: int, ended: bool, n_events: int, stats: np.ndarray) -> int:
    """The run's state after the events at a cut: ``ENDED`` (``ended``), ``FAILED`` (more
    than ``MAX_INTERVAL_EVENTS`` events, ``n_events``, in the interval so far) or ``result``."""
    if ended:
        return ENDED
    if n_events > MAX_INTERVAL_EVENTS:
        return _fail(stats, REASON_EVENT_STORM)
    return result


@compiled(inline="always")
def integrate_interval(t: float, t_next: float, m: Model, d: Data, o: Output, w: Work) -> int:
    """Integrate from the tick ``t`` to ``t_next`` (s); ``RUNNING``, ``ENDED`` or ``FAILED``.

    ``w.g_a``, ``w.gd_a`` hold the pairs' gaps and rates at ``(t, d.x)``.
    The interval's contact events (onsets and ends, one per pair) are
    counted: more than ``MAX_INTERVAL_EVENTS`` fail the run
    (``REASON_EVENT_STORM``: a contact chattering at a discontinuous force,
    docs/NUMERICS.md, "Event budget").
    """
    ls = d.ls
    stats = o.stats
    h_max = m.opts[O_H_MAX] if m.opts[O_H_MAX] > 0.0 else m.opts[O_DT_CONTROL]
    max_steps = int(m.opts[O_MAX_STEPS])
    h = ls[LS_H]
    i_out = int(stats[ST_N_OUT])
    n_steps = int(stats[ST_STEPS + IS_N_STEPS])
    n_rej = int(stats[ST_STEPS + IS_N_REJECTED])
    n_rhs = int(stats[ST_STEPS + IS_N_RHS])
    result = RUNNING
    fsal = False
    n_events = 0  # located events in this interval
    tiny = 1e-12 * max(1.0, abs(t_next))  # boundaries closer than this coincide
    while result == RUNNING:
        if t_next - t <= tiny:
            t = t_next
            break
        if ls[LS_T_SCHED] - t <= tiny:
            _schedule_boundary(t, tiny, m, d, o)
            fsal = False
        t_stop = min(t_next, ls[LS_T_SCHED])
        pending = _pending_onsets(d, o, w)
        if n_steps + n_rej >= max_steps:
            result = _fail(stats, REASON_MAX_STEPS)
            break
        h_try = min(h, h_max, t_stop - t)
        if t + 1.01 * h_try >= t_stop:
            h_try = t_stop - t
        if h_try <= 16.0 * 2.2e-16 * max(1.0, abs(t)) and t_stop - t > h_try:
            result = _fail(stats, REASON_STEP_TOO_SMALL)
            break
        tol_sig = 0.0
        if pending:
            sig_min = 0.0
            copy_into(w.x_b, d.x)
            t_b = t
            h_new = h
        else:
            err = _trial_step(m, d, w, h_try, fsal)
            n_rhs += 6 if fsal else 7
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
            tol_sig = m.opts[O_EVENT_TOL] / h_try
            h_new = h_try * step_factor(err, True)
            dense_coefficients(w.K, w.Q, active_states(m.veh))
            sig_min, sig_crash = _step_events(m, d, w, h_try)
            if sig_min <= 1.0:
                t_b = t + sig_min * h_try
                dense_eval(d.x[: active_states(m.veh)], w.Q, h_try, sig_min, w.x_b)
                fsal = False
            else:
                sig_min = 1.0
                t_b = t + h_try
                copy_into(w.x_b, w.x_new)
                copy_into(w.K[0], w.K[6])
                fsal = True
            if t_stop - t_b < tiny:
                t_b = t_stop
            i_out = _dense_samples(m, d, o, w, t, h_try, t_b, fsal, i_out)
            _track_peaks(m, d, o, w, t, h_try, sig_min)
            if sig_crash <= sig_min:
                record_crash(t_b, w.x_b, stats)
                if m.opts[O_STOP_ON_CRASH] > 0.5:
                    result = ENDED
        # ---- advance to t_b and process the events located there ----
        t = t_b
        copy_into(d.x, w.x_b)
        if not all_finite(d.x):
            result = _fail(stats, REASON_NOT_FINITE)
            break
        h = h_new
        # fsal after a trial step: it ended uncut, at d.x
        n_here, ended = _arrive(fsal and not pending, t, sig_min, tol_sig, m, d, o, w)
        fsal = fsal and n_here == 0
        n_events += n_here
        result = _after_events(result, ended, n_events, stats)
    ls[LS_T] = t
    ls[LS_H] = h
    stats[ST_T_END] = t
    stats[ST_N_OUT] = i_out
    stats[ST_STEPS + IS_N_STEPS] = n_steps
    stats[ST_STEPS + IS_N_REJECTED] = n_rej
    stats[ST_STEPS + IS_N_RHS] = n_rhs
    return result
