"""A downward rangefinder: the slant range along the body's down axis to the ground plane.

The beam leaves the CM along the body +z axis (down, FRD) and meets the plane
``z = 0`` (the ground of every task) at the distance ``d = h / C_zz``, with
``h = -z`` the altitude and ``C_zz = cos(tilt)`` the vertical component of the
body z axis. A sample is **valid** while the tilt is at most ``max_tilt_deg``
and ``min_m <= d <= max_m``; otherwise it reads nothing (``valid = 0``). Noise
grows with range::

    sigma(d) = noise_m + noise_per_m d + exp_noise_m exp(exp_rate_per_m (d - exp_at_m))

Two presets (``preset = "tof"`` or ``"lidar"``, the default), each field of
which a scenario may override:

* ``tof``, a short time-of-flight ranger (VL53L1x, the Crazyflie Flow deck
  v2): 25 Hz, 0.04-4 m, the Crazyflie driver's noise law ``0.0025 (1 + exp(k
  (d - 2.5)))`` m with ``k = ln(80) / 1.5`` (5 mm at 2.5 m, 0.2 m at 4 m;
  crazyflie-firmware ``zranger2.c``);
* ``lidar`` (TFmini or LightWare class): 100 Hz, 0.1-12 m, PX4 EKF2's noise
  ``0.05 m + 1 %`` of range (``EKF2_RNG_NOISE``, ``EKF2_RNG_SFE``).

Both stop at 45 deg of tilt, PX4 EKF2's limit for range and flow data
(``range_cos_max_tilt = cos 45 deg``). The sensor's delay (PX4: 5 ms for a
lidar) is not modelled.
"""

from __future__ import annotations

import math
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import X_POS
from quadimpact.core.sensors.component import (
    PackContext,
    SensorComponent,
    Slot,
    offsets,
    sample_due,
)

__all__ = ["PRESETS", "SENSOR", "RangefinderSettings"]

PRESETS: dict[str, dict[str, float]] = {
    "tof": {
        "rate_hz": 25.0,
        "min_m": 0.04,
        "max_m": 4.0,
        "noise_m": 0.0025,
        "noise_per_m": 0.0,
        "exp_noise_m": 0.0025,
        "exp_rate_per_m": math.log(80.0) / 1.5,
        "exp_at_m": 2.5,
        "max_tilt_deg": 45.0,
    },
    "lidar": {
        "rate_hz": 100.0,
        "min_m": 0.1,
        "max_m": 12.0,
        "noise_m": 0.05,
        "noise_per_m": 0.01,
        "exp_noise_m": 0.0,
        "exp_rate_per_m": 0.0,
        "exp_at_m": 0.0,
        "max_tilt_deg": 45.0,
    },
}
"""The rangefinder presets (module docstring for their sources)."""


class RangefinderSettings(BaseModel):
    """A rangefinder's settings (``[instruments.rangefinder]``): a preset and changes."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    preset: Literal["tof", "lidar"] = Field("lidar", description="'tof' or 'lidar'.")
    rate_hz: float = Field(gt=0, le=1000, description="Sample rate, Hz.")
    min_m: float = Field(ge=0, description="Shortest valid range, m.")
    max_m: float = Field(gt=0, le=1000, description="Longest valid range, m.")
    noise_m: float = Field(ge=0, le=10, description="Constant part of the noise std, m.")
    noise_per_m: float = Field(ge=0, le=1, description="Noise std per metre of range, m/m.")
    exp_noise_m: float = Field(ge=0, le=10, description="Exponential part's scale, m.")
    exp_rate_per_m: float = Field(ge=0, le=100, description="Its growth rate, 1/m.")
    exp_at_m: float = Field(ge=0, le=1000, description="Where it equals its scale, m.")
    max_tilt_deg: float = Field(gt=0, lt=90, description="Largest tilt with a reading, deg.")

    @model_validator(mode="before")
    @classmethod
    def _preset(cls, value: Any) -> Any:
        if isinstance(value, dict):
            name = value.get("preset", "lidar")
            if name in PRESETS:
                value = {**PRESETS[name], **value}
        return value

    @model_validator(mode="after")
    def _window(self) -> RangefinderSettings:
        if self.min_m >= self.max_m:
            raise ValueError(f"min_m: must be below max_m ({self.min_m} >= {self.max_m})")
        return self


CONFIG = (
    Slot("on"),
    Slot("rate_hz", 1, "Hz"),
    Slot("min_m", 1, "m"),
    Slot("max_m", 1, "m"),
    Slot("noise_m", 1, "m"),
    Slot("noise_per_m", 1, "m/m"),
    Slot("exp_noise_m", 1, "m"),
    Slot("exp_rate_per_m", 1, "1/m"),
    Slot("exp_at_m", 1, "m"),
    Slot("cos_max_tilt", 1, "", "cosine of the largest tilt with a reading"),
)
STATE = (Slot("t0_s", 1, "s", "the first sample's time"), Slot("n", 1, "", "samples taken"))
MEASUREMENT = (
    Slot("range_m", 1, "m", "the latest slant range (meaningless unless valid)"),
    Slot("valid", 1, "", "1: the latest sample is a reading"),
    Slot("noise_m", 1, "m", "its noise std"),
    Slot("t_s", 1, "s", "its time"),
    Slot("n", 1, "", "samples taken (valid or not)"),
)
NOISE = (Slot("white"),)
RECORD = (
    Slot("range_m", 1, "m", "measured slant range (NaN: no sample, or not valid)"),
    Slot("range_true_m", 1, "m", "true slant range (NaN: the beam misses the ground)"),
)

_c, _s, _m, _r = (offsets(b) for b in (CONFIG, STATE, MEASUREMENT, RECORD))
C_ON, C_RATE, C_MIN, C_MAX = _c["on"], _c["rate_hz"], _c["min_m"], _c["max_m"]
C_N0, C_N1, C_NE, C_NK, C_NA = (
    _c[k] for k in ("noise_m", "noise_per_m", "exp_noise_m", "exp_rate_per_m", "exp_at_m")
)
C_COS = _c["cos_max_tilt"]
S_T0, S_N = _s["t0_s"], _s["n"]
M_RANGE, M_VALID, M_NOISE, M_T, M_N = (_m[k] for k in ("range_m", "valid", "noise_m", "t_s", "n"))
R_RANGE, R_TRUE = _r["range_m"], _r["range_true_m"]


def pack(settings: RangefinderSettings, context: PackContext) -> list[float]:
    """The config block of ``settings``."""
    del context
    s = settings
    return [
        1.0, s.rate_hz, s.min_m, s.max_m, s.noise_m, s.noise_per_m, s.exp_noise_m,
        s.exp_rate_per_m, s.exp_at_m, math.cos(math.radians(s.max_tilt_deg)),
    ]  # fmt: skip


@compiled
def noise_std(cfg: np.ndarray, d: float) -> float:
    """The noise std (m) at the range ``d`` (m)."""
    return cfg[C_N0] + cfg[C_N1] * d + cfg[C_NE] * math.exp(cfg[C_NK] * (d - cfg[C_NA]))


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
    """One IMU sample's turn: a range sample if one is due at ``t`` (s)."""
    if rec.shape[0] > 0:
        rec[R_RANGE] = np.nan
        rec[R_TRUE] = np.nan
    if cfg[C_ON] < 0.5:
        return
    n = st[S_N]
    if not sample_due(t, st, S_T0, S_N, cfg[C_RATE]):
        return
    st[S_N] = n + 1.0
    meas[M_T] = t
    meas[M_N] = n + 1.0
    h = -x[X_POS + 2]
    czz = C[2, 2]
    d = h / czz if czz > 0.0 else math.inf
    valid = czz >= cfg[C_COS] and cfg[C_MIN] <= d <= cfg[C_MAX]
    if not valid:
        meas[M_VALID] = 0.0
        if rec.shape[0] > 0 and d < math.inf and h > 0.0:
            rec[R_TRUE] = d
        return
    sigma = noise_std(cfg, d)
    y = d + (sigma * noise[0] if noise.shape[0] > 0 else 0.0)
    meas[M_RANGE] = y
    meas[M_VALID] = 1.0
    meas[M_NOISE] = sigma
    if rec.shape[0] > 0:
        rec[R_RANGE] = y
        rec[R_TRUE] = d


SENSOR = SensorComponent(
    name="rangefinder",
    settings=RangefinderSettings,
    pack=pack,
    sample=sample,
    config=CONFIG,
    state=STATE,
    measurement=MEASUREMENT,
    noise=NOISE,
    record=RECORD,
    doc="slant range along the body's down axis to the ground, valid within a window",
)
