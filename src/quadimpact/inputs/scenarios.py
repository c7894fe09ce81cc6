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

All share :class:`RunSettings` (:mod:`quadimpact.inputs.run_settings`: model
variant, controller, vehicle, rotor mode, sensors, integrator settings). A
scenario can be written as a TOML file and read with :func:`load_scenario_file`::

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

from pydantic import Field, ValidationError, field_validator, model_validator

from quadimpact.errors import InputError, format_value, input_error_from_validation
from quadimpact.inputs.run_settings import PowerOff, RunSettings, check_before_final, check_euler
from quadimpact.inputs.toml_files import locate_vehicle, read_toml_file
from quadimpact.inputs.types import Real, RotorReals, Vec3
from quadimpact.inputs.waypoint import Waypoint
from quadimpact.inputs.world import Plane

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
        check_before_final(self, "impact_time_s")
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
    rotor_speeds_rad_s : tuple of n floats or None
        Initial rotor speeds, rad/s, one per rotor of the vehicle; ``None``:
        trimmed for the attitude.
    altitude_ref_m : float or None
        Altitude set-point, m; ``None``: the initial altitude.
    attitude_ref_deg : tuple of 3 floats or None
        Attitude set-point [roll, pitch, yaw], ZYX, deg; ``None``: the initial attitude.
    surfaces : tuple of Plane
        Contact planes (walls, ceilings...); names must be unique.
    start_time_s : float
        Initial time, s, >= 0 and < ``final_time_s``.
    waypoint : Waypoint or None
        A flight toward a waypoint (:class:`~quadimpact.inputs.waypoint.Waypoint`):
        the ``cascade-pid`` controller's position loop holds the start position,
        then flies there; with the ``cascade-pid`` controller, or ``recovery``
        flying it before the impact (``pre_impact = "nominal"``,
        ``nominal_controller = "cascade-pid"``).
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
    rotor_speeds_rad_s: RotorReals | None = Field(
        None, description="Initial rotor speeds, rad/s, one per rotor; None: trimmed."
    )
    altitude_ref_m: Real | None = Field(
        None, gt=0, description="Altitude set-point, m; None: initial altitude."
    )
    attitude_ref_deg: Vec3 | None = Field(
        None, description="Attitude set-point [roll, pitch, yaw], ZYX, deg; None: initial."
    )
    surfaces: tuple[Plane, ...] = Field((), description="Contact planes.")
    start_time_s: Real = Field(0.0, ge=0, description="Initial time, s.")
    waypoint: Waypoint | None = Field(None, description="A flight toward a waypoint.")

    @field_validator("position_m")
    @classmethod
    def _airborne(cls, value: tuple[float, float, float]) -> tuple[float, float, float]:
        if not value[2] < 0:
            raise ValueError("must start above the ground: Z (third entry, NED, down) must be < 0")
        return value

    @field_validator("euler_deg", "attitude_ref_deg")
    @classmethod
    def _euler_ranges(cls, value: tuple[float, float, float] | None):
        return check_euler(value)

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
        check_before_final(self, "start_time_s")
        if self.waypoint is not None:
            flies = self.controller == "cascade-pid" or (
                self.controller == "recovery"
                and self.resolved_pre_impact() == "nominal"
                and self.nominal_controller == "cascade-pid"
            )
            if not flies:
                raise ValueError(
                    "waypoint: needs controller = 'cascade-pid', or 'recovery' with "
                    "pre_impact = 'nominal' and nominal_controller = 'cascade-pid'"
                )
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
    (:func:`~quadimpact.inputs.toml_files.locate_vehicle`).
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
