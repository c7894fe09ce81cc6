"""The estimate beside the truth at every IMU sample: the IMU record's columns and the errors.

After the estimator has processed a sample, :func:`record_estimate` writes
the estimate (``I_Q_HAT``, ``I_BIAS_HAT``, ``I_VEL_HAT``, ``I_POS_HAT``), the
gyro's true bias (``I_BIAS_TRUE``) and the four errors (``I_ERR``: the angle
of ``q_hat (x) q^-1`` in deg, ``|v_hat - v|`` in m/s (inertial CM velocity),
``|b_hat - b|`` in rad/s, ``|p_hat - p|`` in m) into the sample's row, and
accumulates each error's sum of squares, maximum and count by phase in the
stats (``ST_EST_ERR``):

* phase 0, before the first contact with an obstacle (``ST_ONSET_T`` not yet set);
* phase 1, the crash: from the first contact to the entry into stage 4 of a
  staged controller (``ST_STAGE_T[4]``), or to the end;
* phase 2, after stage 4.

(A sample at the tick of an entry precedes that tick's command, so it
belongs to the phase before.)
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.estimator_slots import ES_BIAS, ES_POS, ES_Q, ES_VEL
from quadimpact.core.layout import (
    N_EST_ERR,
    N_PHASES,
    ST_EST_ERR,
    ST_ONSET_T,
    ST_STAGE_T,
    X_POS,
    X_QUAT,
    X_VEL,
)
from quadimpact.core.records import Data, Model, Output
from quadimpact.core.sensors.imu_slots import (
    I_BIAS_HAT,
    I_BIAS_TRUE,
    I_ERR,
    I_POS_HAT,
    I_Q_HAT,
    I_VEL_HAT,
    SC_BIAS,
    SS_N,
    SS_WALK,
)
from quadimpact.core.sensors.rotvec import error_angle

STAGE_RECOVERED = 4  # controllers/recovery.py's


@compiled
def phase_at(t: float, stats: np.ndarray) -> int:
    """The phase (0 before contact, 1 the crash, 2 after stage 4) of a sample at ``t`` (s)."""
    onset = stats[ST_ONSET_T]
    if np.isnan(onset) or t < onset:
        return 0
    t4 = stats[ST_STAGE_T + STAGE_RECOVERED]
    if not np.isnan(t4) and t > t4:
        return 2
    return 1


@compiled
def record_estimate(t: float, xs: np.ndarray, C: np.ndarray, m: Model, d: Data, o: Output) -> None:
    """Errors of the estimate ``d.est`` against the true state ``xs`` (rotation ``C``) at ``t``."""
    est = d.est
    i = int(d.sst[SS_N]) - 1
    e_att = math.degrees(error_angle(est[ES_Q : ES_Q + 4], xs[X_QUAT : X_QUAT + 4]))
    ev = 0.0
    eb = 0.0
    ep = 0.0
    for r in range(3):
        v = C[r, 0] * xs[X_VEL] + C[r, 1] * xs[X_VEL + 1] + C[r, 2] * xs[X_VEL + 2]
        ev += (est[ES_VEL + r] - v) ** 2
        eb += (est[ES_BIAS + r] - (m.scfg[SC_BIAS + 3 + r] + d.sst[SS_WALK + r])) ** 2
        ep += (est[ES_POS + r] - xs[X_POS + r]) ** 2
    errors = (e_att, math.sqrt(ev), math.sqrt(eb), math.sqrt(ep))
    stats = o.stats
    phase = phase_at(t, stats)
    for k in range(N_EST_ERR):
        j = ST_EST_ERR + 3 * (N_PHASES * k + phase)
        stats[j] += errors[k] * errors[k]
        if errors[k] > stats[j + 1]:
            stats[j + 1] = errors[k]
        stats[j + 2] += 1.0
    if not 0 <= i < o.imu.shape[0]:
        return
    row = o.imu[i]
    for a in range(4):
        row[I_Q_HAT + a] = est[ES_Q + a]
        row[I_ERR + a] = errors[a]
    for a in range(3):
        row[I_BIAS_HAT + a] = est[ES_BIAS + a]
        row[I_VEL_HAT + a] = est[ES_VEL + a]
        row[I_POS_HAT + a] = est[ES_POS + a]
        row[I_BIAS_TRUE + a] = m.scfg[SC_BIAS + 3 + a] + d.sst[SS_WALK + a]
