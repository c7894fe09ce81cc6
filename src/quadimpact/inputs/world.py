"""The world's shapes: :class:`Plane`, :class:`Cylinder` and :class:`Box` (inertial NED, SI).

A scenario lists its obstacles (``[[obstacles]]`` in a file, each with a
``kind``: ``"plane"``, ``"cylinder"`` or ``"box"``); every scenario kind
takes them (docs/OBSTACLES.md). The wall approach and the impact trial keep
their wall plane when they list none.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    BeforeValidator,
    Field,
    StrictBool,
    ValidationError,
    field_validator,
)

from quadimpact.errors import format_value
from quadimpact.inputs.types import MODEL_CONFIG, Real, Vec3

__all__ = [
    "GROUND",
    "OBSTACLE_KINDS",
    "Box",
    "Cylinder",
    "Obstacle",
    "Plane",
    "obstacle_from",
    "obstacle_models",
]


def _unit(value: tuple[float, float, float]) -> tuple[float, float, float]:
    norm = math.sqrt(sum(c * c for c in value))
    if norm < 1e-12:
        raise ValueError("must be a non-zero vector")
    return (value[0] / norm, value[1] / norm, value[2] / norm)


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

    kind: Literal["plane"] = Field("plane", description="Shape kind tag.")
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
        return _unit(value)

    @classmethod
    def wall(cls, distance_m: float) -> Plane:
        """The paper's wall: the vertical plane ``X = distance_m``, normal ``-X``."""
        return cls(name="wall", point_m=(float(distance_m), 0.0, 0.0), normal=(-1.0, 0.0, 0.0))


GROUND = Plane(name="ground", point_m=(0.0, 0.0, 0.0), normal=(0.0, 0.0, -1.0), is_ground=True)
"""The ground, altitude 0, as a contact surface (``ground = "contact"``)."""


class Cylinder(BaseModel):
    """A cylinder obstacle (a pole, a bar, a branch), inertial NED, m.

    Attributes
    ----------
    kind : "cylinder"
    name : str
        Label in results; unique per scenario.
    point_m : tuple of 3 floats
        A point of the axis (the centre of a finite cylinder), inertial NED, m.
    axis : tuple of 3 floats
        Direction of the axis, any non-zero length (normalised); a vertical
        pole is ``(0, 0, 1)``.
    radius_m : float
        Radius, m, > 0.
    length_m : float or None
        Length along the axis, m, > 0, centred on ``point_m``, with flat end
        caps; ``None`` (the default): infinite, no caps.
    """

    model_config = MODEL_CONFIG

    kind: Literal["cylinder"] = Field("cylinder", description="Shape kind tag.")
    name: str = Field(min_length=1, description="Label of the obstacle in results.")
    point_m: Vec3 = Field(description="A point of the axis (a finite one's centre), NED, m.")
    axis: Vec3 = Field((0.0, 0.0, 1.0), description="Axis direction (normalised).")
    radius_m: Real = Field(gt=0, le=1e4, description="Radius, m.")
    length_m: Real | None = Field(None, gt=0, description="Length, m; None: infinite.")

    @field_validator("axis")
    @classmethod
    def _normalise(cls, value: tuple[float, float, float]) -> tuple[float, float, float]:
        return _unit(value)


class Box(BaseModel):
    """A box obstacle (a table, a door frame's post, a crate): faces, edges and corners.

    Attributes
    ----------
    kind : "box"
    name : str
        Label in results; unique per scenario.
    centre_m : tuple of 3 floats
        Centre, inertial NED, m.
    half_extents_m : tuple of 3 floats
        Half of its size along its own x, y, z axes, m, each > 0.
    euler_deg : tuple of 3 floats
        Orientation [roll, pitch, yaw], ZYX Euler angles (the sequence yaw,
        pitch, roll) as a vehicle's attitude: its own axes are the columns of
        ``Rz(yaw) Ry(pitch) Rx(roll)``; ``(0, 0, 0)``: aligned with NED.
    """

    model_config = MODEL_CONFIG

    kind: Literal["box"] = Field("box", description="Shape kind tag.")
    name: str = Field(min_length=1, description="Label of the obstacle in results.")
    centre_m: Vec3 = Field(description="Centre, inertial NED, m.")
    half_extents_m: Vec3 = Field(description="Half-extents along its own axes, m.")
    euler_deg: Vec3 = Field((0.0, 0.0, 0.0), description="[roll, pitch, yaw], ZYX, deg.")

    @field_validator("half_extents_m")
    @classmethod
    def _positive(cls, value: tuple[float, float, float]) -> tuple[float, float, float]:
        if min(value) <= 0.0:
            raise ValueError("each half-extent must be > 0 m")
        return value

    def axes(self) -> tuple[tuple[float, float, float], ...]:
        """Its own x, y, z axes in inertial components (the rows of the kernel's ``SH_ROT``)."""
        roll, pitch, yaw = (math.radians(a) for a in self.euler_deg)
        cr, sr, cp, sp, cy, sy = (
            math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch),
            math.cos(yaw), math.sin(yaw),
        )  # fmt: skip
        # columns of Rz Ry Rx
        return (
            (cy * cp, sy * cp, -sp),
            (cy * sp * sr - sy * cr, sy * sp * sr + cy * cr, cp * sr),
            (cy * sp * cr + sy * sr, sy * sp * cr - cy * sr, cp * cr),
        )


OBSTACLE_KINDS: dict[str, type[BaseModel]] = {"plane": Plane, "cylinder": Cylinder, "box": Box}
"""The original obstacle classes by their ``kind`` tag (:func:`obstacle_models` adds the
shape components')."""


def obstacle_models() -> dict[str, type[BaseModel]]:
    """Every obstacle settings model by its ``kind`` tag: the original three, then the
    shape components' (``core/geometry/shapes.py``)."""
    from quadimpact.core.geometry.shapes import components

    return {**OBSTACLE_KINDS, **{c.name: c.settings for c in components()}}


def obstacle_from(value: Any, where: str = "obstacle") -> Any:
    """One obstacle from a mapping with a ``kind`` (or an obstacle object, returned as is).

    Raises
    ------
    ValueError
        One line naming the field and the rule (pydantic adds the list's field).
    """
    models = obstacle_models()
    if isinstance(value, tuple(models.values())):
        return value
    if not isinstance(value, dict):
        raise ValueError(f"{where}: must be a table with a kind (got {format_value(value)})")
    kind = value.get("kind")
    if kind not in models:
        known = ", ".join(repr(k) for k in models)
        raise ValueError(f"{where}: kind: must be one of {known} (got {format_value(kind)})")
    try:
        return models[kind].model_validate(value)
    except ValidationError as exc:
        from quadimpact.errors import input_error_from_validation

        raise ValueError(str(input_error_from_validation(exc, where))) from None


def _obstacles(value: Any) -> Any:
    if hasattr(value, "tolist"):
        value = value.tolist()
    if not isinstance(value, (list, tuple)):
        raise ValueError("must be a list of obstacle tables ([[obstacles]])")
    out = []
    for i, item in enumerate(value):
        name = item.get("name") if isinstance(item, dict) else getattr(item, "name", None)
        label = f"obstacle {i + 1}" + (f" ({name!r})" if isinstance(name, str) else "")
        out.append(obstacle_from(item, label))
    return tuple(out)


Obstacle = Plane | Cylinder | Box
"""Any of the original obstacle shapes (a shape component's settings are obstacles too)."""

Obstacles = Annotated[tuple[Any, ...], BeforeValidator(_obstacles)]
"""A scenario's obstacle list: tables with a ``kind``, validated one by one."""
