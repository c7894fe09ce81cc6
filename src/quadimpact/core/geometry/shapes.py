"""The obstacle-shape components: the registry, their kinds and geometry ids, the dispatch.

**Adding a shape** is its module (``shape_component.py`` says what it
declares; ``sphere.py`` is the example) and one line of :data:`BUILTIN`
below; a plug-in is the same module outside the package and one call of
``core.geometry.register_shape``. The registry numbers the kinds from
:data:`FIRST_KIND` in the order of the tuple and gives each (feature kind,
shape) pair a geometry id from
:data:`FIRST_GEOMETRY`; ``core/geometry/__init__.py`` adds those rows to the
contact table and its compiled dispatch reaches their functions through
:data:`CONTACT_ENTRIES` and :data:`DISTANCE_ENTRIES` (tuples of functions,
unrolled at compile time). The scenario files (``inputs/world.py``), the
packing and the results (``scenario.json``) find a shape here by its name.
"""

from __future__ import annotations

import warnings

from numba.core.errors import NumbaExperimentalFeatureWarning

from quadimpact.core.geometry import sphere
from quadimpact.core.geometry.shape_component import ShapeComponent

__all__ = [
    "BUILTIN",
    "CONTACT_ENTRIES",
    "DISTANCE_ENTRIES",
    "FIRST_GEOMETRY",
    "FIRST_KIND",
    "by_kind",
    "by_name",
    "geometry_rows",
    "components",
    "contact_entries",
    "distance_entries",
    "kind_of",
    "add_plugin",
    "plugin_shapes",
]

warnings.filterwarnings("ignore", category=NumbaExperimentalFeatureWarning)

BUILTIN: tuple[ShapeComponent, ...] = (
    sphere.SHAPE,  # a ball: exact contact for every feature kind
)
"""The shape components, one line each (the plane, cylinder and box predate them)."""

_PLUGINS: list[ShapeComponent] = []

FIRST_KIND = 16  # SH_KIND of the first component (the built-in kinds are 0-2)
FIRST_GEOMETRY = 100  # geometry id of the first component row (built-in rows 0-8)
N_FEATURE_KINDS = 8  # geometry ids per shape component: one per feature kind


def components() -> tuple[ShapeComponent, ...]:
    """Every registered shape component: the built-ins, then the plug-ins in order."""
    return BUILTIN + tuple(_PLUGINS)


def plugin_shapes() -> tuple[ShapeComponent, ...]:
    """The shape components registered as plug-ins so far."""
    return tuple(_PLUGINS)


def kind_of(comp: ShapeComponent) -> int:
    """The ``SH_KIND`` number of a registered shape component."""
    return FIRST_KIND + components().index(comp)


def by_name(name: str) -> ShapeComponent | None:
    """The shape component whose kind tag is ``name`` (None: none)."""
    for c in components():
        if c.name == name:
            return c
    return None


def by_kind(kind: int) -> ShapeComponent | None:
    """The shape component of ``SH_KIND`` number ``kind`` (None: none)."""
    k = int(kind) - FIRST_KIND
    comps = components()
    return comps[k] if 0 <= k < len(comps) else None


def add_plugin(comp: ShapeComponent) -> int:
    """Append a plug-in component (``core.geometry.register_shape`` checks it); its kind."""
    _PLUGINS.append(comp)
    return kind_of(comp)


def contact_entries(comps: tuple[ShapeComponent, ...] | None = None) -> tuple:
    """The dispatch's pairs ``(geometry id, contact function)`` of ``comps`` (all registered)."""
    return tuple((gid, fn) for _, _, gid, fn in geometry_rows(comps))


def distance_entries(comps: tuple[ShapeComponent, ...] | None = None) -> tuple:
    """The dispatch's pairs ``(shape kind, distance function)`` of ``comps`` (all registered)."""
    comps = components() if comps is None else comps
    return tuple((FIRST_KIND + i, c.distance) for i, c in enumerate(comps))


def geometry_rows(
    comps: tuple[ShapeComponent, ...] | None = None,
) -> list[tuple[int, int, int, object]]:
    """The component rows of the contact table: ``(feature kind, shape kind, id, fn)``."""
    rows = []
    for i, c in enumerate(components() if comps is None else comps):
        for feature, fn in sorted(c.contacts.items()):
            rows.append(
                (
                    int(feature),
                    FIRST_KIND + i,
                    FIRST_GEOMETRY + N_FEATURE_KINDS * i + int(feature),
                    fn,
                )
            )
    return rows


CONTACT_ENTRIES = contact_entries(BUILTIN)
"""The compiled dispatch's pairs of the built-ins: (geometry id, contact function)."""
DISTANCE_ENTRIES = distance_entries(BUILTIN)
"""The compiled dispatch's pairs of the built-ins: (shape kind, distance function)."""
