"""A sphere obstacle (a ball, a round lamp, a rock): centre and radius, exact contact.

The shape row holds the centre ``c`` (``SH_POINT``, inertial NED, m) and the
radius ``R`` (``SH_RADIUS``, m). The depth of a point ``p`` is
``R - |p - c|``, with the normal ``(p - c) / |p - c|`` (from the sphere toward
the point). Every pair is closed form and exact:

* a point feature: the point's depth;
* a sphere feature (centre ``o``, radius ``r``): ``R + r - |o - c|``, at
  ``o - r n``;
* a ring (centre ``o``, unit normal ``a``, radius ``rho``): the ring's point
  nearest ``c`` is the deepest, ``q = o + rho u`` with ``u`` the direction
  of ``c - o`` in the ring's plane; when ``c`` is on the ring's axis every
  point of the ring is as deep and a fixed one is taken.

This module is the example of a shape component (``shape_component.py``):
its settings, slots and compiled functions are all here, and one line of
``shapes.py`` adds it to the contact table, the scenario files and the
results.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import BaseModel, ConfigDict, Field

from quadimpact.core.compiled import compiled
from quadimpact.core.feature_slots import (
    F_NORMAL,
    F_RADIUS,
)
from quadimpact.core.geometry.contact_record import ContactRecord, feature_offset, material_record
from quadimpact.core.geometry.shape_component import ShapeComponent, ShapeSlot
from quadimpact.core.layout import (
    FEAT_POINT,
    FEAT_RING,
    FEAT_SPHERE,
    X_POS,
)
from quadimpact.core.shape_slots import (
    SH_POINT,
    SH_RADIUS,
)

__all__ = ["SHAPE", "SphereObstacle"]

AXIS_EPS = 1e-12  # m: the sphere's centre this close to a ring's axis is on it


class SphereObstacle(BaseModel):
    """A sphere obstacle (``kind = "sphere"`` in ``[[obstacles]]``), inertial NED, m."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    kind: Literal["sphere"] = Field("sphere", description="Shape kind tag.")
    name: str = Field(min_length=1, description="Label of the obstacle in results.")
    centre_m: tuple[float, float, float] = Field(description="Centre, inertial NED, m.")
    radius_m: float = Field(gt=0, le=1e4, description="Radius, m.")


@njit(cache=True, inline="always")
def _depth(px: float, py: float, pz: float, shapes: np.ndarray, s: int) -> tuple:
    """Depth (m, > 0 inside) of the inertial point ``p`` and the unit normal there."""
    rx = px - shapes[s, SH_POINT]
    ry = py - shapes[s, SH_POINT + 1]
    rz = pz - shapes[s, SH_POINT + 2]
    d = math.sqrt(rx * rx + ry * ry + rz * rz)
    if d > 0.0:
        return shapes[s, SH_RADIUS] - d, rx / d, ry / d, rz / d
    return shapes[s, SH_RADIUS], 0.0, 0.0, -1.0  # at the centre: up, by convention


@compiled
def sphere_distance(px: float, py: float, pz: float, shapes: np.ndarray, s: int) -> float:
    """Signed distance (m) of the inertial point ``p`` from sphere ``s``, positive outside."""
    return -_depth(px, py, pz, shapes, s)[0]


@compiled
def point_sphere(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, f: int, shapes: np.ndarray, s: int
) -> ContactRecord:
    """Point feature ``f`` (position ``F_CENTRE``, body) against sphere ``s``: exact."""
    dx, dy, dz = feature_offset(C, feat, f)
    g, nx, ny, nz = _depth(x[X_POS] + dx, x[X_POS + 1] + dy, x[X_POS + 2] + dz, shapes, s)
    return material_record(x, C, g, dx, dy, dz, nx, ny, nz)


@compiled
def sphere_sphere(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, f: int, shapes: np.ndarray, s: int
) -> ContactRecord:
    """Sphere feature ``f`` (centre ``F_CENTRE``, radius ``F_RADIUS``) against sphere ``s``."""
    ox, oy, oz = feature_offset(C, feat, f)
    g, nx, ny, nz = _depth(x[X_POS] + ox, x[X_POS + 1] + oy, x[X_POS + 2] + oz, shapes, s)
    r = feat[f, F_RADIUS]
    return material_record(x, C, g + r, ox - r * nx, oy - r * ny, oz - r * nz, nx, ny, nz)


@compiled
def ring_sphere(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, f: int, shapes: np.ndarray, s: int
) -> ContactRecord:
    """Ring feature ``f`` (centre, unit normal ``F_NORMAL``, radius) against sphere ``s``."""
    ox, oy, oz = feature_offset(C, feat, f)
    a0 = feat[f, F_NORMAL]
    a1 = feat[f, F_NORMAL + 1]
    a2 = feat[f, F_NORMAL + 2]
    ax = C[0, 0] * a0 + C[0, 1] * a1 + C[0, 2] * a2
    ay = C[1, 0] * a0 + C[1, 1] * a1 + C[1, 2] * a2
    az = C[2, 0] * a0 + C[2, 1] * a1 + C[2, 2] * a2
    # the sphere's centre from the ring's centre, and its part in the ring's plane
    wx = shapes[s, SH_POINT] - (x[X_POS] + ox)
    wy = shapes[s, SH_POINT + 1] - (x[X_POS + 1] + oy)
    wz = shapes[s, SH_POINT + 2] - (x[X_POS + 2] + oz)
    h = wx * ax + wy * ay + wz * az
    px = wx - h * ax
    py = wy - h * ay
    pz = wz - h * az
    n = math.sqrt(px * px + py * py + pz * pz)
    if n > AXIS_EPS:
        ux, uy, uz = px / n, py / n, pz / n
    else:  # on the axis: a fixed direction of the plane
        if abs(ax) < 0.9:
            ux, uy, uz = 0.0, az, -ay
        else:
            ux, uy, uz = -az, 0.0, ax
        m = math.sqrt(ux * ux + uy * uy + uz * uz)
        ux, uy, uz = ux / m, uy / m, uz / m
    rho = feat[f, F_RADIUS]
    qx = ox + rho * ux
    qy = oy + rho * uy
    qz = oz + rho * uz
    g, nx, ny, nz = _depth(x[X_POS] + qx, x[X_POS + 1] + qy, x[X_POS + 2] + qz, shapes, s)
    return material_record(x, C, g, qx, qy, qz, nx, ny, nz)


def sphere_lines(row: np.ndarray) -> list[np.ndarray]:
    """Three great circles (inertial NED, m) drawing a packed sphere row."""
    c = np.asarray(row[SH_POINT : SH_POINT + 3], dtype=float)
    r = float(row[SH_RADIUS])
    b = np.linspace(0.0, 2.0 * math.pi, 73)
    cos, sin, zero = np.cos(b), np.sin(b), np.zeros_like(b)
    return [
        c + r * np.column_stack(cols)
        for cols in ((cos, sin, zero), (cos, zero, sin), (zero, cos, sin))
    ]


SHAPE = ShapeComponent(
    name="sphere",
    settings=SphereObstacle,
    slots=(ShapeSlot("centre_m", SH_POINT, 3, "m"), ShapeSlot("radius_m", SH_RADIUS, 1, "m")),
    distance=sphere_distance,
    contacts={FEAT_RING: ring_sphere, FEAT_SPHERE: sphere_sphere, FEAT_POINT: point_sphere},
    lines=sphere_lines,
    doc="a sphere: a ball, a round lamp, a rock",
)
