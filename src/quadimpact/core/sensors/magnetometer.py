"""The magnetometer: the Earth's field in body axes, sampled with the IMU (a sensor component).

It reads ``m_B = C^T m_I + bias + noise``, with ``m_I`` the Earth field in
inertial NED (config ``field``: magnetic north along +X, dipping below the
horizon by the dip angle, down positive; unit length unless a norm is
given), a static bias drawn once per run (config ``bias``, body axes) and
white noise of standard deviation ``noise`` per axis (in units of the
field). Without it yaw is unobservable: an estimator's heading drifts with
the gyro bias.

It predates sensor components, so three things stay as they were (docs/
ARCHITECTURE.md 10, "The older sensors' seed streams"): its white noise is
columns 9-11 of the frozen ``snoise`` matrix (``LegacyColumns``); its static
bias is drawn with the estimator's initial errors from ``EXTRA_STREAM``
(``packing/estimator_block.py``, ``draw_estimation``), written into its
``bias`` slot; its IMU table columns keep their names (``mx``...). A
scenario gives its settings as ``[magnetometer]`` (``scenario_key``).
"""

from __future__ import annotations

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.sensors.component import (
    LegacyColumns,
    PackContext,
    SensorComponent,
    Slot,
    offsets,
)
from quadimpact.core.sensors.imu_slots import SN_MAG
from quadimpact.core.sensors.older_settings import Magnetometer

__all__ = ["SENSOR", "Magnetometer"]


CONFIG = (
    Slot("on", 1, "", "1: the run has a magnetometer"),
    Slot("field", 3, "1", "the Earth field m_I, inertial NED (unit field times its norm)"),
    Slot("noise", 1, "1", "white-noise std per axis, unit field"),
    Slot("bias", 3, "1", "static bias, body FRD (drawn per run: draw_estimation)"),
)
MEASUREMENT = (
    Slot("field", 3, "1", "the latest sample, body FRD (unit field)"),
    Slot("t_s", 1, "s", "its time (NaN: none)"),
)
NOISE = (Slot("white", 3, "", "the white noise's draws, per body axis"),)
RECORD = (Slot("field", 3, "1", "the sample, body FRD (NaN: no magnetometer)"),)

_c, _m, _n, _r = (offsets(b) for b in (CONFIG, MEASUREMENT, NOISE, RECORD))
C_ON, C_FIELD, C_NOISE, C_BIAS = (_c[k] for k in ("on", "field", "noise", "bias"))
M_FIELD, M_T = _m["field"], _m["t_s"]
N_WHITE = _n["white"]
R_FIELD = _r["field"]


def pack(settings: Magnetometer, context: PackContext) -> list[float]:
    """The config block of ``settings``: the field from its dip (deg) and norm; bias 0.

    The bias is drawn per run from the run's seed (``draw_estimation``).
    """
    del context
    dip = math.radians(settings.dip_deg)
    field = (math.cos(dip), 0.0, math.sin(dip))
    if settings.norm != 1.0:
        field = tuple(settings.norm * c for c in field)
    return [1.0, *field, float(settings.noise), 0.0, 0.0, 0.0]


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
    """The magnetometer's sample at the IMU sample at ``t`` (s); ``C`` the true rotation.

    Off: its time is NaN (no estimator fuses it) and its columns NaN.
    """
    if cfg[C_ON] < 0.5:
        meas[M_T] = math.nan
        for a in range(rec.shape[0]):
            rec[a] = math.nan
        return
    noisy = noise.shape[0] > 0
    sigma = cfg[C_NOISE]
    for a in range(3):
        v = (
            C[0, a] * cfg[C_FIELD] + C[1, a] * cfg[C_FIELD + 1] + C[2, a] * cfg[C_FIELD + 2]
        ) + cfg[C_BIAS + a]
        if noisy:
            v += sigma * noise[N_WHITE + a]
        meas[M_FIELD + a] = v
        if rec.shape[0] > 0:
            rec[R_FIELD + a] = v
    meas[M_T] = t


SENSOR = SensorComponent(
    name="magnetometer",
    settings=Magnetometer,
    pack=pack,
    sample=sample,
    config=CONFIG,
    measurement=MEASUREMENT,
    noise=NOISE,
    record=RECORD,
    doc="the Earth's field in body axes, with a static bias and white noise",
    legacy_noise=LegacyColumns(start=SN_MAG, width=3),
    columns=("mx", "my", "mz"),
    scenario_key="magnetometer",
)
