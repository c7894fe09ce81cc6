"""The slots each module declares, and those of the central layout (issue 56).

Run: ``python benchmarks/count_layout_slots.py``. It imports every module of
``quadimpact.core`` (so that every ``Block`` is declared), then counts the
named slots of ``Block.registry`` by declaring module (``Block.module``).

A block counts for a component when the component declares it: in its own
compiled module (``core/approach.py``...), or in a declaration module of its
own, listed in :data:`DECLARATIONS` with its owner. A declaration module
counts only if it is honest about it, which this script checks:

- it imports no compiled code (of quadimpact, only ``core.block`` and
  ``core.layout``), so that records and layouts can size arrays from it;
- its owner lies next to it or in its package, and imports it;
- ``core/layout.py`` does not re-export its slots (a size it reads to place
  a region, such as ``NEX``, is not a slot).

Every other declaring module without compiled code counts as central, as
``core/layout.py`` does. With ``--blocks`` it lists the central blocks,
largest first.
"""

from __future__ import annotations

import argparse
import ast
import importlib
import inspect
import pkgutil
from collections import Counter
from pathlib import Path

import quadimpact
from quadimpact.core.layout import Block

CENTRAL = ("quadimpact.core.layout",)
#: A component's declaration module (no compiled code) -> the module that owns its slots.
DECLARATIONS = {
    "quadimpact.core.contact_slots": "quadimpact.core.contact",
    "quadimpact.core.recording_slots": "quadimpact.core.recording",
    "quadimpact.core.excursion_slots": "quadimpact.core.excursion",
    "quadimpact.core.hover_slots": "quadimpact.core.hover_tracking",
    "quadimpact.core.sensors.imu_slots": "quadimpact.core.sensors.imu",
    "quadimpact.core.feature_slots": "quadimpact.core.contact",
    "quadimpact.core.shape_slots": "quadimpact.core.geometry",
    "quadimpact.core.envs.episode_layout": "quadimpact.core.envs.stacked",
    "quadimpact.core.controller_slots": "quadimpact.core.controllers",
    "quadimpact.core.estimator_slots": "quadimpact.core.estimators",
    "quadimpact.core.sensors.measurement_slots": "quadimpact.core.sensors.measurement",
    "quadimpact.core.vehicle_slots": "quadimpact.core.dynamics",
    "quadimpact.core.interval_slots": "quadimpact.core.interval",
}
#: What a declaration module may import of quadimpact.
DECLARATION_IMPORTS = {"quadimpact.core.block", "quadimpact.core.layout"}


def _imports(module: str) -> set[str]:
    """The quadimpact modules ``module`` imports (``from a import b``: ``a``)."""
    tree = ast.parse(Path(inspect.getfile(importlib.import_module(module))).read_text())
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            out.add(node.module)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return {m for m in out if m.startswith("quadimpact")}


def _imports_name(module: str, package: str, name: str) -> bool:
    """Whether ``module`` has ``from package import name`` (a module imported by its package)."""
    tree = ast.parse(Path(inspect.getfile(importlib.import_module(module))).read_text())
    return any(
        isinstance(node, ast.ImportFrom)
        and node.module == package
        and any(a.name == name for a in node.names)
        for node in ast.walk(tree)
    )


def _compiled(module: str) -> bool:
    """Whether ``module`` holds compiled code (it imports Numba or ``core.compiled``)."""
    tree = ast.parse(Path(inspect.getfile(importlib.import_module(module))).read_text())
    for node in ast.walk(tree):
        names = (
            [node.module or ""]
            if isinstance(node, ast.ImportFrom)
            else [a.name for a in node.names]
            if isinstance(node, ast.Import)
            else []
        )
        if any(
            n == "numba" or n.startswith("numba.") or n.endswith("core.compiled") for n in names
        ):
            return True
    return False


def check_declaration(module: str, owner: str) -> None:
    """Raise unless ``module`` is an honest declaration module of ``owner`` (see above)."""
    extra = _imports(module) - DECLARATION_IMPORTS
    if extra or _compiled(module):
        raise SystemExit(f"{module}: a declaration module imports {sorted(extra) or 'Numba'}")
    package = module.rsplit(".", 1)[0]
    if not owner.startswith(package + "."):
        raise SystemExit(f"{module}: its owner {owner} is not next to it or in its package")
    package_, leaf = module.rsplit(".", 1)
    if module not in _imports(owner) and not _imports_name(owner, package_, leaf):
        raise SystemExit(f"{module}: its owner {owner} does not import it")
    layout = importlib.import_module("quadimpact.core.layout")
    for b in Block.registry.values():
        if b.module == module:
            leaked = [n for n in b.slots if hasattr(layout, n)]
            if leaked:
                raise SystemExit(f"{module}: core/layout.py re-exports {leaked}")


def central_modules(declaring: set[str]) -> set[str]:
    """The declaring modules whose blocks count as central."""
    for module, owner in DECLARATIONS.items():
        check_declaration(module, owner)
    return {m for m in declaring if m in CENTRAL or (m not in DECLARATIONS and not _compiled(m))}


def main() -> None:
    """Print the slots per declaring module and the central total."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--blocks", action="store_true", help="list the central blocks too")
    args = ap.parse_args()
    for mod in pkgutil.walk_packages(quadimpact.__path__, "quadimpact."):
        if mod.name.startswith("quadimpact.core"):
            importlib.import_module(mod.name)
    per: Counter[str] = Counter()
    for b in Block.registry.values():
        per[b.module] += len(b.slots)
    central = central_modules(set(per))
    for name, n in sorted(per.items()):
        tag = "  (central)" if name in central else ""
        if name in DECLARATIONS:
            tag = f"  (declares for {DECLARATIONS[name]})"
        print(f"{n:5d}  {name}{tag}")
    print(f"central total: {sum(per[k] for k in central)}")
    if args.blocks:
        rows = [(len(b.slots), b.array) for b in Block.registry.values() if b.module in central]
        for n, array in sorted(rows, reverse=True):
            print(f"{n:5d}  {array}")


if __name__ == "__main__":
    main()
