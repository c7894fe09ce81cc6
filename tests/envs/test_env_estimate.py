"""The estimate observation mode: what an on-board controller sees (docs/LEARNING.md).

The observation holds the estimator's output (attitude, body velocity, position,
rates, gyro bias), the IMU sample, the detector and the rotor speeds, each divided
by a power of two, in float64: the staged-controller baseline recovers every value
exactly and acts on its observation alone; it then recovers in the same trials as the
built-in controller with the same estimator, at the same ticks.
"""

from __future__ import annotations

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import quadimpact.envs as E
from quadimpact.core import layout as L
from quadimpact.core.envs import stacked as B
from quadimpact.core.sensors import measurement_slots as MSS
from quadimpact.simulation.batch import simulate_batch

TRIALS = E.TrialDistribution(estimator="ekf", sensors="impact")


def test_check_env_passes_in_the_estimate_mode():
    env = E.ImpactRecoveryEnv(observe="estimate", trials=TRIALS)
    assert env.observation_space.shape == (B.N_OBS_ESTIMATE,)
    assert env.observation_space.dtype == np.float64
    check_env(env.unwrapped, skip_render_check=True)


def test_the_observation_gives_the_measurement_back_exactly():
    env = E.ImpactRecoveryEnv(observe="estimate", trials=TRIALS)
    obs, _ = env.reset(seed=3)
    meas = env.unwrapped.tick_measurement()
    back = np.zeros(MSS.NMEAS)
    B.measurement_from_estimate(obs, back)
    for lo, n in ((MSS.MS_X, L.NX), (MSS.MS_W_HAT, 3), (MSS.MS_BIAS_HAT, 3), (MSS.MS_IMU_F, 3),
                  (MSS.MS_IMU_W, 3), (MSS.MS_NORMAL, 2), (MSS.MS_DETECTED, 1)):  # fmt: skip
        np.testing.assert_array_equal(back[lo : lo + n], meas[lo : lo + n])
    # the estimate is not the truth
    assert not np.array_equal(meas[MSS.MS_X : MSS.MS_X + L.NX], env.unwrapped._slots.D.x[0])


@pytest.mark.parametrize(
    ("estimator", "sensors"),
    [("complementary", "impact"), ("ekf", "impact"), ("nav-ekf", "onboard")],
)
def test_the_baseline_on_its_observation_recovers_as_the_built_in(estimator, sensors):
    """The ``onboard`` set too: its observation is the navigation filter's estimate."""
    trials = E.TrialDistribution(estimator=estimator, sensors=sensors)
    env = E.ImpactRecoveryEnv(observe="estimate", trials=trials)
    policy = E.RecoveryPolicy(env)
    assert policy.from_observation
    scenarios, got = [], []
    for i in range(25):
        obs, _ = env.reset(seed=11) if i == 0 else env.reset()
        scenarios.append(env.unwrapped.scenario)
        done = False
        while not done:
            obs, _, term, trunc, info = env.step(policy(obs))
            done = term or trunc
        got.append(info["metrics"])
    want = simulate_batch(scenarios)
    assert all(s["estimator"] == estimator and s["sensors"] == sensors for s in want)
    for m, s in zip(got, want, strict=True):
        assert m["stage_source"] == "policy"
        for key in ("recovered", "t_detect_s", "t_stage2_s", "t_stage3_s", "t_stage4_s"):
            assert m[key] == s[key], key
    assert 15 < sum(m["recovered"] for m in got)
