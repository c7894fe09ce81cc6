"""The wall approach's compiled shooting (``core/approach.py``).

The first contact at ``T_c`` with ``V_c`` is checked for the built-in loop in
``tests/simulation/test_approach.py`` and for a plug-in loop (whose shooting
flies with the plug-in controller) in ``tests/core/test_control.py``. Here:
the two ways the solve can fail are reported as errors that say why, from the
compiled status.
"""

from __future__ import annotations

import pytest

from quadimpact import WallApproach
from quadimpact.core import layout as L
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
