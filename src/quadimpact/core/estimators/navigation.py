"""Velocity and position by integrating the accelerometer (the estimators' shared part).

Between pose measurements (and always without a pose sensor) an estimator
knows velocity and position only by integrating the measured specific force
rotated by its attitude estimate, plus gravity::

    a_hat = C_hat f + g e_Z,   p_hat += v_hat dt + a_hat dt^2 / 2,   v_hat += a_hat dt

(the IMU's lever arm is not compensated). Every error of the attitude, every
noise and bias of the accelerometer is integrated too: without a pose sensor
the velocity estimate drifts (linearly in a bias or a tilt error), the
position estimate quadratically.
"""

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.estimator_slots import ES_POS, ES_VEL


@compiled
def integrate_navigation(
    est: np.ndarray, C: np.ndarray, f: np.ndarray, g: float, dt: float
) -> None:
    """Advance ``est``'s velocity and position over ``dt`` (s) with the specific force ``f``.

    ``C``: the attitude estimate's rotation; ``f``: body FRD, m/s^2; ``g``: m/s^2.
    """
    for r in range(3):
        a = C[r, 0] * f[0] + C[r, 1] * f[1] + C[r, 2] * f[2]
        if r == 2:
            a += g
        est[ES_POS + r] += est[ES_VEL + r] * dt + 0.5 * a * dt * dt
        est[ES_VEL + r] += a * dt
