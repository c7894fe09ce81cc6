"""The declaration of consecutive slots of the compiled core's arrays (:class:`Block`).

A module that declares slots imports this one only: it holds no compiled code
and imports nothing of quadimpact, so a component's declaration module
(``core/contact_slots.py``...) and ``core/layout.py``, which sizes its arrays
from those declarations, can import each other's sizes without a cycle.
``tests/core/test_layout.py`` checks every registered block.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from typing import ClassVar

__all__ = ["Block"]


@dataclass
class Block:
    """Consecutive slots of one array (or of a part of one), declared in order.

    Parameters
    ----------
    array : str
        What the slots index: a record field (``"veh"``, ``"stats"``...), or
        ``"ctrl.params.<controller>"`` for a parameter block inside ``ctrl``.
    prefix : str
        The prefix of every slot constant of the block (``"V_"``).
    start : int
        Offset of the first slot (a block may continue another one).
    capacity : int, optional
        An upper bound the block must fit in (a controller's parameter block
        must fit in ``NPARAM``).
    """

    array: str
    prefix: str
    start: int = 0
    capacity: int | None = None
    slots: dict[str, tuple[int, int]] = field(default_factory=dict)
    size_name: str | None = None
    module: str = ""
    registry: ClassVar[dict[str, Block]] = {}

    def __post_init__(self) -> None:
        self.next = self.start
        if not self.module:  # the declaring module: the caller of the generated __init__
            self.module = sys._getframe(2).f_globals.get("__name__", "")
        Block.registry[f"{self.array}:{self.prefix}"] = self  # a module reloaded: the new one

    def slot(self, name: str, width: int = 1) -> int:
        """Declare the next slot (``width`` consecutive numbers); return its offset."""
        if not name.startswith(self.prefix):
            raise ValueError(f"layout: slot {name} must start with {self.prefix}")
        if name in self.slots or width < 1:
            raise ValueError(f"layout: slot {name} declared twice or with width < 1")
        offset = self.next
        self.slots[name] = (offset, width)
        self.next += width
        if self.capacity is not None and self.next > self.capacity:
            raise ValueError(f"layout: block {self.array} overflows its {self.capacity} slots")
        return offset

    def end(self, size_name: str) -> int:
        """Close the block; return its size (the first offset after its last slot)."""
        self.size_name = size_name
        return self.next
