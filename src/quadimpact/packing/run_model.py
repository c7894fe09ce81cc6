"""A resolved run as the compiled core's :class:`~quadimpact.core.records.Model`, in one call.

:func:`pack` writes a :class:`~quadimpact.inputs.resolved.ResolvedRun`
(``simulation/resolve.py``: every default already applied) into every block
of ``core/layout.py``. It decides nothing: a value the resolved description
does not hold as a number is an error here, not a default. It packs in two
parts: :func:`pack_shared`, what a run's initial state, references and seed
do not change (vehicle, features, shapes and their pair table, options,
controller without references, sensors and estimator without their random
draws, the output times), once per resolved shared part (the trials of a
study share one); and :func:`pack_own`, a run's own part (its references and
the seeded draws of the IMU, the added sensors and the estimator's initial
error).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.core.geometry import pair_table
from quadimpact.core.records import Model, model, model_array, model_span
from quadimpact.core.sensors.component import PackContext as ComponentContext
from quadimpact.inputs.controllers import ControllerEntry, PackContext
from quadimpact.inputs.resolved import ResolvedRun, ResolvedShared
from quadimpact.inputs.sensors import ResolvedImu
from quadimpact.packing.component_block import (
    draw_component_noise,
    named_components,
    pack_components,
)
from quadimpact.packing.controller_block import pack_controller, pack_waypoint, set_references
from quadimpact.packing.estimator_block import Estimation, draw_estimation, pack_estimation
from quadimpact.packing.options_block import pack_run_options, pack_schedule
from quadimpact.packing.sensor_block import draw_imu_noise, pack_sensors
from quadimpact.packing.vehicle_block import pack_features, pack_vehicle
from quadimpact.packing.world_block import pack_surfaces

__all__ = ["PackedRun", "SharedPacking", "output_grid", "pack", "pack_own", "pack_shared"]


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


def pack_shared(r: ResolvedShared) -> SharedPacking:
    """Every block of a run from its resolved shared part, once per object (kept in its memo).

    The run starts at ``t0 = 0`` and ends at ``r.final_time_s`` (a run's own
    start: :func:`pack`); the IMU's draws and the integrator's step budget are
    sized by ``r.duration_s``.
    """
    hit = r.memo.get("packing")
    if hit is not None:
        return hit
    s, v, o = r.settings, r.vehicle, r.options
    c = r.controller
    context = PackContext(
        vehicle=v,
        options=o,
        pre_impact=c.pre_impact,
        nominal_controller=c.nominal_controller,
    )
    imu = r.imu
    scfg, n_imu = pack_sensors(imu, s.detection, v, r.duration_s)
    scfg = pack_components(
        scfg,
        named_components(s, r.instruments),
        ComponentContext(
            gravity_m_s2=float(v.gravity_m_s2),
            imu_rate_hz=float(imu.rate_hz),
            duration_s=float(r.duration_s),
        ),
    )
    est = pack_estimation(r, scfg)
    ctrl = pack_controller(c.entry, c.params, context, o.yaw_reaction == "paper")
    if c.step_address:
        ctrl[CTL.C_STEP] = c.step_address
    feat = pack_features(v, s.friction_coefficient, o.bumper_force_scale)
    shapes = pack_surfaces(list(r.surfaces))
    tf = r.final_time_s
    packed = model(
        x0=np.zeros(L.NX),
        t0=0.0,
        tf=tf,
        veh=pack_vehicle(v),
        feat=feat,
        shapes=shapes,
        pairs=pair_table(feat, shapes),
        opts=pack_run_options(r, r.duration_s),
        ctrl=ctrl,
        t_out=output_grid(0.0, tf, r.output_rate_hz),
        scfg=scfg,
        ecfg=est.ecfg,
        snoise=est.snoise,
        **pack_schedule(s),
    )
    resolved = {
        "model": s.model,
        "model_options": o.model_dump(mode="json"),
        "controller": s.controller,
        "controller_params": c.given.model_dump(mode="json"),
        "pre_impact": c.pre_impact,
        "nominal_controller": c.nominal_controller,
        "imu": imu.model_dump(mode="json"),
        "rotor_slew_limit_rad_s2": r.slew_limit_rad_s2,
        **(est.resolved or {}),
    }
    if r.instruments:
        resolved["instruments"] = {k: x.model_dump(mode="json") for k, x in r.instruments.items()}
    shared = SharedPacking(packed, n_imu, imu, est, c.entry, context, resolved, dict(r.instruments))
    r.memo["packing"] = shared
    return shared


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


@dataclass(frozen=True)
class PackedRun:
    """A packed run: the compiled core's arrays and what they were packed from.

    Attributes
    ----------
    model : Model
        Every array of the run (a wall approach's start still the shared zero
        state: its shooting solves it).
    shared : SharedPacking
        The shared part it was completed from.
    free_opts : ndarray or None
        A wall approach's options for the free flight of its shooting (no
        crash rule, sized for the impact time); ``None`` otherwise.
    """

    model: Model
    shared: SharedPacking
    free_opts: np.ndarray | None = None


def pack(r: ResolvedRun) -> PackedRun:
    """A resolved run's arrays, in one call: the shared part (packed once per resolved
    shared part), then the run's own (references, seeded draws, start, waypoint)."""
    shared = pack_shared(r.shared)
    fields = {
        name: model_array(name, a) for name, a in pack_own(shared, r.seed, r.references).items()
    }
    if r.x0 is not None:
        fields["x0"] = model_array("x0", r.x0)
    if r.t0 != 0.0:
        tf = r.shared.final_time_s
        fields["span"] = model_span(r.t0, tf)
        fields["t_out"] = output_grid(r.t0, tf, r.shared.output_rate_hz)
    if r.waypoint is not None:
        pack_waypoint(fields["ctrl"], r.waypoint, r.hold_m)
    free_opts = None
    if r.shot is not None:
        free_opts = pack_run_options(r.shared, r.shot.impact_time_s, free=True)
    return PackedRun(shared.model._replace(**fields), shared, free_opts)
