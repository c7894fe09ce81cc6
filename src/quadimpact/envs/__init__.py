"""Gymnasium environments for learning to recover from wall impacts (docs/LEARNING.md).

Importing this package registers ``quadimpact/ImpactRecovery-v0``::

    import gymnasium as gym
    import quadimpact.envs

    env = gym.make("quadimpact/ImpactRecovery-v0")                 # one trial
    envs = gym.make_vec("quadimpact/ImpactRecovery-v0", num_envs=64)  # batched, compiled

* :class:`ImpactRecoveryEnv`: one impact trial (docs/RECOVERY.md 5.1), one
  control period (5 ms) per step;
* :class:`BatchedImpactRecoveryEnv`: N trials per step in one compiled call
  (the ``vector_entry_point`` of ``gym.make_vec``);
* :class:`TrialDistribution`, :class:`RewardWeights`, :class:`Envelope`:
  what the episodes, the reward and the failures are;
* :class:`RecoveryPolicy`, :class:`RandomPolicy`, :class:`HoverPolicy`: baselines.

Needs the ``rl`` extra (``pip install 'quadimpact[rl]'``: Gymnasium).
"""

from __future__ import annotations

import gymnasium as gym

from quadimpact.envs.policies import HoverPolicy, RandomPolicy, RecoveryPolicy
from quadimpact.envs.settings import Envelope, RewardWeights, TrialDistribution
from quadimpact.envs.single import ImpactRecoveryEnv
from quadimpact.envs.vector import BatchedImpactRecoveryEnv

__all__ = [
    "ENV_ID",
    "BatchedImpactRecoveryEnv",
    "Envelope",
    "HoverPolicy",
    "ImpactRecoveryEnv",
    "RandomPolicy",
    "RecoveryPolicy",
    "RewardWeights",
    "TrialDistribution",
]

ENV_ID = "quadimpact/ImpactRecovery-v0"
"""The registered id (namespace ``quadimpact``)."""

if ENV_ID not in gym.registry:
    gym.register(
        id=ENV_ID,
        entry_point="quadimpact.envs.single:ImpactRecoveryEnv",
        vector_entry_point="quadimpact.envs.vector:BatchedImpactRecoveryEnv",
    )
