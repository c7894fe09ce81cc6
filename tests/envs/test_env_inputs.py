"""The environments' settings and calls are checked when given, with a clear error
(issue 20 item 12): nothing is accepted silently, nothing fails later with an
AttributeError or IndexError."""

from __future__ import annotations

import math

import numpy as np
import pytest

import quadimpact.envs as E
from quadimpact.envs.settings import Envelope, RewardWeights, TrialDistribution


def test_settings_given_as_mappings_are_accepted_and_anything_else_is_a_type_error():
    env = E.ImpactRecoveryEnv(trials={"speed_m_s": 1.0}, reward={"tilt": 2.0},
                              envelope={"max_drop_m": 5.0})  # fmt: skip
    assert env.trials == TrialDistribution(speed_m_s=1.0)
    assert env.reward_weights.tilt == 2.0 and env.envelope.max_drop_m == 5.0
    for name in ("trials", "reward", "envelope"):
        with pytest.raises(TypeError, match=f"{name}: must be a .* or a mapping of its fields"):
            E.ImpactRecoveryEnv(**{name: 3})
    with pytest.raises(TypeError, match="reward: unknown field.*'tlit'"):
        E.ImpactRecoveryEnv(reward={"tlit": 1.0})


@pytest.mark.parametrize(
    ("options", "error", "fragment"),
    [
        ({"ground": "maybe"}, TypeError, "ground: must be True or False"),
        ({"record": "yes"}, TypeError, "record: must be True or False"),
        ({"end_on_recovery": 2}, TypeError, "end_on_recovery: must be True or False"),
        ({"max_redraws": -1}, ValueError, "max_redraws: must be an integer >= 0"),
        ({"hold_s": math.nan}, ValueError, "hold_s: must be a finite number"),
        ({"envelope": {"max_tilt_deg": math.nan}}, ValueError, "max_tilt_deg: must be a finite"),
        ({"reward": {"tilt": math.nan}}, ValueError, "tilt: must be a finite number"),
        ({"reward": {"height_scale_m": 0.0}}, ValueError, "height_scale_m: must be > 0"),
        ({"trials": {"pitch_deg": (-120, 0)}}, ValueError, "pitch_deg: must be > -90 .got -120"),
        ({"trials": {"speed_m_s": (2.0, 1.0)}}, ValueError, "needs low <= high"),
        ({"trials": {"speed_m_s": (0.5, math.inf)}}, ValueError, "speed_m_s: must be a finite"),
        ({"trials": {"vehicle": []}}, ValueError, "vehicle: must be a name or a non-empty list"),
    ],
)
def test_bad_settings_are_refused_when_given(options, error, fragment):
    with pytest.raises(error, match=fragment):
        E.ImpactRecoveryEnv(**options)


def test_num_envs_must_be_at_least_one():
    with pytest.raises(ValueError, match="num_envs: must be an integer >= 1"):
        E.BatchedImpactRecoveryEnv(num_envs=0)


def test_calls_are_checked():
    env = E.ImpactRecoveryEnv(start="trial")
    env.reset(seed=1)
    with pytest.raises(ValueError, match="action: must be an array of shape"):
        env.step(None)
    with pytest.raises(ValueError, match="action: must be finite"):
        env.step(np.full(4, np.nan))
    with pytest.raises(ValueError, match=r"options: unknown key\(s\) 'trail'"):
        env.reset(options={"trail": {}})
    envs = E.BatchedImpactRecoveryEnv(num_envs=4, start="trial")
    envs.reset(seed=0)
    with pytest.raises(ValueError, match=r"action: must have shape \(4, 4\) \(got \(4,\)\)"):
        envs.step(np.zeros(4))
    with pytest.raises(ValueError, match=r"trials: one trial \(or None\) per sub-environment"):
        envs.reset(options={"trials": [{"speed_m_s": 1.0}]})
    with pytest.raises(ValueError, match=r"options: unknown key\(s\) 'mask'"):
        envs.reset(options={"mask": [True] * 4})
    assert RewardWeights() == RewardWeights() and Envelope() == Envelope()
