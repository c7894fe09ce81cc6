"""The vehicle's blocks: ``veh`` (``V_*``: mass, inertia, rotors) and ``feat`` (``F_*``: its
contact features, body frame), packed once per vehicle object (the allocation matrix:
``inputs/allocation.py``)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from quadimpact.core import feature_slots as FS
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.errors import InputError
from quadimpact.inputs.allocation import (  # here too: the packing's names of them
    allocation_inverse,
    allocation_matrix,
    vehicle_memo,
    vehicle_memo_value,
)
from quadimpact.inputs.features import ContactFeature
from quadimpact.inputs.vehicle import Vehicle
from quadimpact.linalg import inverse

__all__ = [
    "FEATURE_KINDS",
    "allocation_inverse",
    "allocation_matrix",
    "feature_records",
    "pack_features",
    "pack_vehicle",
    "vehicle_memo",
    "vehicle_memo_value",
]


def pack_vehicle(v: Vehicle) -> np.ndarray:
    """Vehicle parameters as the ``V_*`` vector (SI, body frame); computed once per vehicle."""
    return vehicle_memo("veh", v, lambda: _pack_vehicle(v))


def _pack_vehicle(v: Vehicle) -> np.ndarray:
    veh = np.zeros(VS.NVEH)
    inertia = v.inertia
    veh[VS.V_MASS] = v.mass_kg
    veh[VS.V_INERTIA : VS.V_INERTIA + 9] = inertia.ravel()
    veh[VS.V_INERTIA_INV : VS.V_INERTIA_INV + 9] = inverse(inertia).ravel()
    n = v.rotor_count
    veh[VS.V_N_ROTORS] = n
    veh[VS.V_ROTOR_POS : VS.V_ROTOR_POS + 3 * n] = v.rotor_positions.ravel()
    veh[VS.V_SPIN : VS.V_SPIN + n] = v.spins
    veh[VS.V_KT : VS.V_KT + n] = v.thrust_coefficients
    veh[VS.V_DT : VS.V_DT + n] = v.drag_torque_coefficients
    veh[VS.V_JR] = v.rotor_inertia_kg_m2
    veh[VS.V_GRAVITY] = v.gravity_m_s2
    veh[VS.V_TAU_M] = v.motor_time_constant_s
    return veh


#: Feature kinds by their names in vehicle data (``core.layout.FeatureKind``).
FEATURE_KINDS: dict[str, int] = {
    "ring": L.FEAT_RING,
    "sphere": L.FEAT_SPHERE,
    "point": L.FEAT_POINT,
}


def pack_features(
    v: Vehicle, friction_coefficient: float, force_scale: Sequence[float] | None = None
) -> np.ndarray:
    """The vehicle's contact features as an (n, NFEAT) array (body frame, SI).

    ``friction_coefficient``: the scenario's, for the features that set none.
    ``force_scale``: a factor on each feature's normal force, in the
    vehicle's feature order (the model switch ``bumper_force_scale``: bumpers
    1-4 of a four-ring vehicle); None or all ones: the contact law itself.
    """
    feat = vehicle_memo("feat", v, lambda: _pack_features(v.contact_features()))
    feat[np.isnan(feat[:, FS.F_MU]), FS.F_MU] = friction_coefficient
    if force_scale is not None and any(f != 1.0 for f in force_scale):
        if len(force_scale) != feat.shape[0]:
            raise InputError(
                f"bumper_force_scale: {len(force_scale)} factors for the {feat.shape[0]} contact "
                "features of this vehicle"
            )
        feat[:, FS.F_FORCE_SCALE] = force_scale
    return feat


def _pack_features(features: Sequence[ContactFeature]) -> np.ndarray:
    feat = np.zeros((len(features), FS.NFEAT))
    for i, f in enumerate(features):
        feat[i, FS.F_KIND] = FEATURE_KINDS[f.kind]
        feat[i, FS.F_CENTRE : FS.F_CENTRE + 3] = f.centre_m
        feat[i, FS.F_NORMAL : FS.F_NORMAL + 3] = f.normal
        feat[i, FS.F_RADIUS] = f.radius_m
        feat[i, FS.F_K] = f.stiffness
        feat[i, FS.F_N] = f.exponent
        feat[i, FS.F_E] = f.restitution
        feat[i, FS.F_MU] = np.nan if f.friction_coefficient is None else f.friction_coefficient
        feat[i, FS.F_FORCE_SCALE] = 1.0
    return feat


def feature_records(feat: np.ndarray, names: Sequence[str]) -> list[dict[str, Any]]:
    """The packed contact features as plain data (``scenario.json``), body FRD, SI.

    Per feature: ``name``, ``kind`` (ring, sphere, point), ``centre_m``,
    ``normal`` (rings), ``radius_m``, ``stiffness``, ``exponent``,
    ``restitution``, ``friction_coefficient`` (the one in force).
    """
    kinds = {v: k for k, v in FEATURE_KINDS.items()}
    out = []
    for name, row in zip(names, feat, strict=True):
        kind = kinds[int(row[FS.F_KIND])]
        rec: dict[str, Any] = {
            "name": str(name),
            "kind": kind,
            "centre_m": [float(c) for c in row[FS.F_CENTRE : FS.F_CENTRE + 3]],
        }
        if kind == "ring":
            rec["normal"] = [float(c) for c in row[FS.F_NORMAL : FS.F_NORMAL + 3]]
        if kind != "point":
            rec["radius_m"] = float(row[FS.F_RADIUS])
        rec.update(
            stiffness=float(row[FS.F_K]),
            exponent=float(row[FS.F_N]),
            restitution=float(row[FS.F_E]),
            friction_coefficient=float(row[FS.F_MU]),
        )
        out.append(rec)
    return out
