"""The settings of the magnetometer and the pose sensor (a scenario's ``[magnetometer]`` and
``[pose_sensor]``), apart from their components.

Every scenario has these two fields, and a scenario is read and checked
without the compiled code (a bad input is said before Numba loads), so
their settings models live here, in a module that imports no compiled code.
The components themselves (blocks, pack, compiled sample) are
``magnetometer.py`` and ``pose.py``, which use these models.
"""

from __future__ import annotations

from pydantic import BaseModel, Field, StrictBool

from quadimpact.core.settings_types import MODEL_CONFIG, Real

__all__ = ["Magnetometer", "PoseSensor"]


class Magnetometer(BaseModel):
    """A magnetometer sampled with the IMU: the unit Earth field in body axes, with noise.

    The field ``m_I`` points to magnetic north (+X) and dips ``dip_deg`` below
    the horizon (down positive, NED), of length ``norm`` (1: a unit field);
    a static bias of standard deviation ``bias`` per axis is drawn once per
    run. Without a magnetometer yaw is unobservable and an estimator's heading
    drifts with the gyro bias.
    """

    model_config = MODEL_CONFIG

    dip_deg: Real = Field(60.0, ge=-90, le=90, description="Dip of the field, deg (down +).")
    noise: Real = Field(7e-3, ge=0, description="White-noise std per axis, unit field.")
    norm: Real = Field(1.0, gt=0, le=10, description="Length of the field (1: unit).")
    bias: Real = Field(0.0, ge=0, description="Std of the static bias per axis (per run).")


class PoseSensor(BaseModel):
    """A pose sensor (motion capture or vision): position, and optionally attitude.

    Measures at ``rate_hz`` (taken at the first IMU sample at or after each of
    its times), with white noise, delivered ``latency_s`` later (rounded to
    whole IMU samples, at most 63).
    """

    model_config = MODEL_CONFIG

    rate_hz: Real = Field(100.0, gt=0, le=100000, description="Measurement rate, Hz.")
    position_noise_m: Real = Field(1e-3, ge=0, description="Position noise std per axis, m.")
    attitude: StrictBool = Field(True, description="Measure the attitude too.")
    attitude_noise_deg: Real = Field(0.5, ge=0, description="Attitude noise std per axis, deg.")
    latency_s: Real = Field(0.0, ge=0, le=1, description="Latency, s.")
