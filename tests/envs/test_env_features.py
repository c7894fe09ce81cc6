"""The learning environment flies a vehicle whose features are not four rings."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import quadimpact.envs as E

CAGE = Path(__file__).resolve().parents[2] / "examples" / "vehicles" / "navi_cage.toml"


@pytest.mark.xfail(
    reason="the environment of this branch's base fails before any vehicle code "
    "(engine.Slots.par has no setter: tests/envs fail alike); passes once that is fixed",
    raises=AttributeError,
    strict=False,
)
def test_a_caged_vehicle_hits_the_wall_in_the_environment():
    env = E.ImpactRecoveryEnv(trials={"vehicle": str(CAGE), "speed_m_s": 2.0})
    obs, _ = env.reset(seed=0)
    assert np.all(np.isfinite(obs))
    info: dict = {}
    for _ in range(1000):
        obs, reward, terminated, truncated, info = env.step(np.zeros(4))
        assert np.all(np.isfinite(obs)) and np.isfinite(reward)
        if terminated or truncated:
            break
    metrics = info["metrics"]
    assert metrics["first_contact_s"] is not None and metrics["detected"]
    assert "feature(s) cage" in metrics["outcome"]
    env.close()
