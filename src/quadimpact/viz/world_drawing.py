"""The world of a run as drawn, in NumPy (no drawing here): its contact surfaces.

From the world record of a run (``scenario.json``) or, for a folder written
before that file existed, from its summary and episodes (:func:`scene_surfaces`);
the polylines of a packed cylinder or box (:func:`shape_lines`); a plane's
axes and a patch of it with grid lines fixed in space (:func:`plane_axes`,
:func:`plane_grid`); points of a circle (:func:`rim_points`: a cylinder's rims,
a bumper's ring). Inertial NED, m. :mod:`quadimpact.viz.scene` puts the world
and the vehicle together.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP
from quadimpact.core.geometry.shapes import by_kind, by_name
from quadimpact.inputs.world import GROUND, Box, Cylinder, Plane, obstacle_from

__all__ = ["plane_axes", "plane_grid", "rim_points", "scene_surfaces", "shape_lines", "world_part"]


def rim_points(
    centre: np.ndarray, u: np.ndarray, n: np.ndarray, radius: float, beta: np.ndarray
) -> np.ndarray:
    """Points ``c + R (cos b u + sin b (n x u))`` of a circle (docs/MODEL.md 4), (len(beta), 3)."""
    w = np.cross(n, u)
    b = np.asarray(beta, dtype=float)[:, None]
    return centre + radius * (np.cos(b) * u + np.sin(b) * w)


def world_part(world: Mapping[str, Any] | None, key: str) -> Any:
    """``world[key]`` of a world record (``scenario.json``), None without one."""
    return world.get(key) if isinstance(world, Mapping) else None


def scene_surfaces(
    summary: Mapping[str, Any],
    episodes: pd.DataFrame | None = None,
    world: Mapping[str, Any] | None = None,
) -> list[Plane | Cylinder | Box]:
    """The contact surfaces of a run: the world record's, else from the summary and episodes.

    With a world record (``scenario.json``), exactly its ``surfaces``, in the
    kernel's order (possibly none). Without one (a folder written before that
    file existed): the wall ``X = wall_distance_m`` (normal -X) of a wall
    approach, and the ground (altitude 0, normal up) when an episode touched it.
    """
    records = world_part(world, "surfaces")
    if isinstance(records, Sequence):
        return [_surface_of_record(r) for r in records]
    out: list[Plane] = []
    if summary.get("wall_distance_m") is not None:
        out.append(Plane.wall(summary["wall_distance_m"]))
    touched = set()
    if episodes is not None and len(episodes) and "surface" in episodes:
        touched = {str(x) for x in episodes["surface"]}
    if "ground" in touched and "ground" not in {s.name for s in out}:
        out.append(GROUND)
    return out


def _surface_of_record(r: Mapping[str, Any]) -> Plane | Cylinder | Box:
    """The shape of a ``scenario.json`` surface record (its drawing; the kernel's numbers are
    packed from the records themselves)."""
    kind = r.get("kind", "plane")
    comp = by_name(kind)
    if comp is not None:
        return obstacle_from({k: r[k] for k in comp.record_keys() if k != "is_ground"})
    if kind == "cylinder":
        return obstacle_from(
            {k: r[k] for k in ("name", "point_m", "axis", "radius_m", "length_m")}
            | {"kind": "cylinder"}
        )
    if kind == "box":
        # the box's axes as recorded: its drawing reads them from the packed row
        return Box(name=str(r["name"]), centre_m=r["centre_m"], half_extents_m=r["half_extents_m"])
    return Plane(
        name=str(r["name"]),
        point_m=tuple(float(c) for c in r["point_m"]),
        normal=tuple(float(c) for c in r["normal"]),
        is_ground=bool(r.get("is_ground", False)),
    )


def shape_lines(row: np.ndarray, centre: np.ndarray, extent: float = 1.5) -> list[np.ndarray]:
    """Polylines (inertial NED) drawing a packed cylinder or box (``SH_*``); a plane: none.

    A cylinder: its two end rims (an infinite one: ``extent`` m each way of
    ``centre``'s axial coordinate) and eight generators; a box: its twelve
    edges.
    """
    kind = int(row[SHP.SH_KIND])
    o = row[SHP.SH_POINT : SHP.SH_POINT + 3]
    if kind == L.SHAPE_CYLINDER:
        e = row[SHP.SH_NORMAL : SHP.SH_NORMAL + 3]
        r = float(row[SHP.SH_RADIUS])
        length = float(row[SHP.SH_LENGTH])
        if np.isfinite(length):
            z0, z1 = -0.5 * length, 0.5 * length
        else:
            zc = float((np.asarray(centre, dtype=float) - o) @ e)
            z0, z1 = zc - extent, zc + extent
        k = np.eye(3)[int(np.argmin(np.abs(e)))]
        u = np.cross(e, k)
        u /= np.linalg.norm(u)
        beta = np.linspace(0.0, 2.0 * math.pi, 73)
        lines = [rim_points(o + z * e, u, e, r, beta) for z in (z0, z1)]
        for b in np.linspace(0.0, 2.0 * math.pi, 8, endpoint=False):
            p = rim_points(o, u, e, r, np.array([b]))[0]
            lines.append(np.array([p + z0 * e, p + z1 * e]))
        return lines
    if kind == L.SHAPE_BOX:
        axes = row[SHP.SH_ROT : SHP.SH_ROT + 9].reshape(3, 3)
        half = row[SHP.SH_HALF : SHP.SH_HALF + 3]
        lines = []
        for i in range(3):
            j, k = (i + 1) % 3, (i + 2) % 3
            for sj in (-1.0, 1.0):
                for sk in (-1.0, 1.0):
                    base = o + sj * half[j] * axes[j] + sk * half[k] * axes[k]
                    lines.append(np.array([base - half[i] * axes[i], base + half[i] * axes[i]]))
        return lines
    comp = by_kind(kind)  # a shape component draws itself
    if comp is not None and comp.lines is not None:
        return comp.lines(row)
    return []


def plane_axes(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors spanning a plane: ``e1`` horizontal (for a non-horizontal
    plane), ``e2 = m x e1`` its steepest direction."""
    m = np.asarray(normal, dtype=float)
    m = m / np.linalg.norm(m)
    ref = np.array([0.0, 0.0, 1.0]) if abs(m[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    e1 = np.cross(m, ref)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(m, e1)


def plane_grid(
    point: np.ndarray,
    normal: np.ndarray,
    centre: np.ndarray,
    half_size: float,
    step: float = 0.1,
    range1: tuple[float, float] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """A rectangular patch of a plane around ``centre`` and grid lines fixed in space.

    Parameters
    ----------
    point, normal : array_like
        The plane (NED).
    centre : array_like
        Point whose projection onto the plane is the patch's reference.
    half_size : float
        Extent each way along ``e2`` (:func:`plane_axes`), m.
    step : float
        Grid spacing, m; the lines sit at multiples of ``step`` from ``point``.
    range1 : (float, float), optional
        Extent along ``e1`` from the reference, m; default ``(-half_size, half_size)``.
        A wall drawn with ``(-w, 0)`` or ``(0, w)`` is cut by the vertical plane
        through ``centre``, so the cut edge shows where the vehicle meets it.

    Returns
    -------
    outline : numpy.ndarray, shape (5, 3)
        Closed rectangle in the plane.
    segments : numpy.ndarray, shape (k, 2, 3)
        Grid lines inside it.
    """
    p0 = np.asarray(point, dtype=float)
    e1, e2 = plane_axes(normal)
    rel = np.asarray(centre, dtype=float) - p0
    a0, b0 = float(rel @ e1), float(rel @ e2)
    lo1, hi1 = (-half_size, half_size) if range1 is None else range1
    ranges = ((a0 + lo1, a0 + hi1), (b0 - half_size, b0 + half_size))
    (a_lo, a_hi), (b_lo, b_hi) = ranges
    corners = [(a_lo, b_lo), (a_hi, b_lo), (a_hi, b_hi), (a_lo, b_hi), (a_lo, b_lo)]
    outline = np.array([p0 + a * e1 + b * e2 for a, b in corners])
    segs = []
    for axis, other, (lo, hi), (olo, ohi) in ((e1, e2, *ranges), (e2, e1, *ranges[::-1])):
        for k in range(math.ceil(lo / step - 1e-9), math.floor(hi / step + 1e-9) + 1):
            base = p0 + k * step * axis
            segs.append([base + olo * other, base + ohi * other])
    return outline, np.array(segs, dtype=float).reshape(-1, 2, 3)
