"""Validated scenario -> resolved run: every default of a run decided, in one place each.

Every default is decided in ``inputs/resolve.py``: one call for the shared
part (``resolve_shared``), one for the run's own (``flight_start``,
``wall_start``, ``trial_start``). This module adds what needs the layers
above the inputs: the kept shared parts, a plug-in step's address (compiled
alone) and an obstacle's front (from its packed shape).

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

from typing import Any

import numpy as np

from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP
from quadimpact.core.geometry import shape_distance
from quadimpact.core.geometry.shapes import by_kind
from quadimpact.core.plugin_call import CONTROLLER_SIGNATURE, ESTIMATOR_SIGNATURE
from quadimpact.errors import InputError
from quadimpact.inputs.resolve import (
    control_rate_hz,
    flight_start,
    initial_speeds,
    resolve_controller,
    trial_start,
    wall_start,
)
from quadimpact.inputs.resolve import resolve_shared as settings_resolved
from quadimpact.inputs.resolved import ResolvedRun, ResolvedShared
from quadimpact.inputs.scenarios import FlightScenario, ImpactTrial, RunSettings, WallApproach
from quadimpact.inputs.vehicle import Vehicle
from quadimpact.inputs.world import GROUND, Plane
from quadimpact.packing.world_block import pack_surfaces
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
    return flight_start(s, resolve_shared(s, v, surfaces, s.final_time_s - s.start_time_s))


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
    return wall_start(s, wall_shared(s, s.build_vehicle()))


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
    centre = np.array(row[0, SHP.SH_POINT : SHP.SH_POINT + 3])
    if row[0, SHP.SH_KIND] == L.SHAPE_PLANE:
        if not row[0, SHP.SH_NORMAL] < -1e-9:
            raise InputError(
                f"obstacles: obstacle 1 ({obstacle.name!r}): an impact trial flies along +X, "
                "so its plane's normal must point toward -X"
            )
        return float(centre[0]), centre
    comp = by_kind(int(row[0, SHP.SH_KIND]))  # a shape component: its own distance
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
    return trial_start(s, trial_shared(s))


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
