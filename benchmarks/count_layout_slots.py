"""The slots each module declares, and those of the central layout modules (issue 56).

Run: ``python benchmarks/count_layout_slots.py``. It imports every module of
``quadimpact.core`` (so that every ``Block`` is declared), then counts the
named slots of ``Block.registry`` by declaring module (``Block.module``): a
component's blocks count for its module, the rest for ``core/layout.py`` and
``core/envs/episode_layout.py`` (the central ones). With ``--blocks`` it
lists the central blocks, largest first.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
from collections import Counter

import quadimpact
from quadimpact.core.layout import Block

CENTRAL = ("quadimpact.core.layout", "quadimpact.core.envs.episode_layout")


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
    for name, n in sorted(per.items()):
        print(f"{n:5d}  {name}{'  (central)' if name in CENTRAL else ''}")
    print(f"central total: {sum(per[k] for k in CENTRAL)}")
    if args.blocks:
        rows = [(len(b.slots), b.array) for b in Block.registry.values() if b.module in CENTRAL]
        for n, array in sorted(rows, reverse=True):
            print(f"{n:5d}  {array}")


if __name__ == "__main__":
    main()
