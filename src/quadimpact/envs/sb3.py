"""Stable-Baselines3's ``VecEnv`` interface over the batched environment (the ``train`` extra).

SB3 collects rollouts through its own vector interface, not Gymnasium's.
:class:`SB3BatchedEnv` presents a :class:`~quadimpact.envs.vector.BatchedImpactRecoveryEnv`
(same-step autoreset) that way: ``done = terminated or truncated``, and at an
episode's end its info holds ``terminal_observation`` (the last observation),
``TimeLimit.truncated`` (so that SB3 bootstraps the value at a time limit),
``episode`` (``r`` return, ``l`` length, as SB3's ``Monitor`` writes it) and
the episode's ``metrics``.

Not imported by ``quadimpact.envs`` itself: ``import quadimpact.envs.sb3``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode
from stable_baselines3.common.vec_env import VecEnv

from quadimpact.envs.vector import BatchedImpactRecoveryEnv

__all__ = ["SB3BatchedEnv"]


class SB3BatchedEnv(VecEnv):
    """SB3 view of a batched impact-recovery environment.

    Parameters
    ----------
    num_envs : int
        Number of sub-environments.
    **kwargs
        As :class:`~quadimpact.envs.vector.BatchedImpactRecoveryEnv` (its
        autoreset mode is same-step here).
    """

    def __init__(self, num_envs: int, **kwargs: Any) -> None:
        kwargs["autoreset_mode"] = AutoresetMode.SAME_STEP
        self.venv = BatchedImpactRecoveryEnv(num_envs, **kwargs)
        super().__init__(
            num_envs, self.venv.single_observation_space, self.venv.single_action_space
        )
        self._actions = np.zeros((num_envs, 4))

    def reset(self) -> np.ndarray:
        """Reset every sub-environment (with the seeds of :meth:`seed`, once)."""
        seeds = self._seeds
        seed: Any = None if all(s is None for s in seeds) else list(seeds)
        obs, _ = self.venv.reset(seed=seed)
        self._reset_seeds()
        self._reset_options()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        """Store the actions of the next :meth:`step_wait`."""
        self._actions[:] = np.clip(actions, -1.0, 1.0)

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        """One control period of every sub-environment, SB3's way."""
        obs, rewards, terminated, truncated, infos = self.venv.step(self._actions)
        dones = terminated | truncated
        out: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        for k in np.flatnonzero(dones):
            final = infos["final_info"]
            metrics = {key: v[k] for key, v in final["metrics"].items() if not key.startswith("_")}
            out[k] = {
                "terminal_observation": infos["final_obs"][k],
                "TimeLimit.truncated": bool(truncated[k] and not terminated[k]),
                "episode": {"r": metrics["episode_return"], "l": metrics["episode_steps"]},
                "metrics": metrics,
            }
        return obs, rewards.astype(np.float32), dones, out

    def close(self) -> None:
        """Nothing to release."""
        self.venv.close()

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        """The attribute of the batched environment, once per selected sub-environment."""
        return [getattr(self.venv, attr_name) for _ in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        """Set an attribute of the batched environment."""
        setattr(self.venv, attr_name, value)

    def env_method(self, method_name: str, *args: Any, indices: Any = None, **kw: Any) -> list:
        """Call a method of the batched environment, once per selected sub-environment."""
        return [getattr(self.venv, method_name)(*args, **kw) for _ in self._get_indices(indices)]

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> Sequence[bool]:
        """No sub-environment is wrapped."""
        return [False for _ in self._get_indices(indices)]
