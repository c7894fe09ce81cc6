"""Settings -> the resolved shared part of a run: every default decided, once each.

:func:`resolve_shared` turns a scenario's validated settings and its vehicle
into the frozen :class:`~quadimpact.inputs.resolved.ResolvedShared`: every
model switch, the controller's and the estimator's parameters with their
defaults and what depends on the vehicle and the sensors applied, the IMU,
the control rate, the integrator's tolerances and the slew limit. The
defaults of these are decided here and nowhere else (the packers write
numbers; ``tests/simulation/test_resolve.py``). The rest of a run's
resolution (the attitude, the start, the references, a plug-in step's
address, the kept shared parts, an obstacle's front) is
``simulation/resolve.py``'s; each kind's own part (:func:`flight_start`,
:func:`wall_start`, :func:`trial_start`: attitude, trim, start state,
references) is here.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from quadimpact.core import layout as L
from quadimpact.errors import InputError
from quadimpact.inputs.allocation import trim_rotor_speeds
from quadimpact.inputs.controllers import RecoveryParams, controller_entry
from quadimpact.inputs.estimators import (
    EstimatorContext,
    estimator_entry,
    resolve_estimator_params,
)
from quadimpact.inputs.model import ModelOptions
from quadimpact.inputs.resolved import (
    ResolvedController,
    ResolvedEstimator,
    ResolvedRun,
    ResolvedShared,
    ResolvedShot,
)
from quadimpact.inputs.run_settings import RunSettings
from quadimpact.inputs.vehicle import Vehicle
from quadimpact.linalg import matvec_t
from quadimpact.rotations import euler_zyx_to_quat, quat_to_matrix

__all__ = [
    "CONTROL_RATE_HZ",
    "DEFAULT_ATOL",
    "DEFAULT_RTOL",
    "PAPER_FIT_OFFSET_RAD",
    "PAPER_FIT_SCALE",
    "RPM",
    "check_rotor_count",
    "control_rate_hz",
    "flight_start",
    "initial_speeds",
    "initial_state",
    "resolve_controller",
    "resolve_estimator",
    "resolve_shared",
    "slew_limit_rad_s2",
    "trial_start",
    "wall_attitude",
    "wall_start",
]

CONTROL_RATE_HZ = 200.0
"""The control ticks' rate when a scenario sets none, Hz."""

# Integrator defaults, chosen by measurement (docs/NUMERICS.md,
# benchmarks/bench_tolerance.py): tightening both tenfold changes delta_init
# of the paper example by far less than 1e-4 relative.
DEFAULT_RTOL = 1e-8
DEFAULT_ATOL = 1e-10

RPM = 2.0 * math.pi / 60.0
"""rad/s per rpm."""


def _builtin_only(role: str, entry: Any) -> float:
    if entry.step is not None:
        raise TypeError(f"{role} {entry.name!r}: a plug-in step needs address_of")
    return 0.0


def control_rate_hz(s: Any) -> float:
    """The rate of a run's control ticks, Hz: its ``control_rate_hz``, else
    :data:`CONTROL_RATE_HZ` (200 Hz)."""
    rate = getattr(s, "control_rate_hz", None)
    return CONTROL_RATE_HZ if rate is None else float(rate)


def slew_limit_rad_s2(s: RunSettings, v: Vehicle) -> float | None:
    """The rotor slew limit (rad/s^2) of a run: its own, the vehicle's (``"vehicle"``) or
    none (``None``)."""
    if s.rotor_slew_limit_rad_s2 == "vehicle":
        if v.rotor_slew_limit_rpm_per_s is None:
            return None
        return v.rotor_slew_limit_rpm_per_s * RPM
    return s.rotor_slew_limit_rad_s2


def resolve_controller(s: RunSettings, v: Vehicle, address: float = 0.0) -> ResolvedController:
    """The run's controller: its entry, its parameters with every default applied.

    The recovery law's parameters: ``[controller_params]`` over the model's
    ``recovery_law`` tuning over ``RecoveryParams``' defaults
    (``RunSettings.resolved_controller_params``); then ``a_mag_m_s2 = None``
    is the vehicle's g and ``hover_a_max_m_s2 = None`` half of it (m/s^2).
    ``address``: a plug-in step's entry address (0: a built-in).
    """
    entry = controller_entry(s.controller)
    given = s.resolved_controller_params()
    params = given
    if isinstance(given, RecoveryParams):
        g = float(v.gravity_m_s2)
        update = {}
        if given.a_mag_m_s2 is None:
            update["a_mag_m_s2"] = g
        if given.hover_a_max_m_s2 is None:
            update["hover_a_max_m_s2"] = 0.5 * g
        params = given.model_copy(update=update) if update else given
    return ResolvedController(
        entry=entry,
        given=given,
        params=params,
        pre_impact=s.resolved_pre_impact(),
        nominal_controller=s.nominal_controller,
        step_address=address,
    )


def resolve_estimator(
    s: RunSettings, v: Vehicle, imu: Any, address: float = 0.0
) -> ResolvedEstimator:
    """The run's estimator: its entry, its parameters with every default applied
    (:func:`~quadimpact.inputs.estimators.resolve_estimator_params`), its sensors.

    ``imu``: the resolved IMU; ``address``: a plug-in step's entry address (0: a built-in).
    """
    entry = estimator_entry(s.estimator)
    given = s.resolved_estimator_params()
    context = EstimatorContext(
        imu=imu,
        magnetometer=s.magnetometer,
        pose_sensor=s.pose_sensor,
        vehicle=v,
        instruments=dict(s.instruments),
    )
    return ResolvedEstimator(
        entry=entry,
        given=given,
        params=resolve_estimator_params(entry.kind, given, context),
        context=context,
        step_address=address,
    )


def check_rotor_count(s: RunSettings, o: ModelOptions, v: Vehicle) -> None:
    """Refuse the settings that name a quadrotor's motors 1-4 for another rotor count."""
    if v.rotor_count == 4:
        return
    if s.power_off is not None:
        raise InputError(
            f"power_off: a schedule of motors 1-4 is for a quadrotor (vehicle {v.name} has "
            f"{v.rotor_count} rotors)"
        )
    if o.cut_step_motors:
        raise InputError(
            f"model_options.cut_step_motors: motors 1-4 of a quadrotor (vehicle {v.name} has "
            f"{v.rotor_count} rotors)"
        )


def resolve_shared(
    s: RunSettings,
    v: Vehicle,
    surfaces: list[Any],
    duration_s: float,
    wall: Any = None,
    front: tuple[float, np.ndarray] | None = None,
    address_of: Callable[[str, Any], float] | None = None,
) -> ResolvedShared:
    """The part of a run that its state, references and seed do not change, resolved.

    ``v``: the scenario's vehicle (``s.build_vehicle()``); ``surfaces``: the
    contact surfaces in packing order; ``duration_s``: how long the run
    lasts (s); ``wall``: its wall plane; ``front``: an impact trial's
    obstacle front (``simulation.resolve.obstacle_front``, m). ``address_of(role,
    entry)``: the entry address of a plug-in's step (``role``: "controller" or
    "estimator"), compiled alone (``simulation/resolve.py`` gives it); ``None``:
    built-ins only.
    """
    o = s.resolved_model_options()
    check_rotor_count(s, o, v)
    rate = control_rate_hz(s)
    imu = s.imu.resolved(v.imu_position_m, rate)
    entry = controller_entry(s.controller)
    est_entry = estimator_entry(s.estimator)
    address = address_of if address_of is not None else _builtin_only
    controller = resolve_controller(s, v, address("controller", entry))
    slew = slew_limit_rad_s2(s, v)
    warnings = [f"vehicle {v.name}: {w}" for w in v.plausibility_warnings()]
    if s.controller == "recovery" and controller.pre_impact == "spin-down" and not slew:
        warnings.append(
            f"no rotor slew limit (vehicle {v.name} has none): the pre-impact spin-down "
            "stops the rotors at the first tick"
        )
    return ResolvedShared(
        settings=s,
        vehicle=v,
        options=o,
        surfaces=tuple(surfaces),
        wall=wall,
        duration_s=float(duration_s),
        final_time_s=float(s.final_time_s),
        output_rate_hz=float(s.output_rate_hz),
        control_rate_hz=rate,
        rtol=DEFAULT_RTOL if s.rtol is None else float(s.rtol),
        atol=DEFAULT_ATOL if s.atol is None else float(s.atol),
        slew_limit_rad_s2=slew,
        imu=imu,
        controller=controller,
        estimator=resolve_estimator(s, v, imu, address("estimator", est_entry)),
        instruments=dict(s.instruments),
        front=front,
        warnings=tuple(warnings),
    )


def initial_speeds(v: Vehicle, roll: float, pitch: float, rule: str, yaw_paper: bool) -> np.ndarray:
    """The rotor speeds a run starts with (rad/s), by the model's ``initial_rotor_speeds``.

    ``"level-hover"``: every rotor at the level hover speed; ``"trimmed"``:
    the speeds of the thrust ``m g / (cos(roll) cos(pitch))`` and no torque.
    """
    weight = v.mass_kg * v.gravity_m_s2
    if rule == "level-hover":
        n = v.rotor_count  # rotors sharing one coefficient: sqrt(m g / (n kt)) each
        kt = v.thrust_coefficients
        if np.all(kt == kt[0]):
            return np.full(n, math.sqrt(weight / (float(n) * float(kt[0]))))
        return np.full(n, v.hover_speed_rad_s)
    return trim_rotor_speeds(v, weight / (math.cos(roll) * math.cos(pitch)), yaw_paper)


PAPER_FIT_OFFSET_RAD = 0.0042477  # the authors' fitted inclination mapping (docs/VARIANTS.md 4.4)
PAPER_FIT_SCALE = 1.3836686


# ------------------------------------------------------------------ attitude
def wall_attitude(
    heading_deg: float, inclination_deg: float, mapping: str = "exact"
) -> tuple[float, float, float]:
    """Roll, pitch, yaw (rad, ZYX) for a heading and an inclination toward the wall.

    ``exact``: yaw = psi and the body z axis in the inertial X-Z plane at
    angle iota from Z, tilted so the thrust points toward +X (docs/STUDIES.md 1):
    ``phi = -asin(sin psi sin iota)``, ``theta = asin(-cos psi sin iota / cos phi)``.
    ``paper-fit``: the authors' mapping (docs/VARIANTS.md 4.4) at psi = 0 and +-45 deg,
    ``exact`` elsewhere.
    """
    psi = math.radians(heading_deg)
    iota = math.radians(inclination_deg)
    if mapping == "paper-fit":
        if heading_deg == 0.0:
            return 0.0, -iota, psi
        if abs(heading_deg) == 45.0:
            a = -(iota - PAPER_FIT_OFFSET_RAD) / PAPER_FIT_SCALE
            return a, a, psi
    phi = -math.asin(math.sin(psi) * math.sin(iota))
    theta = math.asin(-math.cos(psi) * math.sin(iota) / math.cos(phi))
    return phi, theta, psi


def initial_state(
    position: np.ndarray,
    v_inertial: np.ndarray,
    q: np.ndarray,
    omega: np.ndarray,
    rotors: np.ndarray,
) -> np.ndarray:
    """The kernel's state vector (layout ``X_*``) from inertial position and velocity;
    ``rotors``: the speeds of the vehicle's ``n`` rotors (rad/s), 0 beyond them."""
    x = np.zeros(L.NX)
    x[L.X_POS : L.X_POS + 3] = position
    x[L.X_VEL : L.X_VEL + 3] = matvec_t(quat_to_matrix(q), v_inertial)
    x[L.X_QUAT : L.X_QUAT + 4] = q
    x[L.X_OMEGA : L.X_OMEGA + 3] = omega
    x[L.X_ROTOR : L.X_ROTOR + len(rotors)] = rotors
    return x


def flight_start(s: Any, shared: ResolvedShared) -> ResolvedRun:
    """A flight's own part: its start state as given (rotor speeds by the model's
    ``initial_rotor_speeds`` unless given), its references, its waypoint."""
    v = shared.vehicle
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


def wall_start(s: Any, shared: ResolvedShared) -> ResolvedRun:
    """A wall approach's own part: its attitude (``wall_attitude``, or the roll and pitch
    given), references and shooting (its start is solved after packing)."""
    v = shared.vehicle
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


def trial_start(s: Any, shared: ResolvedShared) -> ResolvedRun:
    """An impact trial's own part (docs/RECOVERY.md 5): its start state and references.

    The CM starts at ``X = -start_distance_m``, altitude ``altitude_m``, the
    attitude and the inertial velocity ``(speed_m_s, 0, 0)`` given, at rest in
    rotation, with the rotor speeds of the collective thrust
    ``m g cos(roll) cos(pitch)`` and zero torques. With obstacles, it starts
    ``start_distance_m`` before the first one's front (``shared.front``),
    beside its centre by ``lateral_offset_m``.
    """
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
