"""``quadimpact/ImpactRecovery-v0``: one impact trial, one control period per step.

See docs/LEARNING.md for the spaces (with units and scales), the episodes,
the reward and the metrics.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal

import gymnasium as gym
import numpy as np

from quadimpact.core import layout as L
from quadimpact.core.envs import stacked as B
from quadimpact.envs.engine import Slots
from quadimpact.envs.settings import (
    Envelope,
    RewardWeights,
    TrialDistribution,
    check_episode_options,
    coerce,
)
from quadimpact.inputs.scenarios import ImpactTrial
from quadimpact.packing.episode_block import pack_episode
from quadimpact.results.result import SimulationResult

__all__ = ["ImpactRecoveryEnv", "configure", "observation_dtype", "spaces_for"]

StartMode = Literal["detection", "trial"]


def check_options(options: Any, known: tuple[str, ...]) -> None:
    """Refuse ``reset`` options that are not a mapping or have a key ``reset`` does not use."""
    if options is None:
        return
    if not isinstance(options, Mapping):
        raise TypeError(f"options: must be a mapping (got {type(options).__name__})")
    unknown = [k for k in options if k not in known]
    if unknown:
        raise ValueError(
            f"options: unknown key(s) {', '.join(map(repr, unknown))} (known: "
            f"{', '.join(map(repr, known))})"
        )


def check_actions(action: Any, shape: tuple[int, ...]) -> np.ndarray:
    """The action as float64 of exactly ``shape``, finite; else ``ValueError`` (no broadcast)."""
    if action is None:
        raise ValueError(f"action: must be an array of shape {shape} (got None)")
    try:
        a = np.asarray(action, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"action: must be an array of numbers of shape {shape}") from None
    if a.shape != shape:
        raise ValueError(f"action: must have shape {shape} (got {a.shape})")
    if not np.all(np.isfinite(a)):
        raise ValueError("action: must be finite (got NaN or infinity)")
    return a


def spaces_for(action: str, observe: str) -> tuple[gym.spaces.Box, gym.spaces.Box]:
    """The action and observation spaces of one trial (``Box(-1, 1)``, ``Box(-10, 10)``).

    Actions are float64, so that a policy can give the command it means to the
    last bit (:class:`~quadimpact.envs.policies.RecoveryPolicy`); observations
    float32, but float64 in the ``estimate`` mode (whose values a policy
    recovers exactly: the staged controller acts on that observation alone).
    """
    mode = {"state": B.OBS_STATE, "estimate": B.OBS_ESTIMATE}.get(observe, B.OBS_IMU)
    act = gym.spaces.Box(-1.0, 1.0, shape=(4,), dtype=np.float64)
    obs = gym.spaces.Box(
        -10.0, 10.0, shape=(B.n_observations(mode),), dtype=observation_dtype(observe)
    )
    return act, obs


def observation_dtype(observe: str) -> type:
    """float64 for the ``estimate`` observation, float32 for the others."""
    return np.float64 if observe == "estimate" else np.float32


def configure(
    env: Any,
    n: int,
    *,
    trials: TrialDistribution | None = None,
    start: StartMode = "detection",
    action: Literal["rotors", "ctbr"] = "rotors",
    observe: Literal["imu", "state", "estimate"] = "imu",
    reward: RewardWeights | None = None,
    envelope: Envelope | None = None,
    hold_s: float = 0.2,
    end_on_recovery: bool = True,
    ground: bool = False,
    rotor_floor: Literal["vehicle", "zero"] = "vehicle",
    record: bool = False,
    max_redraws: int = 100,
) -> None:
    """Give an environment (single or batched) its settings and its ``n`` stacked runs.

    The keywords are :class:`ImpactRecoveryEnv`'s.
    """
    if start not in ("detection", "trial"):
        raise ValueError(f"start: 'detection' or 'trial' (got {start!r})")
    if isinstance(max_redraws, bool) or not isinstance(max_redraws, (int, np.integer)):
        raise TypeError(f"max_redraws: must be an integer >= 0 (got {max_redraws!r})")
    if max_redraws < 0:
        raise ValueError(f"max_redraws: must be an integer >= 0 (got {max_redraws!r})")
    if not isinstance(record, (bool, np.bool_)):
        raise TypeError(f"record: must be True or False (got {record!r})")
    env.trials = coerce(TrialDistribution, trials, "trials")
    env.start_mode = start
    env.action_mode = action
    env.observe_mode = observe
    env.reward_weights = coerce(RewardWeights, reward, "reward")
    env.envelope = coerce(Envelope, envelope, "envelope")
    env.max_redraws = int(max_redraws)
    options = {"action": action, "observe": observe, "rotor_floor": rotor_floor,
               "hold_s": hold_s, "end_on_recovery": end_on_recovery, "ground": ground}  # fmt: skip
    check_episode_options(**options)
    par = pack_episode(**options, reward=env.reward_weights, envelope=env.envelope)
    env._slots = Slots(
        n, env.trials, par, until_detection=start == "detection", ground=bool(ground),
        record=bool(record),
    )  # fmt: skip


class ImpactRecoveryEnv(gym.Env):
    """Recover a quadrotor from a wall impact (docs/LEARNING.md).

    One step is one control period of the trial (5 ms, 200 Hz): the action's
    rotor command is applied at the tick through the loop's external command,
    so the rotor slew limit and zero floor apply as to any controller.

    Parameters
    ----------
    trials : TrialDistribution, optional
        What ``reset`` draws (default: the authors' distribution, the Navi).
    start : {"detection", "trial"}
        ``"detection"``: ``reset`` runs the pre-impact spin-down until the
        detector fires; the agent acts from that tick (a drawn trial that is
        never detected is redrawn). ``"trial"``: the agent acts from t = 0 and
        meets the impact itself.
    action : {"rotors", "ctbr"}
        Four rotor speeds, or collective thrust and body rates through the
        staged controller's rate loop.
    observe : {"imu", "state", "estimate"}
        On-board measurements (IMU, detector, the attitude estimate), the full
        state, or the estimator's output with the IMU and the detector (what an
        on-board controller sees; float64; docs/LEARNING.md).
    reward : RewardWeights, optional
    envelope : Envelope, optional
    hold_s : float
        The confirmation window (s): the recovered condition must hold this
        long in stage 4 to end the episode as recovered; the observer's
        stages 2-4 need their tests to hold this long too (docs/LEARNING.md 5).
    end_on_recovery : bool
        End the episode once recovered; False: run to the final time.
    ground : bool
        The ground (altitude 0) is a contact surface and its first contact
        ends the episode as a failure.
    rotor_floor : {"vehicle", "zero"}
        Rotor actions span the vehicle's rotor range, or ``[0, max]``.
    record : bool
        Keep the 1-kHz time series and IMU record (for :meth:`result`).
    max_redraws : int
        Undetected trials redrawn in a row before ``reset`` gives up.
    """

    metadata: dict[str, Any] = {"render_modes": []}

    def __init__(self, **options: Any) -> None:
        configure(self, 1, **options)
        self.action_space, self.observation_space = spaces_for(self.action_mode, self.observe_mode)
        self._act = np.zeros((1, 4))

    # ------------------------------------------------------------ Gymnasium API
    def reset(
        self, *, seed: int | None = None, options: Mapping[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Draw a trial (or take ``options["trial"]``) and begin its episode.

        ``options["trial"]``: an :class:`~quadimpact.inputs.scenarios.ImpactTrial`
        or a mapping of its fields (completed by the distribution's fixed
        settings) to run instead of a draw.
        """
        super().reset(seed=seed)
        check_options(options, ("trial",))
        trial = (options or {}).get("trial")
        self._slots.reset(0, self.np_random, trial, self.max_redraws)
        info = {
            "trial": dict(self._slots.trial_fields[0]),
            "redraws": int(self._slots.redraws[0]),
            "t": self._slots.time(0),
            "stage": self._slots.stage(0),
        }
        return self._slots.obs[0].copy(), info

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Apply the action for one control period."""
        s = self._slots
        if not s.active()[0]:
            raise RuntimeError("step: the episode has ended; call reset()")
        self._act[0] = check_actions(action, (4,))
        s.step(self._act)
        info: dict[str, Any] = {"t": float(s.D.ls[0, L.LS_T]), "stage": int(s.ENV[0, B.B_STAGE])}
        terminated = bool(s.terminated[0])
        truncated = bool(s.truncated[0])
        if terminated or truncated:
            info["metrics"] = s.metrics(0)
            info["outcome"] = info["metrics"]["outcome"]
        return s.obs[0].copy(), float(s.reward[0]), terminated, truncated, info

    # ------------------------------------------------------------ hooks
    def report_stage(self, stage: int) -> None:
        """The policy's stage for the next step (the hook of staged policies).

        A policy with stages of its own (``RecoveryPolicy``) reports, before
        each step, the stage its law is in at that tick; the stage is then
        recorded at the tick as the built-in controller's is, and the metrics'
        stage times and ``recovered`` are the policy's. Once a policy has
        reported in an episode the observer is off for the rest of it.
        """
        self._slots.reported[0] = float(stage)

    def tick_measurement(self) -> np.ndarray:
        """A copy of what a controller sees at the next tick (layout ``MS_*``)."""
        return self._slots.TMEAS[0].copy()

    @property
    def run_setup(self):
        """The packed run of the current trial (``quadimpact.simulation.setup.RunSetup``)."""
        return self._slots.setups[0]

    @property
    def scenario(self) -> ImpactTrial | None:
        """The current trial."""
        return self._slots.scenarios[0]

    def result(self) -> SimulationResult:
        """The current trial's run so far, as ``quadimpact.simulate`` returns it."""
        return self._slots.result(0)
