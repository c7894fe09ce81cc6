"""Validated, immutable scenarios and scenario files.

Frames and units follow docs/MODEL.md section 1: inertial frame NED (X toward the
default wall, Y right, Z down; altitude ``h = -Z``), body frame FRD, SI units,
angles in degrees where a field name says ``_deg``.

Three scenario kinds exist:

- :class:`WallApproach`: the paper's experiment (docs/STUDIES.md section 1):
  the vehicle holds an attitude and altitude and reaches a vertical wall at
  ``X = wall_distance_m`` at ``impact_time_s`` with speed ``speed_m_s``.
- :class:`FlightScenario`: a general initial state set by the user, with any
  number of contact planes (:class:`Plane`).
- :class:`ImpactTrial`: the recovery benchmark (docs/RECOVERY.md section 5):
  the vehicle starts 0.32 m from the wall ``X = 0`` at a given attitude and
  speed, its rotors spinning down, and must detect the impact and recover.

All share :class:`RunSettings` (model variant, controller, vehicle, rotor
mode, sensors, integrator settings). A scenario can be written as a TOML file
and read with :func:`load_scenario_file`::

    kind = "wall-approach"        # or "flight", "impact-trial"; default "wall-approach"
    heading_deg = 45
    inclination_deg = 15
    speed_m_s = 0.75
    model = "paper-replica"

    [model_options]               # override single switches of the variant
    crash_rule = "cm-ground"

    [vehicle_overrides]           # change vehicle fields for this run
    restitution = 0.5

    [controller_params]           # the controller's own parameters
    attitude_pid = [7.2, 4.0, 4.2]

    [imu]                         # on-board IMU and impact detector (docs/RECOVERY.md)
    preset = "noisy"

    [[surfaces]]                  # flight scenarios only
    name = "wall"
    point_m = [1.5, 0.0, 0.0]
    normal = [-1.0, 0.0, 0.0]

    [[obstacles]]                 # any scenario kind: planes, cylinders, boxes
    kind = "cylinder"
    name = "pole"
    point_m = [0.0, 0.0, 0.0]
    axis = [0.0, 0.0, 1.0]
    radius_m = 0.1
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar, Literal

from pydantic import BaseModel, Field, ValidationError, field_validator, model_validator

from quadimpact.errors import InputError, format_value, input_error_from_validation, near_miss
from quadimpact.inputs.controllers import (
    controller_entry,
    controller_names,
    validate_params,
)
from quadimpact.inputs.estimators import estimator_entry, estimator_names, validate_estimator_params
from quadimpact.inputs.files import locate_vehicle, read_toml_file
from quadimpact.inputs.model import ModelName, ModelOptions, resolve_model_options
from quadimpact.inputs.sensors import (
    SENSOR_PRESETS,
    DetectionSettings,
    ImuSettings,
    Magnetometer,
    PoseSensor,
)
from quadimpact.inputs.types import MODEL_CONFIG, Real, Vec2, Vec3, Vec4
from quadimpact.inputs.vehicle import Vehicle, load_vehicle
from quadimpact.inputs.world import Obstacles, Plane

__all__ = [
    "PowerOff",
    "RunSettings",
    "WallApproach",
    "FlightScenario",
    "ImpactTrial",
    "Scenario",
    "load_scenario_file",
    "scenario_from_dict",
]


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
class RunSettings(BaseModel):
    """Settings common to every scenario: model, controller, vehicle, rotors, integrator.

    The defaults reproduce the paper's set-up with the physically consistent
    model: the ``paper`` controller, the Spiri, ideal rotors without limits,
    no friction, a crash when the CM reaches the ground, 3 s of simulation.

    Attributes
    ----------
    model : {"default", "paper-replica", "recovery-replica"}
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
        The controller's own parameters (validated by its registry entry).
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
    sensors : {"ideal", "noisy", "impact", "indoor"} or None
        A preset of sensors (:data:`~quadimpact.inputs.sensors.SENSOR_PRESETS`):
        it sets ``imu``, ``magnetometer`` and ``pose_sensor`` where the scenario
        does not set them itself.
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
        description="Model variant: 'default' (physical), 'paper-replica' or 'recovery-replica'.",
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
    sensors: Literal["ideal", "noisy", "impact", "indoor"] | None = Field(
        None, description="A preset of sensors (imu, magnetometer, pose_sensor not set)."
    )
    estimator: str = Field(
        "ideal", description="State estimator: 'ideal', 'complementary', 'ekf' or a registered one."
    )
    estimator_params: dict[str, Any] = Field(
        default_factory=dict, description="The estimator's own parameters."
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
        """The controller's parameters, validated, with its defaults filled in."""
        return validate_params(self.controller, self.controller_params)

    def resolved_pre_impact(self) -> str:
        """The recovery controller's pre-impact behaviour in force (model switch included)."""
        if self.resolved_model_options().pre_impact == "spin-down":
            return "spin-down"
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


def _check_before_final(model: RunSettings, field: str) -> None:
    value = getattr(model, field)
    if not value < model.final_time_s:
        raise ValueError(
            f"{field}: must be < final_time_s ({model.final_time_s:g}) (got {value:g})"
        )


def _check_euler(value: tuple[float, float, float] | None) -> tuple[float, float, float] | None:
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


# --------------------------------------------------------------- scenarios
class WallApproach(RunSettings):
    """The paper's wall approach (docs/STUDIES.md section 1).

    The vehicle holds a fixed attitude (yaw = heading, tilted by the
    inclination toward the wall) and an altitude set-point, and is started so
    that its first bumper touches the wall ``X = wall_distance_m`` (normal
    ``-X``) exactly at ``impact_time_s`` with CM velocity ``V_X = speed_m_s``.
    The defaults (plus heading 45, inclination 15) give the paper's example.

    Attributes
    ----------
    kind : "wall-approach"
        Scenario kind tag (as in scenario files).
    heading_deg : float
        Yaw of the vehicle relative to the wall normal, deg in [-360, 360]
        (any turn; sweeps may cross +-180); 0: body x axis pointing at the wall
        (bumpers 1 and 4 lead), 180: flying in rear first (bumpers 2 and 3 lead).
    inclination_deg : float
        Tilt of the body z axis from the inertial Z axis within the X-Z plane,
        deg in [-60, 60], positive toward the wall.
    speed_m_s : float
        CM speed toward the wall (inertial X) at the first contact, m/s, in (0, 20].
    impact_time_s : float
        Time of the first contact, s; > 0 and < ``final_time_s``.
    wall_distance_m : float
        Position of the wall along inertial X, m.
    altitude_m : float
        Altitude set-point (and initial altitude unless ``start_altitude_m``),
        ``h = -Z``, m, > 0.
    roll_deg, pitch_deg : float or None
        An explicit attitude instead of the inclination (both or neither):
        ZYX roll and pitch, deg, with yaw = ``heading_deg``; the body z axis
        may then leave the X-Z plane (the experiments' measured attitudes).
        ``inclination_deg`` is ignored and reported as reached.
    start_altitude_m : float or None
        Initial altitude, m, when it differs from the set-point (>= 0; 0: the
        CM on the ground plane, which the crash rules test only after the
        start). With it, an explicit attitude and ``impact_time_s`` this is
        the authors' approach of their crash runs: the controller holds the
        attitude and climbs toward the set-point, so the vehicle reaches the
        wall climbing and drifting sideways, at ``speed_m_s`` toward it.
    """

    kind: Literal["wall-approach"] = Field("wall-approach", description="Scenario kind tag.")
    heading_deg: Real = Field(
        0.0, ge=-360, le=360, description="Yaw relative to the wall normal, deg."
    )
    inclination_deg: Real = Field(
        0.0, ge=-60, le=60, description="Tilt toward the wall in the inertial X-Z plane, deg."
    )
    speed_m_s: Real = Field(
        0.75, gt=0, le=20, description="CM speed toward the wall at first contact, m/s."
    )
    impact_time_s: Real = Field(
        0.5, ge=0.005, description="Time of the first contact, s (at least one control period)."
    )
    wall_distance_m: Real = Field(1.5, description="Wall position along inertial X (NED), m.")
    altitude_m: Real = Field(2.0, gt=0, description="Altitude set-point and initial altitude, m.")
    roll_deg: Real | None = Field(
        None, ge=-60, le=60, description="Explicit roll (with pitch_deg), deg."
    )
    pitch_deg: Real | None = Field(
        None, ge=-60, le=60, description="Explicit pitch (with roll_deg), deg."
    )
    start_altitude_m: Real | None = Field(
        None, ge=0, description="Initial altitude if not the set-point, m (>= 0)."
    )

    @model_validator(mode="after")
    def _impact_before_end(self) -> WallApproach:
        _check_before_final(self, "impact_time_s")
        if (self.roll_deg is None) != (self.pitch_deg is None):
            raise ValueError("roll_deg, pitch_deg: give both or neither")
        return self


class FlightScenario(RunSettings):
    """A general flight from a user-set initial state, among contact planes.

    Attributes
    ----------
    kind : "flight"
        Scenario kind tag (as in scenario files).
    position_m : tuple of 3 floats
        Initial CM position, inertial NED, m; Z < 0 (above the ground).
    velocity_m_s : tuple of 3 floats
        Initial CM velocity, inertial NED components, m/s.
    euler_deg : tuple of 3 floats
        Initial attitude [roll, pitch, yaw], ZYX Euler angles, deg.
    angular_velocity_rad_s : tuple of 3 floats
        Initial angular velocity [p, q, r], body FRD, rad/s.
    rotor_speeds_rad_s : tuple of 4 floats or None
        Initial rotor speeds, rad/s; ``None``: trimmed for the attitude.
    altitude_ref_m : float or None
        Altitude set-point, m; ``None``: the initial altitude.
    attitude_ref_deg : tuple of 3 floats or None
        Attitude set-point [roll, pitch, yaw], ZYX, deg; ``None``: the initial attitude.
    surfaces : tuple of Plane
        Contact planes (walls, ceilings...); names must be unique.
    start_time_s : float
        Initial time, s, >= 0 and < ``final_time_s``.
    """

    kind: Literal["flight"] = Field("flight", description="Scenario kind tag.")
    position_m: Vec3 = Field(
        (0.0, 0.0, -2.0), description="Initial CM position, inertial NED, m (Z < 0: airborne)."
    )
    velocity_m_s: Vec3 = Field(
        (0.0, 0.0, 0.0), description="Initial CM velocity, inertial NED components, m/s."
    )
    euler_deg: Vec3 = Field(
        (0.0, 0.0, 0.0), description="Initial [roll, pitch, yaw], ZYX Euler, deg."
    )
    angular_velocity_rad_s: Vec3 = Field(
        (0.0, 0.0, 0.0), description="Initial body angular velocity [p, q, r], FRD, rad/s."
    )
    rotor_speeds_rad_s: Vec4 | None = Field(
        None, description="Initial rotor speeds, rad/s; None: trimmed."
    )
    altitude_ref_m: Real | None = Field(
        None, gt=0, description="Altitude set-point, m; None: initial altitude."
    )
    attitude_ref_deg: Vec3 | None = Field(
        None, description="Attitude set-point [roll, pitch, yaw], ZYX, deg; None: initial."
    )
    surfaces: tuple[Plane, ...] = Field((), description="Contact planes.")
    start_time_s: Real = Field(0.0, ge=0, description="Initial time, s.")

    @field_validator("position_m")
    @classmethod
    def _airborne(cls, value: tuple[float, float, float]) -> tuple[float, float, float]:
        if not value[2] < 0:
            raise ValueError("must start above the ground: Z (third entry, NED, down) must be < 0")
        return value

    @field_validator("euler_deg", "attitude_ref_deg")
    @classmethod
    def _euler_ranges(cls, value: tuple[float, float, float] | None):
        return _check_euler(value)

    @field_validator("rotor_speeds_rad_s")
    @classmethod
    def _non_negative_speeds(cls, value: tuple[float, ...] | None) -> tuple[float, ...] | None:
        if value is not None and min(value) < 0:
            raise ValueError("rotor speeds must be >= 0")
        return value

    @field_validator("surfaces")
    @classmethod
    def _unique_names(cls, value: tuple[Plane, ...]) -> tuple[Plane, ...]:
        names = [plane.name for plane in value]
        for name in names:
            if names.count(name) > 1:
                raise ValueError(f"surface names must be unique ({name!r} repeats)")
        return value

    @model_validator(mode="after")
    def _start_before_end(self) -> FlightScenario:
        _check_before_final(self, "start_time_s")
        return self


class ImpactTrial(RunSettings):
    """The impact trial of the recovery benchmark (docs/RECOVERY.md section 5).

    The wall is the plane ``X = 0`` (normal ``-X``); the CM starts at
    ``X = -start_distance_m`` at ``altitude_m``, with attitude ``roll_deg``,
    ``pitch_deg``, ``yaw_deg`` (ZYX; positive pitch tilts the thrust away from
    the wall, so the inclination toward the wall is about ``-pitch``),
    inertial velocity ``(speed_m_s, 0, 0)``, no rotation, and rotor speeds
    from the allocation of the collective thrust ``m g cos(roll) cos(pitch)``
    with zero torques. The vehicle's rotor range and slew limit are in force.
    By default: the Navi, the ``recovery`` controller spinning its rotors down
    until it detects the impact, friction 0.3, no ground, 3 s.

    Attributes
    ----------
    kind : "impact-trial"
        Scenario kind tag (as in scenario files).
    roll_deg, pitch_deg, yaw_deg : float
        Initial attitude, ZYX Euler angles, deg (the authors drew roll in
        +-15, pitch in +-45, yaw in +-45).
    speed_m_s : float
        Initial speed toward the wall (inertial X), m/s (the authors: 0.5-2.5).
    start_distance_m : float
        Distance of the CM from the wall at the start, m.
    altitude_m : float
        Initial altitude ``h = -Z``, m (also the nominal controller's set-point).
    lateral_offset_m : float
        Sideways start (+Y, m) from the obstacle's centre line (docs/OBSTACLES.md 2).

    With ``obstacles``, the trial flies toward the first one instead of the
    wall: the CM starts ``start_distance_m`` before the point where the
    line along +X through the obstacle's centre (a plane's point, a
    cylinder's axis point, a box's centre) leaves it toward -X, displaced by
    ``lateral_offset_m`` along +Y, at ``altitude_m``.
    """

    kind: Literal["impact-trial"] = Field("impact-trial", description="Scenario kind tag.")
    vehicle: str = Field(
        "navi", min_length=1, description="Bundled vehicle name or path to a vehicle TOML file."
    )
    controller: str = Field("recovery", description="Controller (default 'recovery').")
    friction_coefficient: Real = Field(
        0.3, ge=0, description="Coulomb friction coefficient at the bumpers."
    )
    ground: Literal["crash", "contact", "none"] = Field(
        "none", description="No ground by default (the trial starts 5 m up)."
    )
    rotor_slew_limit_rad_s2: Real | Literal["vehicle"] | None = Field(
        "vehicle", description="Rotor command slew limit, rad/s^2; default the vehicle's."
    )
    roll_deg: Real = Field(0.0, ge=-90, le=90, description="Initial roll, deg (ZYX).")
    pitch_deg: Real = Field(0.0, gt=-90, lt=90, description="Initial pitch, deg (ZYX).")
    yaw_deg: Real = Field(0.0, ge=-180, le=180, description="Initial yaw, deg (ZYX).")
    speed_m_s: Real = Field(1.5, gt=0, le=20, description="Initial speed toward the wall, m/s.")
    start_distance_m: Real = Field(
        0.32, gt=0, le=100, description="CM distance from the wall at the start, m."
    )
    altitude_m: Real = Field(5.0, gt=0, description="Initial altitude, m.")
    lateral_offset_m: Real = Field(
        0.0, ge=-100, le=100, description="Sideways start (+Y) from the obstacle's centre line, m."
    )

    _default_pre_impact: ClassVar[str] = "spin-down"


Scenario = WallApproach | FlightScenario | ImpactTrial
"""Any scenario accepted by ``simulate``."""

_KINDS: dict[str, type[WallApproach] | type[FlightScenario] | type[ImpactTrial]] = {
    "wall-approach": WallApproach,
    "flight": FlightScenario,
    "impact-trial": ImpactTrial,
}


# -------------------------------------------------------------------- files
def scenario_from_dict(data: Mapping[str, Any], where: str = "scenario") -> Scenario:
    """Validate a scenario given as a mapping (the content of a scenario file).

    Parameters
    ----------
    data : mapping
        Scenario fields; ``kind`` selects the class (default ``"wall-approach"``).
    where : str, optional
        Start of error messages.

    Returns
    -------
    WallApproach or FlightScenario or ImpactTrial
        The validated scenario.
    """
    kind = data.get("kind", "wall-approach")
    if not isinstance(kind, str) or kind not in _KINDS:
        known = ", ".join(repr(k) for k in _KINDS)
        raise InputError(f"{where}: kind: must be one of {known} (got {format_value(kind)})")
    cls = _KINDS[kind]
    try:
        return cls.model_validate(dict(data))
    except ValidationError as exc:
        raise input_error_from_validation(exc, where, model=cls) from None


def load_scenario_file(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file (format in this module's docstring).

    A relative ``vehicle`` path is looked up next to the scenario file first
    (:func:`~quadimpact.inputs.files.locate_vehicle`).
    The vehicle and its overrides are validated too, so that a bad vehicle
    is reported now, naming the file and field.

    Parameters
    ----------
    path : str or pathlib.Path
        The scenario file.

    Returns
    -------
    WallApproach or FlightScenario
        According to ``kind`` (default ``"wall-approach"``).

    Raises
    ------
    InputError
        Missing file, TOML syntax error (with line and column), unknown key,
        or a value that breaks a rule: ``<file>: <field>: <rule> (got <value>)``.
    """
    path = Path(path)
    data = locate_vehicle(read_toml_file(path), path.parent)
    scenario = scenario_from_dict(data, where=str(path))
    scenario.build_vehicle(where=str(path))
    return scenario
