"""The inertial measurement unit: specific force and angular rate at the IMU.

Accelerometer: the specific force at the IMU position ``r_s`` (body frame),
``f = a_s - g`` in body axes, with ``a_s`` the inertial acceleration of that
body point::

    f_B = (v_dot + omega x v) + omega_dot x r_s + omega x (omega x r_s) - C^T (g e_Z)

(``v_dot``, ``omega_dot`` from the right-hand side, contact forces included).
At rest on a level vehicle it reads ``(0, 0, -g)``; in free fall zero; in
free flight without drag, at the CM, its body x-y part is exactly zero, so a
horizontal reading there comes from contact. Gyroscope: ``omega`` (body).

A sample at time ``t`` is evaluated from the state and the right-hand side
at ``t`` with the inputs in force just before ``t``: the run loop takes the
samples on the dense output of each step (``step.py``), so a sample at a
control tick precedes that tick's new command.

Measurement chain, per axis, each stage off unless configured (``scfg``,
layout ``SC_*``): true value + constant bias (drawn once per run) + white
noise (``sigma * noise[i]``, with ``noise`` standard normal draws made by the
caller from the run's seed) -> saturation at the sensor's range -> low-pass
(first-order, ``y += (1 - exp(-dt/tau)) (u - y)``, or a moving average of
the last N samples). Saturation comes before the filter, as in a sensor whose
analogue range clips before its digital filter.

Two options add to the chain, each off unless configured: the impact
disturbance (``disturbance.py``: extra white noise after each contact onset,
decaying with a time constant, drawn from ``snoise[i, SN_IMPACT...]``) is
added to the true value (or, in the authors' ``replace`` mode, takes the
place of the nominal noise on an axis while its standard deviation is the
larger), and the gyro bias random walk (``SS_WALK``, its
increments ``sigma sqrt(1/rate) snoise[i, SN_WALK...]``) to the gyro's
constant bias. With both off the chain is the same arithmetic as without them.
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import (
    FILTER_FIRST_ORDER,
    FILTER_MOVING_AVERAGE,
    ST_N_IMU,
    X_OMEGA,
    X_VEL,
)
from quadimpact.core.records import Data, Model, Output
from quadimpact.core.sensors.disturbance import impact_factor
from quadimpact.core.sensors.imu_slots import (
    I_F,
    I_F_TRUE,
    I_T,
    I_W,
    I_W_TRUE,
    MAX_AVERAGE_WINDOW,
    SC_BIAS,
    SC_BIAS_WALK,
    SC_FILTER,
    SC_FILTER_PARAM,
    SC_IMPACT_F,
    SC_IMPACT_REPLACE,
    SC_IMPACT_TAU,
    SC_IMPACT_W,
    SC_NOISE_F,
    SC_NOISE_W,
    SC_POS,
    SC_RANGE_F,
    SC_RANGE_W,
    SC_RATE,
    SN_IMPACT,
    SN_WALK,
    SS_FILT,
    SS_N,
    SS_RING,
    SS_WALK,
)
from quadimpact.core.sensors.measurement_slots import MS_IMU_F, MS_IMU_T, MS_IMU_W
from quadimpact.core.vehicle_slots import V_GRAVITY


@compiled
def specific_force(
    x: np.ndarray, xdot: np.ndarray, C: np.ndarray, veh: np.ndarray, rx: float, ry: float, rz: float
) -> tuple[float, float, float]:
    """True specific force (m/s^2, body FRD) at the body point ``r`` (m from the CM).

    ``x`` is the state, ``xdot`` its derivative (contact forces included), ``C``
    the body-to-inertial rotation of ``x``.
    """
    u = x[X_VEL]
    v = x[X_VEL + 1]
    w = x[X_VEL + 2]
    p = x[X_OMEGA]
    q = x[X_OMEGA + 1]
    r = x[X_OMEGA + 2]
    pd = xdot[X_OMEGA]
    qd = xdot[X_OMEGA + 1]
    rd = xdot[X_OMEGA + 2]
    # CM acceleration in body axes: v_dot + omega x v
    ax = xdot[X_VEL] + (q * w - r * v)
    ay = xdot[X_VEL + 1] + (r * u - p * w)
    az = xdot[X_VEL + 2] + (p * v - q * u)
    # + omega_dot x r
    ax += qd * rz - rd * ry
    ay += rd * rx - pd * rz
    az += pd * ry - qd * rx
    # + omega x (omega x r)
    cx = q * rz - r * ry
    cy = r * rx - p * rz
    cz = p * ry - q * rx
    ax += q * cz - r * cy
    ay += r * cx - p * cz
    az += p * cy - q * cx
    # - C^T (g e_Z)
    g = veh[V_GRAVITY]
    return ax - g * C[2, 0], ay - g * C[2, 1], az - g * C[2, 2]


@compiled
def _measure_axis(value: float, bias: float, sigma: float, z: float, rng: float) -> float:
    """Bias, noise and saturation of one axis."""
    y = value + bias + sigma * z
    if rng > 0.0:
        if y > rng:
            y = rng
        elif y < -rng:
            y = -rng
    return y


@compiled
def imu_sample(
    t: float, x: np.ndarray, xdot: np.ndarray, C: np.ndarray, m: Model, d: Data, o: Output
) -> None:
    """Take IMU sample number ``d.sst[SS_N]`` at time ``t`` (s) from the true state ``x``.

    ``xdot`` is the state derivative at ``x`` (inputs of the interval), ``C``
    the rotation of ``x``. Writes the measured sample into the measurement
    record (``MS_IMU_*``) and, while there is room, a row of ``o.imu`` (layout
    ``I_*``); counts it in ``o.stats[ST_N_IMU]`` and ``d.sst[SS_N]``.
    """
    veh = m.veh
    scfg = m.scfg
    noise = m.noise
    sst = d.sst
    meas = d.meas
    imu_out = o.imu
    i = int(sst[SS_N])
    rx = scfg[SC_POS]
    ry = scfg[SC_POS + 1]
    rz = scfg[SC_POS + 2]
    fx, fy, fz = specific_force(x, xdot, C, veh, rx, ry, rz)
    true = (fx, fy, fz, x[X_OMEGA], x[X_OMEGA + 1], x[X_OMEGA + 2])
    has_noise = i < noise.shape[0]
    kind = int(scfg[SC_FILTER])
    dt = 1.0 / scfg[SC_RATE]
    window = 1
    if kind == FILTER_MOVING_AVERAGE:
        window = min(max(int(scfg[SC_FILTER_PARAM]), 1), MAX_AVERAGE_WINDOW)
    alpha = 1.0
    if kind == FILTER_FIRST_ORDER and scfg[SC_FILTER_PARAM] > 0.0:
        alpha = 1.0 - math.exp(-dt / scfg[SC_FILTER_PARAM])
    row = i < imu_out.shape[0]
    snoise = m.snoise
    has_extra = i < snoise.shape[0]
    factor = 0.0
    replace = scfg[SC_IMPACT_REPLACE] > 0.5
    if scfg[SC_IMPACT_TAU] > 0.0 and has_extra:
        factor = impact_factor(t, scfg[SC_IMPACT_TAU], o.stats, replace)
    walk = scfg[SC_BIAS_WALK] > 0.0 and has_extra
    if walk and i > 0:
        step = scfg[SC_BIAS_WALK] * math.sqrt(dt)
        for a in range(3):
            sst[SS_WALK + a] += step * snoise[i, SN_WALK + a]
    for a in range(6):
        sigma = scfg[SC_NOISE_F] if a < 3 else scfg[SC_NOISE_W]
        rng = scfg[SC_RANGE_F] if a < 3 else scfg[SC_RANGE_W]
        z = noise[i, a] if has_noise else 0.0
        value = true[a]
        if factor > 0.0:
            amplitude = scfg[SC_IMPACT_F] if a < 3 else scfg[SC_IMPACT_W]
            if not replace:
                value += amplitude * factor * snoise[i, SN_IMPACT + a]
            elif amplitude * factor > sigma:
                sigma = amplitude * factor  # the impact noise replaces the nominal one
                z = snoise[i, SN_IMPACT + a]
        bias = scfg[SC_BIAS + a]
        if walk and a >= 3:
            bias += sst[SS_WALK + a - 3]
        y = _measure_axis(value, bias, sigma, z, rng)
        if kind == FILTER_FIRST_ORDER:
            if i == 0:
                sst[SS_FILT + a] = y
            else:
                sst[SS_FILT + a] += alpha * (y - sst[SS_FILT + a])
            y = sst[SS_FILT + a]
        elif kind == FILTER_MOVING_AVERAGE:
            slot = SS_RING + 6 * (i % window) + a
            if i >= window:
                sst[SS_FILT + a] -= sst[slot]
            sst[slot] = y
            sst[SS_FILT + a] += y
            y = sst[SS_FILT + a] / min(i + 1, window)
        if a < 3:
            meas[MS_IMU_F + a] = y
        else:
            meas[MS_IMU_W + a - 3] = y
        if row:
            imu_out[i, (I_F + a) if a < 3 else (I_W + a - 3)] = y
            imu_out[i, (I_F_TRUE + a) if a < 3 else (I_W_TRUE + a - 3)] = true[a]
    meas[MS_IMU_T] = t
    if row:
        imu_out[i, I_T] = t
    sst[SS_N] = i + 1
    o.stats[ST_N_IMU] = i + 1
