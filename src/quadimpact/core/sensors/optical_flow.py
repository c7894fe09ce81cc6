"""A downward optical-flow camera: the ground image's angular rate about body x and y.

The camera at the CM looks along the body +z axis (down, FRD) and sees the
ground plane ``z = 0`` at the distance ``d = h / C_zz`` (``h = -z``, ``C_zz``
the cosine of the tilt). The ground point on its axis moves in the image at
the angular rate (raw flow, rotation included, as the sensor delivers it)::

    flow_x = v_y / d - p,    flow_y = -v_x / d - q        (rad/s)

with ``(v_x, v_y)`` the CM velocity in body axes and ``(p, q)`` the body
rates: a filter adds the gyro's ``(p, q)`` to recover ``(v_y, -v_x) / d``.

**Quality**, 0 to 1 (0: no measurement), as a PMW3901-class sensor behaves:
0 while the tilt exceeds ``max_tilt_deg`` (45 deg: PX4 EKF2's limit for
flow and range data, ``range_cos_max_tilt``), while ``d`` is outside
``[min_height_m, max_height_m]`` (the PMW3901 focuses from 80 mm; 10 m is
chosen as where a small camera's texture fades indoors), while the raw flow's
magnitude exceeds ``max_rate_rad_s`` (7.4 rad/s, the PMW3901's largest
trackable rate, Bitcraze's Flow deck v2), and while the image is smeared by
an impact: the body's angular acceleration above ``smear_rad_s2`` (chosen:
200 rad/s^2 reaches the 7.4-rad/s limit within one 37-ms frame pair, and a
contact's torque gives thousands). Otherwise ``1 - (|flow| /
max_rate)^2``: correlation weakens as the image moves faster (a chosen law).

**Noise** per axis, white, of std ``n_max - (n_max - n_min) q`` (PX4 EKF2's
range: 0.15 rad/s at full quality, ``EKF2_OF_N_MIN``, to 0.5 rad/s at the
lowest, ``EKF2_OF_N_MAX``). **Delay**: a sample delivered at ``t`` is the
image taken ``delay_s`` earlier (PX4's ``EKF2_OF_DELAY``, 20 ms), rounded to
whole samples of its own rate (at most 15). Rate 100 Hz.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import X_OMEGA, X_POS, X_VEL
from quadimpact.core.sensors.component import (
    PackContext,
    SensorComponent,
    Slot,
    offsets,
    sample_due,
)

__all__ = ["SENSOR", "OpticalFlowSettings"]

MAX_DELAY_SAMPLES = 15
RING = MAX_DELAY_SAMPLES + 1  # images held: the delay's and the newest


class OpticalFlowSettings(BaseModel):
    """An optical-flow camera's settings (``[instruments.optical_flow]``)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    rate_hz: float = Field(100.0, gt=0, le=1000, description="Sample rate, Hz.")
    delay_s: float = Field(0.02, ge=0, le=0.5, description="Delivery delay, s.")
    noise_min_rad_s: float = Field(0.15, ge=0, le=10, description="Noise std at quality 1.")
    noise_max_rad_s: float = Field(0.5, ge=0, le=10, description="Noise std at quality 0.")
    max_rate_rad_s: float = Field(7.4, gt=0, le=100, description="Largest trackable flow.")
    max_tilt_deg: float = Field(45.0, gt=0, lt=90, description="Largest tilt with an image.")
    min_height_m: float = Field(0.08, ge=0, description="Nearest ground in focus, m.")
    max_height_m: float = Field(10.0, gt=0, le=1000, description="Farthest ground with texture.")
    smear_rad_s2: float = Field(200.0, gt=0, description="Angular acceleration that smears.")

    @model_validator(mode="after")
    def _checks(self) -> OpticalFlowSettings:
        if self.min_height_m >= self.max_height_m:
            raise ValueError("min_height_m: must be below max_height_m")
        if self.noise_min_rad_s > self.noise_max_rad_s:
            raise ValueError("noise_min_rad_s: must be at most noise_max_rad_s")
        if round(self.delay_s * self.rate_hz) > MAX_DELAY_SAMPLES:
            raise ValueError(
                f"delay_s: at most {MAX_DELAY_SAMPLES} samples of rate_hz "
                f"({self.delay_s} s at {self.rate_hz} Hz)"
            )
        return self


CONFIG = (
    Slot("on"),
    Slot("rate_hz", 1, "Hz"),
    Slot("delay_samples", 1, "", "the delay in samples of its own rate"),
    Slot("noise_min_rad_s", 1, "rad/s"),
    Slot("noise_max_rad_s", 1, "rad/s"),
    Slot("max_rate_rad_s", 1, "rad/s"),
    Slot("cos_max_tilt"),
    Slot("min_height_m", 1, "m"),
    Slot("max_height_m", 1, "m"),
    Slot("smear_rad_s2", 1, "rad/s^2"),
)
STATE = (
    Slot("t0_s", 1, "s", "the first sample's time"),
    Slot("n", 1, "", "images taken"),
    Slot("ring", 4 * RING, "", "the latest images: flow x, flow y (rad/s), quality, time (s)"),
)
MEASUREMENT = (
    Slot("flow_x_rad_s", 1, "rad/s", "raw flow about body x (rotation included)"),
    Slot("flow_y_rad_s", 1, "rad/s", "raw flow about body y"),
    Slot("quality", 1, "", "0-1; 0: no measurement"),
    Slot("noise_rad_s", 1, "rad/s", "this sample's noise std per axis"),
    Slot("capture_t_s", 1, "s", "when its image was taken"),
    Slot("t_s", 1, "s", "when it was delivered"),
    Slot("n", 1, "", "samples delivered (valid or not)"),
)
NOISE = (Slot("white", 2, "", "per axis"),)
RECORD = (
    Slot("flow_x_rad_s", 1, "rad/s", "delivered flow about x (NaN: none, or quality 0)"),
    Slot("flow_y_rad_s", 1, "rad/s"),
    Slot("quality", 1, "", "delivered quality (NaN: no sample here)"),
    Slot("flow_x_true_rad_s", 1, "rad/s", "true flow of the delivered image"),
    Slot("flow_y_true_rad_s", 1, "rad/s"),
)

_c, _s, _m, _r = (offsets(b) for b in (CONFIG, STATE, MEASUREMENT, RECORD))
C_ON, C_RATE, C_DELAY = _c["on"], _c["rate_hz"], _c["delay_samples"]
C_NMIN, C_NMAX, C_RMAX = _c["noise_min_rad_s"], _c["noise_max_rad_s"], _c["max_rate_rad_s"]
C_COS, C_HMIN, C_HMAX, C_SMEAR = (
    _c[k] for k in ("cos_max_tilt", "min_height_m", "max_height_m", "smear_rad_s2")
)
S_T0, S_N, S_RING = _s["t0_s"], _s["n"], _s["ring"]
M_FX, M_FY, M_Q, M_NOISE, M_CAPTURE, M_T, M_N = (
    _m[k]
    for k in ("flow_x_rad_s", "flow_y_rad_s", "quality", "noise_rad_s", "capture_t_s", "t_s", "n")
)
R_FX, R_FY, R_Q, R_TX, R_TY = (
    _r[k]
    for k in ("flow_x_rad_s", "flow_y_rad_s", "quality", "flow_x_true_rad_s", "flow_y_true_rad_s")
)


def pack(settings: OpticalFlowSettings, context: PackContext) -> list[float]:
    """The config block of ``settings``."""
    del context
    s = settings
    return [
        1.0, s.rate_hz, float(round(s.delay_s * s.rate_hz)), s.noise_min_rad_s,
        s.noise_max_rad_s, s.max_rate_rad_s, math.cos(math.radians(s.max_tilt_deg)),
        s.min_height_m, s.max_height_m, s.smear_rad_s2,
    ]  # fmt: skip


@compiled
def image(
    x: np.ndarray, xdot: np.ndarray, C: np.ndarray, cfg: np.ndarray
) -> tuple[float, float, float]:
    """The true raw flow (rad/s, body x and y) and the quality of an image taken at ``x``."""
    h = -x[X_POS + 2]
    czz = C[2, 2]
    if czz <= 0.0 or h <= 0.0:
        return 0.0, 0.0, 0.0
    d = h / czz
    fx = x[X_VEL + 1] / d - x[X_OMEGA]
    fy = -x[X_VEL] / d - x[X_OMEGA + 1]
    if czz < cfg[C_COS] or d < cfg[C_HMIN] or d > cfg[C_HMAX]:
        return fx, fy, 0.0
    wd = xdot[X_OMEGA : X_OMEGA + 3]
    if wd[0] * wd[0] + wd[1] * wd[1] + wd[2] * wd[2] > cfg[C_SMEAR] * cfg[C_SMEAR]:
        return fx, fy, 0.0
    u = (fx * fx + fy * fy) / (cfg[C_RMAX] * cfg[C_RMAX])
    if u > 1.0:
        return fx, fy, 0.0
    return fx, fy, 1.0 - u


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
    """One IMU sample's turn: an image taken, and one delivered, if one is due at ``t`` (s)."""
    if rec.shape[0] > 0:
        for k in range(5):
            rec[k] = np.nan
    if cfg[C_ON] < 0.5:
        return
    n = st[S_N]
    if not sample_due(t, st, S_T0, S_N, cfg[C_RATE]):
        return
    fx, fy, q = image(x, xdot, C, cfg)
    k = int(n) % RING
    st[S_RING + 4 * k] = fx
    st[S_RING + 4 * k + 1] = fy
    st[S_RING + 4 * k + 2] = q
    st[S_RING + 4 * k + 3] = t
    st[S_N] = n + 1.0
    lag = int(cfg[C_DELAY])
    if n < lag:  # nothing delivered before the first image's delay has passed
        return
    j = (int(n) - lag) % RING
    fx = st[S_RING + 4 * j]
    fy = st[S_RING + 4 * j + 1]
    q = st[S_RING + 4 * j + 2]
    sigma = cfg[C_NMAX] - (cfg[C_NMAX] - cfg[C_NMIN]) * q
    meas[M_Q] = q
    meas[M_NOISE] = sigma
    meas[M_CAPTURE] = st[S_RING + 4 * j + 3]
    meas[M_T] = t
    meas[M_N] = meas[M_N] + 1.0
    if rec.shape[0] > 0:
        rec[R_Q] = q
        rec[R_TX] = fx
        rec[R_TY] = fy
    if q <= 0.0:
        return
    if noise.shape[0] > 0:
        fx += sigma * noise[0]
        fy += sigma * noise[1]
    meas[M_FX] = fx
    meas[M_FY] = fy
    if rec.shape[0] > 0:
        rec[R_FX] = fx
        rec[R_FY] = fy


SENSOR = SensorComponent(
    name="optical_flow",
    settings=OpticalFlowSettings,
    pack=pack,
    sample=sample,
    config=CONFIG,
    state=STATE,
    measurement=MEASUREMENT,
    noise=NOISE,
    record=RECORD,
    doc="the ground image's angular rate about body x and y, with quality and delay",
)
