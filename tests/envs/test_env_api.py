"""The Gymnasium API of ImpactRecovery-v0: registration, the checker, spaces, seeding."""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import quadimpact.envs as E
from quadimpact.core import layout as L
from quadimpact.core.envs import stacked as B
from quadimpact.core.sensors import measurement_slots as MSS


@pytest.mark.parametrize("start", ["detection", "trial"])
@pytest.mark.parametrize("observe", ["imu", "state"])
@pytest.mark.parametrize("action", ["rotors", "ctbr"])
def test_check_env_passes_without_warnings(action, observe, start):
    env = gym.make(E.ENV_ID, action=action, observe=observe, start=start)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a checker warning fails the test
        check_env(env.unwrapped, skip_render_check=True)
    n_obs = B.N_OBS_STATE if observe == "state" else B.N_OBS_IMU
    assert env.observation_space.shape == (n_obs,) and env.observation_space.dtype == np.float32
    assert env.action_space.shape == (4,) and env.action_space.dtype == np.float64
    assert np.all(env.action_space.low == -1) and np.all(env.action_space.high == 1)


def test_registered_in_its_namespace_with_a_vector_entry_point():
    spec = gym.spec(E.ENV_ID)
    assert spec.namespace == "quadimpact" and spec.name == "ImpactRecovery" and spec.version == 0
    envs = gym.make_vec(E.ENV_ID, num_envs=3)
    assert isinstance(envs.unwrapped, E.BatchedImpactRecoveryEnv) and envs.num_envs == 3
    sync = gym.make_vec(E.ENV_ID, num_envs=2, vectorization_mode="sync")
    assert isinstance(sync, gym.vector.SyncVectorEnv)
    with pytest.raises(ValueError, match="start"):
        gym.make(E.ENV_ID, start="later")
    with pytest.raises(ValueError, match="action"):
        gym.make(E.ENV_ID, action="torques")


def _episode(env, seed, actions):
    obs, info = env.reset(seed=seed)
    out = [obs]
    rewards = []
    for a in actions:
        obs, r, term, trunc, _ = env.step(a)
        out.append(obs)
        rewards.append(r)
        if term or trunc:
            break
    return info["trial"], np.array(out), np.array(rewards)


def test_seeding_reproduces_episodes_and_different_seeds_differ():
    env = gym.make(E.ENV_ID)
    actions = np.random.default_rng(0).uniform(-1, 1, size=(60, 4))
    t1, o1, r1 = _episode(env, 11, actions)
    t2, o2, r2 = _episode(env, 11, actions)
    t3, o3, _ = _episode(env, 12, actions)
    assert t1 == t2 and np.array_equal(o1, o2) and np.array_equal(r1, r2)
    assert t1 != t3 and not np.array_equal(o1[0], o3[0])
    # unseeded resets continue the seeded generator: the same sequence of trials
    env.reset(seed=5)
    seq = [env.reset()[1]["trial"] for _ in range(3)]
    env.reset(seed=5)
    assert seq == [env.reset()[1]["trial"] for _ in range(3)]


def test_trials_follow_the_distribution_and_its_draw_order():
    d = E.TrialDistribution()
    rng = np.random.default_rng(3)
    draws = [d.draw(rng) for _ in range(400)]
    for key, (lo, hi) in {"roll_deg": (-15, 15), "pitch_deg": (-45, 45), "yaw_deg": (-45, 45),
                          "speed_m_s": (0.5, 2.5)}.items():  # fmt: skip
        v = np.array([x[key] for x in draws])
        assert lo <= v.min() and v.max() <= hi and v.max() - v.min() > 0.9 * (hi - lo)
    assert {x["vehicle"] for x in draws} == {"navi"}
    assert {x["friction_coefficient"] for x in draws} == {0.3}
    assert len({x["seed"] for x in draws}) == 400
    # fixing a field does not shift the other draws
    fixed = E.TrialDistribution(pitch_deg=10.0, vehicle=("navi", "spiri"))
    a = fixed.draw(np.random.default_rng(3))
    b = draws[0]
    assert a["pitch_deg"] == 10.0 and a["roll_deg"] == b["roll_deg"] and a["seed"] == b["seed"]


def test_observation_scales_and_contents():
    env = E.ImpactRecoveryEnv(observe="imu")
    obs, info = env.reset(seed=2)
    m = env.tick_measurement()
    x = m[MSS.MS_X : MSS.MS_X + L.NX]
    f = m[MSS.MS_IMU_F : MSS.MS_IMU_F + 3]
    np.testing.assert_allclose(obs[0:3], np.clip(f / 9.81, -10, 10), rtol=1e-6)
    gyro = m[MSS.MS_IMU_W : MSS.MS_IMU_W + 3] / 10.0
    np.testing.assert_allclose(obs[3:6], gyro, rtol=1e-6, atol=1e-7)
    from quadimpact.rotations import quat_to_matrix

    C = quat_to_matrix(x[L.X_QUAT : L.X_QUAT + 4])
    np.testing.assert_allclose(obs[6:15], C.ravel(), atol=1e-6)
    np.testing.assert_allclose(obs[15], -(C @ x[L.X_VEL : L.X_VEL + 3])[2] / 2.0, atol=1e-6)
    # detection mode: the agent starts at the detecting tick
    assert obs[16] == 0.0 and obs[17] == 1.0 and info["t"] == m[MSS.MS_T_DETECT]
    np.testing.assert_allclose(np.hypot(obs[18], obs[19]), 1.0, rtol=1e-6)
    senv = E.ImpactRecoveryEnv(observe="state", start="trial")
    sobs, _ = senv.reset(seed=2)
    x0 = senv.run_setup.x0
    assert sobs[0] == pytest.approx(x0[L.X_POS]) and sobs[1] == 0 and sobs[2] == 0
    assert sobs[17] == 0.0 and sobs[18] == 0.0  # not detected yet at t = 0
    assert sobs[6] >= 0  # quaternion sign fixed
