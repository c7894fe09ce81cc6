"""The measurement record a controller sees at a control tick (layout ``MS_*``).

One writer of the state estimate: :func:`measure`. The estimator stage
(``core/estimators``) calls it at every control tick with what it estimates;
the IMU and the detector write their own fields (``MS_IMU_*``,
``MS_DETECTED``, ``MS_T_DETECT``, ``MS_NORMAL``) as the samples are taken.
"""

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import NX
from quadimpact.core.sensors.measurement_slots import MS_T, MS_X


@compiled
def measure(t: float, x_hat: np.ndarray, meas: np.ndarray) -> None:
    """Write the state estimate ``x_hat`` (layout ``X_*``) of the tick ``t`` (s) into ``meas``."""
    for i in range(NX):
        meas[MS_X + i] = x_hat[i]
    meas[MS_T] = t
