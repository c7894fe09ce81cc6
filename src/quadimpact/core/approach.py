"""The wall approach's shooting, compiled: the start that brings first contact at T_c.

The paper's wall approach (docs/STUDIES.md section 1) holds an attitude and
an altitude from the start and must touch the wall first at ``T_c`` with the
speed ``V_c`` toward it. Without aerodynamic drag nothing in the dynamics
depends on X or V_X, so ``V_X(T_c) = v0 + A`` and the leading feature's depth
at ``T_c`` shifts one to one with X0: one free-flight run (no shapes, no IMU,
no crash) gives A and the depth, a correction of v0 and a shift of X0 make
the first contact happen at ``T_c`` with ``V_X = V_c`` (repeated until both
residuals are below ``APPROACH_TOL_M_S``, at most ``APPROACH_MAX_ITER``
runs). If that needs ``v0 < 0``, the vehicle starts later, at rest, at the
``t0`` found by the secant method on ``V_X(T_c; t0) = V_c``, one free-flight
run per evaluation, from the guess of a constant acceleration (Brent's method,
``core/roots.py``, if the secant leaves ``[0, T_c)``). No run is flown twice:
the first solve stops at a correction that leaves v0 far below 0 (the late
start replaces it), and the search's last run, at the root, is the late
solve's first (``AP_RUNS`` counts the runs). Nor is the late start's X shift
flown to be checked when nothing in the free flight reads X (the authors'
controller with the ideal estimator, :func:`_ignores_x`): its run would give
the same speed residual, to the bit, and a depth of zero.

:func:`solve_approach` drives it from Python: the free-flight runs are the
loop's own compiled ``start`` and ``advance`` (so a plug-in kernel's copies,
``core.kernel.make_kernel``, shoot with the plug-in controller), the depths
the contact geometry's. It is not compiled itself: a compiled driver would
link a second copy of the whole loop into its own machine code, about 15 s
of the simulator's cold compile (docs/PERFORMANCE.md), for a few Python
calls per run. It reads its inputs from and writes what it found to one
array (``ap``, slots ``AP_*``, declared below);
``quadimpact.simulation.approach`` packs it and reads it back.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.controller_slots import C_KIND, C_STEP
from quadimpact.core.estimator_slots import EC_KIND, EC_STEP
from quadimpact.core.geometry import pair_contact
from quadimpact.core.layout import (
    CTRL_PAPER,
    EST_IDEAL,
    MAX_ROTORS,
    NX,
    SPAN_T0,
    SPAN_TF,
    ST_N_OUT,
    ST_REASON,
    ST_STATUS,
    STATUS_FAILED,
    X_POS,
    X_QUAT,
    X_ROTOR,
    X_VEL,
    Block,
)
from quadimpact.core.quaternion import rotation_matrix
from quadimpact.core.recording_slots import OUT_X
from quadimpact.core.records import Model, Output, new_data
from quadimpact.core.roots import BR_X, BRENT_ASK, BRENT_NO_BRACKET, NBR, brent_next, brent_start
from quadimpact.core.step import advance, start

__all__ = ["APPROACH_MAX_ITER", "APPROACH_TOL_M_S", "solve_approach"]

# ---- the shooting's record ap (NAP): its inputs, then what it found; inertial NED,
# the wall's normal along -X
_ap = Block("approach", "AP_")
AP_TC = _ap.slot("AP_TC")  # s, T_c: the first contact's time
AP_VC = _ap.slot("AP_VC")  # m/s, V_c: the speed toward the wall at T_c (inertial X)
AP_LATE_RULE = _ap.slot("AP_LATE_RULE")  # 1: start later at rest whenever v0 < 0 is needed
AP_START = _ap.slot("AP_START", 3)  # m, the initial CM position before the X shift
AP_Q = _ap.slot("AP_Q", 4)  # the attitude held (quaternion, body FRD to inertial)
AP_ROTORS = _ap.slot("AP_ROTORS", MAX_ROTORS)  # rad/s, initial rotor speeds
AP_X0 = _ap.slot("AP_X0", NX)  # found: the initial state (layout X_*)
AP_T0 = _ap.slot("AP_T0")  # s, found: the start time (0 unless a late start)
AP_V0 = _ap.slot("AP_V0")  # m/s, found: the start speed (inertial X)
AP_DV = _ap.slot("AP_DV")  # m/s, found: the speed residual at T_c
AP_LATE = _ap.slot("AP_LATE")  # found: 1 if the vehicle starts later, at rest
AP_STATUS = _ap.slot("AP_STATUS")  # APPROACH_*
AP_REASON = _ap.slot("AP_REASON")  # REASON_* of a failed shooting run
AP_RUNS = _ap.slot("AP_RUNS")  # found: the free-flight runs the shooting flew
NAP = _ap.end("NAP")
APPROACH_SOLVED = 0
APPROACH_RUN_FAILED = 1  # a shooting run failed (AP_REASON) or sampled no state at T_c
APPROACH_NO_BRACKET = 2  # the late start's speed residual has one sign over [0, T_c)

APPROACH_TOL_M_S = 1e-12  # shooting residuals (speed m/s, depth m)
APPROACH_MAX_ITER = 4
LATE_START_XTOL_S = 1e-14  # the search's tolerances on the late start time (s, relative)
LATE_START_RTOL = 4.0 * 2.220446049250313e-16
LATE_START_MAXITER = 100
LATE_START_END_GAP_S = 1e-9  # the bracket ends this far before T_c
LATE_START_SECANT_MAXITER = 12  # secant runs before the search falls back to Brent's method
# A first solve whose corrected v0 is below this (m/s) under the late-start rule
# stops there: a further run would only remove rounding from a v0 < 0 that the
# late start replaces (the run's corrections are of order 1e-15 m/s).
LATE_START_DECIDED_M_S = -1e-6


class _Flights:
    """The free-flight runs of one solve: the run ``m`` and its output ``o``, flown by
    the loop's compiled ``start`` and ``advance`` (``loop``), and what every run shares.

    One loop state ``d`` serves every run (``start`` initialises each of its
    arrays from the run's ``x0`` and ``span``), and the attitude held is turned
    into its rotation ``C`` once: the runs are the same to the bit as with a
    fresh state each, for two compiled calls fewer per run.
    """

    __slots__ = ("m", "o", "ap", "d", "C", "xe", "Ce", "start", "advance")

    def __init__(self, m: Model, o: Output, ap: np.ndarray, loop: tuple[Callable, Callable]):
        self.m = m
        self.o = o
        self.ap = ap
        self.d = new_data(m)
        self.C = np.empty((3, 3))
        rotation_matrix(ap[AP_Q : AP_Q + 4], self.C)
        self.xe = np.empty(NX)  # a run's state at T_c
        self.Ce = np.empty((3, 3))  # its rotation
        self.start, self.advance = loop

    def start_state(self, v0: float, x_start: float) -> None:
        """The start at ``V_X = v0`` and ``X0 + x_start``, into ``m.x0`` and ``ap[AP_X0]``."""
        ap = self.ap
        C = self.C
        x0 = self.m.x0
        x0[:] = 0.0  # omega 0: the vehicle starts at rest in rotation
        # the start shifted by (x_start, 0, 0) and the body velocity C^T (v0, 0, 0), with
        # every term of the vector sums (the + 0.0 and * 0.0 turn -0.0 into +0.0 as the
        # vector arithmetic does: the state is the same to the bit as from
        # simulation.approach.initial_state)
        x0[X_POS] = ap[AP_START] + x_start
        x0[X_POS + 1] = ap[AP_START + 1] + 0.0
        x0[X_POS + 2] = ap[AP_START + 2] + 0.0
        for j in range(3):
            x0[X_VEL + j] = C[0, j] * v0 + C[1, j] * 0.0 + C[2, j] * 0.0
        x0[X_QUAT : X_QUAT + 4] = ap[AP_Q : AP_Q + 4]
        x0[X_ROTOR : X_ROTOR + MAX_ROTORS] = ap[AP_ROTORS : AP_ROTORS + MAX_ROTORS]
        ap[AP_X0 : AP_X0 + NX] = x0

    def shoot(self, t0: float, v0: float, x_start: float) -> bool:
        """Fly ``m`` from ``t0`` to ``T_c``, starting at ``V_X = v0`` and ``X0 + x_start``.

        The initial state goes to ``m.x0`` and ``ap[AP_X0]`` (:meth:`start_state`),
        the state at ``T_c`` to ``xe``; False if the run failed or sampled no
        state at ``T_c``.
        """
        m = self.m
        o = self.o
        ap = self.ap
        self.start_state(v0, x_start)
        m.span[SPAN_T0] = t0
        m.span[SPAN_TF] = ap[AP_TC]
        ap[AP_RUNS] += 1.0
        self.start(m, self.d, o)
        self.advance(-1, m, self.d, o)
        stats = o.stats
        if stats[ST_STATUS] == STATUS_FAILED or stats[ST_N_OUT] != 1:
            ap[AP_STATUS] = APPROACH_RUN_FAILED
            ap[AP_REASON] = stats[ST_REASON]
            return False
        self.xe[:] = o.out[0, OUT_X : OUT_X + NX]
        return True

    def vx(self) -> float:
        """Inertial X velocity (m/s) of the last run at ``T_c``."""
        return _inertial_vx(self.xe, self.Ce)


@compiled
def _inertial_vx(x: np.ndarray, C: np.ndarray) -> float:
    """Inertial X velocity (m/s) of the state ``x``; ``C`` receives its rotation."""
    rotation_matrix(x[X_QUAT : X_QUAT + 4], C)
    return C[0, 0] * x[X_VEL] + C[0, 1] * x[X_VEL + 1] + C[0, 2] * x[X_VEL + 2]


@compiled
def _deepest(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, wall: np.ndarray, pairs: np.ndarray
) -> float:
    """Largest penetration (m) of any feature into the wall at ``x`` (NaN if any is NaN)."""
    rotation_matrix(x[X_QUAT : X_QUAT + 4], C)
    best = -math.inf
    for c in range(pairs.shape[0]):
        depth = pair_contact(x, C, feat, wall, pairs, c)[0]
        if depth != depth:
            return depth
        if depth > best:
            best = depth
    return best


def _ignores_x(m: Model) -> bool:
    """True if nothing in the free flight of ``m`` reads the position along X.

    The dynamics never do (no drag, no shape in a free flight); the authors'
    controller reads the attitude, the altitude and the climb rate, and the
    ideal estimator gives it the state. Another controller may hold a
    position (``hover``, ``waypoint``, the recovery controller's hold, a plug-in),
    and another estimator may carry one.
    """
    ctrl = m.ctrl
    ecfg = m.ecfg
    return (
        int(ctrl[C_KIND]) == CTRL_PAPER
        and ctrl[C_STEP] == 0.0
        and int(ecfg[EC_KIND]) == EST_IDEAL
        and ecfg[EC_STEP] == 0.0
    )


def _solve_from(
    t0: float,
    v0: float,
    f: _Flights,
    wall: np.ndarray,
    pairs: np.ndarray,
    flown: bool,
    v0_below: float,
) -> bool:
    """Correct v0 (unless at rest after ``t0 > 0``) and X0 until the residuals vanish.

    ``flown``: the first run (``t0``, ``v0``, no X shift) has flown already,
    its state at ``T_c`` is in ``f.xe`` and its start in ``AP_X0`` (the late
    start search's last run, when the root is the last time it asked). A
    correction that leaves v0 below ``v0_below`` (m/s) ends the solve (a late
    start follows). Writes ``AP_X0``, ``AP_V0``, ``AP_DV``; False if a run failed.
    """
    ap = f.ap
    tc = ap[AP_TC]
    vc = ap[AP_VC]
    x_start = 0.0
    dv = 0.0
    x_free = _ignores_x(f.m)
    for k in range(APPROACH_MAX_ITER):
        if not (flown and k == 0) and not f.shoot(t0, v0, x_start):
            return False
        dv = vc - f.vx()
        depth = _deepest(f.xe, f.Ce, f.m.feat, wall, pairs)
        if abs(dv) <= APPROACH_TOL_M_S and abs(depth) <= APPROACH_TOL_M_S:
            break
        if t0 == 0.0 or v0 != 0.0:
            v0 += dv
            x_start -= depth + dv * (tc - t0)
            if v0 < v0_below:
                break
        else:
            x_start -= depth
            if x_free:  # the shifted run would give the same dv to the bit, the depth 0
                f.start_state(v0, x_start)
                break
    ap[AP_V0] = v0
    ap[AP_DV] = dv
    return True


def _late_start_secant(f: _Flights) -> float:
    """The late start ``t0`` (s) by the secant method on ``V_X(T_c; t0) = V_c``; NaN if
    it leaves ``[0, T_c)`` or does not converge (``AP_STATUS`` tells a failed run).

    The first guess is a constant acceleration: a flight of ``T_c`` gains ``A =
    V_c - v0`` (the first solve's v0), so ``t0 = T_c (1 - V_c / A)``; the second
    point is the flight of zero length (``V_X = 0`` at ``t0 = T_c``). The search
    stops as Brent's did, when the step is below ``xtol + rtol |t0|``, at a time
    it flew: its last run is the late start's run from rest at the root.
    """
    ap = f.ap
    tc = ap[AP_TC]
    vc = ap[AP_VC]
    end = tc - LATE_START_END_GAP_S
    gain = vc - ap[AP_V0]
    a = tc
    fa = -vc
    b = tc * (1.0 - vc / gain)
    for _ in range(LATE_START_SECANT_MAXITER):
        if not (0.0 <= b <= end):
            return math.nan
        if not f.shoot(b, 0.0, 0.0):
            return math.nan
        fb = f.vx() - vc
        if fb == 0.0:
            return b
        if fb == fa or fb != fb:
            return math.nan
        c = b - fb * (b - a) / (fb - fa)
        if abs(c - b) <= LATE_START_XTOL_S + LATE_START_RTOL * abs(b):
            return b
        a = b
        fa = fb
        b = c
    return math.nan


def solve_approach(
    m: Model,
    o: Output,
    wall: np.ndarray,
    pairs: np.ndarray,
    ap: np.ndarray,
    *,
    start: Callable = start,
    advance: Callable = advance,
) -> None:
    """Find the initial state and time that bring the first contact at ``T_c`` with ``V_c``.

    Parameters
    ----------
    m : Model
        The free-flight run: the vehicle, its features, the controller and
        the power-off schedule; no shapes, no IMU, no crash; ``t_out = [T_c]``.
        Its ``x0`` and ``span`` are overwritten at every shooting run.
    o : Output
        Its output (one row, no IMU samples, one episode).
    wall : numpy.ndarray, shape (1, NSHAPE)
        The wall alone, inertial.
    pairs : numpy.ndarray, shape (n_features, NPAIR), int64
        The pair table of the vehicle's features against the wall.
    ap : numpy.ndarray, shape (NAP,)
        In: ``AP_TC``, ``AP_VC``, ``AP_LATE_RULE``, ``AP_START``, ``AP_Q``,
        ``AP_ROTORS``. Out: ``AP_X0``, ``AP_T0``, ``AP_V0``, ``AP_DV``,
        ``AP_LATE``, ``AP_STATUS`` (``APPROACH_*``; ``AP_REASON`` for a
        failed run) and ``AP_RUNS`` (the free-flight runs flown).
    start, advance : compiled functions
        The loop's ``core.step.start`` and ``core.step.advance`` (a plug-in
        kernel's copies: ``core.kernel.make_kernel``), which fly every run.
    """
    f = _Flights(m, o, ap, (start, advance))
    ap[AP_STATUS] = APPROACH_SOLVED
    ap[AP_REASON] = 0.0
    ap[AP_T0] = 0.0
    ap[AP_LATE] = 0.0
    ap[AP_RUNS] = 0.0
    vc = ap[AP_VC]
    decided = LATE_START_DECIDED_M_S if ap[AP_LATE_RULE] != 0.0 else -math.inf
    if not _solve_from(0.0, vc, f, wall, pairs, False, decided):
        return
    late = False
    if ap[AP_V0] < 0.0:
        late = ap[AP_LATE_RULE] != 0.0
        if not late:  # the authors' rule: start later only from beyond the wall
            x0 = ap[AP_X0 : AP_X0 + NX].copy()
            late = _deepest(x0, np.empty((3, 3)), m.feat, wall, pairs) > 0.0
    if not late:
        return
    t0 = _late_start_secant(f)
    if ap[AP_STATUS] == APPROACH_RUN_FAILED:
        return
    if t0 == t0:
        ap[AP_T0] = t0
        ap[AP_LATE] = 1.0
        _solve_from(t0, 0.0, f, wall, pairs, True, -math.inf)
        return
    br = np.empty(NBR)
    brent_start(
        br,
        0.0,
        ap[AP_TC] - LATE_START_END_GAP_S,
        LATE_START_XTOL_S,
        LATE_START_RTOL,
        LATE_START_MAXITER,
    )
    code = BRENT_ASK
    last = math.nan  # the start time of the search's last run
    while code == BRENT_ASK:
        last = br[BR_X]
        if not f.shoot(last, 0.0, 0.0):
            return
        code = brent_next(br, f.vx() - vc)
    if code == BRENT_NO_BRACKET:
        ap[AP_STATUS] = APPROACH_NO_BRACKET
        return
    t0 = br[BR_X]
    ap[AP_T0] = t0
    ap[AP_LATE] = 1.0
    _solve_from(t0, 0.0, f, wall, pairs, t0 == last, -math.inf)
