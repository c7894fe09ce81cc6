"""N impact-recovery trials stepped together in compiled code: :class:`BatchedImpactRecoveryEnv`.

Each ``step`` advances every sub-environment one control period in one
compiled call (``core.envs.stacked.step_batch``, a loop over the N trials' stacked
arrays); Python work is left for the ends of episodes (metrics, the next
trial's packing). Sub-environment ``k`` is the single environment
:class:`~quadimpact.envs.single.ImpactRecoveryEnv` seeded with ``seed + k``
(the convention of ``gymnasium.vector.SyncVectorEnv``): the same trials, the
same numbers.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from quadimpact.core import layout as L
from quadimpact.core.envs import stacked as B
from quadimpact.envs.single import check_actions, check_options, configure, spaces_for

__all__ = ["BatchedImpactRecoveryEnv"]


class BatchedImpactRecoveryEnv(VectorEnv):
    """``num_envs`` impact-recovery trials advanced together (a ``gymnasium.vector.VectorEnv``).

    Parameters
    ----------
    num_envs : int
        Number of sub-environments.
    autoreset_mode : AutoresetMode or str
        ``NEXT_STEP`` (Gymnasium's default: the step after an episode's end
        resets that sub-environment and returns its first observation with
        reward 0), ``SAME_STEP`` (reset within the ending step; the ended
        episode's last observation and info in ``info["final_obs"]`` and
        ``info["final_info"]``) or ``DISABLED`` (reset through
        ``reset(options={"reset_mask": ...})``).
    **options
        As :class:`~quadimpact.envs.single.ImpactRecoveryEnv` (``trials``,
        ``start``, ``action``, ``observe``, ``reward``, ``envelope``,
        ``hold_s``, ``end_on_recovery``, ``ground``, ``rotor_floor``, ``record``, ``max_redraws``).
    """

    def __init__(
        self,
        num_envs: int = 8,
        *,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        **options: Any,
    ) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)):
            raise TypeError(f"num_envs: must be an integer >= 1 (got {num_envs!r})")
        if num_envs < 1:
            raise ValueError(f"num_envs: must be an integer >= 1 (got {num_envs!r})")
        self.num_envs = int(num_envs)
        self.autoreset_mode = AutoresetMode(autoreset_mode)
        self.metadata = {"autoreset_mode": self.autoreset_mode, "render_modes": []}
        configure(self, self.num_envs, **options)
        action, observe = self.action_mode, self.observe_mode
        self.single_action_space, self.single_observation_space = spaces_for(action, observe)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self._rngs: list[np.random.Generator] = [seeding.np_random()[0] for _ in range(num_envs)]
        self._autoreset = np.zeros(self.num_envs, dtype=np.bool_)
        self._actions = np.zeros((self.num_envs, 4))

    # ------------------------------------------------------------ resets
    def _reset_row(self, k: int, trial: Any = None) -> None:
        self._slots.reset(k, self._rngs[k], trial, self.max_redraws)

    def reset(
        self,
        *,
        seed: int | Sequence[int | None] | None = None,
        options: Mapping[str, Any] | None = None,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Reset the sub-environments (all, or those of ``options["reset_mask"]``).

        ``seed``: an int seeds sub-environment ``k`` with ``seed + k``; a list
        gives one seed (or None) per sub-environment. ``options["trials"]``: a
        list of one trial (or None: a draw) per sub-environment.
        """
        super().reset(seed=seed if isinstance(seed, (int, np.integer)) else None)
        n = self.num_envs
        if seed is None:
            seeds: list[int | None] = [None] * n
        elif isinstance(seed, (int, np.integer)):
            seeds = [int(seed) + k for k in range(n)]
        else:
            seeds = list(seed)
            if len(seeds) != n:
                raise ValueError(f"seed: one per sub-environment ({n}), got {len(seeds)}")
        check_options(options, ("reset_mask", "trials"))
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        mask = np.ones(n, dtype=np.bool_) if mask is None else np.asarray(mask, dtype=np.bool_)
        if mask.shape != (n,):
            raise ValueError(f"reset_mask: a boolean array of shape ({n},)")
        trials = options.pop("trials", None)
        if trials is None:
            trials = [None] * n
        elif isinstance(trials, (str, Mapping)) or not isinstance(trials, Sequence):
            raise TypeError(f"trials: a list of one trial (or None) per sub-environment ({n})")
        elif len(trials) != n:
            raise ValueError(
                f"trials: one trial (or None) per sub-environment ({n}), got {len(trials)}"
            )
        infos: dict[str, Any] = {}
        for k in np.flatnonzero(mask):
            if seeds[k] is not None:
                self._rngs[k] = seeding.np_random(seeds[k])[0]
            self._reset_row(int(k), trials[k])
            infos = self._add_info(infos, {"trial": dict(self._slots.trial_fields[k])}, int(k))
        self._autoreset[mask] = False
        return self._slots.obs.copy(), infos

    # ------------------------------------------------------------ stepping
    def report_stages(self, stages: np.ndarray) -> None:
        """The policy's stages for the next step, one per sub-environment (< 0: none).

        The hook of staged policies (see ``ImpactRecoveryEnv.report_stage``).
        """
        self._slots.reported[:] = np.asarray(stages, dtype=float)

    def step(
        self, actions: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """One control period of every sub-environment."""
        s = self._slots
        self._actions[:] = check_actions(actions, (self.num_envs, 4))
        next_step = self.autoreset_mode == AutoresetMode.NEXT_STEP
        resetting = self._autoreset.copy() if next_step else None
        if resetting is not None:
            s.reported[resetting] = -1.0
        s.step(self._actions)
        ended = s.terminated | s.truncated
        stepped = ~resetting if resetting is not None else np.ones(self.num_envs, dtype=bool)
        ended &= stepped
        rewards = np.where(stepped, s.reward, 0.0)
        terminated = s.terminated & stepped
        truncated = s.truncated & stepped
        infos: dict[str, Any] = {}
        for k in np.flatnonzero(ended):
            m = s.metrics(int(k))
            info = {"metrics": m, "outcome": m["outcome"]}
            if self.autoreset_mode == AutoresetMode.SAME_STEP:
                infos = self._add_info(infos, {"final_obs": s.obs[k].copy(), "final_info": info},
                                       int(k))  # fmt: skip
                self._reset_row(int(k))
            else:
                infos = self._add_info(infos, info, int(k))
        if resetting is not None:
            for k in np.flatnonzero(resetting):
                self._reset_row(int(k))
            self._autoreset = ended
        infos["stage"] = s.ENV[:, B.B_STAGE].astype(np.int64)
        infos["t"] = s.D.ls[:, L.LS_T].copy()
        s.terminated[:] = False
        s.truncated[:] = False
        s.reward[:] = 0.0
        return s.obs.copy(), rewards, terminated, truncated, infos

    # ------------------------------------------------------------ reading
    def tick_measurements(self) -> np.ndarray:
        """What a controller sees at the next tick, per sub-environment (N, NMEAS)."""
        return self._slots.TMEAS.copy()

    def render(self) -> None:
        """No rendering (``quadimpact.viz`` draws a recorded episode: ``record=True``)."""
        return None

    def result(self, k: int):
        """Sub-environment ``k``'s run so far, as ``quadimpact.simulate`` returns it."""
        return self._slots.result(k)
