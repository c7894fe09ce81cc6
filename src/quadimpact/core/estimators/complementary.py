"""A nonlinear complementary filter (Mahony-type): the attitude from the gyro, corrected.

At each IMU sample (gyro ``w``, specific force ``f``, period ``dt``):

* the predicted attitude ``q_pred = q_hat (x) exp((w - b_hat) dt)``, at which the
  errors below are measured (a sample consistent with the truth then corrects
  nothing: a constant rotation is tracked exactly);
* accelerometer error, skipped (gated) while ``||f| - g| > gate``: the cross
  product of the measured "up" direction and the estimated one,
  ``e_a = (f / |f|) x (-C_pred^T e_Z)`` (at rest the specific force points up);
* magnetometer error (with a magnetometer): ``h = C_pred m``, its horizontal
  part laid on magnetic north, ``b = (|h_XY|, 0, h_Z)``, and
  ``e_m = m x (C_pred^T b)`` (``m`` the normalised reading): it corrects the
  heading and leaves the inclination of the field to the accelerometer;
* bias (integral) update ``b_hat <- b_hat - k_I (e_a + e_m) dt``, then the
  corrected rate ``w_c = w - b_hat + k_acc e_a + k_mag e_m``;
* attitude ``q_hat <- q_hat (x) exp(w_c dt)`` (the exact exponential of a rate
  held over the period);
* velocity and position by integrating the accelerometer
  (``navigation.py``); with a pose sensor, a complementary correction toward
  each measurement ``p_m``: ``p_hat += k_pos (p_m - p_hat)``,
  ``v_hat += k_vel (p_m - p_hat)``, and with its attitude
  ``q_hat <- q_hat (x) exp(k_pos phi)`` (``phi`` the rotation from the
  estimate to the measured attitude).

The authors' explicit form (``EC_CF_RAW``, Mahony's explicit complementary
filter as their 2016 study wrote it) works on the raw, unnormalised vectors:
``e_a = f x (-g C_pred^T e_Z)`` and ``e_m = m x (C_pred^T m_I)`` (the whole
field, so the magnetometer corrects the inclination too, and alone while the
accelerometer is gated), the correction ``k_p (w_a e_a + w_m e_m) / 2`` and the
bias rate ``-k_I (w_a e_a + w_m e_m) / 2``; ``ecfg`` holds the products
(``EC_K_ACC = k_p w_a / 2``, ``EC_K_MAG = k_p w_m / 2``,
``EC_K_BIAS = k_I w_a / 2``, ``EC_K_BIAS_MAG = k_I w_m / 2``).

The estimated rates given to the controllers are ``w - b_hat``. Gains
(``ecfg``): ``k_acc`` (``EC_K_ACC``, default 0.25 1/s), ``k_mag`` (0.15 1/s),
``k_I`` (``EC_K_BIAS``, 0.25 1/s^2), the gate (1 m/s^2): the authors'
simulation values. With ``k_acc = k_mag`` and no gate this is the ``ahrs``
package's Mahony filter but for two things: ``ahrs`` measures the errors at
the prior attitude (one sample behind the measurement: a lag of ``|w| dt``
under rotation) and integrates to first order (``q += q (x) (0, w_c) dt / 2``,
normalised) where this filter uses the exponential.
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.estimator_slots import (
    EC_OWN,
    ES_BIAS,
    ES_GATED,
    ES_POS,
    ES_Q,
    ES_VEL,
    ES_W,
    N_OWN_ECFG,
)
from quadimpact.core.estimators.navigation import integrate_navigation
from quadimpact.core.estimators.older_sensors import MAG, MAG_FIELD_I, MAG_T, POSE, POSE_ATT, POSE_T
from quadimpact.core.layout import Block
from quadimpact.core.records import Data, Model
from quadimpact.core.sensors.measurement_slots import MS_IMU_F, MS_IMU_W
from quadimpact.core.sensors.rotvec import dcm, error_vector, rotate_by
from quadimpact.core.vehicle_slots import V_GRAVITY

# ---- its block at ecfg[EC_OWN:] (core/estimator_slots.py; packed by packing/estimator_block.py)
_cfg = Block("ecfg.complementary", "EC_", start=EC_OWN, capacity=EC_OWN + N_OWN_ECFG)
EC_K_ACC = _cfg.slot("EC_K_ACC")  # accelerometer gain k_P, 1/s
EC_K_MAG = _cfg.slot("EC_K_MAG")  # magnetometer gain, 1/s
EC_K_BIAS = _cfg.slot("EC_K_BIAS")  # bias (integral) gain k_I, 1/s^2
EC_K_POS = _cfg.slot("EC_K_POS")  # pose position gain, per sample (0-1)
EC_K_VEL = _cfg.slot("EC_K_VEL")  # pose velocity gain, 1/s per sample
EC_GATE = _cfg.slot("EC_GATE")  # m/s^2: accelerometer correction gated while ||f| - g| > this
EC_CF_RAW = _cfg.slot("EC_CF_RAW")  # 1: the authors' form on raw vectors
EC_K_BIAS_MAG = _cfg.slot("EC_K_BIAS_MAG")  # raw form: bias gain of the magnetometer term
N_CF_CFG = _cfg.end("N_CF_CFG")


@compiled
def complementary_sample(t: float, dt: float, m: Model, d: Data, C: np.ndarray) -> None:
    """Update the estimate ``d.est`` with the sample at ``t`` (s), ``dt`` (s) after the last.

    ``C``: scratch 3x3 (the estimate's rotation on return).
    """
    ecfg = m.ecfg
    est = d.est
    meas = d.meas
    g = m.veh[V_GRAVITY]
    q = est[ES_Q : ES_Q + 4]
    w = meas[MS_IMU_W : MS_IMU_W + 3]
    # the errors are measured at the attitude predicted for this sample (the prior
    # advanced by the gyro minus the bias), so that a consistent sample corrects nothing
    p0, p1, p2, p3 = q[0], q[1], q[2], q[3]
    rotate_by(
        q,
        (w[0] - est[ES_BIAS]) * dt,
        (w[1] - est[ES_BIAS + 1]) * dt,
        (w[2] - est[ES_BIAS + 2]) * dt,
    )
    dcm(q, C)
    f = meas[MS_IMU_F : MS_IMU_F + 3]
    ex = 0.0
    ey = 0.0
    ez = 0.0
    mx = 0.0
    my = 0.0
    mz = 0.0
    fn = math.sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2])
    est[ES_GATED] = 1.0
    if ecfg[EC_CF_RAW] > 0.5:
        ex, ey, ez, mx, my, mz = _raw_errors(t, fn, g, C, m, d)
    elif fn > 0.0 and abs(fn - g) <= ecfg[EC_GATE]:
        est[ES_GATED] = 0.0
        ax = f[0] / fn
        ay = f[1] / fn
        az = f[2] / fn
        vx = -C[2, 0]
        vy = -C[2, 1]
        vz = -C[2, 2]
        ex = ay * vz - az * vy
        ey = az * vx - ax * vz
        ez = ax * vy - ay * vx
    if meas[MAG_T] == t and ecfg[EC_CF_RAW] < 0.5:
        mm = meas[MAG : MAG + 3]
        nn = math.sqrt(mm[0] * mm[0] + mm[1] * mm[1] + mm[2] * mm[2])
        if nn > 0.0:
            ux = mm[0] / nn
            uy = mm[1] / nn
            uz = mm[2] / nn
            hx = C[0, 0] * ux + C[0, 1] * uy + C[0, 2] * uz
            hy = C[1, 0] * ux + C[1, 1] * uy + C[1, 2] * uz
            hz = C[2, 0] * ux + C[2, 1] * uy + C[2, 2] * uz
            bx = math.sqrt(hx * hx + hy * hy)
            wx = C[0, 0] * bx + C[2, 0] * hz
            wy = C[0, 1] * bx + C[2, 1] * hz
            wz = C[0, 2] * bx + C[2, 2] * hz
            mx = uy * wz - uz * wy
            my = uz * wx - ux * wz
            mz = ux * wy - uy * wx
    _correct(t, dt, (p0, p1, p2, p3), (ex, ey, ez), (mx, my, mz), m, d, C)


@compiled
def _raw_errors(
    t: float, fn: float, g: float, C: np.ndarray, m: Model, d: Data
) -> tuple[float, float, float, float, float, float]:
    """The authors' explicit form: the errors ``e_a``, ``e_m`` on the raw vectors."""
    ecfg = m.ecfg
    est = d.est
    meas = d.meas
    f = meas[MS_IMU_F : MS_IMU_F + 3]
    ex = 0.0
    ey = 0.0
    ez = 0.0
    mx = 0.0
    my = 0.0
    mz = 0.0
    if abs(fn - g) <= ecfg[EC_GATE]:
        est[ES_GATED] = 0.0
        vx = -g * C[2, 0]
        vy = -g * C[2, 1]
        vz = -g * C[2, 2]
        ex = f[1] * vz - f[2] * vy
        ey = f[2] * vx - f[0] * vz
        ez = f[0] * vy - f[1] * vx
    if meas[MAG_T] == t:
        mm = meas[MAG : MAG + 3]
        mi = m.scfg[MAG_FIELD_I : MAG_FIELD_I + 3]
        wx = C[0, 0] * mi[0] + C[1, 0] * mi[1] + C[2, 0] * mi[2]
        wy = C[0, 1] * mi[0] + C[1, 1] * mi[1] + C[2, 1] * mi[2]
        wz = C[0, 2] * mi[0] + C[1, 2] * mi[1] + C[2, 2] * mi[2]
        mx = mm[1] * wz - mm[2] * wy
        my = mm[2] * wx - mm[0] * wz
        mz = mm[0] * wy - mm[1] * wx
    return ex, ey, ez, mx, my, mz


@compiled
def _correct(
    t: float,
    dt: float,
    prior: tuple[float, float, float, float],
    e_a: tuple[float, float, float],
    e_m: tuple[float, float, float],
    m: Model,
    d: Data,
    C: np.ndarray,
) -> None:
    """The bias and attitude updates from the ``prior`` attitude with the errors ``e_a``
    (accelerometer) and ``e_m`` (magnetometer); then navigation and the pose sensor."""
    ecfg = m.ecfg
    est = d.est
    meas = d.meas
    g = m.veh[V_GRAVITY]
    q = est[ES_Q : ES_Q + 4]
    w = meas[MS_IMU_W : MS_IMU_W + 3]
    f = meas[MS_IMU_F : MS_IMU_F + 3]
    p0, p1, p2, p3 = prior
    ex, ey, ez = e_a
    mx, my, mz = e_m
    k_i = ecfg[EC_K_BIAS]
    if ecfg[EC_CF_RAW] > 0.5:
        k_im = ecfg[EC_K_BIAS_MAG]
        est[ES_BIAS] -= (k_i * ex + k_im * mx) * dt
        est[ES_BIAS + 1] -= (k_i * ey + k_im * my) * dt
        est[ES_BIAS + 2] -= (k_i * ez + k_im * mz) * dt
    else:
        est[ES_BIAS] -= k_i * (ex + mx) * dt
        est[ES_BIAS + 1] -= k_i * (ey + my) * dt
        est[ES_BIAS + 2] -= k_i * (ez + mz) * dt
    ka = ecfg[EC_K_ACC]
    km = ecfg[EC_K_MAG]
    for a in range(3):
        est[ES_W + a] = w[a] - est[ES_BIAS + a]
    wx_c = est[ES_W] + ka * ex + km * mx
    wy_c = est[ES_W + 1] + ka * ey + km * my
    wz_c = est[ES_W + 2] + ka * ez + km * mz
    q[0], q[1], q[2], q[3] = p0, p1, p2, p3
    rotate_by(q, wx_c * dt, wy_c * dt, wz_c * dt)
    dcm(q, C)
    integrate_navigation(est, C, f, g, dt)
    if meas[POSE_T] == t:
        kp = ecfg[EC_K_POS]
        kv = ecfg[EC_K_VEL]
        for a in range(3):
            e = meas[POSE + a] - est[ES_POS + a]
            est[ES_POS + a] += kp * e
            est[ES_VEL + a] += kv * e
        if m.scfg[POSE_ATT] > 0.5:
            px, py, pz = error_vector(q, meas[POSE + 3 : POSE + 7])
            rotate_by(q, kp * px, kp * py, kp * pz)
            dcm(q, C)
