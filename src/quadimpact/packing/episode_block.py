"""The learning environments' block: ``par`` (``EP_*`` of ``core.envs.episode_layout``:
the action and observation modes, the reward's weights and scales, the envelope,
the hold time, the observation scales)."""

from __future__ import annotations

import math
from typing import Any, Literal

import numpy as np

from quadimpact.core.envs import episode_layout as B

__all__ = ["ACTION_MODES", "CTBR_RATE_MAX_RAD_S", "OBSERVATION_MODES", "pack_episode"]

#: The action modes: rotor speeds, or collective thrust and body rates.
ACTION_MODES = ("rotors", "ctbr")
#: The observation modes: the IMU, the true state, the estimator's state.
OBSERVATION_MODES = ("imu", "state", "estimate")
#: The largest body-rate command of the ``ctbr`` mode, rad/s (powers of two: the
#: scaling of a rate action is exact).
CTBR_RATE_MAX_RAD_S = (32.0, 32.0, 8.0)


def pack_episode(
    *,
    action: Literal["rotors", "ctbr"],
    observe: Literal["imu", "state", "estimate"],
    rotor_floor: Literal["vehicle", "zero"],
    reward: Any,
    envelope: Any,
    hold_s: float,
    end_on_recovery: bool,
    ground: bool,
    dt_s: float = 0.005,
) -> np.ndarray:
    """The stacked environments' parameter vector (``core.envs.stacked`` ``EP_*``).

    Parameters
    ----------
    action, observe : str
        The action mode (:data:`ACTION_MODES`) and observation mode
        (:data:`OBSERVATION_MODES`), checked by ``envs.settings``.
    rotor_floor : {"vehicle", "zero"}
        The lowest rotor command: the vehicle's minimum speed, or zero.
    reward : envs.settings.RewardWeights
        The reward's weights and scales (SI).
    envelope : envs.settings.Envelope
        The limits that end an episode (deg, m, rad/s).
    hold_s : float
        How long a recovered state must hold, s (rounded to control ticks of
        ``dt_s``, at least one).
    end_on_recovery, ground : bool
        End the episode once recovered; the ground is a contact surface.
    dt_s : float
        The control period, s.
    """
    par = np.zeros(B.NPAR)
    par[B.EP_ACTION] = B.ACT_CTBR if action == "ctbr" else B.ACT_ROTORS
    par[B.EP_OBSERVE] = {"state": B.OBS_STATE, "estimate": B.OBS_ESTIMATE}.get(observe, B.OBS_IMU)
    par[B.EP_ZERO_LOW] = 1.0 if rotor_floor == "zero" else 0.0
    par[B.EP_RATE_MAX : B.EP_RATE_MAX + 3] = CTBR_RATE_MAX_RAD_S
    par[B.EP_W_TILT] = reward.tilt
    par[B.EP_W_RATE] = reward.rate
    par[B.EP_W_VZ] = reward.vertical_speed
    par[B.EP_W_HEIGHT] = reward.height_loss
    par[B.EP_W_EFFORT] = reward.effort
    par[B.EP_W_RECOVERY] = reward.recovery_bonus
    par[B.EP_W_FAILURE] = reward.failure_penalty
    par[B.EP_FAIL_REMAINING] = 1.0 if reward.failure_remaining else 0.0
    par[B.EP_S_RATE] = reward.rate_scale_rad_s
    par[B.EP_S_VZ] = reward.vertical_speed_scale_m_s
    par[B.EP_S_HEIGHT] = reward.height_scale_m
    par[B.EP_MAX_TILT_COS] = math.cos(math.radians(envelope.max_tilt_deg))
    par[B.EP_MAX_DROP] = envelope.max_drop_m
    par[B.EP_MAX_DIST] = envelope.max_distance_m
    par[B.EP_MAX_RATE] = envelope.max_rate_rad_s
    par[B.EP_HOLD_TICKS] = max(1.0, round(hold_s / dt_s))
    par[B.EP_END_ON_RECOVERY] = 1.0 if end_on_recovery else 0.0
    par[B.EP_GROUND] = 1.0 if ground else 0.0
    par[B.EP_OBS_F] = 9.81
    par[B.EP_OBS_W] = 10.0
    par[B.EP_OBS_V] = 2.0
    par[B.EP_OBS_T] = 1.0
    par[B.EP_OBS_POS] = 1.0
    par[B.EP_OBS_CLIP] = 10.0
    return par
