"""A learned residual on the recovery law: a small network that corrects the staged law.

From the detection to the recovery (stages 1-4; stage 5, the return to hover,
is then the law's alone), or in every stage from the detection on (the hover
too: the block's last stage 5), the ``recovery`` controller's outer loop gives a collective
thrust ``T`` (N) and roll and pitch rate references ``p_des``, ``q_des``
(rad/s). When ``ctrl[C_POLICY]`` holds a network (its first slot, the hidden
width, > 0), :func:`residual_references` corrects them from on-board
quantities only (the state estimate, the estimated rates, the accelerometer,
the detector's wall normal and time, the law's stage)::

    f  = features(...)                     24 numbers, each about unit size
    h  = tanh(W1 f + b1)                   hidden layer (width nh <= MAX_HIDDEN, 32)
    o  = tanh(W2 h + b2)                   3 outputs in (-1, 1)
    T'     = max(0, T + s_T m g o_0)
    p_des' = p_des + s_w o_1,   q_des' = q_des + s_w o_2

so the correction is bounded by ``s_T`` times the hover thrust and ``s_w``
rad/s whatever the weights, and a network whose ``W2`` and ``b2`` are zero
flies the staged law exactly. Stage changes, the lean cut, the rate loop
and the allocation are the law's.

A policy may be *hover-centred* (its block's ``PB_HOVER_CENTRED`` 1): in the
hover stage (5) its outputs are then ``tanh(o(f)) - tanh(o(f*))``, where
``f*`` is ``f`` with the vehicle at rest and level (gravity along body z, no
velocity, no rates, the accelerometer reading ``-g`` along body z, the law at
its hover thrust and zero rate references; the wall normal, the time and the
stage as in ``f``). The correction is then zero at the hover itself: it may
change how the law returns to its hover, never where the hover is
(:func:`hover_features`). The bound becomes twice the scale.

A policy may also *fade* in the hover stage (its block's ``PB_FADE_FROM_S``
and ``PB_FADE_TO_S``, ``0 <= from < to <= 2`` s; ``to`` 0: no fade): its
stage-5 correction is then multiplied by a weight that is 1 until ``from``
seconds after the detecting sample, falls linearly to 0 at ``to`` and stays
0, so the law alone holds the hover it has reached. The time is feature 15,
which the features cap at 2 s; hence ``to <= 2``.

A policy may *hand over* the hover (its block's ``PB_HAND_OVER`` 1): in stage
5 it acts only while the law brakes, and not once the law has captured the
point it holds (``recovery.py``, ``RM_HOLD_SET``; the ``stop`` hold mode, the
default). From then on the law alone holds its hover, as without a policy.

Features (body FRD axes; non-finite inputs read as 0):

======  ==================================================================
0-2     gravity's direction in body axes (from the estimated attitude)
3-5     the wall-normal estimate in body axes (zero before it is known)
6-8     estimated velocity, body axes, / 2 m/s
9-11    estimated body rates / 8 rad/s
12-14   the accelerometer's specific force, body axes, / 16 m/s^2
15      time since the detecting sample, s, capped at 2
16-20   the law's stage (1-5), one-hot
21      the law's thrust / (m g) - 1
22-23   the law's p_des, q_des / 8 rad/s
======  ==================================================================

The parameter block at ``ctrl[C_POLICY:]``: ``[nh, s_T, s_w, last stage, hover-centred,
hand over, fade from (s), fade to (s), W1 (nh x 24, row-major), b1 (nh), W2 (3 x nh,
row-major), b2 (3)]``; the last stage is 4 (stages 1-4; a 0 reads as 4) or 5 (stages
1-5). The weights come from a ``.npz`` file (``quadimpact.inputs.policy_file``); a NumPy
forward pass of the same network is ``PolicyWeights.outputs``. The block's slots
(``PB_*``) are declared below; the network's shape (``N_FEATURES``, ``N_OUTPUTS``,
``MAX_HIDDEN``) in ``core/controller_slots.py``, which the policy file reads too.
"""

import math

import numpy as np

from quadimpact.core.compiled import allocating, compiled
from quadimpact.core.controller_slots import (
    C_POLICY,
    F_SCALE_M_S2,
    MAX_HIDDEN,
    N_FEATURES,
    N_OUTPUTS,
    NPOLICY,
    T_CAP_S,
)
from quadimpact.core.layout import STAGE_HOVER, STAGE_RECOVERED, X_QUAT, X_VEL, Block
from quadimpact.core.sensors.measurement_slots import (
    MS_IMU_F,
    MS_NORMAL,
    MS_T_DETECT,
    MS_W_HAT,
    MS_X,
)
from quadimpact.core.vehicle_slots import V_GRAVITY, V_MASS

# ---- the residual's block, at ctrl[C_POLICY + PB_*]
_policy = Block("ctrl.policy", "PB_", capacity=NPOLICY)
PB_HIDDEN = _policy.slot("PB_HIDDEN")  # hidden width (0: no policy)
PB_THRUST_SCALE = _policy.slot("PB_THRUST_SCALE")  # s_T: the largest thrust correction / (m g)
PB_RATE_SCALE = _policy.slot("PB_RATE_SCALE")  # s_w, rad/s: the largest p, q reference correction
PB_LAST_STAGE = _policy.slot("PB_LAST_STAGE")  # the last stage it acts in: 4 (0 reads as 4) or 5
PB_HOVER_CENTRED = _policy.slot("PB_HOVER_CENTRED")  # 1: zero correction at the hover in stage 5
PB_HAND_OVER = _policy.slot("PB_HAND_OVER")  # 1: none in stage 5 once the law holds its point
PB_FADE_FROM_S = _policy.slot("PB_FADE_FROM_S")  # s after the detection: stage 5's fade begins
PB_FADE_TO_S = _policy.slot("PB_FADE_TO_S")  # s: stage 5's correction 0 from here (0: no fade)
PB_WEIGHTS = _policy.slot(  # W1 (nh x N_FEATURES, row-major), b1 (nh), W2 (N_OUTPUTS x nh), b2
    "PB_WEIGHTS", MAX_HIDDEN * (N_FEATURES + 1 + N_OUTPUTS) + N_OUTPUTS
)
N_POLICY_BLOCK = _policy.end("N_POLICY_BLOCK")

_V_SCALE_M_S = 2.0
_W_SCALE_RAD_S = 8.0


@allocating
def features(
    t: float,
    stage: int,
    refs: tuple[float, float, float],
    meas: np.ndarray,
    veh: np.ndarray,
) -> np.ndarray:
    """The network's 24 input features (table above) at time ``t`` (s) in ``stage``.

    ``refs``: the staged law's ``(thrust N, p_des rad/s, q_des rad/s)``; ``meas``:
    the controller's measurement vector; ``veh``: the vehicle vector.
    """
    f = np.zeros(N_FEATURES)
    x = meas[MS_X:]
    q0 = x[X_QUAT]
    q1 = x[X_QUAT + 1]
    q2 = x[X_QUAT + 2]
    q3 = x[X_QUAT + 3]
    # rows of C^T (body <- inertial): C^T e_Z is the third row of C read as a column
    f[0] = 2.0 * (q1 * q3 - q0 * q2)
    f[1] = 2.0 * (q2 * q3 + q0 * q1)
    f[2] = q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3
    n0 = meas[MS_NORMAL]
    n1 = meas[MS_NORMAL + 1]
    n2 = meas[MS_NORMAL + 2]
    # C^T n, body components of the inertial normal
    f[3] = (
        (q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3) * n0
        + 2.0 * (q1 * q2 + q0 * q3) * n1
        + 2.0 * (q1 * q3 - q0 * q2) * n2
    )
    f[4] = (
        2.0 * (q1 * q2 - q0 * q3) * n0
        + (q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3) * n1
        + 2.0 * (q2 * q3 + q0 * q1) * n2
    )
    f[5] = (
        2.0 * (q1 * q3 + q0 * q2) * n0
        + 2.0 * (q2 * q3 - q0 * q1) * n1
        + (q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3) * n2
    )
    for k in range(3):
        f[6 + k] = x[X_VEL + k] / _V_SCALE_M_S
        f[9 + k] = meas[MS_W_HAT + k] / _W_SCALE_RAD_S
        f[12 + k] = meas[MS_IMU_F + k] / F_SCALE_M_S2
    since = t - meas[MS_T_DETECT]
    f[15] = min(max(since, 0.0), T_CAP_S)
    if 1 <= stage <= 5:
        f[15 + stage] = 1.0
    f[21] = refs[0] / (veh[V_MASS] * veh[V_GRAVITY]) - 1.0
    f[22] = refs[1] / _W_SCALE_RAD_S
    f[23] = refs[2] / _W_SCALE_RAD_S
    for k in range(N_FEATURES):
        if not math.isfinite(f[k]):
            f[k] = 0.0
    return f


@compiled
def residual_last_stage(ctrl: np.ndarray) -> int:
    """The last stage the network at ``ctrl[C_POLICY:]`` acts in: 5 (the hover too) or 4."""
    if ctrl[C_POLICY + PB_LAST_STAGE] > STAGE_RECOVERED + 0.5:
        return STAGE_HOVER
    return STAGE_RECOVERED


@allocating
def hover_features(f: np.ndarray, gravity_m_s2: float) -> np.ndarray:
    """The features ``f`` with the vehicle at rest and level, at its hover (m/s^2 for ``g``).

    Gravity along body z, no velocity, no body rates, the accelerometer reading
    ``-g`` along body z (FRD), the law's thrust at ``m g`` and its rate
    references zero; the wall normal (3-5), the time (15) and the stage (16-20)
    are kept from ``f``.
    """
    h = f.copy()
    h[0] = 0.0
    h[1] = 0.0
    h[2] = 1.0
    for k in range(6, 12):
        h[k] = 0.0
    h[12] = 0.0
    h[13] = 0.0
    h[14] = -gravity_m_s2 / F_SCALE_M_S2
    h[21] = 0.0
    h[22] = 0.0
    h[23] = 0.0
    return h


@compiled
def hover_fade_weight(since_s: float, from_s: float, to_s: float) -> float:
    """The weight of the stage-5 correction ``since_s`` seconds after the detection.

    1 up to ``from_s``, linear down to 0 at ``to_s`` (s, ``from_s < to_s``), 0 after.
    """
    if since_s >= to_s:
        return 0.0
    if since_s <= from_s:
        return 1.0
    return (to_s - since_s) / (to_s - from_s)


@compiled
def network_outputs(f: np.ndarray, ctrl: np.ndarray) -> tuple[float, float, float]:
    """The network at ``ctrl[C_POLICY:]`` on features ``f``: its 3 outputs in (-1, 1)."""
    b = C_POLICY
    nh = int(ctrl[b + PB_HIDDEN])
    w1 = b + PB_WEIGHTS
    b1 = w1 + nh * N_FEATURES
    w2 = b1 + nh
    b2 = w2 + N_OUTPUTS * nh
    o0 = ctrl[b2]
    o1 = ctrl[b2 + 1]
    o2 = ctrl[b2 + 2]
    for j in range(nh):
        a = ctrl[b1 + j]
        row = w1 + j * N_FEATURES
        for i in range(N_FEATURES):
            a += ctrl[row + i] * f[i]
        h = math.tanh(a)
        o0 += ctrl[w2 + j] * h
        o1 += ctrl[w2 + nh + j] * h
        o2 += ctrl[w2 + 2 * nh + j] * h
    return math.tanh(o0), math.tanh(o1), math.tanh(o2)


@allocating
def residual_references(
    t: float,
    stage: int,
    refs: tuple[float, float, float],
    meas: np.ndarray,
    ctrl: np.ndarray,
    veh: np.ndarray,
) -> tuple[float, float, float]:
    """The law's ``refs = (thrust N, p_des rad/s, q_des rad/s)`` corrected by the network.

    The network is the block at ``ctrl[C_POLICY:]`` (module docstring); the
    result is ``(thrust, p_des, q_des)`` in the same units.
    """
    f = features(t, stage, refs, meas, veh)
    b = C_POLICY
    u0, u1, u2 = network_outputs(f, ctrl)
    if stage == STAGE_HOVER and ctrl[b + PB_HOVER_CENTRED] > 0.5:
        c0, c1, c2 = network_outputs(hover_features(f, veh[V_GRAVITY]), ctrl)
        u0 -= c0
        u1 -= c1
        u2 -= c2
    if stage == STAGE_HOVER and ctrl[b + PB_FADE_TO_S] > 0.0:
        w = hover_fade_weight(f[15], ctrl[b + PB_FADE_FROM_S], ctrl[b + PB_FADE_TO_S])
        u0 *= w
        u1 *= w
        u2 *= w
    thrust = refs[0] + ctrl[b + PB_THRUST_SCALE] * veh[V_MASS] * veh[V_GRAVITY] * u0
    if thrust < 0.0:
        thrust = 0.0
    p_des = refs[1] + ctrl[b + PB_RATE_SCALE] * u1
    q_des = refs[2] + ctrl[b + PB_RATE_SCALE] * u2
    return thrust, p_des, q_des
