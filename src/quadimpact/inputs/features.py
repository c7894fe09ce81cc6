"""Contact features of a vehicle: the parts of its protective structure that touch the world.

A feature is one row of the compiled core's feature table (``core/layout.py``,
``F_*``): its kind, its geometry in the body frame (FRD, from the CM, m) and
its own contact law parameters (Hunt-Crossley stiffness and exponent,
restitution, friction). A contact pair is a feature against a shape of the
world; its geometry function is chosen by the two kinds
(``core/geometry``).

Today's vehicles are protected by four bumper rings
(:meth:`quadimpact.inputs.vehicle.Vehicle.contact_features`), named
``"1"`` to ``"4"`` so that their output columns keep the names
``delta1_m`` ... ``force4_n``.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, Field

from quadimpact.inputs.types import MODEL_CONFIG, Real, Vec3

__all__ = ["FEATURE_KINDS", "ContactFeature", "feature_column"]

FEATURE_KINDS = ("ring",)
"""The feature kinds a vehicle can declare."""


class ContactFeature(BaseModel):
    """One contact feature of a vehicle (body frame FRD, SI).

    Attributes
    ----------
    name : str
        Its label in results (episodes, output columns).
    kind : {"ring"}
        ``ring``: a circle (a bumper) of centre ``centre_m``, plane normal
        ``normal`` and radius ``radius_m``.
    centre_m : tuple of 3 floats
        Centre, body FRD, m.
    normal : tuple of 3 floats
        Unit normal of the ring's plane, body FRD.
    radius_m : float
        Ring radius, m.
    stiffness, exponent, restitution : float
        Hunt-Crossley ``k`` (N/m^n), ``n`` and the coefficient of restitution ``e``.
    friction_coefficient : float or None
        Coulomb ``mu`` of this feature; None: the scenario's ``friction_coefficient``.
    """

    model_config = MODEL_CONFIG

    name: str = Field(min_length=1)
    kind: Literal["ring"] = "ring"
    centre_m: Vec3
    normal: Vec3 = (0.0, 0.0, -1.0)
    radius_m: Real = Field(0.0, ge=0)
    stiffness: Real = Field(gt=0)
    exponent: Real = Field(gt=0)
    restitution: Real = Field(gt=0, le=1)
    friction_coefficient: Real | None = Field(None, ge=0)


def feature_column(prefix: str, name: str, unit: str) -> str:
    """The output column of feature ``name``: ``delta1_m`` for ``"1"``, ``delta_cage_m``..."""
    return f"{prefix}{name}_{unit}" if name.isdigit() else f"{prefix}_{name}_{unit}"
