"""The pose sensor: position (and optionally attitude) from motion capture or vision.

A sensor component. It measures at its own rate (config ``rate_hz``,
default 100 Hz): measurement ``n`` arrives at the first IMU sample at or
after ``t0 + n / rate + L / rate_imu``, with ``t0`` the run's first IMU
sample and a latency of ``L`` IMU samples (config ``lag``), and is of the
true pose ``L`` samples before it arrived (a ring of the last poses is kept
in its state). Position noise: white, ``position_noise_m`` per axis;
attitude (when ``attitude``): the true attitude rotated by a small rotation
vector of white noise ``attitude_noise_rad`` per axis (body axes).

A measurement is written into its measurement block (``pose``, and ``t_s``
= the sample at which it arrived) and its IMU table columns (NaN at samples
without one). It predates sensor components, so its draws stay columns
12-17 of the frozen ``snoise`` matrix (``LegacyColumns``), its columns keep
their names (``pose_x_m``...), and a scenario gives its settings as
``[pose_sensor]`` (``scenario_key``); docs/ARCHITECTURE.md 10.
"""

from __future__ import annotations

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import X_POS, X_QUAT
from quadimpact.core.sensors.component import (
    LegacyColumns,
    PackContext,
    SensorComponent,
    Slot,
    offsets,
)
from quadimpact.core.sensors.imu_slots import SN_POSE
from quadimpact.core.sensors.older_settings import PoseSensor
from quadimpact.core.sensors.rotvec import rotate_by

__all__ = ["MAX_POSE_LAG", "SENSOR", "PoseSensor"]

MAX_POSE_LAG = 64  # IMU samples: the ring of true poses (a latency is at most 63 of them)


CONFIG = (
    Slot("on", 1, "", "1: the run has a pose sensor"),
    Slot("rate_hz", 1, "Hz", "its rate"),
    Slot("position_noise_m", 1, "m", "position white-noise std per axis"),
    Slot("attitude", 1, "", "1: it measures the attitude too"),
    Slot("attitude_noise_rad", 1, "rad", "attitude noise std per axis (rotation vector)"),
    Slot("lag", 1, "", "latency, IMU samples (< MAX_POSE_LAG)"),
    Slot("imu_rate_hz", 1, "Hz", "the IMU's rate (the latency's unit)"),
)
STATE = (
    Slot("t0_s", 1, "s", "the run's first IMU sample"),
    Slot("calls", 1, "", "IMU samples so far"),
    Slot("n", 1, "", "pose measurements taken"),
    Slot("ring", 7 * MAX_POSE_LAG, "m, 1", "true poses (position, quaternion) of the last samples"),
)
MEASUREMENT = (
    Slot("pose", 7, "m, 1", "the latest measurement: position (inertial NED), quaternion"),
    Slot("t_s", 1, "s", "the IMU sample at which it arrived (NaN: none)"),
)
NOISE = (
    Slot("position", 3, "", "the position noise's draws"),
    Slot("attitude", 3, "", "the attitude rotation vector's draws"),
)
RECORD = (Slot("pose", 7, "m, 1", "the measurement arrived here (NaN: none)"),)

_c, _s, _m, _n, _r = (offsets(b) for b in (CONFIG, STATE, MEASUREMENT, NOISE, RECORD))
C_ON, C_RATE, C_NOISE_P, C_ATT, C_NOISE_A, C_LAG, C_IMU_RATE = (
    _c[k]
    for k in (
        "on",
        "rate_hz",
        "position_noise_m",
        "attitude",
        "attitude_noise_rad",
        "lag",
        "imu_rate_hz",
    )
)
S_T0, S_CALLS, S_N, S_RING = (_s[k] for k in ("t0_s", "calls", "n", "ring"))
M_POSE, M_T = _m["pose"], _m["t_s"]
N_POS, N_ATT = _n["position"], _n["attitude"]
R_POSE = _r["pose"]


def pack(settings: PoseSensor, context: PackContext) -> list[float]:
    """The config block of ``settings``: noises in m and rad, the latency in IMU samples."""
    rate_imu = float(context.imu_rate_hz)
    return [
        1.0,
        float(settings.rate_hz),
        float(settings.position_noise_m),
        1.0 if settings.attitude else 0.0,
        math.radians(settings.attitude_noise_deg),
        float(min(round(settings.latency_s * rate_imu), MAX_POSE_LAG - 1)),
        rate_imu,
    ]


@compiled
def sample(
    t: float,
    x: np.ndarray,
    xdot: np.ndarray,
    C: np.ndarray,
    veh: np.ndarray,
    cfg: np.ndarray,
    st: np.ndarray,
    meas: np.ndarray,
    noise: np.ndarray,
    rec: np.ndarray,
) -> None:
    """The pose sensor at the IMU sample at ``t`` (s), true state ``x``."""
    for a in range(rec.shape[0]):
        rec[a] = math.nan
    i = int(st[S_CALLS])  # this IMU sample's index
    st[S_CALLS] = i + 1.0
    if i == 0:
        st[S_T0] = t
        meas[M_T] = math.nan
    if cfg[C_ON] < 0.5:
        return
    ring = S_RING + 7 * (i % MAX_POSE_LAG)
    for a in range(3):
        st[ring + a] = x[X_POS + a]
    for a in range(4):
        st[ring + 3 + a] = x[X_QUAT + a]
    lag = int(cfg[C_LAG])
    # measurement n is taken at t0 + n / rate and arrives lag samples later
    due = st[S_T0] + st[S_N] / cfg[C_RATE] + lag / cfg[C_IMU_RATE]
    if i < lag or t < due - 1e-9:
        return
    src = S_RING + 7 * ((i - lag) % MAX_POSE_LAG)
    noisy = noise.shape[0] > 0
    for a in range(3):
        v = st[src + a]
        if noisy:
            v += cfg[C_NOISE_P] * noise[N_POS + a]
        meas[M_POSE + a] = v
    q = meas[M_POSE + 3 : M_POSE + 7]
    n = math.sqrt(st[src + 3] ** 2 + st[src + 4] ** 2 + st[src + 5] ** 2 + st[src + 6] ** 2)
    for a in range(4):
        q[a] = st[src + 3 + a] / n
    if cfg[C_ATT] > 0.5 and noisy:
        s = cfg[C_NOISE_A]
        rotate_by(q, s * noise[N_ATT], s * noise[N_ATT + 1], s * noise[N_ATT + 2])
    meas[M_T] = t
    st[S_N] += 1.0
    if rec.shape[0] > 0:
        for a in range(7):
            rec[R_POSE + a] = meas[M_POSE + a]


SENSOR = SensorComponent(
    name="pose_sensor",
    settings=PoseSensor,
    pack=pack,
    sample=sample,
    config=CONFIG,
    state=STATE,
    measurement=MEASUREMENT,
    noise=NOISE,
    record=RECORD,
    doc="position and attitude from motion capture or vision, at its rate and latency",
    legacy_noise=LegacyColumns(start=SN_POSE, width=6),
    columns=(
        "pose_x_m",
        "pose_y_m",
        "pose_z_m",
        "pose_q0",
        "pose_q1",
        "pose_q2",
        "pose_q3",
    ),
    scenario_key="pose_sensor",
)
