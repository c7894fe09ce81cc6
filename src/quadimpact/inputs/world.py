"""Contact surfaces: :class:`Plane`, the one surface type of scenarios, results and the kernel."""

from __future__ import annotations

import math

from pydantic import BaseModel, Field, StrictBool, field_validator

from quadimpact.inputs.types import MODEL_CONFIG, Vec3

__all__ = ["GROUND", "Plane"]


class Plane(BaseModel):
    """A flat contact surface (wall, floor, ceiling...) in the inertial NED frame.

    Attributes
    ----------
    name : str
        Label used in results (episodes' ``surface`` column); unique per scenario.
    point_m : tuple of 3 floats
        Any point of the plane, inertial NED, m.
    normal : tuple of 3 floats
        Normal pointing out of the obstacle into free space, inertial NED;
        any non-zero length, normalised on validation. The paper's wall at
        ``X = d`` is ``point_m = (d, 0, 0)``, ``normal = (-1, 0, 0)``; the ground
        is ``point_m = (0, 0, 0)``, ``normal = (0, 0, -1)``.
    is_ground : bool
        The ground (:data:`GROUND`): its first contact is the crash. Set for
        the ground of ``ground = "contact"`` runs; a scenario's own surfaces
        are obstacles (the default ``False``).
    """

    model_config = MODEL_CONFIG

    name: str = Field(min_length=1, description="Label of the surface in results.")
    point_m: Vec3 = Field(description="A point of the plane, inertial NED, m.")
    normal: Vec3 = Field(
        description="Unit normal out of the obstacle into free space, inertial NED "
        "(normalised on validation)."
    )
    is_ground: StrictBool = Field(False, description="The ground: its first contact is the crash.")

    @field_validator("normal")
    @classmethod
    def _normalise(cls, value: tuple[float, float, float]) -> tuple[float, float, float]:
        norm = math.sqrt(sum(c * c for c in value))
        if norm < 1e-12:
            raise ValueError("must be a non-zero vector")
        return (value[0] / norm, value[1] / norm, value[2] / norm)

    @classmethod
    def wall(cls, distance_m: float) -> Plane:
        """The paper's wall: the vertical plane ``X = distance_m``, normal ``-X``."""
        return cls(name="wall", point_m=(float(distance_m), 0.0, 0.0), normal=(-1.0, 0.0, 0.0))


GROUND = Plane(name="ground", point_m=(0.0, 0.0, 0.0), normal=(0.0, 0.0, -1.0), is_ground=True)
"""The ground, altitude 0, as a contact surface (``ground = "contact"``)."""
