"""On-board sensing settings: the IMU (``[imu]``) and the impact detector (``[detection]``).

Every run carries an IMU (by default ideal, sampled at every control tick),
records its samples, and runs the impact detector on them; the ``recovery``
controller acts on the detector's verdict. See docs/RECOVERY.md.

In a scenario file::

    imu = "noisy"              # a preset: "ideal" (default) or "noisy"

    [imu]                      # or a table: a preset and single changes
    preset = "noisy"
    rate_hz = 1000
    position = "cm"            # "vehicle" (the vehicle file's imu_position_m), "cm", or [x, y, z]

    [detection]
    threshold_g = 0.5
    frame = "body"             # or "world"
    persistence = 1
"""

from __future__ import annotations

import math
from typing import Any, Literal

from pydantic import BaseModel, Field, StrictBool, field_validator, model_validator

from quadimpact.inputs.types import MODEL_CONFIG, Real, Vec3

__all__ = ["IMU_PRESETS", "DetectionSettings", "ImuSettings", "ResolvedImu"]

G0 = 9.80665  # standard gravity, m/s^2 (sensor ranges are quoted in g)

IMU_PRESETS: dict[str, dict[str, float | None]] = {
    "ideal": {
        "accel_noise_m_s2": 0.0,
        "gyro_noise_rad_s": 0.0,
        "accel_bias_m_s2": 0.0,
        "gyro_bias_rad_s": 0.0,
        "accel_range_m_s2": None,
        "gyro_range_rad_s": None,
    },
    # a consumer MEMS IMU during impacts: noise 1 m/s^2 and 1.8e-3 rad/s per
    # axis, biases of 0.05 m/s^2 and 0.01 rad/s (standard deviations of the
    # per-run draw), ranges +-16 g and +-2000 deg/s
    "noisy": {
        "accel_noise_m_s2": 1.0,
        "gyro_noise_rad_s": 1.8e-3,
        "accel_bias_m_s2": 0.05,
        "gyro_bias_rad_s": 0.01,
        "accel_range_m_s2": 16.0 * G0,
        "gyro_range_rad_s": math.radians(2000.0),
    },
}
"""The IMU presets; a field set in ``[imu]`` overrides its preset's value."""


class ResolvedImu(BaseModel):
    """Every IMU setting with its value (no ``None`` left but the optional ones)."""

    model_config = MODEL_CONFIG

    rate_hz: float
    position_m: tuple[float, float, float]
    accel_noise_m_s2: float
    gyro_noise_rad_s: float
    accel_bias_m_s2: float
    gyro_bias_rad_s: float
    accel_range_m_s2: float | None
    gyro_range_rad_s: float | None
    filter: str
    filter_time_constant_s: float | None
    filter_window: int | None

    @property
    def has_noise(self) -> bool:
        """Whether any random draw is needed (noise or bias)."""
        return any(
            v > 0.0
            for v in (
                self.accel_noise_m_s2,
                self.gyro_noise_rad_s,
                self.accel_bias_m_s2,
                self.gyro_bias_rad_s,
            )
        )


class ImuSettings(BaseModel):
    """The inertial measurement unit: rate, position, noise, bias, range, low-pass.

    Attributes
    ----------
    preset : {"ideal", "noisy"}
        Starting values (:data:`IMU_PRESETS`); the fields below override them.
    rate_hz : float or None
        Sample rate, Hz; ``None``: every control tick (200 Hz). Higher rates
        sample between the ticks from the integrator's dense output.
    position : {"vehicle", "cm"} or tuple of 3 floats
        Where the IMU sits: the vehicle file's ``imu_position_m``, the CM, or a
        point (body FRD, m, from the CM).
    accel_noise_m_s2, gyro_noise_rad_s : float or None
        White-noise standard deviation per axis (m/s^2, rad/s).
    accel_bias_m_s2, gyro_bias_rad_s : float or None
        Standard deviation of the constant per-axis bias drawn once per run.
    accel_range_m_s2, gyro_range_rad_s : float or None
        Saturation (per axis, symmetric), m/s^2 and rad/s; ``None``: none.
    filter : {"none", "first-order", "moving-average"}
        Low-pass applied after saturation.
    filter_time_constant_s : float or None
        First-order filter time constant, s.
    filter_window : int or None
        Moving-average window, samples (1-64).
    """

    model_config = MODEL_CONFIG

    preset: Literal["ideal", "noisy"] = Field("ideal", description="Starting values.")
    rate_hz: Real | None = Field(
        None, gt=0, le=100000, description="Sample rate, Hz; None: every control tick."
    )
    position: Literal["vehicle", "cm"] | Vec3 = Field(
        "vehicle", description="'vehicle' (its imu_position_m), 'cm', or [x, y, z] body FRD, m."
    )
    accel_noise_m_s2: Real | None = Field(None, ge=0, description="Accelerometer noise std.")
    gyro_noise_rad_s: Real | None = Field(None, ge=0, description="Gyro noise std, rad/s.")
    accel_bias_m_s2: Real | None = Field(None, ge=0, description="Accelerometer bias std.")
    gyro_bias_rad_s: Real | None = Field(None, ge=0, description="Gyro bias std, rad/s.")
    accel_range_m_s2: Real | None = Field(None, gt=0, description="Accelerometer range.")
    gyro_range_rad_s: Real | None = Field(None, gt=0, description="Gyro range, rad/s.")
    filter: Literal["none", "first-order", "moving-average"] = Field(
        "none", description="Low-pass after saturation."
    )
    filter_time_constant_s: Real | None = Field(
        None, gt=0, description="First-order filter time constant, s."
    )
    filter_window: int | None = Field(
        None, ge=1, le=64, description="Moving-average window, samples."
    )

    @model_validator(mode="before")
    @classmethod
    def _from_preset_name(cls, value: Any) -> Any:
        if isinstance(value, str):
            return {"preset": value}
        return value

    @model_validator(mode="after")
    def _filter_parameters(self) -> ImuSettings:
        if self.filter == "first-order" and self.filter_time_constant_s is None:
            raise ValueError("filter_time_constant_s: required with filter = 'first-order'")
        if self.filter == "moving-average" and self.filter_window is None:
            raise ValueError("filter_window: required with filter = 'moving-average'")
        return self

    def resolved(self, vehicle_position_m: tuple[float, float, float], control_rate_hz: float):
        """Every setting with its value, for a vehicle and a control rate.

        Returns
        -------
        ResolvedImu
        """
        values = dict(IMU_PRESETS[self.preset])
        for key in values:
            mine = getattr(self, key)
            if mine is not None:
                values[key] = float(mine)
        if self.position == "vehicle":
            position = tuple(float(c) for c in vehicle_position_m)
        elif self.position == "cm":
            position = (0.0, 0.0, 0.0)
        else:
            position = tuple(float(c) for c in self.position)
        return ResolvedImu(
            rate_hz=float(self.rate_hz) if self.rate_hz is not None else float(control_rate_hz),
            position_m=position,
            filter=self.filter,
            filter_time_constant_s=self.filter_time_constant_s,
            filter_window=self.filter_window,
            **values,
        )


class DetectionSettings(BaseModel):
    """The impact detector (it sees the IMU samples only).

    Attributes
    ----------
    enabled : bool
        Run the detector (default true).
    threshold_g : float
        Horizontal specific force that detects an impact, in units of the
        vehicle's gravity (default 0.5).
    frame : {"body", "world"}
        ``"body"``: ``|(f_x, f_y)|`` in body axes (the authors'); ``"world"``: the
        horizontal part of the specific force rotated into inertial axes.
    persistence : int
        Consecutive samples at or above the threshold before it fires (>= 1).
    """

    model_config = MODEL_CONFIG

    enabled: StrictBool = Field(True, description="Run the impact detector.")
    threshold_g: Real = Field(0.5, gt=0, le=100, description="Threshold, in g.")
    frame: Literal["body", "world"] = Field("body", description="Horizontal in body or world axes.")
    persistence: int = Field(1, ge=1, le=1000, description="Consecutive samples needed.")

    @field_validator("persistence", mode="before")
    @classmethod
    def _strict_int(cls, value: Any) -> Any:
        if isinstance(value, bool):
            raise ValueError("must be an integer")
        return value
