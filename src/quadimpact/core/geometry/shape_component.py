"""An obstacle-shape component: everything one shape kind is, declared in one module.

A shape module (``sphere.py`` is the example) holds, side by side:

* its **kind** (the ``kind`` tag of ``[[obstacles]]``) and its settings model
  (pydantic: ``kind``, ``name`` and its geometry fields);
* its **slots**: which numbers of a world-shape row (``shapes[s]``, layout
  ``SH_*``) hold which of its fields, each with its width and unit. Packing
  a scenario's obstacle, writing it to ``scenario.json`` and reading it back
  are derived from them (a field ``centre_m`` of width 3 goes to its slot's
  three numbers and back);
* its **compiled functions**: the signed distance of a point (the contact
  gate) and one contact-record function per feature kind it can touch
  (``contact_record.py``: ``fn(x, C, feat, f, shapes, s) -> ContactRecord``).

It registers with one line in ``shapes.py``. The kind's number and its
geometry ids are given by the registry from the order of registration.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from quadimpact.core.shape_slots import (
    NSHAPE,
    SH_IS_GROUND,
    SH_KIND,
)

__all__ = ["ShapeComponent", "ShapeSlot"]


@dataclass(frozen=True)
class ShapeSlot:
    """A settings field held in a shape row: ``width`` numbers from row slot ``slot``."""

    field: str
    slot: int
    width: int = 1
    unit: str = ""


@dataclass(frozen=True)
class ShapeComponent:
    """An obstacle shape kind, as its module declares it.

    Parameters
    ----------
    name : str
        Its ``kind`` tag in scenario files and results.
    settings : type
        Its settings model (pydantic; fields ``kind``, ``name`` and its slots').
    slots : tuple of ShapeSlot
        Its fields' places in a shape row (the other row slots stay 0).
    distance : numba function
        ``distance(px, py, pz, shapes, s) -> float``: signed distance (m) of
        the inertial point from shape ``s``, positive outside.
    contacts : mapping
        Feature kind (``FEAT_*``) -> its compiled contact-record function.
    lines : callable, optional
        ``lines(row) -> list of (n, 3) arrays``: polylines (inertial NED, m)
        that draw a packed row in the viewer and figures; None: not drawn.
    doc : str
        One line: what it is.
    """

    name: str
    settings: type
    slots: tuple[ShapeSlot, ...]
    distance: Callable[..., float]
    contacts: Mapping[int, Callable[..., Any]]
    lines: Callable[[np.ndarray], list[np.ndarray]] | None = None
    doc: str = ""

    def pack(self, obstacle: Any, kind: int) -> np.ndarray:
        """A shape row (``SH_*``) of a validated obstacle of this kind."""
        row = np.zeros(NSHAPE)
        row[SH_KIND] = kind
        row[SH_IS_GROUND] = 0.0
        for s in self.slots:
            row[s.slot : s.slot + s.width] = np.ravel(
                np.asarray(getattr(obstacle, s.field), dtype=float)
            )
        return row

    def record(self, row: np.ndarray, name: str) -> dict[str, Any]:
        """A packed row as plain data (``scenario.json``): name, kind, its fields."""
        out: dict[str, Any] = {"name": str(name), "kind": self.name}
        for s in self.slots:
            values = [float(c) for c in row[s.slot : s.slot + s.width]]
            out[s.field] = values[0] if s.width == 1 else values
        out["is_ground"] = bool(row[SH_IS_GROUND] > 0.5)
        return out

    def unpack(self, record: Mapping[str, Any], kind: int) -> np.ndarray:
        """The row of a :meth:`record` (as recorded, bit for bit).

        Raises
        ------
        ValueError
            A field of its slots missing from ``record`` (one line).
        """
        missing = [s.field for s in self.slots if s.field not in record]
        if missing:
            raise ValueError(
                f"surface {record.get('name')!r}: a {self.name} record needs {', '.join(missing)}"
            )
        row = np.zeros(NSHAPE)
        row[SH_KIND] = kind
        row[SH_IS_GROUND] = 1.0 if record.get("is_ground") else 0.0
        for s in self.slots:
            row[s.slot : s.slot + s.width] = np.ravel(np.asarray(record[s.field], dtype=float))
        return row

    def record_keys(self) -> tuple[str, ...]:
        """The keys of its :meth:`record`."""
        return ("name", "kind", *(s.field for s in self.slots), "is_ground")
