"""Scenarios to packed runs: the vehicle, trim, surfaces and references of one run.

``prepare(scenario)`` turns a validated :class:`~quadimpact.inputs.scenarios.WallApproach`
or :class:`~quadimpact.inputs.scenarios.FlightScenario` into a :class:`RunSetup`: the
flat arrays of the compiled core plus what the analysis needs to read the
result (surface names, references, the approach solution, warnings). The
wall approach's attitude and shooting are in :mod:`quadimpact.simulation.approach`.

Packing is two stages: :class:`SharedSetup` (what the run's initial state and
seed do not change) and the run's own part (:func:`_for_run`: its state,
references and random draws). An impact trial's and a wall approach's shared
part is kept per process (``simulation/sharing.py``), so the trials of a study
and the runs of a sweep over headings, inclinations and speeds pack only what
differs between them, with the same functions: the same arrays, bit for bit.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from quadimpact.core import announce_compilation
from quadimpact.core import layout as L
from quadimpact.core.geometry import pair_table, shape_distance
from quadimpact.core.geometry.shapes import by_kind, plugin_shapes
from quadimpact.core.kernel import BUILTIN, Kernel, make_kernel
from quadimpact.core.plugin_call import CONTROLLER_SIGNATURE, ESTIMATOR_SIGNATURE
from quadimpact.core.records import Model, model_array, model_span
from quadimpact.core.sensors.registry import plugin_sensors
from quadimpact.errors import InputError
from quadimpact.inputs.model import ModelOptions
from quadimpact.inputs.scenarios import FlightScenario, ImpactTrial, RunSettings, WallApproach
from quadimpact.inputs.vehicle import Vehicle
from quadimpact.inputs.world import GROUND, Plane
from quadimpact.packing.controller_block import pack_waypoint
from quadimpact.packing.options_block import pack_run_options
from quadimpact.packing.run_model import output_grid, pack_own, pack_shared
from quadimpact.packing.world_block import pack_surfaces
from quadimpact.results.costs import CpuClock, cpu_time
from quadimpact.rotations import euler_zyx_to_quat
from quadimpact.simulation.approach import initial_state, solve_approach, wall_attitude
from quadimpact.simulation.checks import check_imu, check_prepared, check_scenario_type
from quadimpact.simulation.plugin_kernel import (
    PluginStep,
    compile_cpu_total,
    guarded,
    plugin_address,
    step_name,
)
from quadimpact.simulation.sharing import SharedSetup, kept_shared
from quadimpact.simulation.trim import trim_rotor_speeds

__all__ = [
    "MODEL_ARRAYS",
    "RunSetup",
    "prepare",
    "prepare_flight",
    "prepare_impact_trial",
    "prepare_wall_approach",
]


#: The arrays of a run's :class:`~quadimpact.core.records.Model` that :meth:`RunSetup.model`
#: may change (``t0`` and ``tf`` are its ``span``).
MODEL_ARRAYS = (
    "x0", "veh", "feat", "shapes", "pairs", "opts", "ctrl", "scfg", "noise", "sched_t",
    "sched_rate", "sched_stop", "t_out", "ecfg", "snoise", "cnoise",
)  # fmt: skip


@dataclass
class RunSetup:
    """A packed run: the compiled loop's :class:`~quadimpact.core.records.Model` and what
    is needed to read its record.

    ``run`` holds every array the loop takes (layouts in ``core/layout.py``),
    its output times and contact-pair table included; the other fields are
    what the Python side reads: names, the validated vehicle and options, the
    references, the approach, the warnings, the kernel, the costs. The arrays
    are read through ``run`` or the read-only properties of the same names
    (``setup.ctrl`` is ``setup.run.ctrl``); a changed run is :meth:`model`.
    """

    run: Model
    """The packed run (SI; inertial NED, body FRD)."""
    feature_names: tuple[str, ...]
    shape_names: tuple[str, ...]
    references: dict[str, float]
    vehicle: Vehicle
    options: ModelOptions
    output_rate_hz: float
    n_imu: int
    """IMU samples the run's draws were made for."""
    wall: Plane | None = None
    approach: dict[str, Any] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    estimator: str = "ideal"
    estimator_settings: str = ""
    controller: str = "paper"
    kernel: Kernel | None = None
    resolved: dict[str, Any] = field(default_factory=dict)
    """What the scenario's settings resolved to, as plain data (``scenario.json``'s
    ``resolved``): the model variant and every switch, the controller and its
    parameters with defaults, the pre-impact behaviour, the IMU and the slew limit."""
    prepare_cpu_s: float = 0.0
    """CPU time of :func:`prepare` (this thread), s; the summary's ``cost`` adds it in."""
    kernel_cpu_s: float = 0.0
    """Of which in the compiled loop (the approach's shooting runs), s."""
    compile_cpu_s: float = 0.0
    """CPU time compiling a plug-in's loop during this run (its first in a process), s: in
    neither of the others (``simulation.plugin_kernel``)."""

    def model(self, **changes: Any) -> Model:
        """The run as the compiled core's :class:`~quadimpact.core.records.Model`.

        Without ``changes``, :attr:`run` itself. ``changes`` replace arrays of
        it (:data:`MODEL_ARRAYS`) or its times (``t0``, ``tf``, s); ``None``
        for a sensor's, the schedule's or the estimator's arrays means none.
        The output times follow changed times and the contact-pair table
        changed features or shapes, unless given.
        """
        if not changes:
            return self.run
        t0 = float(changes.pop("t0", self.t0))
        tf = float(changes.pop("tf", self.tf))
        unknown = set(changes) - set(MODEL_ARRAYS)
        if unknown:
            raise TypeError(f"RunSetup.model: no array {sorted(unknown)}")
        fields = {name: model_array(name, a) for name, a in changes.items()}
        if (t0, tf) != (self.t0, self.tf):
            fields["span"] = model_span(t0, tf)
            if "t_out" not in fields:
                fields["t_out"] = output_grid(t0, tf, self.output_rate_hz)
        if "pairs" not in fields and ("feat" in fields or "shapes" in fields):
            run = self.run
            fields["pairs"] = pair_table(
                fields.get("feat", run.feat), fields.get("shapes", run.shapes)
            )
        return self.run._replace(**fields)

    def output_times(self) -> np.ndarray:
        """The run's output grid (s): ``t0``, the multiples of 1/rate inside, ``tf``."""
        return self.run.t_out

    def pair_table(self) -> np.ndarray:
        """The contact-pair table of the features and shapes (``core.geometry.pair_table``):
        pair ``c = shape * n_features + feature``."""
        return self.run.pairs

    # the run's arrays by name, read-only (a changed run is model(...))
    t0 = property(lambda self: float(self.run.span[L.SPAN_T0]), doc="Start time, s.")
    tf = property(lambda self: float(self.run.span[L.SPAN_TF]), doc="End time, s.")
    x0 = property(lambda self: self.run.x0, doc="Initial state (``X_*``).")
    veh = property(lambda self: self.run.veh, doc="Vehicle (``V_*``).")
    feat = property(lambda self: self.run.feat, doc="Contact features (``F_*``), body frame.")
    shapes = property(lambda self: self.run.shapes, doc="Shapes (``SH_*``), inertial frame.")
    opts = property(lambda self: self.run.opts, doc="Options (``O_*``).")
    ctrl = property(lambda self: self.run.ctrl, doc="Controller (``C_*``).")
    scfg = property(lambda self: self.run.scfg, doc="Sensors (``SC_*``).")
    noise = property(lambda self: self.run.noise, doc="The IMU's normal draws.")
    sched_t = property(lambda self: self.run.sched_t, doc="Power-off segment starts, s.")
    sched_rate = property(lambda self: self.run.sched_rate, doc="Power-off rates, rad/s^2.")
    sched_stop = property(lambda self: self.run.sched_stop, doc="Motors stalled at the trigger.")
    ecfg = property(lambda self: self.run.ecfg, doc="Estimator (``EC_*``).")
    snoise = property(lambda self: self.run.snoise, doc="The added sensors' normal draws.")
    cnoise = property(lambda self: self.run.cnoise, doc="The sensor components' normal draws.")


# ---------------------------------------------------------------- settings
def _initial_speeds(
    v: Vehicle, roll: float, pitch: float, rule: str, yaw_paper: bool
) -> np.ndarray:
    weight = v.mass_kg * v.gravity_m_s2
    if rule == "level-hover":
        n = v.rotor_count  # rotors sharing one coefficient: sqrt(m g / (n kt)) each
        kt = v.thrust_coefficients
        if np.all(kt == kt[0]):
            return np.full(n, math.sqrt(weight / (float(n) * float(kt[0]))))
        return np.full(n, v.hover_speed_rad_s)
    return trim_rotor_speeds(v, weight / (math.cos(roll) * math.cos(pitch)), yaw_paper)


def _ground(s: RunSettings) -> list[Plane]:
    if s.ground == "contact":
        return [GROUND]
    return []


def _kernel(
    entry, est_entry=None, instruments: tuple[str, ...] = (), kinds: tuple[str, ...] = ()
) -> Kernel | None:
    """The loop of a run with plug-ins, guarded (once per process); None for built-ins only.

    A plug-in controller or estimator runs in the cached loop, which calls its
    step by address (:func:`_plugin_addresses`): the kernel is the built-in
    one, guarded (``simulation.plugin_kernel``: an exception in a plug-in a
    one-line ``PluginError``). A plug-in sensor or shape is compiled into a
    loop of its own (``core.kernel.make_kernel``), its compilation announced
    and timed apart. ``instruments``: the run's sensor components; a plug-in
    among them puts every registered plug-in sensor into the loop; ``kinds``:
    its obstacles' kinds, and a plug-in shape among them every registered
    plug-in shape.
    """
    estimator = getattr(est_entry, "step", None)
    sensors = tuple(c.name for c in plugin_sensors())
    if not any(name in sensors for name in instruments):
        sensors = ()
    shapes = tuple(c.name for c in plugin_shapes())
    if not any(kind in shapes for kind in kinds):
        shapes = ()
    if entry.step is None and estimator is None and not sensors and not shapes:
        return None
    key = "kernel" if estimator is None else ("kernel", id(estimator))
    if sensors:
        key = (key, sensors, tuple(id(c.sample) for c in plugin_sensors()))
    if shapes:
        key = (key, shapes, tuple(id(c.distance) for c in plugin_shapes()))
    if key not in entry.kernel_cache:
        plugins = []
        if entry.step is not None:
            plugins.append(PluginStep("controller", entry.name, step_name(entry.step)))
        if estimator is not None:
            plugins.append(PluginStep("estimator", est_entry.name, step_name(estimator)))
        components = []
        for c in plugin_sensors() if sensors else ():
            components.append(PluginStep("sensor", c.name, step_name(c.sample)))
        for c in plugin_shapes() if shapes else ():
            components.append(PluginStep("shape", c.name, step_name(c.distance)))
        if components:  # compiled around the components; the steps still called by address
            kernel = make_kernel(sensors=bool(sensors), shapes=bool(shapes))
            entry.kernel_cache[key] = guarded(kernel, [*plugins, *components])
        else:
            entry.kernel_cache[key] = guarded(BUILTIN, plugins, compiles=False)
    return entry.kernel_cache[key]


def _plugin_addresses(entry, est_entry, ctrl: np.ndarray, ecfg: np.ndarray) -> None:
    """Write the entry addresses of a plug-in controller's and estimator's steps into the
    run's ``ctrl[C_STEP]`` and ``ecfg[EC_STEP]``, each step compiled alone (once per
    process: ``simulation.plugin_kernel.plugin_address``)."""
    if entry.step is not None:
        who = PluginStep("controller", entry.name, step_name(entry.step))
        ctrl[L.C_STEP] = float(plugin_address(who, entry.step, CONTROLLER_SIGNATURE))
    estimator = getattr(est_entry, "step", None)
    if estimator is not None:
        who = PluginStep("estimator", est_entry.name, step_name(estimator))
        ecfg[L.EC_STEP] = float(plugin_address(who, estimator, ESTIMATOR_SIGNATURE))


def _shared(
    s: RunSettings,
    v: Vehicle,
    o: ModelOptions,
    surfaces: list[Plane],
    duration_s: float,
    wall: Plane | None = None,
) -> SharedSetup:
    """The packing common to every scenario kind, without the run's state, references and draws."""
    packing = pack_shared(s, v, o, surfaces, duration_s)
    est = packing.est
    _plugin_addresses(packing.entry, est.entry, packing.model.ctrl, packing.model.ecfg)
    setup = RunSetup(
        run=packing.model,
        feature_names=v.feature_names(),
        shape_names=tuple(x.name for x in surfaces),
        references={},
        vehicle=v,
        options=o,
        output_rate_hz=float(s.output_rate_hz),
        n_imu=packing.n_imu,
        wall=wall,
        estimator=est.name,
        estimator_settings=est.settings,
        controller=s.controller,
        kernel=_kernel(
            packing.entry,
            est.entry,
            tuple(s.instruments),
            tuple(getattr(x, "kind", "") for x in surfaces),
        ),
        resolved=packing.resolved,
    )
    setup.warnings.extend(f"vehicle {v.name}: {w}" for w in v.plausibility_warnings())
    if s.controller == "recovery" and packing.context.pre_impact == "spin-down":
        if setup.opts[L.O_SLEW_MAX] <= 0.0:
            setup.warnings.append(
                f"no rotor slew limit (vehicle {v.name} has none): the pre-impact spin-down "
                "stops the rotors at the first tick"
            )
    check_imu(setup)  # of the shared packing: no draw changes what it checks
    return SharedSetup(setup=setup, packing=packing, entries=(packing.entry, est.entry))


def _for_run(
    shared: SharedSetup, s: RunSettings, refs: dict[str, float], **fields: Any
) -> RunSetup:
    """One run's :class:`RunSetup`: the shared packing with its references and seeded draws.

    ``refs``: ``altitude_m``, ``roll_rad``, ``pitch_rad``, ``yaw_rad``;
    ``fields``: ``x0``, ``t0``. The shared arrays that no run changes
    (vehicle, features, surfaces, options, the pair table, and the output
    times while ``t0`` is the shared one) are the same objects in every run.
    """
    base = shared.setup
    return dataclasses.replace(
        base,
        run=base.model(**pack_own(shared.packing, s.seed, refs), **fields),
        references=refs,
        warnings=list(base.warnings),
        approach={},
        resolved=dict(base.resolved),
    )


# ------------------------------------------------------------- flight scenario
def prepare_flight(s: FlightScenario) -> RunSetup:
    """A general initial state set by the user (no shooting)."""
    v = s.build_vehicle()
    o = s.resolved_model_options()
    roll, pitch, yaw = (math.radians(a) for a in s.euler_deg)
    q = euler_zyx_to_quat(roll, pitch, yaw)
    rotors = (
        np.asarray(s.rotor_speeds_rad_s, dtype=float)
        if s.rotor_speeds_rad_s is not None
        else _initial_speeds(v, roll, pitch, o.initial_rotor_speeds, o.yaw_reaction == "paper")
    )
    if len(rotors) != v.rotor_count:
        raise InputError(
            f"rotor_speeds_rad_s: {len(rotors)} speeds for the {v.rotor_count} rotors of "
            f"vehicle {v.name} (one per rotor)"
        )
    x0 = initial_state(
        np.asarray(s.position_m, float),
        np.asarray(s.velocity_m_s, float),
        q,
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
    surfaces = [*s.surfaces, *s.obstacles, *_ground(s)]
    duration = s.final_time_s - s.start_time_s
    run = _for_run(_shared(s, v, o, surfaces, duration), s, refs, x0=x0, t0=float(s.start_time_s))
    if s.waypoint is not None:
        pack_waypoint(run.ctrl, s.waypoint, s.position_m)
    return run


# --------------------------------------------------------------- wall approach
def prepare_wall_approach(s: WallApproach, kernel: Kernel | None = None) -> RunSetup:
    """The paper's scenario, with the approach solved so that first contact is at T_c.

    ``kernel``: a run loop in place of the scenario's (its shooting runs fly with it).
    """
    v = s.build_vehicle()
    o = s.resolved_model_options()
    if s.roll_deg is not None and s.pitch_deg is not None:
        roll, pitch, yaw = (math.radians(a) for a in (s.roll_deg, s.pitch_deg, s.heading_deg))
    else:
        roll, pitch, yaw = wall_attitude(s.heading_deg, s.inclination_deg, o.attitude_mapping)
    refs = {"altitude_m": float(s.altitude_m), "roll_rad": roll, "pitch_rad": pitch, "yaw_rad": yaw}
    setup = _for_run(_wall_shared(s, v), s, refs)
    if kernel is not None:
        setup.kernel = kernel
    h0 = s.start_altitude_m if s.start_altitude_m is not None else s.altitude_m
    clock = CpuClock()
    x0, t0, setup.approach = solve_approach(
        run=setup.model(),
        free_opts=pack_run_options(s, o, v, float(s.impact_time_s), free=True),
        wall=setup.shapes[:1],  # the wall is the first surface
        q=euler_zyx_to_quat(roll, pitch, yaw),
        rotors=_initial_speeds(v, roll, pitch, o.initial_rotor_speeds, o.yaw_reaction == "paper"),
        start=np.array([0.0, 0.0, -float(h0)]),
        impact_time_s=s.impact_time_s,
        speed_m_s=s.speed_m_s,
        late_start=o.approach_start == "late-start",
        kernel=setup.kernel,
        clock=clock,
    )
    setup.run = setup.model(x0=x0, t0=t0)
    setup.kernel_cpu_s = clock.total
    if setup.approach["late_start"]:
        setup.warnings.append(
            f"the approach needs v0 < 0: the vehicle starts at rest at t0 = {setup.t0:.6f} s"
        )
    return setup


# ---------------------------------------------------------------- impact trial
def prepare_impact_trial(s: ImpactTrial) -> RunSetup:
    """The recovery benchmark's trial (docs/RECOVERY.md 5): the wall ``X = 0``, no shooting.

    The CM starts at ``X = -start_distance_m``, altitude ``altitude_m``, the
    attitude and the inertial velocity ``(speed_m_s, 0, 0)`` given, at rest in
    rotation, with the rotor speeds of the collective thrust
    ``m g cos(roll) cos(pitch)`` and zero torques (multiplied by the cosines:
    the vehicle was flying level before it tilted, as in the authors' set-up).
    With obstacles, the trial flies toward the first one (docs/OBSTACLES.md 2):
    it starts ``start_distance_m`` before the obstacle's front, beside its
    centre by ``lateral_offset_m``; the others stay where they are.
    """
    shared = _trial_shared(s)
    v = shared.setup.vehicle
    roll, pitch, yaw = (math.radians(a) for a in (s.roll_deg, s.pitch_deg, s.yaw_deg))
    weight = v.mass_kg * v.gravity_m_s2
    rotors = trim_rotor_speeds(
        v, weight * math.cos(roll) * math.cos(pitch), shared.setup.options.yaw_reaction == "paper"
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
    return _for_run(shared, s, refs, x0=x0, t0=0.0)


def _wall_shared(s: WallApproach, v: Vehicle | None = None) -> SharedSetup:
    """The :class:`SharedSetup` of a wall approach, kept for its fields but the state's.

    ``v``: the scenario's vehicle (``s.build_vehicle()``), when the caller has it.
    """
    if v is None:
        v = s.build_vehicle()

    def pack() -> SharedSetup:
        wall = Plane.wall(s.wall_distance_m)
        surfaces = [wall, *s.obstacles, *_ground(s)]
        return _shared(s, v, s.resolved_model_options(), surfaces, float(s.final_time_s), wall=wall)

    return kept_shared(s, pack, v)


def _trial_shared(s: ImpactTrial) -> SharedSetup:
    """The :class:`SharedSetup` of an impact trial, kept for its fields but the state's."""

    def pack() -> SharedSetup:
        v = s.build_vehicle()
        o = s.resolved_model_options()
        duration = float(s.final_time_s)
        if s.obstacles:
            shared = _shared(s, v, o, [*s.obstacles, *_ground(s)], duration)
            shared.front = obstacle_front(s.obstacles[0])
            return shared
        wall = Plane.wall(0.0)
        return _shared(s, v, o, [wall, *_ground(s)], duration, wall=wall)

    return kept_shared(s, pack)


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


def prepare(
    scenario: WallApproach | FlightScenario | ImpactTrial, kernel: Kernel | None = None
) -> RunSetup:
    """Validated scenario -> packed run (refused if it starts in contact...: ``checks.py``).

    ``kernel``: a run loop (``core.kernel.make_kernel``) in place of the one the
    scenario's controller and estimator select; a wall approach's shooting
    runs fly with it too. The first call in a process whose compiled loop is
    not in Numba's disk cache says that it compiles (``core.announce_compilation``).
    """
    started = cpu_time()
    compiled = compile_cpu_total()
    check_scenario_type(scenario)
    announce_compilation()
    if isinstance(scenario, WallApproach):
        setup = prepare_wall_approach(scenario, kernel)
    elif isinstance(scenario, ImpactTrial):
        setup = prepare_impact_trial(scenario)
    else:
        setup = prepare_flight(scenario)
    if kernel is not None:
        setup.kernel = kernel
    check_prepared(scenario, setup)
    # a plug-in's loop compiled here (a wall approach's shooting): its time apart
    setup.compile_cpu_s = compile_cpu_total() - compiled
    setup.kernel_cpu_s = max(setup.kernel_cpu_s - setup.compile_cpu_s, 0.0)
    setup.prepare_cpu_s = cpu_time() - started - setup.compile_cpu_s
    return setup
