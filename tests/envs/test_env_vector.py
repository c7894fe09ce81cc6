"""The batched environment: sub-environment k is the single environment seeded with seed + k."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import quadimpact.envs as E

N = 4
STEPS = 260  # long enough for episodes to end and restart (recoveries take ~100-300 ticks)


def _single_streams(seed, actions, kwargs, live_policy):
    """Per sub-environment: its observations, rewards and end flags as a single env gives them,
    with the next-step autoreset order (the step after an end is a reset). ``live_policy``: act
    with a RecoveryPolicy of the single env instead of replaying ``actions``."""
    streams = []
    for k in range(N):
        env = E.ImpactRecoveryEnv(**kwargs)
        pol = E.RecoveryPolicy(env) if live_policy else None
        obs, _ = env.reset(seed=seed + k)
        o, r, te, tr, ends = [obs], [], [], [], []
        reset_next = False
        for t in range(STEPS):
            if reset_next:
                obs, _ = env.reset()
                o.append(obs)
                r.append(0.0)
                te.append(False)
                tr.append(False)
                reset_next = False
                continue
            a = pol(obs) if pol is not None else actions[t, k]
            if pol is not None:
                np.testing.assert_array_equal(a, actions[t, k])  # the same actions
            obs, rew, term, trunc, info = env.step(a)
            o.append(obs)
            r.append(rew)
            te.append(term)
            tr.append(trunc)
            if term or trunc:
                ends.append(info["metrics"])
                reset_next = True
        streams.append((np.array(o), np.array(r), np.array(te), np.array(tr), ends))
    return streams


@pytest.mark.parametrize("policy", ["recovery", "random"])
def test_batched_sub_environment_k_is_the_single_env_seeded_seed_plus_k(policy):
    kwargs = {"action": "rotors", "observe": "imu"}
    venv = E.BatchedImpactRecoveryEnv(N, **kwargs)
    seed = 40
    obs, _ = venv.reset(seed=seed)
    if policy == "recovery":
        # record the batched run's actions, then replay them in single envs
        pol = E.RecoveryPolicy(venv)
        actions = np.zeros((STEPS, N, 4))
    else:
        actions = np.random.default_rng(1).uniform(-1, 1, size=(STEPS, N, 4))
    o, r, te, tr = [obs], [], [], []
    ends: list[list[dict]] = [[] for _ in range(N)]
    for t in range(STEPS):
        if policy == "recovery":
            actions[t] = pol(o[-1])
        ob, rew, term, trunc, info = venv.step(actions[t])
        o.append(ob)
        r.append(rew)
        te.append(term)
        tr.append(trunc)
        for k in np.flatnonzero(info.get("_metrics", np.zeros(N, bool))):
            ends[k].append({key: val[k] for key, val in info["metrics"].items()
                            if not key.startswith("_")})  # fmt: skip
    o, r, te, tr = (np.array(v) for v in (o, r, te, tr))
    assert te.any() or tr.any()  # episodes ended and were reset within the run
    singles = _single_streams(seed, actions, kwargs, live_policy=policy == "recovery")
    for k, (so, sr, ste, strn, sends) in enumerate(singles):
        np.testing.assert_array_equal(o[:, k], so)
        np.testing.assert_array_equal(r[:, k], sr)
        np.testing.assert_array_equal(te[:, k], ste)
        np.testing.assert_array_equal(tr[:, k], strn)
        assert len(ends[k]) == len(sends)
        for a, b in zip(ends[k], sends, strict=True):
            assert a == b  # every metric, the stage source included


def test_same_step_autoreset_and_the_sync_vector_env_agree():
    kwargs = {"action": "ctbr", "observe": "state"}
    actions = np.random.default_rng(2).uniform(-1, 1, size=(120, N, 4))
    mine = E.BatchedImpactRecoveryEnv(N, autoreset_mode=AutoresetMode.SAME_STEP, **kwargs)
    sync = gym.vector.SyncVectorEnv(
        [lambda: E.ImpactRecoveryEnv(**kwargs) for _ in range(N)],
        autoreset_mode=AutoresetMode.SAME_STEP,
    )
    a_obs, _ = mine.reset(seed=7)
    b_obs, _ = sync.reset(seed=7)
    np.testing.assert_array_equal(a_obs, b_obs)
    n_final = 0
    for t in range(actions.shape[0]):
        a = mine.step(actions[t])
        b = sync.step(actions[t])
        for x, y in zip(a[:4], b[:4], strict=True):
            np.testing.assert_array_equal(x, y)
        if "final_obs" in b[4]:
            mask = b[4]["_final_obs"]
            np.testing.assert_array_equal(a[4]["_final_obs"], mask)
            for k in np.flatnonzero(mask):
                np.testing.assert_array_equal(a[4]["final_obs"][k], b[4]["final_obs"][k])
                assert a[4]["final_info"]["outcome"][k] == b[4]["final_info"]["outcome"][k]
                n_final += 1
    assert n_final > 0  # random actions end episodes quickly (the envelope)


def test_disabled_autoreset_and_reset_mask():
    venv = E.BatchedImpactRecoveryEnv(2, autoreset_mode="Disabled", end_on_recovery=False)
    venv.reset(seed=1)
    trial0 = dict(venv._slots.trial_fields[0])
    trial1 = dict(venv._slots.trial_fields[1])
    a = np.full((2, 4), -1.0)  # rotors at the bottom of the range: the vehicle falls
    ended = np.zeros(2, bool)
    for _ in range(400):
        _, r, te, tr, _ = venv.step(a)
        assert np.all(r[ended] == 0.0)  # an ended sub-environment is not stepped
        ended |= te | tr
        if ended.all():
            break
    assert ended.all()
    venv.reset(options={"reset_mask": np.array([True, False])})
    assert venv._slots.trial_fields[0] != trial0 and venv._slots.trial_fields[1] == trial1
    assert venv._slots.active().tolist() == [True, False]
    with pytest.raises(ValueError, match="reset_mask"):
        venv.reset(options={"reset_mask": np.array([True])})
