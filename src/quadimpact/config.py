"""Validated, immutable run inputs: model options, scenarios and scenario files.

Frames and units follow MODEL.md section 1: inertial frame NED (X toward the
default wall, Y right, Z down; altitude ``h = -Z``), body frame FRD, SI units,
angles in degrees where a field name says ``_deg``.

Two scenario kinds exist:

- :class:`WallApproach`: the paper's experiment (STUDIES.md section 1): the
  vehicle holds an attitude and altitude and reaches a vertical wall at
  ``X = wall_distance_m`` at ``impact_time_s`` with speed ``speed_m_s``.
- :class:`FlightScenario`: a general initial state set by the user, with any
  number of contact planes (:class:`Plane`).

Both share :class:`RunSettings` (model variant, controller, vehicle, rotor
mode, integrator settings). A scenario can be written as a TOML file and
read with :func:`load_scenario_file`::

    kind = "wall-approach"        # or "flight"; default "wall-approach"
    heading_deg = 45
    inclination_deg = 15
    speed_m_s = 0.75
    model = "paper-replica"

    [model_options]               # override single switches of the variant
    crash_rule = "cm-ground"

    [vehicle_overrides]           # change vehicle fields for this run
    restitution = 0.5

    [[surfaces]]                  # flight scenarios only
    name = "wall"
    point_m = [1.5, 0.0, 0.0]
    normal = [-1.0, 0.0, 0.0]
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from quadimpact._types import Real, Vec2, Vec3, Vec4
from quadimpact.errors import InputError, input_error_from_validation
from quadimpact.vehicle import Vehicle, bundled_vehicles, load_vehicle

__all__ = [
    "ModelOptions",
    "MODEL_VARIANTS",
    "resolve_model_options",
    "Plane",
    "PowerOff",
    "RunSettings",
    "WallApproach",
    "FlightScenario",
    "Scenario",
    "load_scenario_file",
]

ModelName = Literal["default", "paper-replica"]

_CONFIG = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


# ----------------------------------------------------------------- options
class ModelOptions(BaseModel):
    """Switches between the physically consistent model and the authors' simulator.

    Each field left ``None`` takes the value of the chosen model variant
    (:data:`MODEL_VARIANTS`); set it to change that single behaviour. The
    ``default`` variant is the physically consistent model of MODEL.md
    sections 2-7; the ``paper-replica`` variant reproduces the code behind the
    paper's figures, errors included (MODEL.md section 8), so that published
    numbers can be checked and each correction's effect seen on its own.

    Attributes
    ----------
    yaw_reaction : {"physical", "paper"} or None
        Rotor yaw reaction on the body. ``"physical"`` (default): drag torque
        ``-s_j dt Omega_j^2`` and spin-up term ``-s_j Jr dOmega_j/dt``, the motor
        torque reacting on the body, consistent with the gyroscopic term.
        ``"paper"`` (replica): drag torque ``+s_j dt Omega_j^2`` and spin-up
        ``-Jr sum_j dOmega_j/dt`` (no ``s_j``); the controller's allocation yaw row
        follows the model in use.
    bumper1_yaw_twice : bool or None
        ``True`` (replica) counts bumper 1's contact yaw moment (body z
        component) twice, as the authors' code did; ``False`` (default) once.
    initial_rotor_speeds : {"trimmed", "level-hover"} or None
        ``"trimmed"`` (default): initial rotor speeds from the allocation of
        thrust ``m g / (cos(roll) cos(pitch))`` with zero torques.
        ``"level-hover"`` (replica): all four at ``sqrt(m g / (4 kt))`` whatever
        the tilt.
    attitude_mapping : {"exact", "paper-fit"} or None
        How a wall approach's heading and inclination become roll and pitch.
        ``"exact"`` (default): ZYX Euler angles with yaw = heading and the body
        z axis in the inertial X-Z plane at the inclination from Z.
        ``"paper-fit"`` (replica): the authors' fitted mapping, for heading 0
        roll 0 and pitch ``-inclination``; for heading +-45 deg
        ``roll = pitch = -(incl - 0.0042477) / 1.3836686`` (rad); other
        headings as ``"exact"``.
    crash_rule : {"cm-ground", "paper-ticks"} or None
        ``"cm-ground"`` (default): crash when the CM reaches altitude 0,
        located exactly as an integrator event. ``"paper-ticks"`` (replica):
        crash when the altitude is at or below -0.3 m, tested at the control
        ticks only.
    approach_start : {"late-start", "paper"} or None
        ``"late-start"`` (default): when the vehicle would have to start
        moving away from the wall (needed initial speed < 0), it starts at rest
        later, at the time that brings it to the wall at the requested time
        and speed. ``"paper"`` (replica): it starts at t = 0 even moving away
        from the wall, and later at rest only when the start point would lie
        beyond the wall. Control ticks run at ``t0 + k dt`` from the start.
    """

    model_config = _CONFIG

    yaw_reaction: Literal["physical", "paper"] | None = Field(
        None, description="Rotor yaw reaction torque: 'physical' or the authors' 'paper' signs."
    )
    bumper1_yaw_twice: bool | None = Field(
        None, description="Count bumper 1's contact yaw moment twice (authors' code)."
    )
    initial_rotor_speeds: Literal["trimmed", "level-hover"] | None = Field(
        None, description="Initial rotor speeds: trimmed for the tilt, or all at level hover."
    )
    attitude_mapping: Literal["exact", "paper-fit"] | None = Field(
        None, description="Heading/inclination -> roll/pitch: exact, or the authors' fit."
    )
    crash_rule: Literal["cm-ground", "paper-ticks"] | None = Field(
        None, description="Crash: CM at h = 0 (event), or h <= -0.3 m at control ticks."
    )
    approach_start: Literal["late-start", "paper"] | None = Field(
        None,
        description="Wall-approach start rule when v0 would be < 0: start later at rest, "
        "or the authors' rule.",
    )


MODEL_VARIANTS: dict[str, dict[str, Any]] = {
    "default": {
        "yaw_reaction": "physical",
        "bumper1_yaw_twice": False,
        "initial_rotor_speeds": "trimmed",
        "attitude_mapping": "exact",
        "crash_rule": "cm-ground",
        "approach_start": "late-start",
    },
    "paper-replica": {
        "yaw_reaction": "paper",
        "bumper1_yaw_twice": True,
        "initial_rotor_speeds": "level-hover",
        "attitude_mapping": "paper-fit",
        "crash_rule": "paper-ticks",
        "approach_start": "paper",
    },
}
"""Every switch of :class:`ModelOptions` for each named model variant."""


def resolve_model_options(
    model: str, overrides: ModelOptions | Mapping[str, Any] | None = None
) -> ModelOptions:
    """All model switches for a variant, with some of them overridden.

    Parameters
    ----------
    model : {"default", "paper-replica"}
        The model variant.
    overrides : ModelOptions or mapping or None, optional
        Switches to change; ``None`` values (or missing keys) keep the variant's.

    Returns
    -------
    ModelOptions
        Every field set (none is ``None``).

    Raises
    ------
    InputError
        Unknown variant, unknown switch or invalid value.
    """
    if model not in MODEL_VARIANTS:
        known = ", ".join(repr(name) for name in MODEL_VARIANTS)
        raise InputError(f"model: must be one of {known} (got {model!r})")
    values = dict(MODEL_VARIANTS[model])
    if overrides is not None:
        if not isinstance(overrides, ModelOptions):
            try:
                overrides = ModelOptions.model_validate(dict(overrides))
            except ValidationError as exc:
                raise input_error_from_validation(
                    exc, prefix=("model_options",), model=ModelOptions
                ) from None
        values.update(overrides.model_dump(exclude_none=True))
    return ModelOptions(**values)


# ---------------------------------------------------------------- surfaces
class Plane(BaseModel):
    """A flat contact surface (wall, floor, ceiling...) in the inertial NED frame.

    Attributes
    ----------
    name : str
        Label used in results (episodes' ``surface`` column); unique per scenario.
    point_m : tuple of 3 floats
        Any point of the plane, inertial NED, m.
    normal : tuple of 3 floats
        Normal pointing out of the obstacle into free space, inertial NED;
        any non-zero length, normalised on validation. The paper's wall at
        ``X = d`` is ``point_m = (d, 0, 0)``, ``normal = (-1, 0, 0)``; the ground
        is ``point_m = (0, 0, 0)``, ``normal = (0, 0, -1)``.
    """

    model_config = _CONFIG

    name: str = Field(min_length=1, description="Label of the surface in results.")
    point_m: Vec3 = Field(description="A point of the plane, inertial NED, m.")
    normal: Vec3 = Field(
        description="Unit normal out of the obstacle into free space, inertial NED "
        "(normalised on validation)."
    )

    @field_validator("normal")
    @classmethod
    def _normalise(cls, value: tuple[float, float, float]) -> tuple[float, float, float]:
        norm = math.sqrt(sum(c * c for c in value))
        if norm < 1e-12:
            raise ValueError("must be a non-zero vector")
        return (value[0] / norm, value[1] / norm, value[2] / norm)


# --------------------------------------------------------------- power-off
class PowerOff(BaseModel):
    """Motor power-off: from a trigger, each motor's speed follows a schedule.

    Over segment k, from ``trigger + segment_start_s[k]`` to the next start,
    motor j changes at ``rates_rpm_per_s[k][j]`` (rpm/s, motors 1-4) and never
    goes below zero, whatever the controller commands (the paper's
    experiments: the motors' safety power-off after impact).

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
        once (the logs show them stopped with no measurable ramp).
    """

    model_config = _CONFIG

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
    model : {"default", "paper-replica"}
        Model variant (see :class:`ModelOptions`).
    model_options : ModelOptions
        Single switches overriding the variant; ``None`` fields keep it.
    controller : {"paper", "cascade-pid"}
        ``"paper"``: the authors' discrete PID as they ran it (MODEL.md 6.1);
        ``"cascade-pid"``: the same structure with proper integrals, anti-windup
        and speed limits (MODEL.md 6.2).
    vehicle : str
        Bundled vehicle name (``"spiri"``) or the path of a vehicle TOML file.
    vehicle_overrides : dict
        Vehicle field -> value applied to the vehicle for this run (revalidated).
    rotor_mode : {"ideal", "first-order"}
        ``"ideal"``: commanded speeds applied at once (the paper);
        ``"first-order"``: ``dOmega/dt = (Omega_cmd - Omega) / tau_m``.
    rotor_speed_limits_rpm : tuple of 2 floats or None
        Command limits [min, max], rpm; ``None``: none (the paper).
    rotor_slew_limit_rad_s2 : float or None
        Largest rate of change of the command, rad/s^2; ``None``: none.
    friction_coefficient : float
        Coulomb friction coefficient mu at the bumpers (regularised), >= 0;
        0 is the paper (frictionless).
    ground : {"crash", "contact"}
        ``"crash"``: the run ends when the vehicle reaches the ground (per the
        crash rule); ``"contact"``: the ground is a contact surface instead.
    output_rate_hz : float
        Sampling rate of the output time series, Hz.
    rtol, atol : float or None
        Integrator tolerances (Dormand-Prince 5(4)); ``None``: the kernel's defaults.
    final_time_s : float
        End of the simulation, s.
    power_off : PowerOff or None
        Motor power-off schedule (the paper's experiments); ``None``: none.
    """

    model_config = _CONFIG

    model: ModelName = Field(
        "default", description="Model variant: 'default' (physical) or 'paper-replica'."
    )
    model_options: ModelOptions = Field(
        default_factory=ModelOptions, description="Switches overriding the model variant."
    )
    controller: Literal["paper", "cascade-pid"] = Field(
        "paper", description="Controller: the authors' 'paper' PID or 'cascade-pid'."
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
    rotor_slew_limit_rad_s2: Real | None = Field(
        None, gt=0, description="Rotor speed command slew limit, rad/s^2; None: unlimited."
    )
    friction_coefficient: Real = Field(
        0.0, ge=0, description="Coulomb friction coefficient at the bumpers (0: the paper)."
    )
    ground: Literal["crash", "contact"] = Field(
        "crash", description="Ground: ends the run ('crash') or is a contact surface."
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
    final_time_s: Real = Field(3.0, gt=0, le=600, description="End of the simulation, s.")
    power_off: PowerOff | None = Field(
        None, description="Motor power-off schedule after a trigger (the experiments)."
    )

    @field_validator("vehicle_overrides")
    @classmethod
    def _known_vehicle_fields(cls, value: dict[str, Any]) -> dict[str, Any]:
        for key in value:
            if key not in Vehicle.model_fields:
                raise ValueError(f"unknown vehicle field {key!r}")
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
    """The paper's wall approach (STUDIES.md section 1).

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
        Initial altitude, m, when it differs from the set-point.
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
    impact_time_s: Real = Field(0.5, gt=0, description="Time of the first contact, s.")
    wall_distance_m: Real = Field(1.5, description="Wall position along inertial X (NED), m.")
    altitude_m: Real = Field(2.0, gt=0, description="Altitude set-point and initial altitude, m.")
    roll_deg: Real | None = Field(
        None, ge=-60, le=60, description="Explicit roll (with pitch_deg), deg."
    )
    pitch_deg: Real | None = Field(
        None, ge=-60, le=60, description="Explicit pitch (with roll_deg), deg."
    )
    start_altitude_m: Real | None = Field(
        None, gt=0, description="Initial altitude if not the set-point, m."
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


Scenario = WallApproach | FlightScenario
"""Any scenario accepted by ``simulate``."""

_KINDS: dict[str, type[WallApproach] | type[FlightScenario]] = {
    "wall-approach": WallApproach,
    "flight": FlightScenario,
}


# -------------------------------------------------------------------- files
def read_toml_file(path: str | Path) -> dict[str, Any]:
    """Read a TOML file, turning every failure into a one-line :class:`InputError`.

    Parameters
    ----------
    path : str or pathlib.Path
        The file.

    Returns
    -------
    dict
        The parsed table.
    """
    path = Path(path)
    if not path.is_file():
        reason = "is a directory, not a file" if path.is_dir() else "file not found"
        raise InputError(f"{path}: {reason}")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read file ({exc})") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: invalid TOML: {exc}") from None


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
    WallApproach or FlightScenario
        The validated scenario.
    """
    kind = data.get("kind", "wall-approach")
    if kind not in _KINDS:
        raise InputError(f"{where}: kind: must be 'wall-approach' or 'flight' (got {kind!r})")
    cls = _KINDS[kind]
    try:
        return cls.model_validate(dict(data))
    except ValidationError as exc:
        raise input_error_from_validation(exc, where, model=cls) from None


def load_scenario_file(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file (format in this module's docstring).

    A relative ``vehicle`` path is looked up next to the scenario file first.
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
    data = read_toml_file(path)
    vehicle = data.get("vehicle")
    if isinstance(vehicle, str) and vehicle not in bundled_vehicles():
        beside = path.parent / vehicle
        if not Path(vehicle).is_absolute() and beside.is_file():
            data["vehicle"] = str(beside)
    scenario = scenario_from_dict(data, where=str(path))
    scenario.build_vehicle(where=str(path))
    return scenario
