"""The settings every scenario kind shares: :class:`RunSettings` and :class:`PowerOff`.

:class:`RunSettings` holds what a run is made of whatever its kind: the model
variant and its switches, the controller and its parameters, the vehicle and
its overrides, the rotors, the sensors and estimator, the surfaces' friction,
the ground, the output rate, the integrator's tolerances, the final time and
the seed. The scenario kinds (:mod:`quadimpact.inputs.scenarios`) add their
initial state. Frames and units as there (docs/MODEL.md section 1).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar, Literal

from pydantic import BaseModel, Field, StrictBool, field_validator, model_validator

from quadimpact.errors import InputError, near_miss
from quadimpact.inputs.controllers import (
    controller_entry,
    controller_names,
    validate_params,
)
from quadimpact.inputs.estimators import estimator_entry, estimator_names, validate_estimator_params
from quadimpact.inputs.model import (
    ModelName,
    ModelOptions,
    recovery_law_params,
    resolve_model_options,
)
from quadimpact.inputs.sensors import (
    SENSOR_PRESETS,
    DetectionSettings,
    ImuSettings,
    Instruments,
    Magnetometer,
    PoseSensor,
)
from quadimpact.inputs.types import MODEL_CONFIG, Real, Vec2, Vec4
from quadimpact.inputs.vehicle import Vehicle, load_vehicle
from quadimpact.inputs.world import Obstacles

__all__ = ["PowerOff", "RunSettings"]


# --------------------------------------------------------------- power-off
class PowerOff(BaseModel):
    """Motor power-off: from a trigger, each motor's speed follows a schedule.

    Over segment k, from ``trigger + segment_start_s[k]`` to the next start,
    motor j changes at ``rates_rpm_per_s[k][j]`` (rpm/s, motors 1-4) and never
    goes below zero, whatever the controller commands (the paper's
    experiments: the motors' safety power-off after impact). A rate of
    exactly 0 (or -0) is the motor switched off over that segment: its speed is
    0 from the segment's start (the crash data's convention: the log reads its
    powered-off marker next), unless ``zero_rate = "hold"``.

    Attributes
    ----------
    trigger : "first-contact" or float
        When the schedule starts: the first contact with an obstacle (the
        default), or a time in s.
    segment_start_s : tuple of float
        Segment starts after the trigger, s; the first is 0, increasing.
    rates_rpm_per_s : tuple of 4-tuples
        Per segment, the rate of change of motors 1-4, rpm/s.
    stopped_motors : tuple of int
        Motors (1-4) that stall at the trigger: their speed drops to zero at
        once (as a zero rate in the first segment does).
    zero_rate : {"off", "hold"}
        What a rate of exactly 0 means: ``"off"`` (default), the motor is
        switched off (speed 0 from the segment's start); ``"hold"``, it keeps
        its speed over the segment.
    """

    model_config = MODEL_CONFIG

    trigger: Literal["first-contact"] | Real = Field(
        "first-contact", description="'first-contact' or a start time in s."
    )
    segment_start_s: tuple[Real, ...] = Field(
        min_length=1, description="Segment starts after the trigger, s (first 0, increasing)."
    )
    rates_rpm_per_s: tuple[Vec4, ...] = Field(
        min_length=1, description="Per segment, the rates of motors 1-4, rpm/s."
    )
    stopped_motors: tuple[int, ...] = Field(
        (), description="Motors (1-4) that stall at the trigger: speed 0 at once."
    )
    zero_rate: Literal["off", "hold"] = Field(
        "off", description="A rate of exactly 0: the motor switched off ('off'), or held."
    )

    @model_validator(mode="after")
    def _consistent(self) -> PowerOff:
        starts = self.segment_start_s
        if starts[0] != 0.0:
            raise ValueError("segment_start_s: the first segment must start at 0")
        if any(b <= a for a, b in zip(starts, starts[1:], strict=False)):
            raise ValueError("segment_start_s: must be strictly increasing")
        if len(self.rates_rpm_per_s) != len(starts):
            raise ValueError(
                f"rates_rpm_per_s: must have one row per segment ({len(starts)}) "
                f"(got {len(self.rates_rpm_per_s)})"
            )
        if any(m not in (1, 2, 3, 4) for m in self.stopped_motors) or len(
            set(self.stopped_motors)
        ) != len(self.stopped_motors):
            raise ValueError("stopped_motors: distinct motor numbers 1-4")
        if not isinstance(self.trigger, str) and self.trigger < 0:
            raise ValueError(f"trigger: a time must be >= 0 s (got {self.trigger:g})")
        return self


# ---------------------------------------------------------------- settings
SensorPreset = str
"""A name of :data:`~quadimpact.inputs.sensors.SENSOR_PRESETS`: a built-in preset
("ideal", "noisy", "impact", "indoor", "onboard", "authors-2016") or a registered one
(:func:`~quadimpact.inputs.sensors.register_sensor_preset`)."""


class RunSettings(BaseModel):
    """Settings common to every scenario: model, controller, vehicle, rotors, integrator.

    The defaults reproduce the paper's set-up with the physically consistent
    model: the ``paper`` controller, the Spiri, ideal rotors without limits,
    no friction, a crash when the CM reaches the ground, 3 s of simulation.

    Attributes
    ----------
    model : {"default", "paper-replica", "recovery-replica", "pole-replica"}
        Model variant (see :class:`ModelOptions`, docs/VARIANTS.md).
    model_options : ModelOptions
        Single switches overriding the variant; ``None`` fields keep it.
    controller : str
        A registered controller (``quadimpact.inputs.controllers``):
        ``"paper"``, the authors' discrete PID as they ran it (docs/MODEL.md
        6.1); ``"cascade-pid"``, the same structure with proper integrals,
        anti-windup and speed limits (6.2); ``"recovery"``, a pre-impact
        behaviour then the staged recovery law after detection
        (docs/RECOVERY.md 3); or one registered by the user.
    controller_params : dict
        The controller's own parameters (validated by its registry entry); for
        the ``recovery`` controller, those not given take the values of the
        model's ``recovery_law`` switch (the pole replica's tuning), else their
        defaults.
    pre_impact : {"nominal", "hold", "spin-down", "immediate"} or None
        The ``recovery`` controller's behaviour before detection; ``None``: the
        kind's default (``"nominal"``; ``"spin-down"`` for impact trials).
    nominal_controller : {"paper", "cascade-pid"}
        The nominal controller of ``pre_impact = "nominal"``.
    vehicle : str
        Bundled vehicle name (``"spiri"``) or the path of a vehicle TOML file.
    vehicle_overrides : dict
        Vehicle field -> value applied to the vehicle for this run (revalidated).
    rotor_mode : {"ideal", "first-order"}
        ``"ideal"``: commanded speeds applied at once (the paper);
        ``"first-order"``: ``dOmega/dt = (Omega_cmd - Omega) / tau_m``.
    rotor_speed_limits_rpm : tuple of 2 floats or None
        Command limits [min, max], rpm; ``None``: none (the paper).
    rotor_slew_limit_rad_s2 : float or "vehicle" or None
        Largest rate of change of the command, rad/s^2; ``"vehicle"``: the
        vehicle file's ``rotor_slew_limit_rpm_per_s`` (none if it has none);
        ``None``: none.
    friction_coefficient : float
        Coulomb friction coefficient mu at the bumpers (regularised), >= 0;
        0 is the paper (frictionless).
    ground : {"crash", "contact", "none"}
        ``"crash"``: the run ends when the vehicle reaches the ground (per the
        crash rule); ``"contact"``: the ground is a contact surface instead;
        ``"none"``: no ground at all (the vehicle may fall through altitude 0).
    output_rate_hz : float
        Sampling rate of the output time series, Hz.
    rtol, atol : float or None
        Integrator tolerances (Dormand-Prince 5(4)); ``None``: the kernel's defaults.
    final_time_s : float
        End of the simulation, s.
    power_off : PowerOff or None
        Motor power-off schedule (the paper's experiments); ``None``: none.
    imu : ImuSettings
        The on-board IMU (``"ideal"``, ``"noisy"`` or a table).
    detection : DetectionSettings
        The impact detector working on the IMU samples.
    seed : int
        Seed of the run's random draws (IMU noise and bias), >= 0.
    obstacles : tuple of Plane, Cylinder, Box
        The world's obstacles (docs/OBSTACLES.md), names unique; the wall
        approach and the impact trial keep their wall plane when empty.
    magnetometer : Magnetometer or None
        A magnetometer sampled with the IMU (docs/ESTIMATION.md); ``None``: none.
    pose_sensor : PoseSensor or None
        A pose sensor (motion capture, vision); ``None``: none.
    instruments : dict
        Sensor components (``core/sensors/registry.py``: the barometer, and
        any plug-in registered) by name, each with its validated settings;
        empty by default.
    sensors : str or None
        A preset of sensors (:data:`~quadimpact.inputs.sensors.SENSOR_PRESETS`:
        "ideal", "noisy", "impact", "indoor", "onboard", "authors-2016" or a
        registered one): it sets ``imu``, ``magnetometer``, ``pose_sensor`` and
        ``instruments`` where the scenario does not set them itself.
    estimator : str
        A registered state estimator (``quadimpact.inputs.estimators``):
        ``"ideal"`` (the true state; the default), ``"complementary"``,
        ``"ekf"``, or one registered by the user.
    estimator_params : dict
        The estimator's own parameters (validated by its registry entry).
    """

    model_config = MODEL_CONFIG

    model: ModelName = Field(
        "default",
        description="Model variant: 'default' (physical), 'paper-replica', 'recovery-replica' "
        "or 'pole-replica'.",
    )
    model_options: ModelOptions = Field(
        default_factory=ModelOptions, description="Switches overriding the model variant."
    )
    controller: str = Field(
        "paper", description="Controller: 'paper', 'cascade-pid', 'recovery' or a registered one."
    )
    controller_params: dict[str, Any] = Field(
        default_factory=dict, description="The controller's own parameters."
    )
    pre_impact: Literal["nominal", "hold", "spin-down", "immediate"] | None = Field(
        None, description="Recovery controller before detection; None: the kind's default."
    )
    nominal_controller: Literal["paper", "cascade-pid"] = Field(
        "paper", description="Nominal controller of pre_impact = 'nominal'."
    )
    vehicle: str = Field(
        "spiri", min_length=1, description="Bundled vehicle name or path to a vehicle TOML file."
    )
    vehicle_overrides: dict[str, Any] = Field(
        default_factory=dict, description="Vehicle field -> value for this run."
    )
    rotor_mode: Literal["ideal", "first-order"] = Field(
        "ideal", description="Rotor response: 'ideal' (instant) or 'first-order' lag."
    )
    rotor_speed_limits_rpm: Vec2 | None = Field(
        None, description="Rotor speed command limits [min, max], rpm; None: unlimited."
    )
    rotor_slew_limit_rad_s2: Real | Literal["vehicle"] | None = Field(
        None,
        description="Rotor speed command slew limit, rad/s^2; 'vehicle': the vehicle's; "
        "None: unlimited.",
    )
    friction_coefficient: Real = Field(
        0.0, ge=0, description="Coulomb friction coefficient at the bumpers (0: the paper)."
    )
    ground: Literal["crash", "contact", "none"] = Field(
        "crash", description="Ground: ends the run ('crash'), a contact surface, or 'none'."
    )
    output_rate_hz: Real = Field(
        1000.0, gt=0, le=100000, description="Output time-series sampling rate, Hz."
    )
    control_rate_hz: Real | None = Field(
        None,
        ge=10,
        le=10000,
        description="Rate of the control ticks (the controller's steps), Hz; None: 200 Hz.",
    )
    rtol: Real | None = Field(
        None, gt=0, lt=0.1, description="Integrator relative tolerance; None: kernel default."
    )
    atol: Real | None = Field(
        None, gt=0, description="Integrator absolute tolerance; None: kernel default."
    )
    final_time_s: Real = Field(
        3.0, ge=0.005, le=600, description="End of the simulation, s (at least one control period)."
    )
    power_off: PowerOff | None = Field(
        None, description="Motor power-off schedule after a trigger (the experiments)."
    )
    imu: ImuSettings = Field(default_factory=ImuSettings, description="The on-board IMU.")
    detection: DetectionSettings = Field(
        default_factory=DetectionSettings, description="The impact detector."
    )
    seed: int = Field(0, ge=0, lt=2**63, description="Seed of the run's random draws.")
    obstacles: Obstacles = Field(
        (),
        description="Obstacles ([[obstacles]]: kind = 'plane', 'cylinder' or 'box'); the wall "
        "approach and the impact trial keep their wall when none is given.",
    )

    @field_validator("obstacles")
    @classmethod
    def _unique_obstacles(cls, value: tuple) -> tuple:
        names = [o.name for o in value]
        for name in names:
            if names.count(name) > 1:
                raise ValueError(f"obstacle names must be unique ({name!r} repeats)")
        return value

    @model_validator(mode="after")
    def _ground_name_free(self) -> RunSettings:
        names = [o.name for o in self.obstacles] + [p.name for p in getattr(self, "surfaces", ())]
        for name in names:
            if names.count(name) > 1:
                raise ValueError(
                    f"obstacles: names must differ from the surfaces' ({name!r} repeats)"
                )
        if self.ground == "contact" and "ground" in names:
            raise ValueError(
                "obstacles: 'ground' is the name of the ground of ground = 'contact'; "
                "name the obstacle otherwise, or use ground = 'none'"
            )
        return self

    magnetometer: Magnetometer | None = Field(None, description="A magnetometer (None: none).")
    pose_sensor: PoseSensor | None = Field(None, description="A pose sensor (None: none).")
    instruments: Instruments = Field(
        default_factory=dict,
        description="Sensor components by name, each with its settings table "
        "([instruments.barometer]); none by default.",
    )
    sensors: SensorPreset | None = Field(
        None,
        description="A preset of sensors (fills imu, magnetometer, pose_sensor and "
        "instruments where not set).",
    )
    estimator: str = Field(
        "ideal", description="State estimator: 'ideal', 'complementary', 'ekf' or a registered one."
    )
    estimator_params: dict[str, Any] = Field(
        default_factory=dict, description="The estimator's own parameters."
    )
    estimate_in_loop: StrictBool = Field(
        True,
        description="The controller and the detector read the estimate; false: the "
        "estimator is an observer (computed and scored, the loop reads the true state).",
    )
    end_after_recovery_s: Real | None = Field(
        None, gt=0, description="End the run this long after the entry into stage 4, s."
    )

    @model_validator(mode="before")
    @classmethod
    def _sensor_preset(cls, value: Any) -> Any:
        # the preset fills the sensor fields the scenario does not set itself
        if isinstance(value, Mapping) and isinstance(value.get("sensors"), str):
            preset = SENSOR_PRESETS.get(value["sensors"])
            if preset is not None:
                value = {**{k: v for k, v in preset.items() if k not in value}, **value}
        return value

    @field_validator("sensors", mode="before")
    @classmethod
    def _known_preset(cls, value: Any) -> Any:
        if value is not None and (not isinstance(value, str) or value not in SENSOR_PRESETS):
            known = ", ".join(repr(k) for k in SENSOR_PRESETS)
            raise ValueError(f"unknown preset of sensors {value!r} (one of {known})")
        return value

    @field_validator("estimator")
    @classmethod
    def _registered_estimator(cls, value: str) -> str:
        if value not in estimator_names():
            try:
                estimator_entry(value)
            except InputError as exc:
                raise ValueError(str(exc).removeprefix("estimator: ")) from None
        return value

    @model_validator(mode="after")
    def _estimator_params(self) -> RunSettings:
        validate_estimator_params(self.estimator, self.estimator_params)
        return self

    def resolved_estimator_params(self) -> BaseModel:
        """The estimator's parameters, validated, with its defaults filled in."""
        return validate_estimator_params(self.estimator, self.estimator_params)

    @field_validator("seed", mode="before")
    @classmethod
    def _integer_seed(cls, value: Any) -> Any:
        if isinstance(value, bool) or (isinstance(value, float) and not value.is_integer()):
            raise ValueError("must be an integer")
        if isinstance(value, float):
            return int(value)
        return value

    @field_validator("controller")
    @classmethod
    def _registered_controller(cls, value: str) -> str:
        if value not in controller_names():
            try:
                controller_entry(value)
            except InputError as exc:  # the rule without the field name (pydantic adds it)
                raise ValueError(str(exc).removeprefix("controller: ")) from None
        return value

    @model_validator(mode="after")
    def _controller_params(self) -> RunSettings:
        # unknown keys and bad values of the controller's parameters, reported now
        validate_params(self.controller, self.controller_params)
        return self

    def resolved_controller_params(self) -> BaseModel:
        """The controller's parameters, validated, with its defaults filled in.

        For the ``recovery`` controller the parameters not given take the values
        of the model's ``recovery_law`` switch first (``RECOVERY_LAWS``).
        """
        if self.controller == "recovery":
            law = self.resolved_model_options().recovery_law
            assert law is not None  # resolved: every switch set
            return validate_params(
                self.controller, recovery_law_params(law, self.controller_params)
            )
        return validate_params(self.controller, self.controller_params)

    def resolved_pre_impact(self) -> str:
        """The recovery controller's pre-impact behaviour in force (model switch included)."""
        forced = self.resolved_model_options().pre_impact
        if forced != "scenario":
            assert forced is not None  # resolved: every switch set
            return forced
        if self.pre_impact is not None:
            return self.pre_impact
        return self._default_pre_impact

    _default_pre_impact: ClassVar[str] = "nominal"

    @field_validator("rotor_slew_limit_rad_s2")
    @classmethod
    def _positive_slew(cls, value: Any) -> Any:
        if isinstance(value, float) and not value > 0:
            raise ValueError(f"must be > 0 (got {value:g})")
        return value

    @field_validator("vehicle_overrides")
    @classmethod
    def _known_vehicle_fields(cls, value: dict[str, Any]) -> dict[str, Any]:
        for key in value:
            if key not in Vehicle.model_fields:
                close = near_miss(str(key), list(Vehicle.model_fields))
                hint = f"; did you mean {close!r}?" if close else ""
                raise ValueError(f"unknown vehicle field {key!r}{hint}")
        return value

    @field_validator("rotor_speed_limits_rpm")
    @classmethod
    def _check_limits(cls, value: tuple[float, float] | None) -> tuple[float, float] | None:
        if value is not None:
            if value[0] < 0:
                raise ValueError("minimum must be >= 0")
            if not value[0] < value[1]:
                raise ValueError("must be [min, max] with min < max")
        return value

    def resolved_model_options(self) -> ModelOptions:
        """Every model switch for this run: the variant's, with ``model_options`` applied.

        Returns
        -------
        ModelOptions
            No field is ``None``.
        """
        return resolve_model_options(self.model, self.model_options)

    def build_vehicle(self, where: str | None = None) -> Vehicle:
        """Load ``vehicle`` and apply ``vehicle_overrides``.

        Parameters
        ----------
        where : str, optional
            Start of override error messages (e.g. the scenario file name);
            by default ``"vehicle <name> overrides"``.

        Returns
        -------
        Vehicle
            The validated vehicle for this run.

        Raises
        ------
        InputError
            Bad vehicle name or file, or an override that breaks a rule.
        """
        vehicle = load_vehicle(self.vehicle)
        if where is None:
            return vehicle.with_overrides(**self.vehicle_overrides)
        return vehicle.apply_overrides(
            dict(self.vehicle_overrides), where=where, prefix=("vehicle_overrides",)
        )


def check_before_final(model: RunSettings, field: str) -> None:
    """Refuse a time ``field`` (s) of a scenario that is not before its ``final_time_s``."""
    value = getattr(model, field)
    if not value < model.final_time_s:
        raise ValueError(
            f"{field}: must be < final_time_s ({model.final_time_s:g}) (got {value:g})"
        )


def check_euler(value: tuple[float, float, float] | None) -> tuple[float, float, float] | None:
    """Refuse ZYX Euler angles (deg: roll, pitch, yaw) outside their ranges; None passes."""
    if value is None:
        return value
    roll, pitch, yaw = value
    if not -180.0 <= roll <= 180.0:
        raise ValueError("roll (first entry) must be in [-180, 180] deg")
    if not -90.0 < pitch < 90.0:
        raise ValueError("pitch (second entry) must be in (-90, 90) deg")
    if not -180.0 <= yaw <= 180.0:
        raise ValueError("yaw (third entry) must be in [-180, 180] deg")
    return value
