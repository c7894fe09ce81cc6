"""State estimation: the stage between the sensors and the controller.

The controllers and the impact detector's wall-normal estimate read only
what this stage gives them: the state estimate in the measurement record
(``meas[MS_X:MS_X+NX]``, the estimated rates ``meas[MS_W_HAT]`` and bias
``meas[MS_BIAS_HAT]``, written by :func:`write_estimate` through
``sensors.measurement.measure``) and the attitude at each IMU sample
(:func:`attitude_at_sample`).

The estimator is chosen by ``ecfg[EC_KIND]`` (``EST_*``):

* ``ideal``: the true state (attitude, velocity, position), with the gyro as
  measured for the rates (no bias correction): every result is what it was
  before estimators existed, bit for bit;
* ``complementary`` (``complementary.py``): a Mahony-type filter on the attitude;
* ``ekf`` (``ekf.py``): a multiplicative error-state Kalman filter;
* ``ekf-additive`` (``ekf_additive.py``): the authors' 7-state EKF on an
  additive quaternion;
* ``nav-ekf`` (``nav_ekf.py``): the navigation filter, 16 error states,
  fusing the magnetometer, barometer, rangefinder and optical flow;
* a plug-in (``EST_USER``): a compiled step called by its address
  (``ecfg[EC_STEP]``, ``core/plugin_call.py``), compiled alone; or, in a loop
  compiled around it (``core.kernel.make_kernel(estimator=...)``), bound in
  place of :func:`plugin_estimator`.

The stage runs at each IMU sample, after the IMU, the magnetometer and the
pose sensor have written their readings into the measurement record and
before the detector (:func:`estimate_sample`); at each control tick
:func:`at_tick` writes the latest estimate for the controller. Out of the
loop (``ecfg[EC_OBSERVER]``, an observer) the estimate is computed and
scored all the same, but the controller and the detector read what the
ideal estimator gives them (the true state, the gyro as measured). The initial
estimate is the true initial state plus the seeded error of ``ecfg``,
and the gyro's bias (:func:`init_estimate`). Rotor speeds in the state estimate are the true
ones (the motor controllers measure them).
"""

import math

import numpy as np
from numba import njit

from quadimpact.core.compiled import allocating, compiled
from quadimpact.core.estimator_slots import (
    EC_INIT_ATT,
    EC_INIT_BIAS,
    EC_INIT_BIAS_ZERO,
    EC_INIT_EULER,
    EC_INIT_POS,
    EC_INIT_VEL,
    EC_KIND,
    EC_OBSERVER,
    EC_STEP,
    ES_BIAS,
    ES_N,
    ES_POS,
    ES_Q,
    ES_T,
    ES_VEL,
    ES_W,
)
from quadimpact.core.estimators.complementary import complementary_sample
from quadimpact.core.estimators.ekf import ES_T_IMPACT, ekf_init, ekf_sample
from quadimpact.core.estimators.ekf_additive import additive_init, additive_sample
from quadimpact.core.estimators.estimate_errors import record_estimate
from quadimpact.core.estimators.nav_ekf import nav_ekf_sample, nav_init
from quadimpact.core.layout import (
    EST_COMPLEMENTARY,
    EST_EKF,
    EST_EKF_ADDITIVE,
    EST_IDEAL,
    EST_NAV_EKF,
    NX,
    X_OMEGA,
    X_POS,
    X_QUAT,
    X_VEL,
)
from quadimpact.core.plugin_call import call_estimator
from quadimpact.core.quaternion import euler_zyx
from quadimpact.core.records import Data, Model, Output, Work
from quadimpact.core.sensors.imu_slots import (
    SC_BIAS,
)
from quadimpact.core.sensors.measurement import measure
from quadimpact.core.sensors.measurement_slots import MS_BIAS_HAT, MS_IMU_W, MS_W_HAT, MS_X
from quadimpact.core.sensors.rotvec import dcm, rotate_by


@njit(cache=True, inline="always")
def plugin_estimator(t: float, dt: float, meas: np.ndarray, ecfg: np.ndarray, est: np.ndarray):
    """A plug-in estimator's step (rebound by ``core.kernel.make_kernel``); none here.

    A plug-in registered for a run is called by address instead (``ecfg[EC_STEP]``).

    At each IMU sample ``t`` (s), ``dt`` (s) after the previous one (0 at the
    first), it reads the measurement record ``meas`` (``MS_IMU_F``,
    ``MS_IMU_W``; the magnetometer's and the pose sensor's slots, sensor
    components' addresses: ``older_sensors.MAG`` when ``meas[MAG_T] == t``,
    ``POSE`` when ``meas[POSE_T] == t``) and its parameters ``ecfg[EC_USER...]``, and
    updates its state ``est``: the estimate in ``ES_Q``, ``ES_BIAS``,
    ``ES_VEL``, ``ES_POS``, ``ES_W`` (the initial estimate is there at the
    first call), its own state in ``ES_USER``.
    """
    return


@compiled
def _truth(xs: np.ndarray, C: np.ndarray, d: Data) -> None:
    """The ideal estimator's estimate: the true state (no gyro bias estimate)."""
    est = d.est
    for a in range(4):
        est[ES_Q + a] = xs[X_QUAT + a]
    for r in range(3):
        est[ES_VEL + r] = C[r, 0] * xs[X_VEL] + C[r, 1] * xs[X_VEL + 1] + C[r, 2] * xs[X_VEL + 2]
        est[ES_POS + r] = xs[X_POS + r]
        est[ES_BIAS + r] = 0.0
        est[ES_W + r] = d.meas[MS_IMU_W + r]


@allocating
def init_estimate(m: Model, d: Data) -> None:
    """The initial estimate from the initial state ``d.x``: the truth plus ``ecfg``'s error.

    The truth includes the gyro's bias (the vehicle has flown before the run, so
    a filter's bias estimate has converged): a filter starts from the IMU's
    drawn bias plus ``ecfg[EC_INIT_BIAS]``; the ideal estimator does not
    correct the gyro at all.
    """
    est = d.est
    est[:] = 0.0
    x = d.x
    n = math.sqrt(x[X_QUAT] ** 2 + x[X_QUAT + 1] ** 2 + x[X_QUAT + 2] ** 2 + x[X_QUAT + 3] ** 2)
    for a in range(4):
        est[ES_Q + a] = x[X_QUAT + a] / n
    C = np.empty((3, 3))
    dcm(est[ES_Q : ES_Q + 4], C)
    e = m.ecfg
    for r in range(3):
        est[ES_VEL + r] = (
            C[r, 0] * x[X_VEL] + C[r, 1] * x[X_VEL + 1] + C[r, 2] * x[X_VEL + 2]
        ) + e[EC_INIT_VEL + r]
        est[ES_POS + r] = x[X_POS + r] + e[EC_INIT_POS + r]
        est[ES_W + r] = x[X_OMEGA + r]
    rotate_by(est[ES_Q : ES_Q + 4], e[EC_INIT_ATT], e[EC_INIT_ATT + 1], e[EC_INIT_ATT + 2])
    if e[EC_INIT_EULER] != 0.0 or e[EC_INIT_EULER + 1] != 0.0 or e[EC_INIT_EULER + 2] != 0.0:
        _add_euler(est[ES_Q : ES_Q + 4], e[EC_INIT_EULER : EC_INIT_EULER + 3])
    if int(e[EC_KIND]) != EST_IDEAL:
        zero = e[EC_INIT_BIAS_ZERO] > 0.5
        for r in range(3):
            true_bias = 0.0 if zero else m.scfg[SC_BIAS + 3 + r]
            est[ES_BIAS + r] = true_bias + e[EC_INIT_BIAS + r]
    est[ES_T] = np.nan
    est[ES_T_IMPACT] = np.nan
    if int(e[EC_KIND]) == EST_EKF:
        ekf_init(m, d)
    elif int(e[EC_KIND]) == EST_EKF_ADDITIVE:
        additive_init(m, d)
    elif int(e[EC_KIND]) == EST_NAV_EKF:
        nav_init(m, d)


@compiled
def _add_euler(q: np.ndarray, de: np.ndarray) -> None:
    """``q`` (in place) with its ZYX Euler angles increased by ``de`` (roll, pitch, yaw; rad)."""
    roll, pitch, yaw = euler_zyx(q)
    hr = 0.5 * (roll + de[0])
    hp = 0.5 * (pitch + de[1])
    hy = 0.5 * (yaw + de[2])
    cr, sr = math.cos(hr), math.sin(hr)
    cp, sp = math.cos(hp), math.sin(hp)
    cy, sy = math.cos(hy), math.sin(hy)
    q[0] = cr * cp * cy + sr * sp * sy
    q[1] = sr * cp * cy - cr * sp * sy
    q[2] = cr * sp * cy + sr * cp * sy
    q[3] = cr * cp * sy - sr * sp * cy


@compiled
def estimate_sample(
    t: float, xs: np.ndarray, C: np.ndarray, m: Model, d: Data, o: Output, w: Work
) -> None:
    """The estimator's update with the sample at ``t`` (s); then the estimate's errors.

    ``xs``, ``C``: the true state there and its rotation (read only by the
    ideal estimator and by the error record). Leaves the estimate's rotation
    in ``w.C_hat``.
    """
    est = d.est
    kind = int(m.ecfg[EC_KIND])
    dt = t - est[ES_T] if est[ES_N] > 0.0 else 0.0
    if kind == EST_IDEAL:
        _truth(xs, C, d)
    elif kind == EST_COMPLEMENTARY:
        complementary_sample(t, dt, m, d, w.C_hat)
    elif kind == EST_EKF:
        ekf_sample(t, dt, m, d, w.C_hat, w.ekf)
    elif kind == EST_EKF_ADDITIVE:
        additive_sample(t, dt, m, d, w.C_hat)
    elif kind == EST_NAV_EKF:
        nav_ekf_sample(t, dt, m, d, w.C_hat)
    elif m.ecfg[EC_STEP] != 0.0:  # a plug-in, by address (core/plugin_call.py)
        call_estimator(np.int64(m.ecfg[EC_STEP]), t, dt, d.meas, m.ecfg, est)
    else:
        plugin_estimator(t, dt, d.meas, m.ecfg, est)
    if kind != EST_IDEAL:
        dcm(est[ES_Q : ES_Q + 4], w.C_hat)
    est[ES_T] = t
    est[ES_N] += 1.0
    record_estimate(t, xs, C, m, d, o)


@njit(cache=True, inline="always")
def attitude_at_sample(
    t: float, xs: np.ndarray, C: np.ndarray, m: Model, d: Data, w: Work
) -> np.ndarray:
    """The estimated body-to-inertial rotation at the IMU sample ``t`` (s), 3x3.

    ``xs`` is the true state there and ``C`` its rotation: the ideal
    estimator's answer, and an observer's (out of the loop). Others: the
    estimate after the sample (:func:`estimate_sample` left it in ``w.C_hat``).
    """
    if int(m.ecfg[EC_KIND]) == EST_IDEAL or m.ecfg[EC_OBSERVER] > 0.5:
        return C
    return w.C_hat


@compiled
def write_estimate(t: float, x: np.ndarray, m: Model, d: Data, meas: np.ndarray) -> None:
    """The estimate of the tick ``t`` (s) into the measurement record ``meas``.

    ``x``: the true state (quaternion renormalised), which the ideal estimator
    writes as it is; with it the estimated rates are the gyro as measured.
    Others write their estimate (velocity in body axes of the estimated
    attitude; the true rotor speeds), unless out of the loop (an observer:
    what the ideal estimator writes).
    """
    if int(m.ecfg[EC_KIND]) == EST_IDEAL or m.ecfg[EC_OBSERVER] > 0.5:
        measure(t, x, meas)
        for a in range(3):
            meas[MS_W_HAT + a] = meas[MS_IMU_W + a]
            meas[MS_BIAS_HAT + a] = 0.0
        return
    est = d.est
    measure(t, x, meas)  # the true rotor speeds; the rest is replaced by the estimate
    xh = meas[MS_X : MS_X + NX]
    q0, q1, q2, q3 = est[ES_Q], est[ES_Q + 1], est[ES_Q + 2], est[ES_Q + 3]
    n2 = q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3
    vx, vy, vz = est[ES_VEL], est[ES_VEL + 1], est[ES_VEL + 2]
    # C^T v with C the rotation of q (normalised)
    xh[X_VEL] = ((1.0 - 2.0 * (q2 * q2 + q3 * q3) / n2) * vx + 2.0 * (q1 * q2 + q0 * q3) / n2 * vy
                 + 2.0 * (q1 * q3 - q0 * q2) / n2 * vz)  # fmt: skip
    xh[X_VEL + 1] = (2.0 * (q1 * q2 - q0 * q3) / n2 * vx + (1.0 - 2.0 * (q1 * q1 + q3 * q3) / n2)
                     * vy + 2.0 * (q2 * q3 + q0 * q1) / n2 * vz)  # fmt: skip
    xh[X_VEL + 2] = (2.0 * (q1 * q3 + q0 * q2) / n2 * vx + 2.0 * (q2 * q3 - q0 * q1) / n2 * vy
                     + (1.0 - 2.0 * (q1 * q1 + q2 * q2) / n2) * vz)  # fmt: skip
    for a in range(4):
        xh[X_QUAT + a] = est[ES_Q + a]
    for a in range(3):
        xh[X_POS + a] = est[ES_POS + a]
        xh[X_OMEGA + a] = est[ES_W + a]
    for a in range(3):
        meas[MS_W_HAT + a] = est[ES_W + a]
        meas[MS_BIAS_HAT + a] = est[ES_BIAS + a]


@njit(cache=True, inline="always")
def at_tick(t: float, m: Model, d: Data) -> None:
    """The estimate at the control tick ``t`` (s) into the measurement record.

    Ideal: the true state ``d.x`` (its quaternion already renormalised by the tick).
    """
    write_estimate(t, d.x, m, d, d.meas)
