"""The controller's block: ``ctrl`` (``C_*``: the kind, the references, the inverse
allocation, the rotor range, the controller's own parameters, a learned residual; a
waypoint flight's slots)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from pydantic import BaseModel

from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.core.controllers import common as PID
from quadimpact.core.controllers import recovery as REC
from quadimpact.inputs.controllers import (
    CascadePidParams,
    ControllerEntry,
    PackContext,
    RecoveryParams,
    controller_entry,
    param_slots,
)
from quadimpact.inputs.policy_file import load_policy
from quadimpact.inputs.vehicle import Vehicle
from quadimpact.packing.constants import RPM
from quadimpact.packing.vehicle_block import allocation_inverse, vehicle_memo
from quadimpact.rotations import euler_zyx_to_quat, quat_to_matrix

__all__ = [
    "BUILTIN_PACKERS",
    "pack_controller",
    "pack_fields",
    "pack_waypoint",
    "policy_block",
    "reference_z_axis",
    "refuse_nan",
    "set_references",
]


def pack_controller(
    entry: ControllerEntry,
    params: object,
    context: PackContext,
    yaw_paper: bool,
) -> np.ndarray:
    """Controller settings as the ``C_*`` vector, references 0 (a run's: :func:`set_references`).

    The common head (kind, inverse allocation, the vehicle's rotor range)
    and the controller's parameter block (its registry entry's packer).
    """
    v: Vehicle = context.vehicle
    ctrl = np.zeros(CTL.NCTRL)
    ctrl[CTL.C_KIND] = entry.kind
    n = v.rotor_count
    ctrl[CTL.C_N_ROTORS] = n
    ctrl[CTL.C_ALLOC_INV : CTL.C_ALLOC_INV + CTL.N_WRENCH * n] = vehicle_memo(
        f"alloc-inv-{yaw_paper}", v, lambda: allocation_inverse(v, yaw_paper).ravel()
    )
    lo, hi = v.rotor_speed_range_rpm
    ctrl[CTL.C_OMEGA_MIN] = lo * RPM
    ctrl[CTL.C_OMEGA_MAX] = hi * RPM
    pack = entry.pack or BUILTIN_PACKERS.get(entry.kind, pack_fields)
    block = np.asarray(pack(params, context), dtype=float)
    if block.shape != (CTL.NPARAM,):
        raise ValueError(f"controller {entry.name!r}: its packer must return {CTL.NPARAM} numbers")
    refuse_nan(block, f"controller {entry.name!r}: its parameter block")
    ctrl[CTL.C_PARAMS : CTL.C_PARAMS + CTL.NPARAM] = block
    policy = getattr(params, "policy", None) if entry.kind == L.CTRL_RECOVERY else None
    if policy is not None:
        ctrl[CTL.C_POLICY : CTL.C_POLICY + CTL.NPOLICY] = policy_block(policy)
    return ctrl


def refuse_nan(block: np.ndarray, what: str) -> None:
    """Refuse a packed block with a NaN: a parameter left ``None`` (NumPy writes ``None``
    as NaN). Defaults are decided when a run is resolved (``simulation/resolve.py``),
    never here.

    Raises
    ------
    ValueError
        Naming the block and the first slot.
    """
    bad = np.flatnonzero(np.isnan(block))
    if bad.size:
        raise ValueError(
            f"{what}: slot {int(bad[0])} is not a number (a parameter left None? "
            "defaults are applied when a run is resolved)"
        )


def policy_block(policy: str) -> np.ndarray:
    """The ``C_POLICY`` block of a learned residual (``learned`` or a ``.npz`` file), in
    ``core/controllers/residual.py``'s layout, zero-padded to ``NPOLICY``."""
    block = np.zeros(CTL.NPOLICY)
    weights = load_policy(policy).block()
    block[: weights.size] = weights
    return block


def set_references(ctrl: np.ndarray, refs: Mapping[str, float]) -> None:
    """Write the references into a ``C_*`` vector, in place (m and rad).

    ``refs`` holds ``altitude_m``, ``roll_rad``, ``pitch_rad``, ``yaw_rad``;
    the only slots of the controller's vector that depend on them (with the
    reference's body z axis, :func:`reference_z_axis`).
    """
    ctrl[CTL.C_H_REF] = refs["altitude_m"]
    ctrl[CTL.C_PHI_REF] = refs["roll_rad"]
    ctrl[CTL.C_THETA_REF] = refs["pitch_rad"]
    ctrl[CTL.C_PSI_REF] = refs["yaw_rad"]
    ctrl[CTL.C_Z_REF : CTL.C_Z_REF + 3] = reference_z_axis(refs)


def pack_waypoint(ctrl: np.ndarray, waypoint: Any, start_m: Any) -> None:
    """The waypoint flight's slots of a ``C_*`` vector, in place (``waypoint``: a
    :class:`~quadimpact.inputs.waypoint.Waypoint`; ``start_m``: the position held first)."""
    ctrl[CTL.C_WAYPOINT_ON] = 1.0
    ctrl[CTL.C_HOLD_POS : CTL.C_HOLD_POS + 3] = start_m
    ctrl[CTL.C_WAYPOINT : CTL.C_WAYPOINT + 3] = (waypoint.x_m, waypoint.y_m, 0.0)
    ctrl[CTL.C_WAYPOINT_T] = waypoint.time_s
    ctrl[CTL.C_POS_GAINS : CTL.C_POS_GAINS + 4] = (
        waypoint.kp_1_s,
        waypoint.kv_1_s,
        waypoint.v_max_m_s,
        math.radians(waypoint.tilt_max_deg),
    )


def reference_z_axis(refs: Mapping[str, float]) -> np.ndarray:
    """The reference attitude's body z axis in inertial axes (NED, unit): the third column
    of ``C`` of the ZYX attitude (``roll_rad``, ``pitch_rad``, ``yaw_rad``), from which the
    summary's tilt is measured."""
    q = euler_zyx_to_quat(refs["roll_rad"], refs["pitch_rad"], refs["yaw_rad"])
    return quat_to_matrix(q)[:, 2]


def pack_fields(params: BaseModel, ctx: PackContext) -> np.ndarray:
    """The default packing: the model's fields in order (:func:`param_slots`)."""
    block = np.zeros(CTL.NPARAM)
    for name, (offset, width) in param_slots(type(params)).items():
        value = getattr(params, name)
        block[offset : offset + width] = np.asarray(value, dtype=float).reshape(width)
    return block


def _pack_pid(params: BaseModel, ctx: PackContext) -> np.ndarray:
    block = np.zeros(CTL.NPARAM)
    block[PID.P_GAINS : PID.P_GAINS + 15] = params.gains()
    if isinstance(params, CascadePidParams):  # the paper's law has no floor (slot unread)
        block[PID.P_THRUST_COS_FLOOR] = params.thrust_cos_floor
    return block


def _pack_recovery(params: BaseModel, ctx: PackContext) -> np.ndarray:
    nominal = controller_entry(ctx.nominal_controller)
    block = _pack_pid(nominal.params(), ctx)
    p: RecoveryParams = params  # type: ignore[assignment]
    block[REC.R_NOMINAL_KIND] = nominal.kind
    block[REC.R_PRE_IMPACT] = REC.PRE_IMPACT_KINDS[ctx.pre_impact]
    block[REC.R_K_ATT] = p.k_att_1_s
    block[REC.R_K_RATE : REC.R_K_RATE + 3] = p.k_rate_1_s
    block[REC.R_A_MAG] = p.a_mag_m_s2  # resolved: a number (None, the vehicle's g: resolve)
    block[REC.R_K_Z : REC.R_K_Z + 4] = p.k_z_1_s
    block[REC.R_Q_TOL] = p.tilt_error_tol
    block[REC.R_RATE_TOL] = p.rate_tol_rad_s
    block[REC.R_W_TOL] = p.w_tol_m_s
    euler = p.level_test == "euler"
    block[REC.R_LEVEL_TEST] = REC.LEVEL_EULER if euler else REC.LEVEL_TILT_ERROR
    block[REC.R_EULER_TOL] = p.euler_tol_rad
    lean = p.lean_cut_deg
    block[REC.R_LEAN_CUT] = 2.0 if lean is None else math.sin(math.radians(lean))
    block[REC.R_LEAN_FORCE] = p.lean_cut_force_m_s2
    level = ctx.options.detection_tick_reference == "level"
    block[REC.R_FIRST_TICK_LEVEL] = 1.0 if level else 0.0
    block[REC.R_HOVER] = 1.0 if p.hover else 0.0
    block[REC.R_HOVER_GAINS : REC.R_HOVER_GAINS + 5] = (
        p.hover_kp_1_s,
        p.hover_kv_1_s,
        p.hover_v_max_m_s,
        p.hover_a_max_m_s2,  # resolved: a number (None, g/2: resolve)
        p.hover_k_yaw_1_s,
    )
    block[REC.R_HOVER_MODE] = REC.HOLD_STOP if p.hover_hold == "stop" else REC.HOLD_ENTRY
    if p.hover_set_point_m is not None:
        block[REC.R_HOVER_MODE] = REC.HOLD_GIVEN
        block[REC.R_HOVER_SET : REC.R_HOVER_SET + 3] = p.hover_set_point_m
    return block


#: The built-in controllers' packers, by kind (a plug-in's is its registry entry's, else
#: :func:`pack_fields`).
BUILTIN_PACKERS = {
    L.CTRL_PAPER: _pack_pid,
    L.CTRL_CASCADE_PID: _pack_pid,
    L.CTRL_RECOVERY: _pack_recovery,
}
