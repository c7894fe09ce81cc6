"""The IMU's impact disturbance: noise that rings after each contact onset.

An impact excites the airframe's structure, so the accelerometer and gyro
read extra noise that decays after the contact (the authors' model): from
each contact onset ``t_c``, extra white noise of standard deviation
``a0 exp(-(t - t_c)/tau)`` on each accelerometer axis and
``g0 exp(-(t - t_c)/tau)`` on each gyro axis, added to the nominal noise
(their values ``a0 = 14 m/s^2``, ``g0 = 0.1 rad/s``, ``tau = 0.4 s``).

Onsets are the loop's own located contact onsets (every pair, every shape,
``recording.open_episode`` calls :func:`impact_onset`). The noises of
several onsets are independent, so their variances add: the loop keeps
``V = sum_c exp(-2 (T - t_c)/tau)`` at the latest onset ``T``
(``ST_IMPACT_V``, ``ST_IMPACT_T``), and a sample at ``t`` has the standard
deviations ``a0 f``, ``g0 f`` with ``f = sqrt(V) exp(-(t - T)/tau)``
(:func:`impact_factor`).

The authors' model (``SC_IMPACT_REPLACE``, the ``replace`` mode): the noise of
the latest onset alone, ``exp(-(t - T)/tau)`` per unit amplitude (a new contact
restarts it), and it *replaces* the nominal noise on an axis while its standard
deviation exceeds the nominal one (``imu.py``).
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import (
    ST_IMPACT_T,
    ST_IMPACT_V,
)
from quadimpact.core.sensors.imu_slots import (
    SC_IMPACT_TAU,
)


@compiled
def impact_onset(t: float, scfg: np.ndarray, stats: np.ndarray) -> None:
    """A contact onset at ``t`` (s): fold it into the disturbance's variance sum."""
    tau = scfg[SC_IMPACT_TAU]
    if not tau > 0.0:
        return
    last = stats[ST_IMPACT_T]
    if np.isnan(last):
        stats[ST_IMPACT_V] = 1.0
    else:
        stats[ST_IMPACT_V] = stats[ST_IMPACT_V] * math.exp(-2.0 * (t - last) / tau) + 1.0
    stats[ST_IMPACT_T] = t


@compiled
def impact_factor(t: float, tau: float, stats: np.ndarray, restart: bool) -> float:
    """The disturbance's standard deviation at ``t`` (s) per unit amplitude (0: none yet).

    ``restart``: the latest onset's alone (the ``replace`` mode), else the
    onsets' variances summed.
    """
    last = stats[ST_IMPACT_T]
    if np.isnan(last) or t < last:
        return 0.0
    if restart:
        return math.exp(-(t - last) / tau)
    return math.sqrt(stats[ST_IMPACT_V]) * math.exp(-(t - last) / tau)
