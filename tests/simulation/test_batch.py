"""simulate_batch gives the summaries of single simulate() calls, bit for bit."""

from __future__ import annotations

import json

from quadimpact import FlightScenario, ImpactTrial, WallApproach, simulate
from quadimpact.simulation.batch import simulate_batch


def _same(a, b):
    """Equal summaries but for what the runs cost (wall-clock and CPU times)."""
    a, b = dict(a), dict(b)
    a["integrator"].pop("wall_time_s"), b["integrator"].pop("wall_time_s")
    a.pop("cost"), b.pop("cost")
    return json.dumps(a, sort_keys=True, allow_nan=True) == json.dumps(b, sort_keys=True,
                                                                       allow_nan=True)  # fmt: skip


def test_batch_equals_single_runs():
    scenarios = [
        WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75, model="paper-replica"),
        WallApproach(heading_deg=0, inclination_deg=-10, speed_m_s=1.0),  # a shorter output
        WallApproach(heading_deg=45, inclination_deg=20, speed_m_s=0.5),  # a late start
        ImpactTrial(roll_deg=5, pitch_deg=-30, yaw_deg=20, speed_m_s=1.5, imu="noisy", seed=3),
        FlightScenario(final_time_s=4.0),  # longer than the others: the buffers grow
        WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75, model="paper-replica"),
    ]
    batch = simulate_batch(scenarios)
    assert len(batch) == len(scenarios)
    for s, b in zip(scenarios, batch, strict=True):
        assert _same(simulate(s).summary, b)


def test_a_run_that_raises_is_a_failed_summary():
    bad = WallApproach(vehicle_overrides={"thrust_coefficient": 1e-12})  # cannot hover: raises
    good = WallApproach(final_time_s=1.0)
    out = simulate_batch([bad, good])
    assert out[0]["status"] == "failed" and out[0]["reason"]
    assert _same(out[1], simulate(good).summary)
