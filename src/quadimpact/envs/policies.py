"""Baseline policies: the built-in staged controller, random actions, hover thrust.

Each is called with the observation (single env: (n_obs,); batched env:
(N, n_obs)) and returns the action(s) of the environment it was made for.

* :class:`RecoveryPolicy`: the ``recovery`` controller's staged law
  (docs/RECOVERY.md 3) with its own memory; in the ``estimate`` observation
  mode it acts on its observation alone (what an on-board controller sees),
  in the others on the environment's tick measurement; it reports its stages
  through the environment's hook, so the episode metrics are the
  controller's own.
* :class:`RandomPolicy`: uniform actions (the floor).
* :class:`HoverPolicy`: the level-hover rotor speeds (or the hover thrust and
  zero rate references), no correction.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.envs import stacked as B

__all__ = ["HoverPolicy", "RandomPolicy", "RecoveryPolicy"]


def _slots(env: Any):
    base = env.unwrapped
    if not hasattr(base, "_slots"):
        raise TypeError("policy: a quadimpact.envs environment (or one wrapping it)")
    return base, base._slots


def _batched(base: Any) -> bool:
    return hasattr(base, "num_envs")


def _shape(base: Any, actions: np.ndarray) -> np.ndarray:
    return actions.copy() if _batched(base) else actions[0].copy()


class RecoveryPolicy:
    """The built-in staged recovery controller as a policy.

    At each call it runs the compiled ``recovery_step`` on the environment's
    tick measurement (what the built-in controller would see at that tick),
    with the policy's own controller memory (cleared when a row begins a new
    episode), and returns the action whose map gives exactly its rotor
    commands where such an action exists (``core.envs.actions.affine_inverse``); the
    few commands near the bottom of the rotor range that no float action
    maps to exactly are replaced by the nearest one and counted in the
    metrics' ``inexact_commands``. It reports its stage through the
    environment's hook before the step.

    With ``action="ctbr"`` it returns the staged law's thrust and rate
    references (the environment's rate loop is the controller's); the thrust
    is limited to the vehicle's maximum, so the run can differ from the
    built-in where the law asks for more.

    Parameters
    ----------
    env : ImpactRecoveryEnv or BatchedImpactRecoveryEnv
        The environment it acts in (wrappers allowed).
    """

    def __init__(self, env: Any) -> None:
        self._base, s = _slots(env)
        self._mem = np.zeros((s.n, L.NMEM))
        self._seen = s.episode_id.copy() - 1
        self._actions = np.zeros((s.n, 4))
        self._stages = np.zeros(s.n)
        self._meas = np.zeros((s.n, s.E.tmeas.shape[1]))
        self.inexact = np.zeros(s.n)
        """Estimate mode: commands the rotor map could not give exactly, per row (this episode)."""
        self.from_observation = bool(s.par[B.EP_OBSERVE] == B.OBS_ESTIMATE)
        """True in the ``estimate`` mode: the policy reads nothing but its observation."""

    def __call__(self, observation: np.ndarray | None = None) -> np.ndarray:
        """The action(s) for the next step.

        In the ``estimate`` mode from ``observation`` alone (its values are the
        estimator's output, recovered exactly: ``core.envs.stacked.measurement_from_estimate``);
        the controller's gains, the vehicle's constants and the rotor map are
        the policy's own configuration. Otherwise the observation is not needed.
        """
        s = self._base._slots
        fresh = s.episode_id != self._seen
        self._mem[fresh] = 0.0
        self.inexact[fresh] = 0.0
        self._seen[:] = s.episode_id
        active = s.active()
        if self.from_observation:
            if observation is None:
                raise ValueError("RecoveryPolicy: the estimate mode needs the observation")
            obs = np.asarray(observation, dtype=np.float64).reshape(s.n, -1)
            for k in range(s.n):
                B.measurement_from_estimate(obs[k], self._meas[k])
            B.staged_actions(active, self._meas, s.M, s.par, self._mem, self._actions,
                             self._stages, self.inexact)  # fmt: skip
        else:
            B.staged_policy(active, s.M, s.E, self._mem, self._actions, self._stages)
        if _batched(self._base):
            self._base.report_stages(np.where(active, self._stages, -1.0))
        elif active[0]:
            self._base.report_stage(int(self._stages[0]))
        return _shape(self._base, self._actions)


class RandomPolicy:
    """Uniform random actions in ``[-1, 1]`` from its own seeded generator."""

    def __init__(self, env: Any, seed: int | None = None) -> None:
        self._base, s = _slots(env)
        self._n = s.n
        self._rng = np.random.default_rng(seed)

    def __call__(self, observation: np.ndarray | None = None) -> np.ndarray:
        """Uniform actions."""
        a = self._rng.uniform(-1.0, 1.0, size=(self._n, 4))
        return _shape(self._base, a)


class HoverPolicy:
    """Hover thrust and no correction.

    Rotor actions: every rotor at the vehicle's trimmed level-hover speed (the
    allocation of ``m g`` with zero torques); ctbr: the thrust ``m g`` with zero
    rate references (the rate loop still damps the rates).
    """

    def __init__(self, env: Any) -> None:
        self._base, s = _slots(env)
        self._s = s

    def __call__(self, observation: np.ndarray | None = None) -> np.ndarray:
        """Hover actions of each row's vehicle."""
        s = self._s
        a = np.zeros((s.n, 4))
        for k in range(s.n):
            veh, ctrl = s.M.veh[k], s.M.ctrl[k]
            weight = veh[VS.V_MASS] * veh[VS.V_GRAVITY]
            if s.par[B.EP_ACTION] == B.ACT_CTBR:
                a[k, 0] = B.affine_inverse(weight, 0.0, B.max_thrust(veh, ctrl))[0]
                continue
            inv = ctrl[CTL.C_ALLOC_INV : CTL.C_ALLOC_INV + 16].reshape(4, 4)
            speeds = np.sqrt(np.clip(inv[:, 0] * weight, 0.0, None))
            lo, hi = B.rotor_range(ctrl, s.par)
            a[k] = [B.affine_inverse(float(w), lo, hi)[0] for w in speeds]
        return _shape(self._base, a)
