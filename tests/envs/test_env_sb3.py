"""The Stable-Baselines3 adapter (skipped without the ``train`` extra)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

import quadimpact.envs as E  # noqa: E402
from quadimpact.envs.sb3 import SB3BatchedEnv  # noqa: E402


def test_sb3_view_of_the_batched_env():
    env = SB3BatchedEnv(3, action="ctbr")
    env.seed(4)
    obs = env.reset()
    assert obs.shape == (3, 24)
    same = E.BatchedImpactRecoveryEnv(3, action="ctbr", autoreset_mode="SameStep")
    np.testing.assert_array_equal(obs, same.reset(seed=4)[0])
    rng = np.random.default_rng(0)
    ended = 0
    for _ in range(300):
        a = rng.uniform(-1, 1, (3, 4))
        obs, rewards, dones, infos = env.step(a)
        ref = same.step(a)
        np.testing.assert_array_equal(obs, ref[0])
        np.testing.assert_allclose(rewards, ref[1], rtol=1e-6)
        assert len(infos) == 3
        for k in np.flatnonzero(dones):
            info = infos[k]
            np.testing.assert_array_equal(info["terminal_observation"], ref[4]["final_obs"][k])
            assert info["episode"]["l"] == info["metrics"]["episode_steps"]
            assert info["TimeLimit.truncated"] == (info["metrics"]["outcome"] == "time limit")
            ended += 1
    assert ended > 0
