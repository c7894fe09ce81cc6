"""State estimation: the stage between the sensors and the controller.

The controllers and the impact detector's wall-normal estimate read only
what this stage gives them: the state estimate in the measurement record
(``meas[MS_X:MS_X+NX]``, written by ``sensors.measurement.measure``) and the
attitude at each IMU sample.

Only the ``ideal`` estimator exists today: it reads the true state (so the
controllers see the truth, and every result is what it was before the seam).
An estimator that filters the IMU (complementary, EKF) is a module here with
its own state, selected by an option, and branches in :func:`at_tick` and
:func:`attitude_at_sample`.
"""

import numpy as np
from numba import njit

from ..records import Data, Model
from ..sensors.measurement import measure


@njit(cache=True, inline="always")
def at_tick(t: float, m: Model, d: Data) -> None:
    """The estimate at the control tick ``t`` (s) into the measurement record.

    Ideal: the true state ``d.x`` (its quaternion already renormalised by the tick).
    """
    measure(t, d.x, d.meas)


@njit(cache=True, inline="always")
def attitude_at_sample(t: float, xs: np.ndarray, C: np.ndarray, m: Model, d: Data) -> np.ndarray:
    """The estimated body-to-inertial rotation at the IMU sample ``t`` (s), 3x3.

    ``xs`` is the true state there and ``C`` its rotation. Ideal: ``C`` itself.
    """
    return C
