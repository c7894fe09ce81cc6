"""The sensor stage of the loop: one IMU sample, the estimator's update there, detection.

At each IMU sample: the IMU (``imu.py``), every sensor component
(``sensors/registry.py``: the barometer..., the magnetometer and the pose
sensor), the
estimator's update (``core/estimators``), the detector with the estimated
attitude (``detection.py``), then a plug-in sensor. The run loop takes the
samples on the dense output of each step (so a sample at a control tick
precedes that tick's new command), at the times ``t0 + n / rate``. A plug-in
sensor (``core.kernel.make_kernel(sensor=...)``) is sampled with the IMU and
writes the measurement record's user block.
"""

import numpy as np
from numba import njit

from quadimpact.core.compiled import compiled
from quadimpact.core.dynamics import state_derivative
from quadimpact.core.estimators import attitude_at_sample, estimate_sample
from quadimpact.core.layout import LS_T0
from quadimpact.core.records import Data, Model, Output, Work
from quadimpact.core.sensors.detection import detect
from quadimpact.core.sensors.imu import imu_sample
from quadimpact.core.sensors.imu_slots import (
    SC_RATE,
    SS_N,
    SS_NEXT_T,
)
from quadimpact.core.sensors.registry import sample_components


@njit(cache=True, inline="always")
def plugin_sensor(
    t: float, xs: np.ndarray, xd: np.ndarray, C: np.ndarray, m: Model, d: Data
) -> None:
    """A plug-in sensor's sample (rebound by ``core.kernel.make_kernel``); none here.

    It reads the true state ``xs``, its derivative ``xd`` and rotation ``C`` at
    the IMU sample ``t`` (s) and writes its readings into the measurement
    record's user block ``d.meas[MS_USER : MS_USER + N_USER_MEAS]``.
    """
    return


@compiled
def take_sample(
    t: float, xs: np.ndarray, xd: np.ndarray, m: Model, d: Data, o: Output, w: Work
) -> None:
    """IMU sample and detection at ``t`` (s) from the true state ``xs`` and its derivative ``xd``.

    ``w.C`` must hold the rotation of ``xs``. Schedules the next sample.
    """
    imu_sample(t, xs, xd, w.C, m, d, o)
    sample_components(t, xs, xd, w.C, m, d, o)
    estimate_sample(t, xs, w.C, m, d, o, w)
    detect(t, xs, attitude_at_sample(t, xs, w.C, m, d, w), m, d, o)
    plugin_sensor(t, xs, xd, w.C, m, d)
    d.sst[SS_NEXT_T] = d.ls[LS_T0] + d.sst[SS_N] / m.scfg[SC_RATE]


@compiled
def sample_at(t: float, xs: np.ndarray, m: Model, d: Data, o: Output, w: Work) -> None:
    """:func:`take_sample` at a state ``xs`` whose derivative is not known (interval inputs)."""
    state_derivative(xs, w.xd, m, d, w)
    # (not counted in IS_N_RHS: that is the integrator's own count)
    take_sample(t, xs, w.xd, m, d, o, w)
