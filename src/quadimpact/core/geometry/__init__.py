"""Contact geometry: one table of functions keyed on (feature kind, shape kind).

A vehicle declares contact **features** (rows of ``feat``, layout ``F_*``:
rings, the bumpers; spheres, a cage or a ball; points, landing-gear feet, arm
tips, body corners), the world declares **shapes** (rows of ``shapes``, layout
``SH_*``: planes, cylinders, boxes). A run's contact-pair table
(``pairs``, built once by :func:`pair_table`, shape-major) names for every
(feature, shape) pair the geometry function that computes its contact record
(``record.py``): point, normal, depth, velocity. Everything else (events,
forces, outputs) goes through :func:`pair_contact`; the force law
(``core/contact.py``) never reads a shape.

The table (:data:`GEOMETRIES`) maps ``(FeatureKind, ShapeKind)`` to a
geometry id and its compiled function ``fn(x, C, feat, f, shapes, s) ->
ContactRecord``; the compiled dispatch :func:`pair_contact` branches on the
id. Each shape kind also has a point-distance function (the contact gate of
the recovery replica): :data:`SHAPE_DISTANCES`.

Built-in rows (one module per shape kind):

========  ========  ============================  ======================================
feature   shape     function                      method (accuracy; cost)
========  ========  ============================  ======================================
ring      plane     ``plane.ring_plane``          closed form, paper eqs. 10-15 (exact)
sphere    plane     ``plane.sphere_plane``        closed form (exact)
point     plane     ``plane.point_plane``         closed form (exact)
ring      cylinder  ``ring.ring_solid``           certified search over the circle
                                                  (within 1e-13 m; 3-6 point depths;
                                                  around a pole, a quartic; rarely a
                                                  branch and bound)
sphere    cylinder  ``cylinder.sphere_cylinder``  closed form (exact)
point     cylinder  ``cylinder.point_cylinder``   closed form (exact)
ring      box       ``ring.ring_solid``           certified search (as for the cylinder;
                                                  where it cannot certify, the exact
                                                  solution of ``ring_box.py``)
sphere    box       ``box.sphere_box``            closed form (exact)
point     box       ``box.point_box``             closed form (exact)
========  ========  ============================  ======================================

docs/OBSTACLES.md (section 2) gives each pair's method, accuracy and cost.

**Broad phase.** A pair whose record is a search (a ring against a cylinder
or a box: :func:`has_bound`) also has certified bounds on its depth and on
its rate's size (:func:`pair_bound`, one point depth): the event checks
skip the search of a pair out of contact that the bound proves apart
(``interval.contact_values``) and compute it wherever the bound decides
nothing (``events.contact_event``), so no result changes.

**A new shape kind** is a shape component: one module declaring its
settings, slots and compiled functions, and one line in ``shapes.py``
(``sphere.py`` is the example); its rows join this table with ids from
``shapes.FIRST_GEOMETRY`` and the dispatch reaches them without an edit
here. **A new row for a built-in kind** (plane, cylinder, box): write the
function in the shape's module, give it a ``GEOM_*`` id, a row in
:data:`GEOMETRIES` and a branch in :func:`pair_contact`; or register it at run time with
:func:`register_geometry` (and :func:`register_shape_distance`): a run whose
pairs use a registered row runs in a loop compiled around the registered
functions (``core.kernel.make_kernel``), as a plug-in controller does.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numba import literal_unroll, njit

from quadimpact.core.compiled import compiled
from quadimpact.core.feature_slots import (
    F_KIND,
)
from quadimpact.core.geometry.box import box_distance, point_box, sphere_box
from quadimpact.core.geometry.contact_record import ContactRecord, no_contact
from quadimpact.core.geometry.cylinder import cylinder_distance, point_cylinder, sphere_cylinder
from quadimpact.core.geometry.plane import plane_distance, point_plane, ring_plane, sphere_plane
from quadimpact.core.geometry.ring import ring_solid, ring_solid_bound
from quadimpact.core.geometry.shape_component import ShapeComponent
from quadimpact.core.geometry.shapes import BUILTIN as BUILTIN_SHAPES
from quadimpact.core.geometry.shapes import (
    CONTACT_ENTRIES,
    DISTANCE_ENTRIES,
    add_plugin,
    by_name,
    geometry_rows,
)
from quadimpact.core.layout import (
    FEAT_POINT,
    FEAT_RING,
    FEAT_SPHERE,
    SHAPE_BOX,
    SHAPE_CYLINDER,
    SHAPE_PLANE,
    Block,
    FeatureKind,
    ShapeKind,
)
from quadimpact.core.shape_slots import (
    SH_KIND,
)

# ---- contact pairs pairs (n_pairs, NPAIR), int64: one row per (feature,
# shape) pair, shape-major (pair c = shape * n_features + feature); built
# once per run, the geometry function chosen by the two kinds (pair_table)
_pair = Block("pairs", "PR_")
PR_FEATURE = _pair.slot("PR_FEATURE")  # row of feat
PR_SHAPE = _pair.slot("PR_SHAPE")  # row of shapes
PR_GEOMETRY = _pair.slot("PR_GEOMETRY")  # GEOM_* below: the pair's function
NPAIR = _pair.end("NPAIR")

__all__ = [
    "GEOMETRIES",
    "SHAPE_DISTANCES",
    "contact_record",
    "geometry_id",
    "has_bound",
    "pair_bound",
    "pair_contact",
    "pair_depths",
    "pair_table",
    "plugin_geometries",
    "register_geometry",
    "register_shape",
    "register_shape_distance",
    "shape_distance",
]

GEOM_RING_PLANE = 0
GEOM_SPHERE_PLANE = 1
GEOM_POINT_PLANE = 2
GEOM_RING_CYLINDER = 3
GEOM_SPHERE_CYLINDER = 4
GEOM_POINT_CYLINDER = 5
GEOM_RING_BOX = 6
GEOM_SPHERE_BOX = 7
GEOM_POINT_BOX = 8
GEOM_PLUGIN = 1000  # registered rows get ids from here on


@dataclass(frozen=True)
class Geometry:
    """A row of the table: the compiled contact function of one (feature, shape) pair."""

    feature: int
    shape: int
    id: int
    fn: Callable
    plugin: bool = False


GEOMETRIES: dict[tuple[int, int], Geometry] = {
    (FEAT_RING, SHAPE_PLANE): Geometry(FEAT_RING, SHAPE_PLANE, GEOM_RING_PLANE, ring_plane),
    (FEAT_SPHERE, SHAPE_PLANE): Geometry(FEAT_SPHERE, SHAPE_PLANE, GEOM_SPHERE_PLANE, sphere_plane),
    (FEAT_POINT, SHAPE_PLANE): Geometry(FEAT_POINT, SHAPE_PLANE, GEOM_POINT_PLANE, point_plane),
    (FEAT_RING, SHAPE_CYLINDER): Geometry(
        FEAT_RING, SHAPE_CYLINDER, GEOM_RING_CYLINDER, ring_solid
    ),
    (FEAT_SPHERE, SHAPE_CYLINDER): Geometry(
        FEAT_SPHERE, SHAPE_CYLINDER, GEOM_SPHERE_CYLINDER, sphere_cylinder
    ),
    (FEAT_POINT, SHAPE_CYLINDER): Geometry(
        FEAT_POINT, SHAPE_CYLINDER, GEOM_POINT_CYLINDER, point_cylinder
    ),
    (FEAT_RING, SHAPE_BOX): Geometry(FEAT_RING, SHAPE_BOX, GEOM_RING_BOX, ring_solid),
    (FEAT_SPHERE, SHAPE_BOX): Geometry(FEAT_SPHERE, SHAPE_BOX, GEOM_SPHERE_BOX, sphere_box),
    (FEAT_POINT, SHAPE_BOX): Geometry(FEAT_POINT, SHAPE_BOX, GEOM_POINT_BOX, point_box),
}
"""The table: (feature kind, shape kind) -> its geometry."""
for _feature, _shape, _gid, _fn in geometry_rows(BUILTIN_SHAPES):  # shape components' rows
    GEOMETRIES[(_feature, _shape)] = Geometry(_feature, _shape, _gid, _fn)

SHAPE_DISTANCES: dict[int, tuple[Callable, bool]] = {
    SHAPE_PLANE: (plane_distance, False),
    SHAPE_CYLINDER: (cylinder_distance, False),
    SHAPE_BOX: (box_distance, False),
    **{kind: (fn, False) for kind, fn in DISTANCE_ENTRIES},
}
"""Shape kind -> (its point-distance function, registered at run time)."""


# ---------------------------------------------------------------- compiled dispatch
@njit(cache=True, inline="always")
def plugin_contact(
    g: int, x: np.ndarray, C: np.ndarray, feat: np.ndarray, f: int, shapes: np.ndarray, s: int
) -> ContactRecord:
    """Registered rows (rebound by ``core.kernel.make_kernel``); none here: no contact."""
    return no_contact()


@compiled
def pair_contact(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, shapes: np.ndarray, pairs: np.ndarray, c: int
) -> ContactRecord:
    """The contact record of pair ``c`` of the pair table at the state ``x``.

    ``C`` is the body-to-inertial rotation of ``x``'s quaternion.
    """
    f = pairs[c, PR_FEATURE]
    s = pairs[c, PR_SHAPE]
    g = pairs[c, PR_GEOMETRY]
    if g == GEOM_RING_PLANE:
        return ring_plane(x, C, feat, f, shapes, s)
    if g == GEOM_RING_CYLINDER or g == GEOM_RING_BOX:
        return ring_solid(x, C, feat, f, shapes, s)
    if g == GEOM_SPHERE_PLANE:
        return sphere_plane(x, C, feat, f, shapes, s)
    if g == GEOM_POINT_PLANE:
        return point_plane(x, C, feat, f, shapes, s)
    if g == GEOM_SPHERE_CYLINDER:
        return sphere_cylinder(x, C, feat, f, shapes, s)
    if g == GEOM_POINT_CYLINDER:
        return point_cylinder(x, C, feat, f, shapes, s)
    if g == GEOM_SPHERE_BOX:
        return sphere_box(x, C, feat, f, shapes, s)
    if g == GEOM_POINT_BOX:
        return point_box(x, C, feat, f, shapes, s)
    if g < GEOM_PLUGIN:
        return component_contact(g, x, C, feat, f, shapes, s)
    return plugin_contact(g, x, C, feat, f, shapes, s)


@compiled
def component_contact(
    g: int, x: np.ndarray, C: np.ndarray, feat: np.ndarray, f: int, shapes: np.ndarray, s: int
) -> ContactRecord:
    """The rows of the shape components (``shapes.py``), by geometry id."""
    rec = no_contact()
    for e in literal_unroll(CONTACT_ENTRIES):
        if g == e[0]:
            rec = e[1](x, C, feat, f, shapes, s)
    return rec


@compiled
def pair_depth(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, shapes: np.ndarray, pairs: np.ndarray, c: int
) -> tuple[float, float]:
    """Penetration ``delta`` (m) and its rate ``delta_dot`` (m/s) of pair ``c`` only."""
    rec = pair_contact(x, C, feat, shapes, pairs, c)
    return rec[0], rec[1]


@njit(cache=True, inline="always")
def plugin_distance(px: float, py: float, pz: float, shapes: np.ndarray, s: int) -> float:
    """Registered shape kinds (rebound by ``core.kernel.make_kernel``); none here."""
    return math.inf


@compiled
def shape_distance(px: float, py: float, pz: float, shapes: np.ndarray, s: int) -> float:
    """Signed distance (m) of the inertial point ``p`` from shape ``s``, positive outside."""
    kind = int(shapes[s, SH_KIND])
    if kind == SHAPE_PLANE:
        return plane_distance(px, py, pz, shapes, s)
    if kind == SHAPE_CYLINDER:
        return cylinder_distance(px, py, pz, shapes, s)
    if kind == SHAPE_BOX:
        return box_distance(px, py, pz, shapes, s)
    found = False
    d = math.inf
    for e in literal_unroll(DISTANCE_ENTRIES):
        if kind == e[0]:
            d = e[1](px, py, pz, shapes, s)
            found = True
    if found:
        return d
    return plugin_distance(px, py, pz, shapes, s)


@njit(cache=True, inline="always")
def has_bound(pairs: np.ndarray, c: int) -> bool:
    """Whether pair ``c`` has a broad phase (:func:`pair_bound`): a ring against a cylinder or
    a box, whose record is a search; the closed forms cost what a bound would."""
    g = pairs[c, PR_GEOMETRY]
    return g == GEOM_RING_CYLINDER or g == GEOM_RING_BOX


@compiled
def pair_bound(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, shapes: np.ndarray, pairs: np.ndarray, c: int
) -> tuple[float, float]:
    """The broad phase of pair ``c`` (:func:`has_bound`): certified upper bounds on its
    penetration ``delta`` (m) and on ``|delta_dot|`` (m/s) at the state ``x``.

    A bound below zero proves the pair apart without its record
    (``ring.ring_solid_bound``: one point depth). Pairs without a broad phase:
    ``(inf, inf)``.
    """
    if has_bound(pairs, c):
        return ring_solid_bound(x, C, feat, pairs[c, PR_FEATURE], shapes, pairs[c, PR_SHAPE])
    return math.inf, math.inf


@compiled
def pair_depths(
    x: np.ndarray,
    C: np.ndarray,
    feat: np.ndarray,
    shapes: np.ndarray,
    pairs: np.ndarray,
    depths: np.ndarray,
) -> None:
    """``depths[c]``: the penetration (m) of every pair ``c`` of the table at the state ``x``."""
    for c in range(pairs.shape[0]):
        depths[c] = pair_contact(x, C, feat, shapes, pairs, c)[0]


@compiled
def _contact_record(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, shapes: np.ndarray, pairs: np.ndarray, c: int
) -> ContactRecord:
    return pair_contact(x, C, feat, shapes, pairs, c)


# ---------------------------------------------------------------- the table, from Python
def geometry_id(feature_kind: int, shape_kind: int) -> int:
    """The geometry id of a (feature kind, shape kind) pair; ``KeyError`` names a missing row."""
    try:
        return GEOMETRIES[(int(feature_kind), int(shape_kind))].id
    except KeyError:
        raise KeyError(
            f"no contact geometry for feature kind {_kind_name(FeatureKind, feature_kind)} "
            f"against shape kind {_kind_name(ShapeKind, shape_kind)}"
        ) from None


def _kind_name(enum: type, value: int) -> str:
    try:
        return enum(int(value)).name.lower()
    except ValueError:
        from quadimpact.core.geometry.shapes import by_kind

        comp = by_kind(int(value)) if enum is ShapeKind else None
        return comp.name if comp is not None else str(int(value))


def pair_table(feat: np.ndarray, shapes: np.ndarray) -> np.ndarray:
    """The contact-pair table of a run: every (feature, shape) pair, shape-major (int64).

    Pair ``c = s * n_features + f`` is feature ``f`` against shape ``s``; its
    ``PR_GEOMETRY`` is the table's id for their kinds.
    """
    nf = feat.shape[0]
    ns = shapes.shape[0]
    pairs = np.zeros((nf * ns, NPAIR), dtype=np.int64)
    for s in range(ns):
        for f in range(nf):
            c = s * nf + f
            pairs[c, PR_FEATURE] = f
            pairs[c, PR_SHAPE] = s
            pairs[c, PR_GEOMETRY] = geometry_id(feat[f, F_KIND], shapes[s, SH_KIND])
    return pairs


def contact_record(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, shapes: np.ndarray, f: int, s: int
) -> ContactRecord:
    """The contact record of feature ``f`` against shape ``s`` at ``x`` (from Python).

    ``C`` is the body-to-inertial rotation of ``x``'s quaternion. Built-in rows
    only (a registered row runs in its own compiled loop).
    """
    kind = (int(feat[f, F_KIND]), int(shapes[s, SH_KIND]))
    pairs = np.array([[f, s, geometry_id(*kind)]], dtype=np.int64)
    return _contact_record(
        np.ascontiguousarray(x, dtype=np.float64),
        np.ascontiguousarray(C, dtype=np.float64),
        feat,
        shapes,
        pairs,
        0,
    )


# ---------------------------------------------------------------- registered rows
def register_geometry(feature_kind: int, shape_kind: int, fn: Callable) -> int:
    """Add a row to the table: ``fn(x, C, feat, f, shapes, s) -> ContactRecord`` (``njit``).

    Returns its geometry id. A run whose pair table uses it runs in a loop
    compiled around the registered rows (``core.kernel.make_kernel``; compiled
    once per process, not cached on disk).
    """
    if not hasattr(fn, "py_func"):
        raise TypeError("register_geometry: fn must be a numba.njit function")
    key = (int(feature_kind), int(shape_kind))
    if key in GEOMETRIES and not GEOMETRIES[key].plugin:
        raise ValueError(f"register_geometry: {key} is a built-in row")
    gid = GEOMETRIES[key].id if key in GEOMETRIES else GEOM_PLUGIN + len(plugin_geometries())
    GEOMETRIES[key] = Geometry(key[0], key[1], gid, fn, plugin=True)
    return gid


def register_shape(comp: ShapeComponent) -> None:
    """Add a plug-in shape component: named from ``[[obstacles]]`` like a built-in.

    Its rows join :data:`GEOMETRIES` and its distance :data:`SHAPE_DISTANCES`;
    a run with one of its obstacles compiles a loop of its own around the
    registered shapes (``core.kernel.make_kernel(shapes=True)``), once per process.

    Raises
    ------
    TypeError
        Not a ``ShapeComponent``, or a function of it not compiled.
    ValueError
        Its name is taken (a built-in kind, or another plug-in).
    """
    if not isinstance(comp, ShapeComponent):
        raise TypeError("register_shape: expected a ShapeComponent")
    for fn in (comp.distance, *comp.contacts.values()):
        if not hasattr(fn, "py_func"):
            raise TypeError(f"shape {comp.name}: its functions must be numba.njit functions")
    if comp.name in ("plane", "cylinder", "box") or by_name(comp.name) is not None:
        raise ValueError(f"register_shape: {comp.name!r} is registered already")
    kind = add_plugin(comp)
    for feature, shape, gid, fn in geometry_rows():
        if shape == kind:
            GEOMETRIES[(feature, shape)] = Geometry(feature, shape, gid, fn)
    SHAPE_DISTANCES[kind] = (comp.distance, False)


def register_shape_distance(shape_kind: int, fn: Callable) -> None:
    """The point-distance function ``fn(px, py, pz, shapes, s) -> float`` of a new shape kind."""
    if not hasattr(fn, "py_func"):
        raise TypeError("register_shape_distance: fn must be a numba.njit function")
    if int(shape_kind) in SHAPE_DISTANCES and not SHAPE_DISTANCES[int(shape_kind)][1]:
        raise ValueError(f"register_shape_distance: shape kind {shape_kind} is built in")
    SHAPE_DISTANCES[int(shape_kind)] = (fn, True)


def plugin_geometries() -> list[Geometry]:
    """The registered rows, in id order."""
    return sorted((g for g in GEOMETRIES.values() if g.plugin), key=lambda g: g.id)


def plugin_distances() -> dict[int, Callable]:
    """The registered shape kinds' distance functions."""
    return {k: fn for k, (fn, plugin) in SHAPE_DISTANCES.items() if plugin}
