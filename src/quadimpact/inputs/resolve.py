"""Settings -> the resolved shared part of a run: every default decided, once each.

:func:`resolve_shared` turns a scenario's validated settings and its vehicle
into the frozen :class:`~quadimpact.inputs.resolved.ResolvedShared`: every
model switch, the controller's and the estimator's parameters with their
defaults and what depends on the vehicle and the sensors applied, the IMU,
the control rate, the integrator's tolerances and the slew limit. The
defaults of these are decided here and nowhere else (the packers write
numbers; ``tests/simulation/test_resolve.py``). The rest of a run's
resolution (the attitude, the start, the references, a plug-in step's
address, the kept shared parts) is ``simulation/resolve.py``'s.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from quadimpact.errors import InputError
from quadimpact.inputs.allocation import trim_rotor_speeds
from quadimpact.inputs.controllers import RecoveryParams, controller_entry
from quadimpact.inputs.estimators import (
    EstimatorContext,
    estimator_entry,
    resolve_estimator_params,
)
from quadimpact.inputs.model import ModelOptions
from quadimpact.inputs.resolved import ResolvedController, ResolvedEstimator, ResolvedShared
from quadimpact.inputs.run_settings import RunSettings
from quadimpact.inputs.vehicle import Vehicle

__all__ = [
    "CONTROL_RATE_HZ",
    "DEFAULT_ATOL",
    "DEFAULT_RTOL",
    "RPM",
    "check_rotor_count",
    "control_rate_hz",
    "initial_speeds",
    "resolve_controller",
    "resolve_estimator",
    "resolve_shared",
    "slew_limit_rad_s2",
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
