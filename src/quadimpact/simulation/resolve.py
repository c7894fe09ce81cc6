"""Validated scenario -> resolved run: every default of a run decided, in one place each.

The settings' defaults are decided in ``inputs/resolve.py`` (one call per
shared part); this module adds what each scenario kind implies and what
needs the compiler (a plug-in step's address) or the packed shapes (an
obstacle's front).

:func:`resolve` turns a validated :class:`~quadimpact.inputs.scenarios.WallApproach`,
:class:`~quadimpact.inputs.scenarios.FlightScenario` or
:class:`~quadimpact.inputs.scenarios.ImpactTrial` into one frozen
:class:`~quadimpact.inputs.resolved.ResolvedRun`: the vehicle, every model
switch, the controller's and the estimator's parameters with their defaults
and what depends on the vehicle and the sensors applied, the IMU, the control
rate, the integrator's tolerances, the slew limit, the surfaces, the
references and the start. ``packing/run_model.py``'s ``pack`` writes it into
arrays without deciding anything.

The shared part (:class:`~quadimpact.inputs.resolved.ResolvedShared`) of an
impact trial and a wall approach is kept per process
(``simulation/sharing.py``): the trials of a study resolve it once, and their
packing is packed once.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from quadimpact.core import layout as L
from quadimpact.core.geometry import shape_distance
from quadimpact.core.geometry.shapes import by_kind
from quadimpact.core.plugin_call import CONTROLLER_SIGNATURE, ESTIMATOR_SIGNATURE
from quadimpact.errors import InputError
from quadimpact.inputs.allocation import trim_rotor_speeds
from quadimpact.inputs.resolve import control_rate_hz, initial_speeds, resolve_controller
from quadimpact.inputs.resolve import resolve_shared as settings_resolved
from quadimpact.inputs.resolved import ResolvedRun, ResolvedShared, ResolvedShot
from quadimpact.inputs.scenarios import FlightScenario, ImpactTrial, RunSettings, WallApproach
from quadimpact.inputs.vehicle import Vehicle
from quadimpact.inputs.world import GROUND, Plane
from quadimpact.packing.world_block import pack_surfaces
from quadimpact.rotations import euler_zyx_to_quat
from quadimpact.simulation.approach import initial_state, wall_attitude
from quadimpact.simulation.plugin_kernel import PluginStep, plugin_address, step_name
from quadimpact.simulation.sharing import kept_shared

__all__ = [
    "control_rate_hz",
    "initial_speeds",
    "obstacle_front",
    "resolve",
    "resolve_controller",
    "resolve_shared",
]


def _address_of(role: str, entry: Any) -> float:
    """A plug-in step's entry address, compiled alone (once per process); 0 for a built-in."""
    if entry.step is None:
        return 0.0
    who = PluginStep(role, entry.name, step_name(entry.step))
    signature = CONTROLLER_SIGNATURE if role == "controller" else ESTIMATOR_SIGNATURE
    return float(plugin_address(who, entry.step, signature))


def resolve_shared(
    s: RunSettings,
    v: Vehicle,
    surfaces: list[Any],
    duration_s: float,
    wall: Plane | None = None,
    front: tuple[float, np.ndarray] | None = None,
) -> ResolvedShared:
    """``inputs.resolve.resolve_shared`` with the plug-in steps' addresses (compiled alone)."""
    return settings_resolved(
        s, v, surfaces, duration_s, wall=wall, front=front, address_of=_address_of
    )


def _ground(s: RunSettings) -> list[Plane]:
    if s.ground == "contact":
        return [GROUND]
    return []


# ------------------------------------------------------------- flight scenario
def _resolve_flight(s: FlightScenario) -> ResolvedRun:
    v = s.build_vehicle()
    surfaces = [*s.surfaces, *s.obstacles, *_ground(s)]
    shared = resolve_shared(s, v, surfaces, s.final_time_s - s.start_time_s)
    o = shared.options
    roll, pitch, yaw = (math.radians(a) for a in s.euler_deg)
    rotors = (
        np.asarray(s.rotor_speeds_rad_s, dtype=float)
        if s.rotor_speeds_rad_s is not None
        else initial_speeds(v, roll, pitch, o.initial_rotor_speeds, o.yaw_reaction == "paper")
    )
    if len(rotors) != v.rotor_count:
        raise InputError(
            f"rotor_speeds_rad_s: {len(rotors)} speeds for the {v.rotor_count} rotors of "
            f"vehicle {v.name} (one per rotor)"
        )
    x0 = initial_state(
        np.asarray(s.position_m, float),
        np.asarray(s.velocity_m_s, float),
        euler_zyx_to_quat(roll, pitch, yaw),
        np.asarray(s.angular_velocity_rad_s, float),
        rotors,
    )
    ref_att = s.attitude_ref_deg if s.attitude_ref_deg is not None else s.euler_deg
    refs = {
        "altitude_m": float(s.altitude_ref_m if s.altitude_ref_m is not None else -s.position_m[2]),
        "roll_rad": math.radians(ref_att[0]),
        "pitch_rad": math.radians(ref_att[1]),
        "yaw_rad": math.radians(ref_att[2]),
    }
    return ResolvedRun(
        shared=shared,
        seed=s.seed,
        references=refs,
        x0=x0,
        t0=float(s.start_time_s),
        waypoint=s.waypoint,
        hold_m=tuple(float(c) for c in s.position_m),
    )


# --------------------------------------------------------------- wall approach
def wall_shared(s: WallApproach, v: Vehicle | None = None) -> ResolvedShared:
    """A wall approach's resolved shared part, kept for its fields but the state's.

    ``v``: the scenario's vehicle (``s.build_vehicle()``), when the caller has it.
    """
    if v is None:
        v = s.build_vehicle()

    def make() -> ResolvedShared:
        wall = Plane.wall(s.wall_distance_m)
        surfaces = [wall, *s.obstacles, *_ground(s)]
        return resolve_shared(s, v, surfaces, float(s.final_time_s), wall=wall)

    return kept_shared(s, make, v)


def _resolve_wall_approach(s: WallApproach) -> ResolvedRun:
    v = s.build_vehicle()
    shared = wall_shared(s, v)
    o = shared.options
    if s.roll_deg is not None and s.pitch_deg is not None:
        roll, pitch, yaw = (math.radians(a) for a in (s.roll_deg, s.pitch_deg, s.heading_deg))
    else:
        roll, pitch, yaw = wall_attitude(s.heading_deg, s.inclination_deg, o.attitude_mapping)
    refs = {"altitude_m": float(s.altitude_m), "roll_rad": roll, "pitch_rad": pitch, "yaw_rad": yaw}
    h0 = s.start_altitude_m if s.start_altitude_m is not None else s.altitude_m
    shot = ResolvedShot(
        q=euler_zyx_to_quat(roll, pitch, yaw),
        rotors=initial_speeds(v, roll, pitch, o.initial_rotor_speeds, o.yaw_reaction == "paper"),
        start=np.array([0.0, 0.0, -float(h0)]),
        impact_time_s=float(s.impact_time_s),
        speed_m_s=float(s.speed_m_s),
        late_start=o.approach_start == "late-start",
    )
    return ResolvedRun(shared=shared, seed=s.seed, references=refs, x0=None, shot=shot)


# ---------------------------------------------------------------- impact trial
def obstacle_front(obstacle: Any) -> tuple[float, np.ndarray]:
    """Where the line along +X through an obstacle's centre enters it, and that centre (m).

    The centre is a plane's point, a cylinder's axis point, a box's or a
    sphere's centre (a shape component's ``SH_POINT``); the entry is found by
    bisection on the shape's signed distance along -X from the centre (exact
    to rounding; a plane's point is on it).

    Raises
    ------
    InputError
        The obstacle does not face the vehicle (a plane whose normal has no -X part).
    """
    row = pack_surfaces([obstacle])
    centre = np.array(row[0, L.SH_POINT : L.SH_POINT + 3])
    if row[0, L.SH_KIND] == L.SHAPE_PLANE:
        if not row[0, L.SH_NORMAL] < -1e-9:
            raise InputError(
                f"obstacles: obstacle 1 ({obstacle.name!r}): an impact trial flies along +X, "
                "so its plane's normal must point toward -X"
            )
        return float(centre[0]), centre
    comp = by_kind(int(row[0, L.SH_KIND]))  # a shape component: its own distance
    distance = comp.distance if comp is not None else shape_distance
    inside = 0.0
    outside = 1.0
    while distance(centre[0] - outside, centre[1], centre[2], row, 0) <= 0.0:
        outside *= 2.0
    for _ in range(200):
        mid = 0.5 * (inside + outside)
        if mid in (inside, outside):
            break
        if distance(centre[0] - mid, centre[1], centre[2], row, 0) > 0.0:
            outside = mid
        else:
            inside = mid
    return float(centre[0] - inside), centre


def trial_shared(s: ImpactTrial) -> ResolvedShared:
    """An impact trial's resolved shared part, kept for its fields but the state's."""

    def make() -> ResolvedShared:
        v = s.build_vehicle()
        duration = float(s.final_time_s)
        if s.obstacles:
            surfaces = [*s.obstacles, *_ground(s)]
            front = obstacle_front(s.obstacles[0])
            return resolve_shared(s, v, surfaces, duration, front=front)
        wall = Plane.wall(0.0)
        return resolve_shared(s, v, [wall, *_ground(s)], duration, wall=wall)

    return kept_shared(s, make)


def _resolve_impact_trial(s: ImpactTrial) -> ResolvedRun:
    shared = trial_shared(s)
    v = shared.vehicle
    roll, pitch, yaw = (math.radians(a) for a in (s.roll_deg, s.pitch_deg, s.yaw_deg))
    weight = v.mass_kg * v.gravity_m_s2
    rotors = trim_rotor_speeds(
        v, weight * math.cos(roll) * math.cos(pitch), shared.options.yaw_reaction == "paper"
    )
    if shared.front is None:
        start = np.array([-float(s.start_distance_m), 0.0, -float(s.altitude_m)])
    else:
        x_face, centre = shared.front
        start = np.array(
            [
                x_face - float(s.start_distance_m),
                centre[1] + float(s.lateral_offset_m),
                -float(s.altitude_m),
            ]
        )
    x0 = initial_state(
        start,
        np.array([float(s.speed_m_s), 0.0, 0.0]),
        euler_zyx_to_quat(roll, pitch, yaw),
        np.zeros(3),
        rotors,
    )
    refs = {"altitude_m": float(s.altitude_m), "roll_rad": roll, "pitch_rad": pitch, "yaw_rad": yaw}
    return ResolvedRun(shared=shared, seed=s.seed, references=refs, x0=x0, t0=0.0)


def resolve(scenario: WallApproach | FlightScenario | ImpactTrial) -> ResolvedRun:
    """A validated scenario's :class:`~quadimpact.inputs.resolved.ResolvedRun`.

    Every default of the run is applied here (and nowhere after): the packer
    (``packing.run_model.pack``) writes the numbers it is given. A wall
    approach's start is left to its shooting (``ResolvedRun.shot``), which
    flies the packed run.
    """
    if isinstance(scenario, WallApproach):
        return _resolve_wall_approach(scenario)
    if isinstance(scenario, ImpactTrial):
        return _resolve_impact_trial(scenario)
    return _resolve_flight(scenario)
