"""The measurement record a controller sees at a control tick (layout ``MS_*``)."""

import numpy as np
from numba import njit

from ..layout import MS_T, MS_X, NX


@njit(cache=True)
def observe_state(t: float, x: np.ndarray, meas: np.ndarray) -> None:
    """State estimate at the tick ``t`` (s): an ideal estimator, the true state ``x``.

    The IMU fields of ``meas`` are written by the IMU and the detector as the
    samples are taken.
    """
    for i in range(NX):
        meas[MS_X + i] = x[i]
    meas[MS_T] = t
