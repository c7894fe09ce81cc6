"""The learning environments' own records and slots (``core/envs/stacked.py`` runs them).

The record :class:`Env` (stacked like the runs' records: row ``k`` is run
``k``), the per-run episode state (``B_*``), the episode outcomes (``OC_*``),
the parameters shared by the runs (``EP_*``), the action and observation
modes (``ACT_*``, ``OBS_*``) and the observation lengths, declared as
:class:`~quadimpact.core.layout.Block`s like the core's own slots
(``tests/core/test_layout.py``). No compiled code: this is the environment's
declaration module, imported by its four stages (``stacked.py``,
``actions.py``, ``observation.py``, ``reward.py``) and its packer
(``packing/episode_block.py``), so none of them owns the blocks alone.
"""

from typing import NamedTuple

import numpy as np

from quadimpact.core.layout import Block

#: The environments fly quadrotors: four rotor commands per action (the ``rotors``
#: action mode) and four rotor speeds per observation. ``envs/engine.py`` refuses a
#: vehicle with another rotor count.
ENV_ROTORS = 4


# ---------------------------------------------------------------- records
class Env(NamedTuple):
    """The environments' own arrays, stacked like the runs' records (row ``k``: run ``k``)."""

    state: np.ndarray  # (N, NB) per-run episode state (B_*)
    par: np.ndarray  # (NPAR,) parameters shared by the runs (EP_*)
    tmeas: np.ndarray  # (N, NMEAS + tail) the measurement record of each run's next tick
    reported: np.ndarray  # (N,) the stage the policy reports for this tick (< 0: none)
    obs: np.ndarray  # (N, n_obs) float32 observations
    reward: np.ndarray  # (N,)
    terminated: np.ndarray  # (N,) bool
    truncated: np.ndarray  # (N,) bool


# ---------------------------------------------------------------- per-run env state (N, NB)
_b = Block("env.state", "B_")
B_ACTIVE = _b.slot("B_ACTIVE")  # 1 while the episode runs
B_STAGE = _b.slot("B_STAGE")  # stage in force (the policy's or the observer's)
B_POLICY = _b.slot("B_POLICY")  # 1 once the policy has reported a stage this episode
B_HOLD = _b.slot("B_HOLD")  # consecutive ticks (after the takeover) the recovered condition held
B_H_REF = _b.slot("B_H_REF")  # m, altitude at the takeover (height-loss reference)
B_X_REF = _b.slot("B_X_REF")  # m, CM X and Y at the takeover (distance reference)
B_Y_REF = _b.slot("B_Y_REF")
B_STEPS = _b.slot("B_STEPS")  # steps taken this episode
B_OUTCOME = _b.slot("B_OUTCOME")  # OC_* below
B_RETURN = _b.slot("B_RETURN")  # sum of the rewards of the episode
B_INEXACT = _b.slot("B_INEXACT")  # policy commands the action map could not give exactly
B_LEVEL_N = _b.slot("B_LEVEL_N")  # consecutive ticks (after the takeover) the level test held
B_LEVEL_T = _b.slot("B_LEVEL_T")  # s, first tick of that run
B_LEVEL_P = _b.slot("B_LEVEL_P", 3)  # CM position there, inertial, m
B_HOLD_T = _b.slot("B_HOLD_T")  # s, first tick of the recovered condition's run
B_HOLD_P = _b.slot("B_HOLD_P", 3)  # CM position there, inertial, m
NB = _b.end("NB")

OC_RUNNING = 0
OC_RECOVERED = 1
OC_GROUND = 2
OC_TILT = 3
OC_ALTITUDE = 4
OC_DISTANCE = 5
OC_RATE = 6
OC_TIME_LIMIT = 7
OC_FAILED = 8

# ---------------------------------------------------------------- parameters (NPAR)
_ep = Block("env.par", "EP_")
EP_ACTION = _ep.slot("EP_ACTION")  # ACT_* below
EP_OBSERVE = _ep.slot("EP_OBSERVE")  # OBS_* below
EP_ZERO_LOW = _ep.slot("EP_ZERO_LOW")  # 1: rotor actions map onto [0, hi], not [lo, hi]
EP_RATE_MAX = _ep.slot("EP_RATE_MAX", 3)  # ctbr rate reference scale (p, q, r), rad/s
EP_W_TILT = _ep.slot("EP_W_TILT")  # reward weights per second of simulated time
EP_W_RATE = _ep.slot("EP_W_RATE")
EP_W_VZ = _ep.slot("EP_W_VZ")
EP_W_HEIGHT = _ep.slot("EP_W_HEIGHT")
EP_W_EFFORT = _ep.slot("EP_W_EFFORT")
EP_W_RECOVERY = _ep.slot("EP_W_RECOVERY")  # bonus on the recovered termination
EP_W_FAILURE = _ep.slot("EP_W_FAILURE")  # penalty on a failure termination (ground, envelope)
EP_FAIL_REMAINING = _ep.slot("EP_FAIL_REMAINING")  # 1: a failure costs the top rate to the end
EP_S_RATE = _ep.slot("EP_S_RATE")  # rad/s, scale of the rate cost
EP_S_VZ = _ep.slot("EP_S_VZ")  # m/s, scale of the vertical-speed cost
EP_S_HEIGHT = _ep.slot("EP_S_HEIGHT")  # m, scale of the height-loss cost
EP_MAX_TILT_COS = _ep.slot("EP_MAX_TILT_COS")  # envelope: cos of the largest tilt from vertical
EP_MAX_DROP = _ep.slot("EP_MAX_DROP")  # m, envelope: altitude below the takeover altitude
EP_MAX_DIST = _ep.slot("EP_MAX_DIST")  # m, envelope: horizontal distance from the takeover
EP_MAX_RATE = _ep.slot("EP_MAX_RATE")  # rad/s, envelope: |omega|
EP_HOLD_TICKS = _ep.slot("EP_HOLD_TICKS")  # confirmation window of the level test, ticks
EP_GROUND = _ep.slot("EP_GROUND")  # 1: the first ground contact ends the episode
EP_OBS_F = _ep.slot("EP_OBS_F")  # observation scales: specific force m/s^2, rates rad/s,
EP_OBS_W = _ep.slot("EP_OBS_W")  # speed m/s, time s, position m; observations are
EP_OBS_V = _ep.slot("EP_OBS_V")  # clipped to +-EP_OBS_CLIP
EP_OBS_T = _ep.slot("EP_OBS_T")
EP_OBS_POS = _ep.slot("EP_OBS_POS")
EP_OBS_CLIP = _ep.slot("EP_OBS_CLIP")
EP_END_ON_RECOVERY = _ep.slot("EP_END_ON_RECOVERY")  # 1: the episode ends once recovered
NPAR = _ep.end("NPAR")

ACT_ROTORS = 0
ACT_CTBR = 1
OBS_IMU = 0
OBS_STATE = 1
OBS_ESTIMATE = 2
N_OBS_IMU = 24
N_OBS_STATE = 19
N_OBS_ESTIMATE = 30
# the estimate mode's scales: powers of two, so that value = observation * scale exactly
# (observations float64): the staged controller can act on its observation alone
OBS_EST_VEL = 2.0  # m/s
OBS_EST_POS = 8.0  # m
OBS_EST_RATE = 8.0  # rad/s
OBS_EST_F = 16.0  # m/s^2
OBS_EST_BIAS = 0.125  # rad/s
OBS_EST_ROTOR = 1024.0  # rad/s


def n_observations(mode: int) -> int:
    """The observation length of a mode (``OBS_*``)."""
    if mode == OBS_STATE:
        return N_OBS_STATE
    if mode == OBS_ESTIMATE:
        return N_OBS_ESTIMATE
    return N_OBS_IMU
