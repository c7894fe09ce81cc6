"""The wall approach's compiled shooting (``core/approach.py``).

The first contact at ``T_c`` with ``V_c`` is checked for the built-in loop in
``tests/simulation/test_approach.py`` and for a plug-in loop (whose shooting
flies with the plug-in controller) in ``tests/core/test_control.py``. Here:
the two ways the solve can fail are reported as errors that say why, from the
compiled status.
"""

from __future__ import annotations

import numpy as np
import pytest

from quadimpact import WallApproach
from quadimpact.core import approach as core_approach
from quadimpact.core import controller_slots as CTL
from quadimpact.core import estimator_slots as ESL
from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP
from quadimpact.core.approach import (
    AP_LATE,
    AP_RUNS,
    AP_STATUS,
    AP_T0,
    AP_X0,
    APPROACH_SOLVED,
    APPROACH_TOL_M_S,
    LATE_START_END_GAP_S,
    LATE_START_MAXITER,
    LATE_START_RTOL,
    LATE_START_XTOL_S,
    _inertial_vx,
)
from quadimpact.core.geometry import NPAIR
from quadimpact.core.kernel import execute
from quadimpact.core.recording_slots import OUT_X
from quadimpact.core.roots import brentq
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.simulation import approach as approach_py
from quadimpact.simulation import setup as setup_py
from quadimpact.simulation.setup import prepare

T_C = 0.5  # s, the scenarios' impact time


def _solve_inputs(monkeypatch: pytest.MonkeyPatch, scenario: WallApproach) -> dict:
    """The arguments ``prepare`` hands to the approach solve for ``scenario``."""
    seen: dict = {}
    real = setup_py.solve_approach

    def spy(**kw):
        seen.update(kw)
        return real(**kw)

    monkeypatch.setattr(setup_py, "solve_approach", spy)
    prepare(scenario)
    monkeypatch.setattr(setup_py, "solve_approach", real)
    return seen


def test_a_failed_shooting_run_is_an_error_with_its_reason(monkeypatch):
    kw = _solve_inputs(monkeypatch, WallApproach(heading_deg=0, inclination_deg=5, speed_m_s=1.0))
    opts = kw["free_opts"].copy()
    opts[L.O_MAX_STEPS] = 3  # the free flight to T_c needs hundreds of steps
    with pytest.raises(RuntimeError, match="approach shooting run failed: step budget exhausted"):
        approach_py.solve_approach(**{**kw, "free_opts": opts})


def test_a_late_start_without_a_bracket_is_an_error(monkeypatch):
    """Leaning toward the wall, arriving at rest (V_c = 0) needs v0 < 0, and no later
    start at rest reaches the wall at zero speed: the residual keeps its sign."""
    kw = _solve_inputs(monkeypatch, WallApproach(heading_deg=0, inclination_deg=20, speed_m_s=0.5))
    x0, t0, found = approach_py.solve_approach(**kw)
    assert found["late_start"] and 0.0 < t0 < T_C  # the scenario as it is: a late start
    with pytest.raises(ValueError, match="no late start reaches the wall"):
        approach_py.solve_approach(**{**kw, "speed_m_s": 0.0})


def _runs(monkeypatch: pytest.MonkeyPatch, scenario: WallApproach) -> tuple[int, float]:
    """Free-flight runs the shooting flew for ``scenario``, and the start time it found."""
    ap = approach_py.shooting_record(**_solve_inputs(monkeypatch, scenario))
    assert ap[AP_STATUS] == APPROACH_SOLVED
    return int(ap[AP_RUNS]), float(ap[AP_T0])


def _speed_at_impact_from_rest(kw: dict, t: float) -> float:
    """Inertial X speed (m/s) at ``T_c`` of a free flight (no wall) from rest at ``t`` (s),
    from the start before any X shift: one run of the late start's search."""
    x0 = np.zeros(L.NX)
    x0[L.X_POS : L.X_POS + 3] = kw["start"] + 0.0
    x0[L.X_QUAT : L.X_QUAT + 4] = kw["q"]
    x0[L.X_ROTOR : L.X_ROTOR + len(kw["rotors"])] = kw["rotors"]
    span = np.zeros(L.NSPAN)
    span[L.SPAN_T0], span[L.SPAN_TF] = t, kw["impact_time_s"]
    free = kw["run"]._replace(
        x0=x0,
        span=span,
        shapes=np.zeros((0, SHP.NSHAPE)),
        pairs=np.zeros((0, NPAIR), dtype=np.int64),
        opts=kw["free_opts"],
        scfg=np.zeros(IMS.NSCFG),
        noise=np.zeros((0, 6)),
        t_out=np.array([float(kw["impact_time_s"])]),
    )
    out = execute(free, kernel=kw["kernel"]).out
    return _inertial_vx(np.ascontiguousarray(out[0, OUT_X : OUT_X + L.NX]), np.empty((3, 3)))


def test_an_approach_without_late_start_flies_a_run_and_its_check(monkeypatch):
    """The replica's rule keeps t = 0 here: one run gives the corrections (the
    velocity gained and the depth are exact shifts), a second checks them."""
    scenario = WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75,
                            model="paper-replica")  # fmt: skip
    runs, t0 = _runs(monkeypatch, scenario)
    assert t0 == 0.0
    assert runs == 2


def test_a_late_start_finds_brents_root_in_a_few_runs(monkeypatch):
    """The default's rule starts the paper's example late, at rest. The first
    solve stops at its first correction (v0 far below 0: the late start
    replaces it). The secant search from the constant-acceleration guess finds
    the start time that Brent's method finds on the same runs, to Brent's
    tolerance, in at most four runs; its last run, at the root, is the late
    solve's first, and its X shift needs no run of its own (the authors'
    controller reads no X: the test below)."""
    scenario = WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75)
    runs, t0 = _runs(monkeypatch, scenario)
    assert 0.0 < t0 < T_C
    kw = _solve_inputs(monkeypatch, scenario)
    searched: list[float] = []

    def speed_gap(t: float) -> float:  # one run of Brent's search, from rest at t
        searched.append(t)
        return _speed_at_impact_from_rest(kw, t) - kw["speed_m_s"]

    root = brentq(speed_gap, 0.0, T_C - LATE_START_END_GAP_S, LATE_START_XTOL_S, LATE_START_RTOL,
                  LATE_START_MAXITER)  # fmt: skip
    brent_runs = len(searched)
    assert abs(t0 - root) <= LATE_START_XTOL_S + LATE_START_RTOL * root
    assert abs(speed_gap(t0)) <= APPROACH_TOL_M_S
    assert runs <= 1 + 4
    assert runs < brent_runs  # the whole shooting, against Brent's search alone


def test_a_late_starts_x_shift_is_exact_when_nothing_in_the_flight_reads_x(monkeypatch):
    """The authors' controller with the ideal estimator reads no position along X, so the
    late start's X shift moves the depth at T_c one to one and the speed not at all: the
    shooting takes it without flying it again. The run it skips would find the same
    start, the same speed residual and no depth, to the bit."""
    scenario = WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75)
    kw = _solve_inputs(monkeypatch, scenario)
    assert core_approach._ignores_x(kw["run"])
    skipped = approach_py.shooting_record(**kw)
    monkeypatch.setattr(core_approach, "_ignores_x", lambda m: False)  # fly the check
    checked = approach_py.shooting_record(**kw)
    assert skipped[AP_T0] > 0.0  # a late start
    assert skipped[AP_RUNS] == checked[AP_RUNS] - 1
    found = slice(AP_X0, AP_LATE + 1)  # the start, its time, v0, the speed residual, late
    assert np.array_equal(skipped[found], checked[found])


def test_a_controller_that_may_read_x_keeps_the_check_of_the_x_shift(monkeypatch):
    """Only the authors' controller with the ideal estimator is known to ignore X."""
    kw = _solve_inputs(monkeypatch, WallApproach(heading_deg=45, inclination_deg=15,
                                                 speed_m_s=0.75))  # fmt: skip
    ctrl = kw["run"].ctrl.copy()
    ctrl[CTL.C_KIND] = L.CTRL_CASCADE_PID
    assert not core_approach._ignores_x(kw["run"]._replace(ctrl=ctrl))
    ecfg = kw["run"].ecfg.copy()
    ecfg[ESL.EC_KIND] = L.EST_EKF
    assert not core_approach._ignores_x(kw["run"]._replace(ecfg=ecfg))
