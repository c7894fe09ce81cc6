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

import copy
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from quadimpact.core import announce_compilation
from quadimpact.core import layout as L
from quadimpact.core.geometry import pair_table, shape_distance
from quadimpact.core.kernel import Kernel, make_kernel
from quadimpact.core.records import Model, model
from quadimpact.errors import InputError
from quadimpact.inputs.controllers import PackContext, controller_entry
from quadimpact.inputs.model import ModelOptions
from quadimpact.inputs.scenarios import FlightScenario, ImpactTrial, RunSettings, WallApproach
from quadimpact.inputs.vehicle import Vehicle
from quadimpact.inputs.world import GROUND, Plane
from quadimpact.packing.constants import CONTROL_RATE_HZ
from quadimpact.packing.controller import pack_controller, pack_waypoint, set_references
from quadimpact.packing.estimation import draw_estimation, pack_estimation
from quadimpact.packing.options import pack_run_options, pack_schedule, slew_limit_rad_s2
from quadimpact.packing.sensors import draw_imu_noise, pack_sensors
from quadimpact.packing.vehicle import pack_features, pack_vehicle
from quadimpact.packing.world import pack_surfaces
from quadimpact.results.costs import CpuClock, cpu_time
from quadimpact.rotations import euler_zyx_to_quat
from quadimpact.simulation.approach import initial_state, solve_approach, wall_attitude
from quadimpact.simulation.checks import check_imu, check_prepared, check_scenario_type
from quadimpact.simulation.sharing import SharedSetup, kept_shared
from quadimpact.simulation.trim import trim_rotor_speeds

__all__ = ["RunSetup", "prepare", "prepare_flight", "prepare_impact_trial", "prepare_wall_approach"]


@dataclass
class RunSetup:
    """Everything the compiled loop takes, and what is needed to read its record.

    The packed arrays (layouts in ``core/layout.py``) become the run's
    :class:`~quadimpact.core.records.Model` with :meth:`model`.
    """

    x0: np.ndarray
    t0: float
    tf: float
    veh: np.ndarray
    feat: np.ndarray
    shapes: np.ndarray
    opts: np.ndarray
    ctrl: np.ndarray
    feature_names: tuple[str, ...]
    shape_names: tuple[str, ...]
    references: dict[str, float]
    vehicle: Vehicle
    options: ModelOptions
    output_rate_hz: float
    wall: Plane | None = None
    approach: dict[str, Any] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    sched_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    sched_rate: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))
    sched_stop: np.ndarray = field(default_factory=lambda: np.zeros(4))
    scfg: np.ndarray = field(default_factory=lambda: np.zeros(L.NSCFG))
    noise: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))
    n_imu: int = 0
    ecfg: np.ndarray = field(default_factory=lambda: np.zeros(L.NECFG))
    snoise: np.ndarray = field(default_factory=lambda: np.zeros((0, L.NSN)))
    estimator: str = "ideal"
    estimator_settings: str = ""
    controller: str = "paper"
    kernel: Kernel | None = None
    resolved: dict[str, Any] = field(default_factory=dict)
    """What the scenario's settings resolved to, as plain data (``scenario.json``'s
    ``resolved``): the model variant and every switch, the controller and its
    parameters with defaults, the pre-impact behaviour, the IMU and the slew limit."""
    kept_grid: tuple[tuple[float, float, float], np.ndarray] | None = None
    """The output times kept for (``t0``, ``tf``, ``output_rate_hz``) (see :meth:`model`)."""
    kept_pairs: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    """``feat``, ``shapes`` and their pair table, kept (:meth:`keep_grid_and_pairs`)."""
    prepare_cpu_s: float = 0.0
    """CPU time of :func:`prepare` (this thread), s; the summary's ``cost`` adds it in."""
    kernel_cpu_s: float = 0.0
    """Of which in the compiled loop (the approach's shooting runs), s."""

    def model(self, **changes: Any) -> Model:
        """The run as the compiled core's :class:`~quadimpact.core.records.Model`.

        ``changes`` replace fields of the packed run (``x0``, ``t0``, ``tf``,
        ``shapes``, ``opts``, ``t_out``...); the output times default to
        :meth:`output_times` and the contact-pair table is built from the
        features and shapes.
        """
        fields: dict[str, Any] = {
            "x0": self.x0,
            "t0": self.t0,
            "tf": self.tf,
            "veh": self.veh,
            "feat": self.feat,
            "shapes": self.shapes,
            "opts": self.opts,
            "ctrl": self.ctrl,
            "scfg": self.scfg,
            "noise": self.noise,
            "sched_t": self.sched_t,
            "sched_rate": self.sched_rate,
            "sched_stop": self.sched_stop,
            "ecfg": self.ecfg,
            "snoise": self.snoise,
        }
        fields.update(changes)
        if "t_out" not in fields:
            fields["t_out"] = self._output_grid()
        if fields["feat"] is self.feat and fields["shapes"] is self.shapes:
            fields["pairs"] = self.pair_table()
        else:
            fields["pairs"] = pair_table(fields["feat"], fields["shapes"])
        return model(**fields)

    def pair_table(self) -> np.ndarray:
        """The contact-pair table of the features and shapes (``core.geometry.pair_table``):
        pair ``c = shape * n_features + feature``; the kept one where it is of these arrays."""
        kept = self.kept_pairs
        if kept is not None and kept[0] is self.feat and kept[1] is self.shapes:
            return kept[2]
        return pair_table(self.feat, self.shapes)

    def keep_grid_and_pairs(self) -> None:
        """Compute the output times and the pair table now and keep them (no run changes them).

        Runs copied from this setup (the shared packing's runs, ``_for_run``)
        share them while their times, features and shapes are
        this setup's (checked in :meth:`model`): the same arrays, not recomputed.
        """
        self._output_grid()
        self.kept_pairs = (self.feat, self.shapes, pair_table(self.feat, self.shapes))

    def _output_grid(self) -> np.ndarray:
        """:meth:`output_times`, kept with the times and rate it is of."""
        key = (self.t0, self.tf, self.output_rate_hz)
        kept = self.kept_grid
        if kept is None or kept[0] != key:
            kept = self.kept_grid = (key, self.output_times())
        return kept[1]

    def output_times(self) -> np.ndarray:
        """Output grid: ``t0``, the multiples of 1/rate inside (t0, tf), and ``tf`` (s)."""
        dt = 1.0 / self.output_rate_hz
        k0 = math.floor(self.t0 / dt) + 1
        k1 = math.ceil(self.tf / dt)
        inner = np.arange(k0, k1) * dt
        inner = inner[(inner > self.t0 + 1e-12) & (inner < self.tf - 1e-12)]
        return np.concatenate([[self.t0], inner, [self.tf]])


# ---------------------------------------------------------------- settings
def _initial_speeds(
    v: Vehicle, roll: float, pitch: float, rule: str, yaw_paper: bool
) -> np.ndarray:
    weight = v.mass_kg * v.gravity_m_s2
    if rule == "level-hover":
        return np.full(4, math.sqrt(weight / (4.0 * v.thrust_coefficient)))
    return trim_rotor_speeds(v, weight / (math.cos(roll) * math.cos(pitch)), yaw_paper)


def _ground(s: RunSettings) -> list[Plane]:
    if s.ground == "contact":
        return [GROUND]
    return []


def _kernel(entry, estimator=None) -> Kernel | None:
    """The compiled loop of a plug-in controller or estimator (once per process and pair).

    None for built-ins.
    """
    if entry.step is None and estimator is None:
        return None
    key = "kernel" if estimator is None else ("kernel", id(estimator))
    if key not in entry.kernel_cache:
        entry.kernel_cache[key] = make_kernel(entry.step, estimator=estimator)
    return entry.kernel_cache[key]


def _shared(
    s: RunSettings,
    v: Vehicle,
    o: ModelOptions,
    surfaces: list[Plane],
    duration_s: float,
    wall: Plane | None = None,
) -> SharedSetup:
    """The packing common to every scenario kind, without the run's state, references and draws."""
    yaw_paper = o.yaw_reaction == "paper"
    entry = controller_entry(s.controller)
    context = PackContext(
        vehicle=v,
        options=o,
        pre_impact=s.resolved_pre_impact(),
        nominal_controller=s.nominal_controller,
    )
    imu = s.imu.resolved(v.imu_position_m, CONTROL_RATE_HZ)
    scfg, n_imu = pack_sensors(imu, s.detection, v, duration_s)
    est = pack_estimation(s, imu, scfg, v)
    params = s.resolved_controller_params()
    resolved = {
        "model": s.model,
        "model_options": o.model_dump(mode="json"),
        "controller": s.controller,
        "controller_params": params.model_dump(mode="json"),
        "pre_impact": context.pre_impact,
        "nominal_controller": s.nominal_controller,
        "imu": imu.model_dump(mode="json"),
        "rotor_slew_limit_rad_s2": slew_limit_rad_s2(s, v),
        **(est.resolved or {}),
    }
    setup = RunSetup(
        x0=np.zeros(L.NX),
        t0=0.0,
        tf=float(s.final_time_s),
        veh=pack_vehicle(v),
        feat=pack_features(v, s.friction_coefficient, o.bumper_force_scale),
        shapes=pack_surfaces(surfaces),
        opts=pack_run_options(s, o, v, duration_s),
        ctrl=pack_controller(entry, params, context, yaw_paper),
        feature_names=v.feature_names(),
        shape_names=tuple(x.name for x in surfaces),
        references={},
        vehicle=v,
        options=o,
        output_rate_hz=float(s.output_rate_hz),
        wall=wall,
        scfg=scfg,
        n_imu=n_imu,
        ecfg=est.ecfg,
        snoise=est.snoise,
        estimator=est.name,
        estimator_settings=est.settings,
        controller=s.controller,
        kernel=_kernel(entry, est.step),
        resolved=resolved,
        **pack_schedule(s),
    )
    setup.warnings.extend(f"vehicle {v.name}: {w}" for w in v.plausibility_warnings())
    if s.controller == "recovery" and context.pre_impact == "spin-down":
        if setup.opts[L.O_SLEW_MAX] <= 0.0:
            setup.warnings.append(
                f"no rotor slew limit (vehicle {v.name} has none): the pre-impact spin-down "
                "stops the rotors at the first tick"
            )
    check_imu(setup)  # of the shared packing: no draw changes what it checks
    setup.keep_grid_and_pairs()
    return SharedSetup(setup=setup, imu=imu, est=est, entries=(entry, est.entry))


def _for_run(
    shared: SharedSetup, s: RunSettings, refs: dict[str, float], **fields: Any
) -> RunSetup:
    """One run's :class:`RunSetup`: the shared packing with its references and seeded draws.

    ``refs``: ``altitude_m``, ``roll_rad``, ``pitch_rad``, ``yaw_rad``;
    ``fields``: ``x0``, ``t0``. The shared arrays that no run changes
    (vehicle, features, surfaces, options) are the same objects in every run.
    """
    base = shared.setup
    scfg = base.scfg.copy()
    noise = draw_imu_noise(shared.imu, s.seed, base.n_imu, scfg)
    ecfg, snoise = draw_estimation(shared.est, s.seed, base.n_imu, scfg)
    ctrl = base.ctrl.copy()
    set_references(ctrl, refs)
    # dataclasses.replace without its checks (a plain dataclass, every field set in
    # __init__): a shallow copy with the run's fields in place, a sixth of its time
    run = copy.copy(base)
    run.__dict__.update(
        references=refs,
        ctrl=ctrl,
        scfg=scfg,
        noise=noise,
        ecfg=ecfg,
        snoise=snoise,
        warnings=list(base.warnings),
        approach={},
        resolved=dict(base.resolved),
        **fields,
    )
    return run


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
    setup.x0, setup.t0, setup.approach = solve_approach(
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

    The centre is a plane's point, a cylinder's axis point or a box's
    centre; the entry is found by bisection on the shape's signed distance
    along -X from the centre (exact to rounding; a plane's point is on it).

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
    inside = 0.0
    outside = 1.0
    while shape_distance(centre[0] - outside, centre[1], centre[2], row, 0) <= 0.0:
        outside *= 2.0
    for _ in range(200):
        mid = 0.5 * (inside + outside)
        if mid in (inside, outside):
            break
        if shape_distance(centre[0] - mid, centre[1], centre[2], row, 0) > 0.0:
            outside = mid
        else:
            inside = mid
    return float(centre[0] - inside), centre


def prepare(
    scenario: WallApproach | FlightScenario | ImpactTrial, kernel: Kernel | None = None
) -> RunSetup:
    """Validated scenario -> packed run (refused if it starts in contact...: ``checks.py``).

    ``kernel``: a run loop (``core.run.make_kernel``) in place of the one the
    scenario's controller and estimator select; a wall approach's shooting
    runs fly with it too. The first call in a process whose compiled loop is
    not in Numba's disk cache says that it compiles (``core.announce_compilation``).
    """
    started = cpu_time()
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
    setup.prepare_cpu_s = cpu_time() - started
    return setup
