"""Contact features of a vehicle: the parts of its protective structure that touch the world.

A feature is one row of the compiled core's feature table (``core/layout.py``,
``F_*``): its kind, its geometry in the body frame (FRD, from the CM, m) and
its own contact law parameters (Hunt-Crossley stiffness and exponent,
restitution, friction). A contact pair is a feature against a shape of the
world; its geometry function is chosen by the two kinds
(``core/geometry``).

Three kinds: ``ring`` (a bumper around a rotor: centre, plane normal,
radius), ``sphere`` (a spherical cage or a ball: centre, radius) and
``point`` (a landing-gear foot, an arm tip, a body corner: a position). The
Spiri and the Navi are protected by four bumper rings
(:meth:`quadimpact.inputs.vehicle.Vehicle.contact_features`), named ``"1"`` to
``"4"`` so that their output columns keep the names ``delta1_m`` ...
``force4_n``; a vehicle file may list its own (``[[features]]``).
"""

from __future__ import annotations

import math
import re
from typing import Literal

from pydantic import BaseModel, Field, field_validator, model_validator

from quadimpact.inputs.types import MODEL_CONFIG, Real, Vec3

__all__ = ["FEATURE_KINDS", "ContactFeature", "feature_column"]

FEATURE_KINDS = ("ring", "sphere", "point")
"""The feature kinds a vehicle can declare."""

POINT_VALID_DEPTH_M = 0.02
"""Default depth a point feature models (a foot's pad or a bumper tip), m."""


class ContactFeature(BaseModel):
    """One contact feature of a vehicle (body frame FRD, SI).

    Attributes
    ----------
    name : str
        Its label in results (episodes, output columns).
    kind : {"ring", "sphere", "point"}
        ``ring``: a circle (a bumper) of centre ``centre_m``, plane normal
        ``normal`` and radius ``radius_m``; ``sphere``: a sphere (a cage, a
        ball) of centre ``centre_m`` and radius ``radius_m``; ``point``: the
        point ``centre_m`` (a foot, an arm tip, a corner).
    centre_m : tuple of 3 floats
        Centre (a point's position), body FRD, m.
    normal : tuple of 3 floats
        Normal of the ring's plane, body FRD (normalised; rings only).
    radius_m : float
        Ring or sphere radius, m (> 0 for them; 0 for a point).
    valid_depth_m : float or None
        Deepest penetration the feature models (a run deeper than this is
        flagged: the body itself would touch); ``None``: the radius of a ring
        or sphere, 0.02 m for a point.
    stiffness, exponent, restitution : float
        Hunt-Crossley ``k`` (N/m^n), ``n`` and the coefficient of restitution ``e``.
    friction_coefficient : float or None
        Coulomb ``mu`` of this feature; None: the scenario's ``friction_coefficient``.
    """

    model_config = MODEL_CONFIG

    name: str = Field(min_length=1, max_length=32)
    kind: Literal["ring", "sphere", "point"] = "ring"
    centre_m: Vec3
    normal: Vec3 = (0.0, 0.0, -1.0)
    radius_m: Real = Field(0.0, ge=0, le=5)
    stiffness: Real = Field(gt=0)
    exponent: Real = Field(gt=0)
    restitution: Real = Field(gt=0, le=1)
    friction_coefficient: Real | None = Field(None, ge=0)
    valid_depth_m: Real | None = Field(None, gt=0)

    @field_validator("name")
    @classmethod
    def _column_safe(cls, value: str) -> str:
        if not re.fullmatch(r"[A-Za-z0-9_]+", value):
            raise ValueError("must be letters, digits and underscores (it names output columns)")
        return value

    @field_validator("normal")
    @classmethod
    def _unit_normal(cls, value: tuple[float, float, float]) -> tuple[float, float, float]:
        norm = math.sqrt(sum(c * c for c in value))
        if norm < 1e-12:
            raise ValueError("must be a non-zero vector")
        if abs(norm - 1.0) <= 1e-12:  # unit already: kept bit for bit
            return value
        return (value[0] / norm, value[1] / norm, value[2] / norm)

    @model_validator(mode="after")
    def _radius_of_kind(self) -> ContactFeature:
        if self.kind in ("ring", "sphere") and not self.radius_m > 0:
            raise ValueError(f"radius_m: a {self.kind} needs a radius > 0 m")
        if self.kind == "point" and self.radius_m != 0:
            raise ValueError("radius_m: a point has no radius (leave it out)")
        return self

    @property
    def depth_limit_m(self) -> float:
        """Deepest penetration the feature models, m (``valid_depth_m`` or its default)."""
        if self.valid_depth_m is not None:
            return float(self.valid_depth_m)
        return float(self.radius_m) if self.kind != "point" else POINT_VALID_DEPTH_M


def feature_column(prefix: str, name: str, unit: str) -> str:
    """The output column of feature ``name``: ``delta1_m`` for ``"1"``, ``delta_cage_m``..."""
    return f"{prefix}{name}_{unit}" if name.isdigit() else f"{prefix}_{name}_{unit}"
