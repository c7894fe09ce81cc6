"""Simulation advanced tick by tick reproduces simulate(): every summary number, every episode."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadimpact import ImpactTrial, Simulation, WallApproach, simulate
from quadimpact.core import layout as L


def _compare(a, b, path="summary"):
    """Recursively equal, numbers to 1e-12 (relative), wall-clock and CPU timings skipped."""
    if isinstance(a, dict):
        assert set(a) == set(b), path
        for k in a:
            if k in ("wall_time_s", "cost"):
                continue
            _compare(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _compare(x, y, f"{path}[{i}]")
    elif isinstance(a, float) and isinstance(b, float):
        if math.isnan(a):
            assert math.isnan(b), path
        else:
            assert b == pytest.approx(a, rel=1e-12, abs=1e-15), path
    else:
        assert a == b, path


@pytest.mark.parametrize("model", ["paper-replica", "default"])
@pytest.mark.parametrize("controller", ["paper", "cascade-pid"])
def test_tick_by_tick_reproduces_simulate(model, controller):
    s = WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75, model=model,
                     controller=controller)  # fmt: skip
    whole = simulate(s)
    sim = Simulation(s)
    ticks = 0
    while not sim.done:
        ticks += sim.advance(1)
    stepped = sim.result()
    assert ticks == whole.summary["integrator"]["control_ticks"]
    _compare(whole.summary, stepped.summary)
    assert whole.episodes.equals(stepped.episodes)
    assert whole.timeseries.equals(stepped.timeseries)
    assert whole.imu.equals(stepped.imu)
    assert len(whole.episodes) >= 3  # the example really hits the wall more than once


def test_impact_trial_stepping_and_partial_results():
    s = ImpactTrial(roll_deg=5, pitch_deg=-30, yaw_deg=20, speed_m_s=1.5)
    whole = simulate(s)
    sim = Simulation(s)
    assert sim.advance(10) == 10 and sim.tick == 10 and sim.time == pytest.approx(0.05)
    partial = sim.result()  # readable mid-run, and the run goes on unchanged
    assert partial.summary["t_final_s"] == pytest.approx(0.05)
    sim.advance(-1)
    _compare(whole.summary, sim.result().summary)
    assert whole.summary["recovered"] and sim.stage == 5  # stage 5 (hover) follows stage 4


def test_external_command_drives_the_rotors():
    s = ImpactTrial(speed_m_s=0.5, start_distance_m=5.0)  # far from the wall: free flight
    sim = Simulation(s)
    hover = sim.setup.vehicle.hover_speed_rad_s
    sim.advance(20, command=[hover] * 4)
    x = sim.state
    np.testing.assert_allclose(x[L.X_ROTOR : L.X_ROTOR + 4], hover, rtol=0, atol=1e-9)
    sim.advance(1, command=[0.0] * 4)  # the slew limit still applies
    slew = sim.setup.opts[L.O_SLEW_MAX] * sim.dt
    np.testing.assert_allclose(sim.state[L.X_ROTOR : L.X_ROTOR + 4], hover - slew, atol=1e-9)
    with pytest.raises(ValueError, match="command"):
        sim.advance(1, command=[np.nan, 0, 0, 0])
