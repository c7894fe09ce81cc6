"""A run's resolved description: every input of a run with every default applied.

``simulation/resolve.py``'s ``resolve(scenario)`` makes one :class:`ResolvedRun`
from a validated scenario; ``packing/run_model.py``'s ``pack(resolved)`` writes
it into the compiled core's arrays in one call. Each default is decided once,
before packing: the resolved description holds a number wherever a packer
writes one (``tests/test_defaults.py`` checks it for every built-in component).
A ``None`` left here means "none" (no magnetometer, no slew limit, no lean cut),
never "the default".

The records are frozen (their mappings read-only): what a run is does not
change once resolved. Units
and frames as in docs/MODEL.md section 1 (SI; inertial NED, body FRD).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np
from pydantic import BaseModel

__all__ = [
    "ResolvedController",
    "ResolvedEstimator",
    "ResolvedRun",
    "ResolvedShared",
    "ResolvedShot",
]


@dataclass(frozen=True)
class ResolvedController:
    """The run's controller, resolved.

    Attributes
    ----------
    entry : quadimpact.inputs.controllers.ControllerEntry
        Its registry entry.
    given : pydantic.BaseModel
        Its parameters as validated: ``[controller_params]`` over the model's
        tuning (``recovery_law``) over the parameter model's defaults (what
        ``scenario.json`` reports).
    params : pydantic.BaseModel
        The same with what depends on the vehicle applied (the recovery law's
        ``a_mag_m_s2`` ``None``: the vehicle's g, m/s^2; ``hover_a_max_m_s2``
        ``None``: g/2): what the packer writes.
    pre_impact : str
        The recovery controller's pre-impact behaviour in force.
    nominal_controller : str
        The nominal controller (the wall approach's; recovery's pre-impact).
    step_address : float
        A plug-in step's entry address (compiled alone), 0 for a built-in.
    """

    entry: Any
    given: BaseModel
    params: BaseModel
    pre_impact: str
    nominal_controller: str
    step_address: float = 0.0


@dataclass(frozen=True)
class ResolvedEstimator:
    """The run's estimator, resolved.

    Attributes
    ----------
    entry : quadimpact.inputs.estimators.EstimatorEntry
    given : pydantic.BaseModel
        Its parameters as validated (what the summary and ``scenario.json`` report).
    params : pydantic.BaseModel
        The same with every noise and initial spread a number (``None``: from
        the run's sensors, floored: ``inputs.estimators.resolve_estimator_params``).
    context : quadimpact.inputs.estimators.EstimatorContext
        The run's sensors and vehicle.
    step_address : float
        A plug-in step's entry address (compiled alone), 0 for a built-in.
    """

    entry: Any
    given: BaseModel
    params: BaseModel
    context: Any
    step_address: float = 0.0


@dataclass(frozen=True)
class ResolvedShared:
    """What a run's initial state, references and seed do not change, resolved.

    Runs that share it (the trials of a study, the runs of a sweep over
    headings) share one object, and one packing of it.

    Attributes
    ----------
    settings : quadimpact.inputs.run_settings.RunSettings
        The validated scenario (the fields without a default to decide:
        ground, rotor mode and limits, power-off, friction, instruments).
    vehicle, options
        The vehicle with its overrides; every model switch (none ``None``).
    surfaces : tuple
        The contact surfaces in packing order (the wall or the obstacles, then
        the ground when it is a contact surface).
    wall : Plane or None
        The wall plane of a wall approach or of a trial without obstacles.
    duration_s, final_time_s : float
        How long the run lasts and when it ends, s.
    output_rate_hz, control_rate_hz : float
        Output sampling and control tick rates, Hz.
    rtol, atol : float
        The integrator's tolerances.
    slew_limit_rad_s2 : float or None
        The rotor command slew limit, rad/s^2; ``None``: none.
    imu : quadimpact.inputs.sensors.ResolvedImu
    controller : ResolvedController
    estimator : ResolvedEstimator
    instruments : mapping
        The sensor components, name -> validated settings.
    front : tuple or None
        An impact trial toward an obstacle: where it enters the obstacle (m)
        and its centre.
    warnings : tuple of str
        What the run should be told (the vehicle's plausibility, the slew limit).
    memo : dict
        Its packing, once packed (``packing.run_model.pack``: one per object),
        and its loop; not an argument, compared with nothing, not copied by
        ``dataclasses.replace``.
    """

    settings: Any
    vehicle: Any
    options: Any
    surfaces: tuple[Any, ...]
    wall: Any
    duration_s: float
    final_time_s: float
    output_rate_hz: float
    control_rate_hz: float
    rtol: float
    atol: float
    slew_limit_rad_s2: float | None
    imu: Any
    controller: ResolvedController
    estimator: ResolvedEstimator
    instruments: Mapping[str, Any]
    front: tuple[float, np.ndarray] | None = None
    warnings: tuple[str, ...] = ()
    memo: dict[str, Any] = field(default_factory=dict, init=False, compare=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "instruments", MappingProxyType(dict(self.instruments)))


@dataclass(frozen=True)
class ResolvedShot:
    """What a wall approach's shooting needs (``simulation/approach.py``).

    ``q``: the attitude (quaternion, body to inertial); ``rotors``: trimmed
    speeds, rad/s; ``start``: the start position (NED, m); the impact time, s;
    the approach speed, m/s; ``late_start``: the model's start rule.
    """

    q: np.ndarray
    rotors: np.ndarray
    start: np.ndarray
    impact_time_s: float
    speed_m_s: float
    late_start: bool


@dataclass(frozen=True)
class ResolvedRun:
    """One run, resolved: the shared part and the run's own.

    Attributes
    ----------
    shared : ResolvedShared
    seed : int
        The seed of the run's random draws.
    references : mapping
        ``altitude_m`` (m), ``roll_rad``, ``pitch_rad``, ``yaw_rad`` (rad).
    x0 : ndarray or None
        The initial state (``X_*``); ``None`` for a wall approach, whose start
        the shooting solves after packing (``shot``).
    t0 : float
        The start time, s.
    waypoint : Waypoint or None
        A flight's waypoint, and ``hold_m`` the position it holds first (m).
    shot : ResolvedShot or None
        A wall approach's shooting.
    """

    shared: ResolvedShared
    seed: int
    references: Mapping[str, float]
    x0: np.ndarray | None
    t0: float = 0.0
    waypoint: Any = None
    hold_m: tuple[float, float, float] | None = None
    shot: ResolvedShot | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "references", MappingProxyType(dict(self.references)))
