"""The learning environment flies a vehicle whose features are not four rings."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import quadimpact.envs as E

CAGE = Path(__file__).resolve().parents[2] / "examples" / "vehicles" / "navi_cage.toml"


def test_a_caged_vehicle_hits_the_wall_in_the_environment():
    # the cage (radius 0.33 m) reaches further than the default start (0.32 m) allows
    trials = {"vehicle": str(CAGE), "speed_m_s": 2.0, "start_distance_m": 0.5}
    env = E.ImpactRecoveryEnv(trials=trials)
    obs, _ = env.reset(seed=0)
    assert np.all(np.isfinite(obs))
    info: dict = {}
    for _ in range(1000):
        obs, reward, terminated, truncated, info = env.step(np.zeros(4))
        assert np.all(np.isfinite(obs)) and np.isfinite(reward)
        if terminated or truncated:
            break
    metrics = info["metrics"]
    assert metrics["detected"] and not metrics["false_detection"]
    summary = env.result().summary  # the episode as simulate() reports it
    assert summary["first_contact_s"] is not None
    assert summary["first_contact_bumper"] == 1  # the vehicle's one feature: the cage
    assert "cage" in summary["outcome"]
    env.close()
