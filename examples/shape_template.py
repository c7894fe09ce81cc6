"""A plug-in obstacle shape: copy this file to add a shape of your own.

This one is a capsule: the points within ``radius_m`` of the segment from
``a_m`` to ``b_m`` (a rounded bar, a branch, a cable with its clearance). A
shape is one module like this one: its settings model, its slots (which
numbers of a shape row hold which field), its compiled distance and one
contact function per feature kind it can touch, then one call of
``register_shape``. A built-in shape is the same module in
``src/quadimpact/core/geometry/`` and one line of that folder's ``shapes.py``
instead of the call (``sphere.py`` is one).

This capsule touches sphere and point features (a cage, landing-gear feet);
a vehicle with bumper rings cannot fly into it (a run says so in one line).

Fly it::

    import examples.shape_template  # registers "capsule"
    from quadimpact import simulate
    from quadimpact.inputs.scenarios import scenario_from_dict

    r = simulate(scenario_from_dict({
        "kind": "flight", "vehicle": "examples/vehicles/navi_cage.toml",
        "velocity_m_s": [1.0, 0.0, 0.0],
        "obstacles": [{"kind": "capsule", "name": "bar", "a_m": [0.6, 0.0, -3.0],
                       "b_m": [0.6, 0.0, -1.0], "radius_m": 0.05}]}))
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import BaseModel, ConfigDict, Field

from quadimpact.core.feature_slots import (
    F_RADIUS,
)
from quadimpact.core.geometry import register_shape
from quadimpact.core.geometry.contact_record import feature_offset, material_record
from quadimpact.core.geometry.shape_component import ShapeComponent, ShapeSlot
from quadimpact.core.layout import (
    FEAT_POINT,
    FEAT_SPHERE,
    X_POS,
)
from quadimpact.core.shape_slots import (
    SH_HALF,
    SH_POINT,
    SH_RADIUS,
)


class Capsule(BaseModel):
    """``kind = "capsule"`` in ``[[obstacles]]``: a segment and a radius, inertial NED, m."""

    model_config = ConfigDict(extra="forbid", frozen=True)
    kind: Literal["capsule"] = "capsule"
    name: str = Field(min_length=1)
    a_m: tuple[float, float, float] = Field(description="One end of the segment, m.")
    b_m: tuple[float, float, float] = Field(description="The other end, m.")
    radius_m: float = Field(gt=0, description="Radius, m.")


@njit
def _depth(px, py, pz, shapes, s):
    """Depth (m, > 0 inside) of the point and the unit normal (from the capsule toward it)."""
    ax, ay, az = shapes[s, SH_POINT], shapes[s, SH_POINT + 1], shapes[s, SH_POINT + 2]
    ex, ey, ez = shapes[s, SH_HALF] - ax, shapes[s, SH_HALF + 1] - ay, shapes[s, SH_HALF + 2] - az
    u = ((px - ax) * ex + (py - ay) * ey + (pz - az) * ez) / (ex * ex + ey * ey + ez * ez)
    u = min(1.0, max(0.0, u))
    rx, ry, rz = px - (ax + u * ex), py - (ay + u * ey), pz - (az + u * ez)
    d = math.sqrt(rx * rx + ry * ry + rz * rz)
    if d == 0.0:
        return shapes[s, SH_RADIUS], 0.0, 0.0, -1.0
    return shapes[s, SH_RADIUS] - d, rx / d, ry / d, rz / d


@njit
def capsule_distance(px, py, pz, shapes, s):
    """Signed distance (m) of the inertial point from the capsule, positive outside."""
    return -_depth(px, py, pz, shapes, s)[0]


@njit
def point_capsule(x, C, feat, f, shapes, s):
    """A point feature against the capsule: exact."""
    dx, dy, dz = feature_offset(C, feat, f)
    g, nx, ny, nz = _depth(x[X_POS] + dx, x[X_POS + 1] + dy, x[X_POS + 2] + dz, shapes, s)
    return material_record(x, C, g, dx, dy, dz, nx, ny, nz)


@njit
def sphere_capsule(x, C, feat, f, shapes, s):
    """A sphere feature against the capsule: exact."""
    ox, oy, oz = feature_offset(C, feat, f)
    g, nx, ny, nz = _depth(x[X_POS] + ox, x[X_POS + 1] + oy, x[X_POS + 2] + oz, shapes, s)
    r = feat[f, F_RADIUS]
    return material_record(x, C, g + r, ox - r * nx, oy - r * ny, oz - r * nz, nx, ny, nz)


def capsule_lines(row: np.ndarray) -> list[np.ndarray]:
    """Its axis, for the viewer (inertial NED, m)."""
    return [np.array([row[SH_POINT : SH_POINT + 3], row[SH_HALF : SH_HALF + 3]])]


SHAPE = ShapeComponent(
    name="capsule",
    settings=Capsule,
    # the segment's ends in SH_POINT and SH_HALF (a row's free 3-vectors), its radius
    slots=(
        ShapeSlot("a_m", SH_POINT, 3, "m"),
        ShapeSlot("b_m", SH_HALF, 3, "m"),
        ShapeSlot("radius_m", SH_RADIUS, 1, "m"),
    ),
    distance=capsule_distance,
    contacts={FEAT_SPHERE: sphere_capsule, FEAT_POINT: point_capsule},
    lines=capsule_lines,
    doc="a capsule: the points within a radius of a segment",
)
register_shape(SHAPE)
