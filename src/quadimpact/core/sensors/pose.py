"""The pose sensor: position (and optionally attitude) from motion capture or vision.

It measures at its own rate (``scfg[SC_POSE_RATE]``, default 100 Hz):
measurement ``n`` arrives at the first IMU sample at or after
``t0 + n / rate + L / rate_imu``, with a latency of ``L`` IMU samples
(``scfg[SC_POSE_LAG]``), and is of the true pose ``L`` samples before it
arrived (a ring of the last poses is kept in ``sst``). Position noise:
white, ``scfg[SC_POSE_NOISE_P]`` per axis; attitude (when ``SC_POSE_ATT``):
the true attitude rotated by a small rotation vector of white noise
``scfg[SC_POSE_NOISE_A]`` per axis (body axes). Draws: ``snoise[i, SN_POSE...]``.

A measurement is written into the measurement record (``MS_POSE``,
``MS_POSE_T`` = the sample at which it arrived) and the IMU record's
``I_POSE`` columns (NaN at samples without one).
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import (
    I_POSE,
    LS_T0,
    MAX_POSE_LAG,
    MS_POSE,
    MS_POSE_T,
    SC_POSE,
    SC_POSE_ATT,
    SC_POSE_LAG,
    SC_POSE_NOISE_A,
    SC_POSE_NOISE_P,
    SC_POSE_RATE,
    SC_RATE,
    SN_POSE,
    SS_N,
    SS_POSE_N,
    SS_POSE_RING,
    X_POS,
    X_QUAT,
)
from quadimpact.core.records import Data, Model, Output
from quadimpact.core.sensors.rotvec import rotate_by


@compiled
def pose_sample(t: float, xs: np.ndarray, m: Model, d: Data, o: Output) -> None:
    """The pose sensor at IMU sample ``d.sst[SS_N] - 1`` (time ``t``, s; true state ``xs``)."""
    scfg = m.scfg
    sst = d.sst
    i = int(sst[SS_N]) - 1
    row = 0 <= i < o.imu.shape[0]
    if row:
        for a in range(7):
            o.imu[i, I_POSE + a] = math.nan
    if scfg[SC_POSE] < 0.5:
        return
    ring = SS_POSE_RING + 7 * (i % MAX_POSE_LAG)
    for a in range(3):
        sst[ring + a] = xs[X_POS + a]
    for a in range(4):
        sst[ring + 3 + a] = xs[X_QUAT + a]
    lag = int(scfg[SC_POSE_LAG])
    # measurement n is taken at t0 + n / rate and arrives lag samples later
    due = d.ls[LS_T0] + sst[SS_POSE_N] / scfg[SC_POSE_RATE] + lag / scfg[SC_RATE]
    if i < lag or t < due - 1e-9:
        return
    src = SS_POSE_RING + 7 * ((i - lag) % MAX_POSE_LAG)
    noisy = 0 <= i < m.snoise.shape[0]
    meas = d.meas
    for a in range(3):
        v = sst[src + a]
        if noisy:
            v += scfg[SC_POSE_NOISE_P] * m.snoise[i, SN_POSE + a]
        meas[MS_POSE + a] = v
    q = meas[MS_POSE + 3 : MS_POSE + 7]
    n = math.sqrt(sst[src + 3] ** 2 + sst[src + 4] ** 2 + sst[src + 5] ** 2 + sst[src + 6] ** 2)
    for a in range(4):
        q[a] = sst[src + 3 + a] / n
    if scfg[SC_POSE_ATT] > 0.5 and noisy:
        s = scfg[SC_POSE_NOISE_A]
        rotate_by(
            q,
            s * m.snoise[i, SN_POSE + 3],
            s * m.snoise[i, SN_POSE + 4],
            s * m.snoise[i, SN_POSE + 5],
        )
    meas[MS_POSE_T] = t
    sst[SS_POSE_N] += 1.0
    if row:
        for a in range(7):
            o.imu[i, I_POSE + a] = meas[MS_POSE + a]
