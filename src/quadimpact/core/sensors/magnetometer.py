"""The magnetometer: the Earth's field in body axes, sampled with the IMU.

It reads ``m_B = C^T m_I + bias + noise``, with ``m_I`` the Earth field in
inertial NED (``scfg[SC_MAG_FIELD]``: magnetic north along +X, dipping
below the horizon by the dip angle, down positive; unit length unless a norm
is given), a static bias drawn once per run (``scfg[SC_MAG_BIAS]``, body
axes) and white noise of
standard deviation ``scfg[SC_MAG_NOISE]`` per axis (in units of the field),
drawn from ``snoise[i, SN_MAG...]``. Without it yaw is unobservable: an
estimator's heading drifts with the gyro bias.
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import (
    I_MAG,
    MS_MAG,
    MS_MAG_T,
    SC_MAG,
    SC_MAG_BIAS,
    SC_MAG_FIELD,
    SC_MAG_NOISE,
    SN_MAG,
    SS_N,
)
from quadimpact.core.records import Data, Model, Output


@compiled
def magnetometer_sample(t: float, C: np.ndarray, m: Model, d: Data, o: Output) -> None:
    """The magnetometer's sample with IMU sample ``d.sst[SS_N] - 1`` at ``t`` (s).

    ``C``: the true rotation there. Writes ``MS_MAG``, ``MS_MAG_T`` and the IMU
    record's ``I_MAG`` columns (NaN without a magnetometer).
    """
    scfg = m.scfg
    i = int(d.sst[SS_N]) - 1
    row = 0 <= i < o.imu.shape[0]
    if scfg[SC_MAG] < 0.5:
        if row:
            for a in range(3):
                o.imu[i, I_MAG + a] = math.nan
        return
    noisy = 0 <= i < m.snoise.shape[0]
    sigma = scfg[SC_MAG_NOISE]
    for a in range(3):
        v = (
            C[0, a] * scfg[SC_MAG_FIELD]
            + C[1, a] * scfg[SC_MAG_FIELD + 1]
            + C[2, a] * scfg[SC_MAG_FIELD + 2]
        ) + scfg[SC_MAG_BIAS + a]
        if noisy:
            v += sigma * m.snoise[i, SN_MAG + a]
        d.meas[MS_MAG + a] = v
        if row:
            o.imu[i, I_MAG + a] = v
    d.meas[MS_MAG_T] = t
