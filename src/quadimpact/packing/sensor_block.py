"""The sensors' block: ``scfg`` (``SC_*``: the IMU and the impact detector) and the IMU's
seeded draws (``noise``, and its biases into ``scfg``)."""

from __future__ import annotations

import numpy as np

from quadimpact.core import layout as L
from quadimpact.core.sensors import detection as DET
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.inputs.sensors import DetectionSettings, ResolvedImu
from quadimpact.inputs.vehicle import Vehicle

__all__ = ["draw_imu_noise", "pack_sensors"]


def pack_sensors(
    imu: ResolvedImu,
    detection: DetectionSettings,
    v: Vehicle,
    duration_s: float,
) -> tuple[np.ndarray, int]:
    """The IMU and detector as the ``SC_*`` vector and the sample count (no random draw).

    The biases' slots stay 0 here: :func:`draw_imu_noise` fills them with the run's seed.

    Returns
    -------
    scfg : ndarray (NSCFG,)
    n_imu : int
        Samples the run takes at most: ``t0`` and every ``1/rate`` to the end.
    """
    scfg = np.zeros(IMS.NSCFG)
    rate = float(imu.rate_hz)
    n_imu = int(np.floor(duration_s * rate + 1e-9)) + 2
    scfg[IMS.SC_RATE] = rate
    scfg[IMS.SC_POS : IMS.SC_POS + 3] = imu.position_m
    scfg[IMS.SC_NOISE_F] = imu.accel_noise_m_s2
    scfg[IMS.SC_NOISE_W] = imu.gyro_noise_rad_s
    scfg[IMS.SC_RANGE_F] = imu.accel_range_m_s2 or 0.0
    scfg[IMS.SC_RANGE_W] = imu.gyro_range_rad_s or 0.0
    scfg[IMS.SC_FILTER] = {
        "none": L.FILTER_NONE,
        "first-order": L.FILTER_FIRST_ORDER,
        "moving-average": L.FILTER_MOVING_AVERAGE,
    }[imu.filter]
    if imu.filter == "first-order":
        scfg[IMS.SC_FILTER_PARAM] = float(imu.filter_time_constant_s)
    elif imu.filter == "moving-average":
        scfg[IMS.SC_FILTER_PARAM] = float(imu.filter_window)
    if detection.enabled:
        scfg[DET.SC_DET_THRESHOLD] = detection.threshold_g * v.gravity_m_s2
    scfg[DET.SC_DET_WORLD] = 1.0 if detection.frame == "world" else 0.0
    scfg[DET.SC_DET_PERSIST] = float(detection.persistence)
    return scfg, n_imu


def draw_imu_noise(imu: ResolvedImu, seed: int, n_imu: int, scfg: np.ndarray) -> np.ndarray:
    """The IMU's random draws of a run: its biases (into ``scfg``, in place) and white noise.

    NumPy's PCG64 seeded with ``seed``: first the six biases (standard
    normal times the configured bias standard deviation: accelerometer
    m/s^2, gyro rad/s, body axes), then one row of six standard normal
    numbers per sample, only when the IMU has noise or bias (an ideal IMU
    draws nothing and gets a (0, 6) array).

    Returns
    -------
    noise : ndarray (n_imu, 6) or (0, 6)
    """
    if not imu.has_noise:
        return np.zeros((0, 6))
    rng = np.random.default_rng(seed)
    sigma_bias = np.array([imu.accel_bias_m_s2] * 3 + [imu.gyro_bias_rad_s] * 3)
    scfg[IMS.SC_BIAS : IMS.SC_BIAS + 6] = rng.standard_normal(6) * sigma_bias
    return rng.standard_normal((n_imu, 6))
