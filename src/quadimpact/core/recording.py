"""What the loop records: output rows, contact episodes and their peaks, extremes, the crash.

All functions write into the run's :class:`~quadimpact.core.records.Output`
(layouts ``OUT_*`` and ``E_*`` in ``core/recording_slots.py``, ``ST_*`` in
``core/layout.py``); none changes the dynamics. Per contact feature an output
row holds its deflection (the deepest of its pairs, >= 0, m) and its normal
force (the sum over its active pairs, N).
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.contact import pair_damping, pair_normal_force
from quadimpact.core.contact_slots import CS_ACTIVE, CS_EPISODE, CS_LAMBDA
from quadimpact.core.controller_slots import C_PHI_REF, C_PSI_REF, C_THETA_REF, C_Z_REF
from quadimpact.core.excursion import excursion_add, settled
from quadimpact.core.excursion_slots import NEX
from quadimpact.core.geometry import (
    GEOM_RING_PLANE,
    PR_FEATURE,
    PR_GEOMETRY,
    PR_SHAPE,
    has_bound,
    pair_bound,
    pair_depth,
)
from quadimpact.core.geometry.plane import ring_plane
from quadimpact.core.integrator import dense_eval
from quadimpact.core.layout import (
    LS_STAGE,
    MAX_ROTORS,
    NX,
    O_V_MIN,
    ST_CRASH_T,
    ST_CRASH_X,
    ST_EPISODES_DROPPED,
    ST_EXCURSION,
    ST_LAST_ONSET_T,
    ST_MAX_RATE,
    ST_MIN_ALT,
    ST_MIN_TILT_COS,
    ST_N_EPISODES,
    ST_STATUS,
    ST_X_LAST,
    STATUS_CRASHED,
    X_OMEGA,
    X_POS,
    X_QUAT,
)
from quadimpact.core.quaternion import rotation_matrix
from quadimpact.core.recording_slots import (
    E_FEATURE,
    E_OPEN,
    E_PEAK_DELTA,
    E_PEAK_FORCE,
    E_SHAPE,
    E_T_END,
    E_T_PEAK,
    E_T_PEAK_FORCE,
    E_T_START,
    E_V_I,
    OUT_CMD,
    OUT_DELTA,
    OUT_STAGE,
    OUT_T,
    OUT_X,
)
from quadimpact.core.records import Data, Model, Output, Work
from quadimpact.core.rotors import RIN_CMD, active_states
from quadimpact.core.sensors.disturbance import impact_onset


@compiled(inline="always")
def add_attitude(xs: np.ndarray, m: Model, o: Output, w: Work) -> None:
    """A sample's attitude (the quaternion of ``xs``, its rotation into ``w.C``) joins the
    run's excursion (``ST_EXCURSION``): all of a sample that has no row and is not kept as
    the last state (:func:`write_sample`'s first part, which reads only the quaternion)."""
    rotation_matrix(xs[X_QUAT : X_QUAT + 4], w.C)
    excursion_add(
        w.C,
        m.ctrl[C_PHI_REF],
        m.ctrl[C_THETA_REF],
        m.ctrl[C_PSI_REF],
        m.ctrl[C_Z_REF : C_Z_REF + 3],
        o.stats[ST_EXCURSION : ST_EXCURSION + NEX],
    )


@compiled(inline="always")
def keep_last_state(xs: np.ndarray, o: Output) -> None:
    """The sample's state ``xs`` kept as the last one (``ST_X_LAST``, what the summary reads)."""
    for i in range(NX):
        o.stats[ST_X_LAST + i] = xs[i]


@compiled
def attitude_settled(x: np.ndarray, Q: np.ndarray, h: float, m: Model, o: Output, w: Work) -> bool:
    """Whether no sample of the step of ``h`` (s) from ``x`` can change the run's excursion.

    The step's dense output (coefficients ``Q``) moves the quaternion from
    ``x``'s by at most ``r = |h| sqrt(sum_i (sum_k |Q[i, k]|)^2)`` (its
    components ``i``, its powers ``k``; ``sigma`` in [0, 1]); the unit
    quaternions by at most ``2 r / |q|``, and a rotation's entries by at most
    4 times that (their gradients on the unit ball). ``excursion.settled``
    then says whether any sample within that reach of ``x``'s rotation
    (``w.C`` receives it) could change the excursion. True: the step's samples
    without a row can be left out of it, bit for bit.
    """
    r2 = 0.0
    for i in range(X_QUAT, X_QUAT + 4):
        ri = abs(h) * (abs(Q[i, 0]) + abs(Q[i, 1]) + abs(Q[i, 2]) + abs(Q[i, 3]))
        r2 += ri * ri
    q = x[X_QUAT : X_QUAT + 4]
    nq = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    r = math.sqrt(r2)
    if not r < 0.1 * nq:
        return False
    rotation_matrix(q, w.C)
    dc = 8.0 * r / nq
    return settled(
        w.C,
        dc,
        m.ctrl[C_THETA_REF],
        m.ctrl[C_Z_REF : C_Z_REF + 3],
        o.stats[ST_EXCURSION : ST_EXCURSION + NEX],
    )


@compiled
def write_sample(row: int, t: float, xs: np.ndarray, m: Model, d: Data, o: Output, w: Work) -> None:
    """The output sample ``row`` at time ``t`` (s) of the state ``xs``.

    Every sample: its attitude joins the run's excursion (``excursion_add``,
    stats ``ST_EXCURSION``) and its state is kept as the last one
    (``ST_X_LAST``). Its row (state, command, stage, contacts) is written
    where the output has rows: a sweep's runs have none
    (``records.new_output(..., rows=False)``), since their summary reads
    only the excursion and the last state. The contacts (each feature's
    deflection and normal force, from the contact geometry of every pair)
    only where the rows have their columns
    (``records.new_output(..., contact_columns=False)`` skips that work).
    A ring against a plane takes its depth (and, in contact, its rate) from
    the closed form inlined here (``geometry.plane.ring_plane``): the rest of
    its record is not computed, nor its force out of contact.
    """
    out = o.out
    nf = m.feat.shape[0]
    add_attitude(xs, m, o, w)
    keep_last_state(xs, o)
    if row >= out.shape[0]:
        return
    out[row, OUT_T] = t
    for i in range(NX):
        out[row, OUT_X + i] = xs[i]
    for j in range(MAX_ROTORS):  # a copy: zeros beyond the vehicle's rotors
        out[row, OUT_CMD + j] = d.rin[RIN_CMD + j]
    out[row, OUT_STAGE] = d.ls[LS_STAGE]
    if out.shape[1] <= OUT_DELTA:
        return
    for f in range(nf):
        out[row, OUT_DELTA + f] = 0.0
        out[row, OUT_DELTA + nf + f] = 0.0
    for c in range(d.cs.shape[0]):
        f = m.pairs[c, PR_FEATURE]
        active = d.cs[c, CS_ACTIVE] > 0.5
        if m.pairs[c, PR_GEOMETRY] == GEOM_RING_PLANE:  # the closed form, inlined
            rec = ring_plane(xs, w.C, m.feat, f, m.shapes, m.pairs[c, PR_SHAPE])
            if rec[0] > out[row, OUT_DELTA + f]:
                out[row, OUT_DELTA + f] = rec[0]
            if active:
                lam = d.cs[c, CS_LAMBDA]
                out[row, OUT_DELTA + nf + f] += pair_normal_force(m, c, rec[0], rec[1], lam)
            continue
        if not active and has_bound(m.pairs, c):
            if pair_bound(xs, w.C, m.feat, m.shapes, m.pairs, c)[0] < 0.0:
                continue  # apart (the broad phase): no deflection, no force
        dp, dd = pair_depth(xs, w.C, m.feat, m.shapes, m.pairs, c)
        if dp > out[row, OUT_DELTA + f]:
            out[row, OUT_DELTA + f] = dp
        if d.cs[c, CS_ACTIVE] > 0.5:
            out[row, OUT_DELTA + nf + f] += pair_normal_force(m, c, dp, dd, d.cs[c, CS_LAMBDA])


@compiled
def track_peak(o: Output, e: int, t: float, delta: float, force: float) -> None:
    """Update episode ``e``'s peak deflection (m) and peak force (N) with a new observation."""
    if e < 0:
        return
    ep = o.episodes
    if delta > ep[e, E_PEAK_DELTA]:
        ep[e, E_PEAK_DELTA] = delta
        ep[e, E_T_PEAK] = t
    if force > ep[e, E_PEAK_FORCE]:
        ep[e, E_PEAK_FORCE] = force
        ep[e, E_T_PEAK_FORCE] = t


@compiled
def observe_peak(
    m: Model, d: Data, o: Output, w: Work, e: int, c: int, sigma: float, t: float, h: float
) -> float:
    """Track episode ``e``'s peaks with pair ``c`` at ``t + sigma h`` on the step's dense output.

    The step starts at ``d.x`` (time ``t``, s) with size ``h`` (s) and
    coefficients ``w.Q``. Returns the penetration rate there (m/s).
    """
    dense_eval(d.x[: active_states(m.veh)], w.Q, h, sigma, w.xs)
    rotation_matrix(w.xs[X_QUAT : X_QUAT + 4], w.C)
    dp, dd = pair_depth(w.xs, w.C, m.feat, m.shapes, m.pairs, c)
    track_peak(o, e, t + sigma * h, dp, pair_normal_force(m, c, dp, dd, d.cs[c, CS_LAMBDA]))
    return dd


@compiled
def open_episode(c: int, t: float, gd: float, m: Model, d: Data, o: Output, w: Work) -> None:
    """Onset of pair ``c`` at ``t`` (s), state ``d.x``, rate ``gd`` (m/s): damping, episode."""
    cs = d.cs
    stats = o.stats
    episodes = o.episodes
    cs[c, CS_ACTIVE] = 1.0
    cs[c, CS_LAMBDA] = pair_damping(m, c, gd, m.opts[O_V_MIN])
    impact_onset(t, m.scfg, stats)  # the IMU's impact disturbance (off unless configured)
    stats[ST_LAST_ONSET_T] = t
    n_ep = int(stats[ST_N_EPISODES])
    if n_ep < episodes.shape[0]:
        rotation_matrix(d.x[X_QUAT : X_QUAT + 4], w.C)
        dp, _ = pair_depth(d.x, w.C, m.feat, m.shapes, m.pairs, c)
        e = n_ep
        episodes[e, E_FEATURE] = m.pairs[c, PR_FEATURE]
        episodes[e, E_SHAPE] = m.pairs[c, PR_SHAPE]
        episodes[e, E_T_START] = t
        episodes[e, E_T_END] = np.nan
        episodes[e, E_V_I] = gd
        episodes[e, E_PEAK_DELTA] = max(dp, 0.0)
        episodes[e, E_T_PEAK] = t
        episodes[e, E_PEAK_FORCE] = 0.0
        episodes[e, E_T_PEAK_FORCE] = t
        episodes[e, E_OPEN] = 1.0
        cs[c, CS_EPISODE] = e
        stats[ST_N_EPISODES] = n_ep + 1
    else:
        cs[c, CS_EPISODE] = -1.0
        stats[ST_EPISODES_DROPPED] += 1.0


@compiled
def close_episode(c: int, t: float, d: Data, o: Output) -> None:
    """End of pair ``c``'s contact at ``t`` (s)."""
    cs = d.cs
    cs[c, CS_ACTIVE] = 0.0
    cs[c, CS_LAMBDA] = 0.0
    e = int(cs[c, CS_EPISODE])
    if e >= 0:
        o.episodes[e, E_T_END] = t
        o.episodes[e, E_OPEN] = 0.0
    cs[c, CS_EPISODE] = -1.0


@compiled
def track_extremes(x: np.ndarray, detected: bool, stats: np.ndarray) -> None:
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


@compiled
def record_crash(t: float, x: np.ndarray, stats: np.ndarray) -> None:
    """The crash at ``t`` (s) with the CM at ``x``'s position."""
    stats[ST_CRASH_T] = t
    for i in range(3):
        stats[ST_CRASH_X + i] = x[X_POS + i]
    stats[ST_STATUS] = STATUS_CRASHED
