"""The old flat module paths (``quadimpact.config``, ``quadimpact.io``...), kept working.

Before the layered layout every module sat flat under ``quadimpact/``. An
import of an old path is answered with the module that took its place, the
very same module object (``quadimpact.config.WallApproach is
quadimpact.inputs.scenarios.WallApproach``), and a ``DeprecationWarning``
naming the new path. Installed on ``sys.meta_path`` by ``quadimpact/__init__.py``;
no file stands at the old paths. Where a module was split, the old path is
the part that kept most of it, and the warning says where the rest went.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings
from types import ModuleType
from typing import Any

__all__ = ["ALSO", "MOVED", "LegacyFinder", "install"]

#: Old dotted name -> the module that took its place.
MOVED: dict[str, str] = {
    "quadimpact.analysis": "quadimpact.simulation.metrics",
    "quadimpact.config": "quadimpact.inputs.scenarios",
    "quadimpact.findings": "quadimpact.paper.findings",
    "quadimpact.frames": "quadimpact.rotations",
    "quadimpact.io": "quadimpact.results.files",
    "quadimpact.packing": "quadimpact.simulation.packing",
    "quadimpact.plots": "quadimpact.results.figures",
    "quadimpact.result": "quadimpact.results.result",
    "quadimpact.scenario": "quadimpact.simulation.setup",
    "quadimpact.study": "quadimpact.paper.study",
    "quadimpact.sweep_plots": "quadimpact.sweep.plots",
    "quadimpact.vehicle": "quadimpact.inputs.vehicle",
}

#: Where the rest of a split module went (added to the warning).
ALSO = {
    "quadimpact.analysis": "the episodes and time-series tables: quadimpact.simulation.record",
    "quadimpact.config": "model options and variants: quadimpact.inputs.model, surfaces: "
    "quadimpact.inputs.world, the TOML reader: quadimpact.inputs.files",
    "quadimpact.io": "read_result: quadimpact.results.result",
    "quadimpact.packing": "Surface is quadimpact.inputs.world.Plane",
    "quadimpact.scenario": "the wall attitude and the approach shooting: "
    "quadimpact.simulation.approach",
    "quadimpact.study": "the report's Markdown: quadimpact.paper.report",
}


class _MovedLoader(importlib.abc.Loader):
    """Loads an old name as the module that replaced it."""

    def __init__(self, new: str, note: str) -> None:
        self.new = new
        self.note = note

    def create_module(self, spec: Any) -> ModuleType:
        warnings.warn(
            f"{spec.name} is deprecated: import {self.new} instead{self.note}",
            DeprecationWarning,
            stacklevel=2,
        )
        module = importlib.import_module(self.new)
        self._spec = module.__spec__
        return module

    def exec_module(self, module: ModuleType) -> None:
        # the import system set the old name's spec on the module: give it back its own
        module.__spec__ = self._spec


class LegacyFinder(importlib.abc.MetaPathFinder):
    """Finds the old module paths of :data:`MOVED` (and nothing else)."""

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> Any:
        if fullname not in MOVED:
            return None
        note = f"; {ALSO[fullname]}" if fullname in ALSO else ""
        return importlib.util.spec_from_loader(fullname, _MovedLoader(MOVED[fullname], note))


def install() -> None:
    """Put :class:`LegacyFinder` on ``sys.meta_path`` (once)."""
    if not any(isinstance(finder, LegacyFinder) for finder in sys.meta_path):
        sys.meta_path.append(LegacyFinder())
