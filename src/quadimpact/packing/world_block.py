"""The world's block: ``shapes`` (``SH_*``: planes, cylinders, boxes, inertial frame), and
the packed shapes as plain data (``scenario.json``) and back."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP
from quadimpact.core.geometry.shapes import by_kind, by_name, components, kind_of
from quadimpact.inputs.world import Box, Cylinder, Plane
from quadimpact.linalg import norm

__all__ = ["SURFACE_KINDS", "pack_surface_records", "pack_surfaces", "surface_records"]

#: Surface kinds by the names written in ``scenario.json`` (``core.layout.ShapeKind``); the
#: shape components' are :func:`surface_kinds`'.
SURFACE_KINDS: dict[str, int] = {
    "plane": L.SHAPE_PLANE,
    "cylinder": L.SHAPE_CYLINDER,
    "box": L.SHAPE_BOX,
}


def surface_kinds() -> dict[str, int]:
    """Every surface kind by name: :data:`SURFACE_KINDS` and the registered shape components."""
    return {**SURFACE_KINDS, **{c.name: kind_of(c) for c in components()}}


def pack_surfaces(surfaces: Sequence[Plane | Cylinder | Box]) -> np.ndarray:
    """Surfaces (planes, cylinders, boxes) as an (n, NSHAPE) array of world shapes.

    Plane normals and cylinder axes are normalised (again); a box's axes are
    the columns of its ZYX rotation, stored as the rows of ``SH_ROT``; an
    infinite cylinder has ``SH_LENGTH = inf``.
    """
    surf = np.zeros((len(surfaces), SHP.NSHAPE))
    for i, s in enumerate(surfaces):
        comp = by_name(getattr(s, "kind", ""))
        if comp is not None:  # a shape component: its declared slots
            surf[i] = comp.pack(s, kind_of(comp))
            continue
        surf[i, SHP.SH_IS_GROUND] = 1.0 if getattr(s, "is_ground", False) else 0.0
        if isinstance(s, Cylinder):
            e = np.asarray(s.axis, dtype=float)
            surf[i, SHP.SH_KIND] = L.SHAPE_CYLINDER
            surf[i, SHP.SH_POINT : SHP.SH_POINT + 3] = s.point_m
            surf[i, SHP.SH_NORMAL : SHP.SH_NORMAL + 3] = e / norm(e)
            surf[i, SHP.SH_RADIUS] = s.radius_m
            surf[i, SHP.SH_LENGTH] = np.inf if s.length_m is None else s.length_m
            continue
        if isinstance(s, Box):
            surf[i, SHP.SH_KIND] = L.SHAPE_BOX
            surf[i, SHP.SH_POINT : SHP.SH_POINT + 3] = s.centre_m
            surf[i, SHP.SH_HALF : SHP.SH_HALF + 3] = s.half_extents_m
            surf[i, SHP.SH_ROT : SHP.SH_ROT + 9] = np.asarray(s.axes(), dtype=float).ravel()
            continue
        n = np.asarray(s.normal, dtype=float)
        surf[i, SHP.SH_POINT : SHP.SH_POINT + 3] = s.point_m
        surf[i, SHP.SH_NORMAL : SHP.SH_NORMAL + 3] = n / norm(n)
        surf[i, SHP.SH_KIND] = L.SHAPE_PLANE
    return surf


def _floats(a: np.ndarray) -> list[float]:
    return [float(c) for c in a]


def surface_records(surf: np.ndarray, names: Sequence[str]) -> list[dict[str, Any]]:
    """The packed surfaces as plain data, as the kernel received them (``scenario.json``).

    Parameters
    ----------
    surf : numpy.ndarray, shape (n, NSHAPE)
        Packed surfaces (:func:`pack_surfaces`).
    names : sequence of str
        Their names, in the same order.

    Returns
    -------
    list of dict
        Per surface: ``name``, ``kind`` (a key of :data:`SURFACE_KINDS`),
        ``is_ground`` and its geometry (inertial NED, m): a plane's
        ``point_m`` and ``normal`` (unit, out of the obstacle); a cylinder's
        ``point_m`` (on the axis), ``axis`` (unit), ``radius_m`` and
        ``length_m`` (null: infinite); a box's ``centre_m``,
        ``half_extents_m`` and ``axes`` (its own x, y, z axes, rows).
        :func:`pack_surface_records` gives ``surf`` back bit for bit.
    """
    kinds = {v: k for k, v in surface_kinds().items()}
    out: list[dict[str, Any]] = []
    for name, row in zip(names, surf, strict=True):
        kind = kinds[int(row[SHP.SH_KIND])]
        comp = by_kind(int(row[SHP.SH_KIND]))
        if comp is not None:
            out.append(comp.record(row, name))
            continue
        if kind == "plane":
            rec: dict[str, Any] = {
                "name": str(name),
                "point_m": _floats(row[SHP.SH_POINT : SHP.SH_POINT + 3]),
                "normal": _floats(row[SHP.SH_NORMAL : SHP.SH_NORMAL + 3]),
                "is_ground": bool(row[SHP.SH_IS_GROUND] > 0.5),
                "kind": kind,
            }
        elif kind == "cylinder":
            length = float(row[SHP.SH_LENGTH])
            rec = {
                "name": str(name),
                "kind": kind,
                "point_m": _floats(row[SHP.SH_POINT : SHP.SH_POINT + 3]),
                "axis": _floats(row[SHP.SH_NORMAL : SHP.SH_NORMAL + 3]),
                "radius_m": float(row[SHP.SH_RADIUS]),
                "length_m": length if np.isfinite(length) else None,
                "is_ground": bool(row[SHP.SH_IS_GROUND] > 0.5),
            }
        else:
            rec = {
                "name": str(name),
                "kind": kind,
                "centre_m": _floats(row[SHP.SH_POINT : SHP.SH_POINT + 3]),
                "half_extents_m": _floats(row[SHP.SH_HALF : SHP.SH_HALF + 3]),
                "axes": [
                    _floats(row[SHP.SH_ROT + 3 * i : SHP.SH_ROT + 3 * i + 3]) for i in range(3)
                ],
                "is_ground": bool(row[SHP.SH_IS_GROUND] > 0.5),
            }
        out.append(rec)
    return out


def pack_surface_records(records: Sequence[Mapping[str, Any]]) -> np.ndarray:
    """The packed surfaces of :func:`surface_records`' output (no normalisation: as recorded).

    Raises
    ------
    ValueError
        A record with a kind not in :data:`SURFACE_KINDS`.
    """
    surf = np.zeros((len(records), SHP.NSHAPE))
    for i, r in enumerate(records):
        kind = r.get("kind", "plane")
        if kind not in surface_kinds():
            known = ", ".join(surface_kinds())
            name = r.get("name")
            raise ValueError(f"surface {name!r}: kind must be one of {known} (got {kind!r})")
        comp = by_name(kind)
        if comp is not None:
            surf[i] = comp.unpack(r, kind_of(comp))
            continue
        surf[i, SHP.SH_IS_GROUND] = 1.0 if r.get("is_ground") else 0.0
        surf[i, SHP.SH_KIND] = SURFACE_KINDS[kind]
        if kind == "cylinder":
            surf[i, SHP.SH_POINT : SHP.SH_POINT + 3] = [float(c) for c in r["point_m"]]
            surf[i, SHP.SH_NORMAL : SHP.SH_NORMAL + 3] = [float(c) for c in r["axis"]]
            surf[i, SHP.SH_RADIUS] = float(r["radius_m"])
            length = r.get("length_m")
            surf[i, SHP.SH_LENGTH] = np.inf if length is None else float(length)
        elif kind == "box":
            surf[i, SHP.SH_POINT : SHP.SH_POINT + 3] = [float(c) for c in r["centre_m"]]
            surf[i, SHP.SH_HALF : SHP.SH_HALF + 3] = [float(c) for c in r["half_extents_m"]]
            surf[i, SHP.SH_ROT : SHP.SH_ROT + 9] = [float(c) for row in r["axes"] for c in row]
        else:
            surf[i, SHP.SH_POINT : SHP.SH_POINT + 3] = [float(c) for c in r["point_m"]]
            surf[i, SHP.SH_NORMAL : SHP.SH_NORMAL + 3] = [float(c) for c in r["normal"]]
    return surf
