"""A barometer: the CM's altitude above the ground plane, with white noise and a bias walk.

It reads ``h = -z`` (inertial NED: altitude above the plane ``z = 0``, the
ground of every task) plus a bias and white noise::

    h_meas = h + b + sigma w_k,     b_k = b_{k-1} + sigma_b sqrt(1/rate) u_k

with ``w_k`` and ``u_k`` standard normal draws from the run's seed and ``b_0``
the configured static offset. It samples at ``rate_hz``, at the first IMU
sample at or after each of its times (``t0 + n / rate``), so its rate is at
most the IMU's. It sits at the CM: prop wash and ground effect, which bias a
real barometer near surfaces, are not modelled.

Defaults: 50 Hz (a MEMS barometer's output rate; PX4 fuses it at up to
20 Hz), 0.1 m of white noise (a MEMS barometer's altitude noise is of that
order; PX4's filter assumes a conservative 3.5 m, ``EKF2_BARO_NOISE``), a
bias walk of 0.01 m/sqrt(s) (a slow drift: about 2 cm over a 4-s benchmark
run; chosen, not from a datasheet).

This module is the example of a sensor component (``component.py``): its
slots, settings, pack and sample functions are all here, and one line of
``registry.py`` adds it to the run.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import X_POS
from quadimpact.core.sensors.component import (
    PackContext,
    SensorComponent,
    Slot,
    offsets,
    sample_due,
)

__all__ = ["SENSOR", "BarometerSettings"]


class BarometerSettings(BaseModel):
    """A barometer's settings (``[instruments.barometer]`` in a scenario file)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    rate_hz: float = Field(50.0, gt=0, le=1000, description="Sample rate, Hz.")
    noise_m: float = Field(0.1, ge=0, le=100, description="White-noise std, m.")
    bias_walk_m_sqrt_s: float = Field(0.01, ge=0, le=10, description="Bias random walk, m/sqrt(s).")
    offset_m: float = Field(0.0, ge=-1e4, le=1e4, description="Static bias b_0, m.")


CONFIG = (
    Slot("on", 1, "", "1: the run has a barometer"),
    Slot("rate_hz", 1, "Hz"),
    Slot("noise_m", 1, "m"),
    Slot("walk_m_sqrt_s", 1, "m/sqrt(s)"),
    Slot("offset_m", 1, "m"),
)
STATE = (
    Slot("t0_s", 1, "s", "the first sample's time"),
    Slot("n", 1, "", "samples taken"),
    Slot("bias_m", 1, "m", "the bias so far (offset and walk)"),
)
MEASUREMENT = (
    Slot("altitude_m", 1, "m", "the latest measured altitude"),
    Slot("t_s", 1, "s", "its time"),
    Slot("n", 1, "", "samples taken (0: none yet)"),
)
NOISE = (
    Slot("white", 1, "", "the white noise's draw"),
    Slot("walk", 1, "", "the bias walk's increment's draw"),
)
RECORD = (
    Slot("altitude_m", 1, "m", "measured altitude (NaN: no sample here)"),
    Slot("altitude_true_m", 1, "m", "true CM altitude at the sample"),
)

_c, _s, _m, _n, _r = (offsets(b) for b in (CONFIG, STATE, MEASUREMENT, NOISE, RECORD))
C_ON, C_RATE, C_NOISE, C_WALK, C_OFFSET = (
    _c[k] for k in ("on", "rate_hz", "noise_m", "walk_m_sqrt_s", "offset_m")
)
S_T0, S_N, S_BIAS = (_s[k] for k in ("t0_s", "n", "bias_m"))
M_ALT, M_T, M_N = (_m[k] for k in ("altitude_m", "t_s", "n"))
N_WHITE, N_WALK = _n["white"], _n["walk"]
R_ALT, R_TRUE = _r["altitude_m"], _r["altitude_true_m"]


def pack(settings: BarometerSettings, context: PackContext) -> list[float]:
    """The config block of ``settings`` (its rate capped at the IMU's: it samples with it)."""
    del context
    return [
        1.0,
        float(settings.rate_hz),
        float(settings.noise_m),
        float(settings.bias_walk_m_sqrt_s),
        float(settings.offset_m),
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
    """One IMU sample's turn: a barometer sample if one is due at ``t`` (s)."""
    if rec.shape[0] > 0:
        rec[R_ALT] = np.nan
        rec[R_TRUE] = np.nan
    if cfg[C_ON] < 0.5:
        return
    rate = cfg[C_RATE]
    n = st[S_N]
    if not sample_due(t, st, S_T0, S_N, rate):
        return
    if n == 0.0:
        st[S_BIAS] = cfg[C_OFFSET]
    h = -x[X_POS + 2]
    white = 0.0
    if noise.shape[0] > 0:
        if n > 0.0:
            st[S_BIAS] += cfg[C_WALK] * math.sqrt(1.0 / rate) * noise[N_WALK]
        white = cfg[C_NOISE] * noise[N_WHITE]
    y = h + st[S_BIAS] + white
    st[S_N] = n + 1.0
    meas[M_ALT] = y
    meas[M_T] = t
    meas[M_N] = n + 1.0
    if rec.shape[0] > 0:
        rec[R_ALT] = y
        rec[R_TRUE] = h


SENSOR = SensorComponent(
    name="barometer",
    settings=BarometerSettings,
    pack=pack,
    sample=sample,
    config=CONFIG,
    state=STATE,
    measurement=MEASUREMENT,
    noise=NOISE,
    record=RECORD,
    doc="altitude above the ground plane, with white noise and a bias walk",
)
