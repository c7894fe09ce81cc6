"""An estimator plug-in, from its template: copy this file, change ``step``, register, fly.

An estimator is four things (docs/ESTIMATION.md section 3, docs/howto/add-an-estimator.md):

1. its **parameters**: a pydantic model, validated, with defaults and units in
   the names; scenario files set them under ``[estimator_params]``;
2. its **pack** function: the parameters (and what it needs of the run, such as
   the vehicle's gravity) written into the estimator's settings, ``ecfg``, from
   ``ecfg[EC_USER]`` on (16 slots);
3. its **step**: a compiled function called at every IMU sample with the
   measurement record ``meas``, its settings ``ecfg`` and its estimate ``est``,
   which it updates in place: the attitude at ``ES_Q`` (body to inertial,
   scalar first), the rates at ``ES_W`` (rad/s, body FRD), the velocity at
   ``ES_VEL`` and the position at ``ES_POS`` (m/s and m, inertial NED); its own
   state may go to ``est[ES_USER:]`` (32 slots);
4. a **name**, under which ``register_estimator`` makes it an estimator like the
   built-ins: in scenario files, sweeps, studies, the benchmark and the CLI
   (``--plugin examples/estimator_template.py --estimator template-strapdown``).

This one is the simplest inertial navigation: a strapdown integration. It
integrates the gyro (minus a bias given as a parameter) into the attitude, and
the accelerometer's specific force, rotated to inertial axes and with gravity
added back, into the velocity and the position. It never corrects: with an
ideal IMU at the centre of mass it tracks the truth to integration accuracy,
and with a wrong bias it drifts. Add a correction (an accelerometer tilt
correction, the pose sensor) to make it a filter.

The estimate starts from the truth (plus the scenario's initial error); the
controllers and the detector read it as they read the built-ins'. The run
compiles the step alone, a second or two; the loop is the cached one, which
calls the step by its address.

Run it: ``python examples/estimator_template.py``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import BaseModel, ConfigDict, Field

from quadimpact import ImpactTrial, simulate
from quadimpact.core.estimator_slots import EC_USER, ES_POS, ES_Q, ES_VEL, ES_W, NECFG
from quadimpact.core.sensors.measurement_slots import MS_IMU_F, MS_IMU_W
from quadimpact.inputs.estimators import EstimatorContext, register_estimator


class StrapdownParams(BaseModel):
    """The parameters (``[estimator_params]``), with units in the names."""

    model_config = ConfigDict(extra="forbid", frozen=True)
    gyro_bias_rad_s: tuple[float, float, float] = Field(
        (0.0, 0.0, 0.0), description="Bias subtracted from the gyro, body FRD, rad/s."
    )


# Where the settings are in ``ecfg``: constants the compiled step reads by name.
EC_BIAS = EC_USER  # 3 slots: the gyro bias subtracted, rad/s
EC_GRAVITY = EC_USER + 3  # gravity, m/s^2 (along inertial +z, NED)


def pack(params: StrapdownParams, ctx: EstimatorContext) -> np.ndarray:
    """The settings block ``ecfg`` (``NECFG`` floats): the bias, then the vehicle's gravity."""
    ecfg = np.zeros(NECFG)
    ecfg[EC_BIAS : EC_BIAS + 3] = params.gyro_bias_rad_s
    ecfg[EC_GRAVITY] = ctx.vehicle.gravity_m_s2
    return ecfg


@njit
def strapdown_step(t, dt, meas, ecfg, est):
    """One IMU sample: the rates held over ``dt`` (s) rotate the attitude; the specific
    force, rotated to inertial axes, plus gravity, is the acceleration that moves the
    velocity and the position."""
    w0 = meas[MS_IMU_W] - ecfg[EC_BIAS]
    w1 = meas[MS_IMU_W + 1] - ecfg[EC_BIAS + 1]
    w2 = meas[MS_IMU_W + 2] - ecfg[EC_BIAS + 2]
    est[ES_W] = w0
    est[ES_W + 1] = w1
    est[ES_W + 2] = w2
    if dt <= 0.0:  # the first sample: nothing to integrate yet
        return

    # the acceleration, inertial NED, with the attitude at the sample's start
    q0, q1, q2, q3 = est[ES_Q], est[ES_Q + 1], est[ES_Q + 2], est[ES_Q + 3]
    f0, f1, f2 = meas[MS_IMU_F], meas[MS_IMU_F + 1], meas[MS_IMU_F + 2]
    a0 = (
        (1 - 2 * (q2 * q2 + q3 * q3)) * f0
        + 2 * (q1 * q2 - q0 * q3) * f1
        + 2 * (q1 * q3 + q0 * q2) * f2
    )
    a1 = (
        2 * (q1 * q2 + q0 * q3) * f0
        + (1 - 2 * (q1 * q1 + q3 * q3)) * f1
        + 2 * (q2 * q3 - q0 * q1) * f2
    )
    a2 = (
        2 * (q1 * q3 - q0 * q2) * f0
        + 2 * (q2 * q3 + q0 * q1) * f1
        + (1 - 2 * (q1 * q1 + q2 * q2)) * f2
    )
    a2 += ecfg[EC_GRAVITY]
    for i, a in enumerate((a0, a1, a2)):
        est[ES_POS + i] += (est[ES_VEL + i] + 0.5 * a * dt) * dt
        est[ES_VEL + i] += a * dt

    # the attitude: the rotation of the held rate over dt, composed on the right (body)
    angle = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2) * dt
    if angle == 0.0:
        return
    s = math.sin(0.5 * angle) / angle * dt
    c = math.cos(0.5 * angle)
    bx, by, bz = s * w0, s * w1, s * w2
    est[ES_Q] = q0 * c - q1 * bx - q2 * by - q3 * bz
    est[ES_Q + 1] = q0 * bx + q1 * c + q2 * bz - q3 * by
    est[ES_Q + 2] = q0 * by - q1 * bz + q2 * c + q3 * bx
    est[ES_Q + 3] = q0 * bz + q1 * by - q2 * bx + q3 * c


register_estimator(
    "template-strapdown",
    step=strapdown_step,
    params=StrapdownParams,
    pack=pack,
    description="the plug-in template: strapdown integration of the IMU, no correction",
    replace=True,
)


if __name__ == "__main__":
    # a wall impact with an ideal IMU at the CM: exact before the contact, then the
    # impact's spin and shocks, sampled at the IMU's rate, make it drift
    trial = ImpactTrial(
        roll_deg=5.0, pitch_deg=-20.0, yaw_deg=10.0, speed_m_s=1.2,
        imu={"position": "cm"}, estimator="template-strapdown", final_time_s=1.5,
    )  # fmt: skip
    s = simulate(trial).summary
    for q, unit in (("attitude", "deg"), ("velocity", "m_s"), ("position", "m")):
        pre, crash = s[f"est_{q}_max_pre_{unit}"], s[f"est_{q}_max_crash_{unit}"]
        print(f"{q} error, largest: {pre:.2e} before the contact, {crash:.3f} after ({unit})")
