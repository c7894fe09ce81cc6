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

    [magnetometer]             # optional sensors (docs/ESTIMATION.md): absent by default
    dip_deg = 60
    [pose_sensor]
    rate_hz = 100

    sensors = "indoor"         # or a preset of sensors: "ideal", "noisy", "impact", "indoor"

The IMU's impact disturbance (``[imu.impact_disturbance]``, or
``impact_disturbance = true`` for the authors' values) and its gyro bias random
walk (``gyro_bias_walk_rad_s_sqrt_s``) are IMU options; the ``"impact"`` IMU
preset has both (with the ``"noisy"`` preset's noise).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    BeforeValidator,
    Field,
    StrictBool,
    field_validator,
    model_validator,
)

from quadimpact.core.sensors.older_settings import Magnetometer, PoseSensor
from quadimpact.inputs.types import MODEL_CONFIG, Real, Vec3

__all__ = [
    "IMU_PRESETS",
    "SENSOR_PRESETS",
    "DetectionSettings",
    "BUILTIN_SENSOR_PRESETS",
    "ImpactDisturbance",
    "ImuSettings",
    "Instruments",
    "Magnetometer",
    "PoseSensor",
    "ResolvedImu",
    "register_sensor_preset",
    "sensor_preset_names",
]

G0 = 9.80665  # standard gravity, m/s^2 (sensor ranges are quoted in g)


class ImpactDisturbance(BaseModel):
    """The IMU's impact disturbance: noise that rings after each contact onset.

    From each contact onset ``t_c``, extra white noise of standard deviation
    ``accel_m_s2 exp(-(t - t_c)/time_constant_s)`` on each accelerometer axis
    and ``gyro_rad_s exp(-(t - t_c)/time_constant_s)`` on each gyro axis, added
    to the nominal noise (before saturation). Defaults: the authors' values.
    With ``mode = "replace"`` (their 2016 estimator study) the noise of the
    latest onset alone (a new contact restarts it) takes the place of the
    nominal noise on each axis until it decays below it.
    """

    model_config = MODEL_CONFIG

    accel_m_s2: Real = Field(14.0, ge=0, description="Accelerometer amplitude a0, m/s^2.")
    gyro_rad_s: Real = Field(0.1, ge=0, description="Gyro amplitude g0, rad/s.")
    time_constant_s: Real = Field(0.4, gt=0, description="Decay time constant tau, s.")
    mode: Literal["add", "replace"] = Field(
        "add",
        description="'add': each onset's noise added to the nominal noise (variances of "
        "several onsets add); 'replace': the latest onset's noise replaces the nominal noise "
        "while it is the larger (the authors' 2016 study).",
    )


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
# the noisy IMU through impacts: its structure rings after each contact (the
# authors' disturbance) and its gyro bias wanders (1e-4 rad/s/sqrt(s))
IMU_PRESETS["impact"] = dict(IMU_PRESETS["noisy"])
# the authors' 2016 estimator study: the noisy IMU's noise, static biases drawn with
# 0.1 m/s^2 and 0.01 rad/s, no saturation
IMU_PRESETS["authors-2016"] = {
    **IMU_PRESETS["noisy"],
    "accel_bias_m_s2": 0.1,
    "accel_range_m_s2": None,
    "gyro_range_rad_s": None,
}
"""The IMU presets; a field set in ``[imu]`` overrides its preset's value."""
IMU_EXTRAS: dict[str, dict[str, Any]] = {
    "ideal": {"impact_disturbance": None, "gyro_bias_walk_rad_s_sqrt_s": 0.0},
    "noisy": {"impact_disturbance": None, "gyro_bias_walk_rad_s_sqrt_s": 0.0},
    "impact": {"impact_disturbance": {}, "gyro_bias_walk_rad_s_sqrt_s": 1e-4},
    "authors-2016": {
        "impact_disturbance": {"mode": "replace"},
        "gyro_bias_walk_rad_s_sqrt_s": 0.0,
    },
}
"""Each IMU preset's impact disturbance (None: off; a table: its settings) and bias walk."""

SENSOR_PRESETS: dict[str, dict[str, Any]] = {
    "ideal": {"imu": "ideal"},
    "noisy": {"imu": "noisy"},
    "impact": {"imu": "impact"},
    "indoor": {"imu": "impact", "magnetometer": {}, "pose_sensor": {}},
    # what a small drone carries to hold a hover without motion capture: the impact IMU,
    # a magnetometer, a barometer, a lidar rangefinder and a downward flow camera
    "onboard": {
        "imu": "impact",
        "magnetometer": {},
        "instruments": {"barometer": {}, "rangefinder": {"preset": "lidar"}, "optical_flow": {}},
    },
    # the authors' 2016 estimator study: 100 Hz at the CM, their magnetometer
    "authors-2016": {
        "imu": {"preset": "authors-2016", "rate_hz": 100.0, "position": "cm"},
        "magnetometer": {"dip_deg": 71.9, "norm": 0.99, "noise": 7e-4, "bias": 1e-3},
    },
}
"""Realistic combinations of sensors (a scenario's ``sensors``): the IMU preset and the
optional sensors (``{}``: present with their defaults) and the sensor components
(``instruments``). Fields a scenario sets itself (``imu``, ``magnetometer``,
``pose_sensor``, ``instruments``) win over its preset's."""

#: The presets that ship with quadimpact (a registered one is a plug-in's).
BUILTIN_SENSOR_PRESETS: tuple[str, ...] = tuple(SENSOR_PRESETS)
_PRESET_FIELDS = ("imu", "magnetometer", "pose_sensor", "instruments")


def register_sensor_preset(name: str, preset: Mapping[str, Any]) -> None:
    """Register a preset of sensors of your own, by name (a plug-in's).

    A scenario names it as ``sensors = "<name>"``; ``quadimpact recovery`` and
    ``quadimpact pole`` take it as ``--sensors <name>`` and the benchmark as a
    sensor set (``--sensors ideal,<name>``), once the module that registers it
    is loaded (``--plugin FILE.py``). Registering the same name again replaces
    it (a sweep's worker processes import the module again).

    Parameters
    ----------
    name : str
        The preset's name; not one of :data:`BUILTIN_SENSOR_PRESETS`.
    preset : mapping
        Its sensors, as in a scenario: ``imu`` (an IMU preset's name or a table
        of settings), ``magnetometer`` and ``pose_sensor`` (tables; ``{}``: the
        defaults) and ``instruments`` (sensor component name -> its settings
        table). Components must be registered before the preset names them.

    Raises
    ------
    InputError
        A bad name, a field that is not a sensor, or settings the sensors refuse
        (one line naming the preset and the field).
    """
    from quadimpact.errors import InputError

    where = f"sensor preset {name!r}"
    if not isinstance(name, str) or not name.strip() or name != name.strip():
        raise InputError(f"sensor preset: the name must be a non-empty word (got {name!r})")
    if name in BUILTIN_SENSOR_PRESETS:
        raise InputError(f"{where}: a built-in preset has that name (choose another)")
    if not isinstance(preset, Mapping):
        raise InputError(f"{where}: must be a mapping of sensors (got {type(preset).__name__})")
    for key in preset:
        if key not in _PRESET_FIELDS:
            raise InputError(
                f"{where}: {key}: not a sensor field (one of {', '.join(_PRESET_FIELDS)})"
            )
    from pydantic import ValidationError

    from quadimpact.errors import input_error_from_validation

    checks = {"magnetometer": Magnetometer, "pose_sensor": PoseSensor}
    for key, value in preset.items():  # each field checked now, so that a bad preset fails here
        try:
            if key == "imu":
                ImuSettings.model_validate({"preset": value} if isinstance(value, str) else value)
            elif key == "instruments":
                _instruments(value)
            elif value is not None:
                checks[key].model_validate(value)
        except ValidationError as exc:
            raise input_error_from_validation(exc, where, prefix=(key,)) from None
        except ValueError as exc:
            raise InputError(f"{where}: {key}: {exc}") from None
    SENSOR_PRESETS[name] = dict(preset)


def sensor_preset_names() -> tuple[str, ...]:
    """Every preset's name: the built-in ones, then the registered ones."""
    return tuple(SENSOR_PRESETS)


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
    impact_disturbance: ImpactDisturbance | None = None
    gyro_bias_walk_rad_s_sqrt_s: float = 0.0

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
    preset : {"ideal", "noisy", "impact", "authors-2016"}
        Starting values (:data:`IMU_PRESETS`); the fields below override them.
        ``"impact"``: the noisy IMU with the impact disturbance and a gyro
        bias random walk of 1e-4 rad/s/sqrt(s); ``"authors-2016"``: the
        authors' estimator study (the noisy IMU's noise, biases of 0.1 m/s^2
        and 0.01 rad/s, no saturation, the impact disturbance replacing the
        nominal noise).
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
    impact_disturbance : ImpactDisturbance or bool or None
        Extra noise after each contact onset (:class:`ImpactDisturbance`);
        ``True``: with the authors' values; ``False``: none; ``None``: the preset's.
    gyro_bias_walk_rad_s_sqrt_s : float or None
        Standard deviation of the gyro bias random walk, rad/s per sqrt(s)
        (e.g. 1e-4); ``None``: the preset's (0 but for ``"impact"``).
    """

    model_config = MODEL_CONFIG

    preset: Literal["ideal", "noisy", "impact", "authors-2016"] = Field(
        "ideal", description="Starting values."
    )
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
    impact_disturbance: ImpactDisturbance | StrictBool | None = Field(
        None, description="Noise after each contact onset: a table, true (defaults), false."
    )
    gyro_bias_walk_rad_s_sqrt_s: Real | None = Field(
        None, ge=0, description="Gyro bias random walk, rad/s/sqrt(s)."
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
        extras = IMU_EXTRAS[self.preset]
        disturbance = extras["impact_disturbance"]
        if self.impact_disturbance is not None:
            disturbance = self.impact_disturbance
        if disturbance is True:
            disturbance = ImpactDisturbance()
        elif disturbance is False:
            disturbance = None
        elif isinstance(disturbance, dict):
            disturbance = ImpactDisturbance(**disturbance)
        walk = self.gyro_bias_walk_rad_s_sqrt_s
        return ResolvedImu(
            rate_hz=float(self.rate_hz) if self.rate_hz is not None else float(control_rate_hz),
            position_m=position,
            filter=self.filter,
            filter_time_constant_s=self.filter_time_constant_s,
            filter_window=self.filter_window,
            impact_disturbance=disturbance,
            gyro_bias_walk_rad_s_sqrt_s=float(
                extras["gyro_bias_walk_rad_s_sqrt_s"] if walk is None else walk
            ),
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


def _instruments(value: Any) -> dict[str, Any]:
    """A scenario's ``instruments``: component name -> its settings, validated by its model.

    Each value is a table of the component's settings (``{}``: its defaults)
    or ``true`` (the defaults too); ``false`` or an absent name: none.
    """
    from pydantic import ValidationError

    from quadimpact.core.sensors.registry import component, components
    from quadimpact.errors import format_value, input_error_from_validation

    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise ValueError(
            "must be a table of sensor name = settings table ([instruments.barometer])"
        )
    out: dict[str, Any] = {}
    for name, table in value.items():
        try:
            comp = component(str(name))
        except KeyError:
            known = ", ".join(repr(c.name) for c in components() if not c.scenario_key)
            raise ValueError(f"{name}: no such sensor component (registered: {known})") from None
        if comp.scenario_key:
            raise ValueError(
                f"{name}: set it as the scenario's [{comp.scenario_key}] table, not in instruments"
            )
        if table is False:
            continue
        if table is True:
            table = {}
        if isinstance(table, comp.settings):
            out[comp.name] = table
            continue
        if hasattr(table, "model_dump"):
            table = table.model_dump()
        if not isinstance(table, Mapping):
            raise ValueError(
                f"{name}: must be a table of its settings or true (got {format_value(table)})"
            )
        try:
            out[comp.name] = comp.settings.model_validate(dict(table))
        except ValidationError as exc:
            raise ValueError(str(input_error_from_validation(exc, str(name)))) from None
    return out


Instruments = Annotated[dict[str, Any], BeforeValidator(_instruments)]
"""A scenario's sensor components by name (``core/sensors/registry.py``), validated."""
