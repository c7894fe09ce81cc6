"""The obstacle-shape components: the registry, their kinds and geometry ids, the dispatch.

**Adding a shape** is its module (``shape_component.py`` says what it
declares; ``sphere.py`` is the example) and one line of :data:`BUILTIN`
below. The registry numbers the kinds from :data:`FIRST_KIND` in the order
of the tuple and gives each (feature kind, shape) pair a geometry id from
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
    "kind_of",
]

warnings.filterwarnings("ignore", category=NumbaExperimentalFeatureWarning)

BUILTIN: tuple[ShapeComponent, ...] = (
    sphere.SHAPE,  # a ball: exact contact for every feature kind
)
"""The shape components, one line each (the plane, cylinder and box predate them)."""

FIRST_KIND = 16  # SH_KIND of the first component (the built-in kinds are 0-2)
FIRST_GEOMETRY = 100  # geometry id of the first component row (built-in rows 0-8)
N_FEATURE_KINDS = 8  # geometry ids per shape component: one per feature kind


def kind_of(comp: ShapeComponent) -> int:
    """The ``SH_KIND`` number of a registered shape component."""
    return FIRST_KIND + BUILTIN.index(comp)


def by_name(name: str) -> ShapeComponent | None:
    """The shape component whose kind tag is ``name`` (None: none)."""
    for c in BUILTIN:
        if c.name == name:
            return c
    return None


def by_kind(kind: int) -> ShapeComponent | None:
    """The shape component of ``SH_KIND`` number ``kind`` (None: none)."""
    k = int(kind) - FIRST_KIND
    return BUILTIN[k] if 0 <= k < len(BUILTIN) else None


def geometry_rows() -> list[tuple[int, int, int, object]]:
    """Every component row of the contact table: ``(feature kind, shape kind, id, fn)``."""
    rows = []
    for i, c in enumerate(BUILTIN):
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


CONTACT_ENTRIES = tuple((gid, fn) for _, _, gid, fn in geometry_rows())
"""The compiled dispatch's pairs: (geometry id, contact function)."""
DISTANCE_ENTRIES = tuple((FIRST_KIND + i, c.distance) for i, c in enumerate(BUILTIN))
"""The compiled dispatch's pairs: (shape kind, distance function)."""
