"""A run's whole :class:`~quadimpact.core.records.Model`, block by block, in two parts.

:func:`pack_shared` packs what a run's initial state, references and seed do
not change (every block of ``core/layout.py``: vehicle, features, shapes and
their pair table, options, controller without references, sensors and
estimator without their random draws, the output times); :func:`pack_own`
packs a run's own part from it (its references and the seeded draws of the
IMU, the added sensors and the estimator's initial error). Runs that share
the first part (the trials of a study) pack only the second
(``simulation/sharing.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from quadimpact.core import layout as L
from quadimpact.core.geometry import pair_table
from quadimpact.core.records import Model, model
from quadimpact.core.sensors.component import PackContext as ComponentContext
from quadimpact.errors import InputError
from quadimpact.inputs.controllers import ControllerEntry, PackContext, controller_entry
from quadimpact.inputs.model import ModelOptions
from quadimpact.inputs.run_settings import RunSettings
from quadimpact.inputs.sensors import ResolvedImu
from quadimpact.inputs.vehicle import Vehicle
from quadimpact.packing.component_block import draw_component_noise, pack_components
from quadimpact.packing.controller_block import pack_controller, set_references
from quadimpact.packing.estimator_block import Estimation, draw_estimation, pack_estimation
from quadimpact.packing.options_block import (
    control_rate_hz,
    pack_run_options,
    pack_schedule,
    slew_limit_rad_s2,
)
from quadimpact.packing.sensor_block import draw_imu_noise, pack_sensors
from quadimpact.packing.vehicle_block import pack_features, pack_vehicle
from quadimpact.packing.world_block import pack_surfaces

__all__ = ["SharedPacking", "output_grid", "pack_own", "pack_shared"]


def output_grid(t0: float, tf: float, rate_hz: float) -> np.ndarray:
    """Output times: ``t0``, the multiples of ``1/rate_hz`` inside (t0, tf), and ``tf`` (s)."""
    dt = 1.0 / rate_hz
    k0 = math.floor(t0 / dt) + 1
    k1 = math.ceil(tf / dt)
    inner = np.arange(k0, k1) * dt
    inner = inner[(inner > t0 + 1e-12) & (inner < tf - 1e-12)]
    return np.concatenate([[t0], inner, [tf]])


@dataclass(frozen=True)
class SharedPacking:
    """The part of a run's packing that its state, references and seed do not change.

    Attributes
    ----------
    model : Model
        Every block; the state zero, the references zero, no random draw.
    n_imu : int
        IMU samples the draws are made for.
    imu : ResolvedImu
        The IMU as resolved for the vehicle and the control rate.
    est : Estimation
        The packed estimator and added sensors (what their draws need).
    entry : ControllerEntry
        The controller's registry entry it was packed with.
    context : PackContext
        What the controller's packer was given (vehicle, options, pre-impact behaviour).
    instruments : dict
        The sensor components the run has, name -> settings (what their draws need).
    resolved : dict
        What the settings resolved to, as plain data (``scenario.json``'s ``resolved``).
    """

    model: Model
    n_imu: int
    imu: ResolvedImu
    est: Estimation
    entry: ControllerEntry
    context: PackContext
    resolved: dict[str, Any]
    instruments: dict[str, Any]


def _check_rotor_count(s: RunSettings, o: ModelOptions, v: Vehicle) -> None:
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


def pack_shared(
    s: RunSettings,
    v: Vehicle,
    o: ModelOptions,
    surfaces: list[Any],
    duration_s: float,
) -> SharedPacking:
    """Every block of a run from its validated settings, vehicle, options and surfaces.

    ``duration_s``: how long the run lasts (s; the IMU's draws and the
    integrator's step budget are sized by it). The run starts at ``t0 = 0``
    and ends at ``s.final_time_s`` (a run's own start: :func:`pack_own`).
    """
    _check_rotor_count(s, o, v)
    entry = controller_entry(s.controller)
    context = PackContext(
        vehicle=v,
        options=o,
        pre_impact=s.resolved_pre_impact(),
        nominal_controller=s.nominal_controller,
    )
    imu = s.imu.resolved(v.imu_position_m, control_rate_hz(s))
    scfg, n_imu = pack_sensors(imu, s.detection, v, duration_s)
    scfg = pack_components(
        scfg,
        s.instruments,
        ComponentContext(
            gravity_m_s2=float(v.gravity_m_s2),
            imu_rate_hz=float(imu.rate_hz),
            duration_s=float(duration_s),
        ),
    )
    est = pack_estimation(s, imu, scfg, v)
    params = s.resolved_controller_params()
    feat = pack_features(v, s.friction_coefficient, o.bumper_force_scale)
    shapes = pack_surfaces(surfaces)
    tf = float(s.final_time_s)
    packed = model(
        x0=np.zeros(L.NX),
        t0=0.0,
        tf=tf,
        veh=pack_vehicle(v),
        feat=feat,
        shapes=shapes,
        pairs=pair_table(feat, shapes),
        opts=pack_run_options(s, o, v, duration_s),
        ctrl=pack_controller(entry, params, context, o.yaw_reaction == "paper"),
        t_out=output_grid(0.0, tf, float(s.output_rate_hz)),
        scfg=scfg,
        ecfg=est.ecfg,
        snoise=est.snoise,
        **pack_schedule(s),
    )
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
    if s.instruments:
        resolved["instruments"] = {k: v.model_dump(mode="json") for k, v in s.instruments.items()}
    return SharedPacking(packed, n_imu, imu, est, entry, context, resolved, dict(s.instruments))


def pack_own(shared: SharedPacking, seed: int, refs: dict[str, float]) -> dict[str, np.ndarray]:
    """A run's own arrays: the controller with its references, the seeded draws.

    ``refs``: ``altitude_m`` (m), ``roll_rad``, ``pitch_rad``, ``yaw_rad``
    (rad). Returns ``ctrl``, ``scfg`` (with the IMU's drawn biases),
    ``noise``, ``ecfg`` (with the estimator's initial error), ``snoise`` and
    ``cnoise`` (the sensor components' draws);
    the shared arrays are not changed.
    """
    base = shared.model
    scfg = base.scfg.copy()
    noise = draw_imu_noise(shared.imu, seed, shared.n_imu, scfg)
    ecfg, snoise = draw_estimation(shared.est, seed, shared.n_imu, scfg)
    cnoise = draw_component_noise(shared.instruments, seed, shared.n_imu)
    ctrl = base.ctrl.copy()
    set_references(ctrl, refs)
    return {
        "ctrl": ctrl,
        "scfg": scfg,
        "noise": noise,
        "ecfg": ecfg,
        "snoise": snoise,
        "cnoise": cnoise,
    }
