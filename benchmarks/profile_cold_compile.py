"""Where the simulator's cold compile spends its CPU: per function, per LLVM library, per pass.

Run: ``NUMBA_CACHE_DIR=$(mktemp -d) python benchmarks/profile_cold_compile.py OUT.json``
(an empty cache, or nothing is compiled). It runs ``quadimpact compile
--no-environments`` in this process with listeners on Numba's compile and
pass events (``numba:compile``, ``numba:run_pass``) and timers around
Numba's LLVM stages, then prints:

* each function's own compile CPU (its nested compiles subtracted) and its
  number of specialisations, the largest first, and every function compiled
  more than once with its argument types;
* each compiled function's library: how many functions its machine code
  holds (its callees linked in) and the LLVM CPU it took;
* the CPU of each compiler pass, summed over the functions.

``OUT.json`` keeps the raw figures. docs/PERFORMANCE.md ("The simulator's
cold compile") reads them.
"""

from __future__ import annotations

import collections
import json
import re
import sys
import time
from typing import Any

from numba.core import codegen, event

CPU = time.process_time
_stack: list[list[Any]] = []  # [kind, key, started, nested CPU, depth]
_specs: list[tuple[str, str, float, int]] = []  # function, argument types, total CPU, depth
_passes: collections.Counter = collections.Counter()
_libraries: dict[str, collections.Counter] = collections.defaultdict(collections.Counter)
_functions: dict[str, int] = {}
_LLVM_STAGES = ("add_ir_module", "_optimize_final_module", "_finalize_specific")


class _Compiles(event.Listener):
    def on_start(self, ev: event.Event) -> None:
        fn = ev.data["dispatcher"].py_func
        args = ", ".join(str(a) for a in ev.data["args"])
        depth = sum(1 for f in _stack if f[0] == "c")
        _stack.append(["c", (f"{fn.__module__}.{fn.__qualname__}", args), CPU(), 0.0, depth])

    def on_end(self, ev: event.Event) -> None:
        kind, (name, args), started, _, depth = _stack.pop()
        spent = CPU() - started
        _specs.append((name, args, spent, depth))
        for frame in reversed(_stack):  # subtracted from the enclosing pass and compile
            frame[3] += spent
            if frame[0] == "c":
                break


class _Passes(event.Listener):
    def on_start(self, ev: event.Event) -> None:
        _stack.append(["p", ev.data["name"], CPU(), 0.0, 0])

    def on_end(self, ev: event.Event) -> None:
        _, name, started, nested, _ = _stack.pop()
        _passes[name] += CPU() - started - nested


def _timed(cls: type, name: str) -> None:
    original = getattr(cls, name)

    def timed(self: Any, *args: Any, **kwargs: Any) -> Any:
        started = CPU()
        try:
            return original(self, *args, **kwargs)
        finally:
            _libraries[self.name][name] += CPU() - started
            if name == "_finalize_specific":
                mod = self._final_module
                _functions[self.name] = sum(1 for f in mod.functions if not f.is_declaration)

    setattr(cls, name, timed)


def _report(out: dict) -> None:
    own: collections.Counter = collections.Counter()
    count: collections.Counter = collections.Counter()
    signatures = collections.defaultdict(list)
    nested = collections.defaultdict(float)
    for name, args, spent, depth in out["specs"]:  # post-order: children end first
        mine = spent - nested.pop(depth + 1, 0.0)
        nested[depth] += spent
        own[name] += mine
        count[name] += 1
        signatures[name].append(args)
    print(
        f"cold compile: {out['cpu_s']:.1f} s of CPU, {len(out['specs'])} specialisations "
        f"of {len(count)} functions"
    )
    print("\nfunction | specialisations | own CPU s")
    for name, spent in own.most_common(30):
        print(f"{name.replace('quadimpact.core.', '')} | {count[name]} | {spent:.1f}")
    print("\ncompiled more than once:")
    for name in sorted((n for n in count if count[n] > 1), key=lambda n: -own[n]):
        print(f"{name} ({own[name]:.1f} s)")
        for args in signatures[name]:
            print(f"    {args[:200]}")
    rows = sorted(
        (
            (sum(st.get(k, 0.0) for k in _LLVM_STAGES), out["functions"].get(lib), lib)
            for lib, st in out["libraries"].items()
        ),
        reverse=True,
    )
    print(f"\nLLVM: {sum(r[0] for r in rows):.1f} s of CPU in {len(rows)} libraries")
    print("library | functions in its machine code | LLVM CPU s")
    for spent, n, lib in rows[:25]:
        print(f"{lib} | {n} | {spent:.1f}")
    by_pass: collections.Counter = collections.Counter()
    for key, spent in out["passes"].items():
        by_pass[re.sub(r" \[.*\]$", "", key)] += spent
    print("\npass | CPU s")
    for name, spent in by_pass.most_common(10):
        print(f"{name} | {spent:.1f}")


def main() -> None:
    event.register("numba:compile", _Compiles())
    event.register("numba:run_pass", _Passes())
    for name in ("add_ir_module", "_optimize_final_module"):
        _timed(codegen.CPUCodeLibrary, name)
    _timed(codegen.JITCodeLibrary, "_finalize_specific")
    from quadimpact.cli import main as cli

    try:
        cli(["compile", "--no-environments"])
    except SystemExit:
        pass
    out = {
        "cpu_s": CPU(),
        "specs": _specs,
        "passes": dict(_passes),
        "libraries": {k: dict(v) for k, v in _libraries.items()},
        "functions": _functions,
    }
    if len(sys.argv) > 1:
        with open(sys.argv[1], "w") as f:
            json.dump(out, f)
    _report(out)


if __name__ == "__main__":
    main()
