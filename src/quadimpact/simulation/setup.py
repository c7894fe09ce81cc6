"""Scenarios to packed runs: resolve, pack, and the loop that runs them.

``prepare(scenario)`` turns a validated :class:`~quadimpact.inputs.scenarios.WallApproach`,
:class:`~quadimpact.inputs.scenarios.FlightScenario` or
:class:`~quadimpact.inputs.scenarios.ImpactTrial` into a :class:`RunSetup`: the
flat arrays of the compiled core plus what the analysis needs to read the
result (surface names, references, the approach solution, warnings).

It is three steps. :func:`~quadimpact.simulation.resolve.resolve` makes the
run's resolved description (every default applied, once: the vehicle, the
attitude and trim, the controller's and estimator's parameters, the rates).
:func:`~quadimpact.packing.run_model.pack` writes it into arrays in one call.
Then the loop: the run's plug-in loop, and a wall approach's shooting
(:mod:`quadimpact.simulation.approach`), which flies the packed run. The
shared part of an impact trial's and a wall approach's description is kept
per process (``simulation/sharing.py``) and packed once, so the trials of a
study pack only what differs between them: the same arrays, bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from quadimpact.core import announce_compilation
from quadimpact.core import controller_slots as CTL
from quadimpact.core import estimator_slots as ESL
from quadimpact.core import layout as L
from quadimpact.core.geometry import pair_table
from quadimpact.core.geometry.shapes import plugin_shapes
from quadimpact.core.kernel import BUILTIN, Kernel, make_kernel
from quadimpact.core.records import Model, model_array, model_span
from quadimpact.core.sensors.registry import plugin_sensors
from quadimpact.inputs.model import ModelOptions
from quadimpact.inputs.resolved import ResolvedRun, ResolvedShot
from quadimpact.inputs.scenarios import FlightScenario, ImpactTrial, WallApproach
from quadimpact.inputs.vehicle import Vehicle
from quadimpact.inputs.world import Plane
from quadimpact.packing.run_model import PackedRun, output_grid, pack
from quadimpact.results.costs import CpuClock, cpu_time
from quadimpact.simulation.approach import solve_approach
from quadimpact.simulation.checks import check_imu, check_prepared, check_scenario_type
from quadimpact.simulation.plugin_kernel import PluginStep, compile_cpu_total, guarded, step_name
from quadimpact.simulation.resolve import obstacle_front, resolve

__all__ = [
    "MODEL_ARRAYS",
    "RunSetup",
    "obstacle_front",
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


# ---------------------------------------------------------------- the loop
def _kernel(
    entry, est_entry=None, instruments: tuple[str, ...] = (), kinds: tuple[str, ...] = ()
) -> Kernel | None:
    """The loop of a run with plug-ins, guarded (once per process); None for built-ins only.

    A plug-in controller or estimator runs in the cached loop, which calls its
    step by address (its address resolved by ``simulation.resolve``): the kernel is the built-in
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


def _run_setup(r: ResolvedRun, packed: PackedRun) -> RunSetup:
    """A packed run with what the Python side reads (names, references, warnings, the loop).

    The loop of the run's plug-ins (:func:`_kernel`), the names and the IMU's
    check are once per resolved shared part (kept in its memo).
    """
    shared = r.shared
    packing = packed.shared
    est = packing.est
    memo = shared.memo
    if "kernel" not in memo:
        memo["kernel"] = _kernel(
            shared.controller.entry,
            shared.estimator.entry,
            tuple(shared.instruments),
            tuple(getattr(x, "kind", "") for x in shared.surfaces),
        )
        memo["names"] = (
            shared.vehicle.feature_names(),
            tuple(x.name for x in shared.surfaces),
        )
    feature_names, shape_names = memo["names"]
    setup = RunSetup(
        run=packed.model,
        feature_names=feature_names,
        shape_names=shape_names,
        references=dict(r.references),
        vehicle=shared.vehicle,
        options=shared.options,
        output_rate_hz=shared.output_rate_hz,
        n_imu=packing.n_imu,
        wall=shared.wall,
        warnings=list(shared.warnings),
        estimator=est.name,
        estimator_settings=est.settings,
        controller=shared.settings.controller,
        kernel=memo["kernel"],
        resolved=dict(packing.resolved),
    )
    if "imu-checked" not in memo:
        check_imu(setup)  # of the shared packing: no draw changes what it checks
        memo["imu-checked"] = True
    return setup


def _shoot(setup: RunSetup, shot: ResolvedShot, free_opts: np.ndarray) -> None:
    """Solve a wall approach's start so that first contact is at the impact time, in place.

    Its shooting flies the packed run with the run's loop (``simulation/approach.py``).
    """
    clock = CpuClock()
    x0, t0, setup.approach = solve_approach(
        run=setup.model(),
        free_opts=free_opts,
        wall=setup.shapes[:1],  # the wall is the first surface
        q=shot.q,
        rotors=shot.rotors,
        start=shot.start,
        impact_time_s=shot.impact_time_s,
        speed_m_s=shot.speed_m_s,
        late_start=shot.late_start,
        kernel=setup.kernel,
        clock=clock,
    )
    setup.run = setup.model(x0=x0, t0=t0)
    setup.kernel_cpu_s = clock.total
    if setup.approach["late_start"]:
        setup.warnings.append(
            f"the approach needs v0 < 0: the vehicle starts at rest at t0 = {setup.t0:.6f} s"
        )


def _prepared(r: ResolvedRun, kernel: Kernel | None = None, plugins: bool = True) -> RunSetup:
    """Resolved run -> packed run (one ``pack`` call), its start solved when it is shot
    (``plugins=False``: with its own copies of ``ctrl`` and ``ecfg`` whose plug-in
    addresses are 0, so that no run calls a plug-in step)."""
    packed = pack(r)
    setup = _run_setup(r, packed)
    if kernel is not None:
        setup.kernel = kernel
    if not plugins:  # copies: the packed arrays may be shared with other runs
        m = setup.run
        setup.run = m._replace(ctrl=m.ctrl.copy(), ecfg=m.ecfg.copy())
        setup.run.ctrl[CTL.C_STEP] = setup.run.ecfg[ESL.EC_STEP] = 0.0
    if r.shot is not None:
        _shoot(setup, r.shot, packed.free_opts)
    return setup


def prepare_flight(s: FlightScenario) -> RunSetup:
    """A general initial state set by the user (no shooting), unchecked."""
    return _prepared(resolve(s))


def prepare_wall_approach(s: WallApproach, kernel: Kernel | None = None) -> RunSetup:
    """The paper's scenario, with the approach solved so that first contact is at T_c.

    ``kernel``: a run loop in place of the scenario's (its shooting runs fly with it).
    """
    return _prepared(resolve(s), kernel)


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
    return _prepared(resolve(s))


def prepare(
    scenario: WallApproach | FlightScenario | ImpactTrial,
    kernel: Kernel | None = None,
    *,
    plugins: bool = True,
) -> RunSetup:
    """Validated scenario -> packed run (refused if it starts in contact...: ``checks.py``).

    Three steps: :func:`~quadimpact.simulation.resolve.resolve` (every default
    applied, once), :func:`~quadimpact.packing.run_model.pack` (the arrays, in
    one call), then the run's loop (a wall approach's shooting flies it).
    ``kernel``: a run loop (``core.kernel.make_kernel``) in place of the one the
    scenario's controller and estimator select; a wall approach's shooting
    runs fly with it too. The first call in a process whose compiled loop is
    not in Numba's disk cache says that it compiles (``core.announce_compilation``).
    ``plugins=False``: no plug-in step is called, a wall approach's shooting runs
    holding the rotors where a plug-in controller would command them (what a
    plug-in's pre-flight needs: ``simulation.plugin_check`` calls the step itself
    before any run does).
    """
    started = cpu_time()
    compiled = compile_cpu_total()
    check_scenario_type(scenario)
    announce_compilation()
    resolved = resolve(scenario)  # every default applied, once
    setup = _prepared(resolved, kernel, plugins)  # pack (one call), then the run's loop
    check_prepared(scenario, setup)
    # a plug-in's loop compiled here (a wall approach's shooting): its time apart
    setup.compile_cpu_s = compile_cpu_total() - compiled
    setup.kernel_cpu_s = max(setup.kernel_cpu_s - setup.compile_cpu_s, 0.0)
    setup.prepare_cpu_s = cpu_time() - started - setup.compile_cpu_s
    return setup
