"""The package's layers: every import (module- and function-level, absolute and
relative) of every module, parsed with ``ast``, against the layer order.

1. ``quadimpact.core`` imports nothing of quadimpact outside ``core``; the
   base modules (``errors``, ``libm``, ``linalg``, ``rotations``) import nothing of
   quadimpact but ``errors``, ``libm`` and ``linalg`` (the package root nothing);
2. no import cycle between modules anywhere in the package;
3. no module imports a layer above its own (:data:`LAYERS`, lowest first);
   a module may import its own layer and the layers below.

``from quadimpact import simulate`` names the module the root exports it from
(``_EXPORTS`` in ``quadimpact/__init__.py``, imported lazily there). Imports of
third-party packages do not count; ``import a.b`` counts as an import of
``a.b`` only (not of the package ``a``, which Python also runs).
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path

import pytest

import quadimpact

ROOT = Path(quadimpact.__file__).resolve().parent

#: The layers, lowest first: a module may import its own layer and those below.
LAYERS: list[tuple[str, tuple[str, ...]]] = [
    # and the package root, quadimpact/__init__.py
    (
        "base",
        (
            "quadimpact.core",
            "quadimpact.errors",
            "quadimpact.libm",
            "quadimpact.linalg",
            "quadimpact.rotations",
        ),
    ),
    ("inputs", ("quadimpact.inputs",)),
    ("packing", ("quadimpact.packing",)),
    ("results", ("quadimpact.results",)),
    ("simulation", ("quadimpact.simulation",)),
    ("sweep, viz, envs", ("quadimpact.sweep", "quadimpact.viz", "quadimpact.envs")),
    ("experiments", ("quadimpact.experiments",)),
    ("studies", ("quadimpact.studies",)),
    ("cli", ("quadimpact.cli",)),
]
#: What the base modules may import of quadimpact (rule 1).
BASE_ALLOWED: dict[str, tuple[str, ...]] = {
    "quadimpact": (),
    "quadimpact.errors": (),
    "quadimpact.libm": (),
    "quadimpact.linalg": (),
    "quadimpact.rotations": ("quadimpact.errors", "quadimpact.libm", "quadimpact.linalg"),
}


@dataclass(frozen=True)
class Import:
    """One import statement's target inside the package."""

    module: str  # the importing module
    target: str  # the imported module
    line: int

    def __str__(self) -> str:
        return f"{self.module} (line {self.line}) imports {self.target}"


# ------------------------------------------------------------------ parsing
def package_sources(root: Path = ROOT) -> dict[str, tuple[bool, str]]:
    """Dotted module name -> (is a package ``__init__``, source) for every module."""
    out = {}
    for path in sorted(root.rglob("*.py")):
        parts = ("quadimpact", *path.relative_to(root).with_suffix("").parts)
        is_package = parts[-1] == "__init__"
        name = ".".join(parts[:-1] if is_package else parts)
        out[name] = (is_package, path.read_text(encoding="utf-8"))
    return out


def lazy_exports(sources: dict[str, tuple[bool, str]]) -> dict[str, str]:
    """The root's ``_EXPORTS``: public name -> the module it is imported from."""
    for node in ast.walk(ast.parse(sources["quadimpact"][1])):
        if isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == "_EXPORTS" for t in node.targets
        ):
            return ast.literal_eval(node.value)
    return {}


def _known(name: str, modules: set[str]) -> str | None:
    """The deepest module of the package that ``name`` is or lies in."""
    parts = name.split(".")
    for k in range(len(parts), 0, -1):
        candidate = ".".join(parts[:k])
        if candidate in modules:
            return candidate
    return None


def imports(sources: dict[str, tuple[bool, str]]) -> list[Import]:
    """Every import of a package module by a package module (anywhere in the file)."""
    modules = set(sources)
    exports = lazy_exports(sources) if "quadimpact" in sources else {}
    found: list[Import] = []
    for name, (is_package, source) in sources.items():
        package = name if is_package else name.rpartition(".")[0]
        for node in ast.walk(ast.parse(source, filename=name)):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")
                    base = base[: len(base) - (node.level - 1)]
                    origin = ".".join([*base, *([node.module] if node.module else [])])
                else:
                    origin = node.module or ""
                for alias in node.names:
                    sub = f"{origin}.{alias.name}"
                    if sub in modules:
                        targets.append(sub)
                    elif origin == "quadimpact" and alias.name in exports:
                        targets.append(exports[alias.name])
                    else:
                        targets.append(origin)
            for target in targets:
                known = _known(target, modules)
                if known is not None and known != name:
                    found.append(Import(name, known, node.lineno))
    return found


# ------------------------------------------------------------------ rules
def layer_of(module: str) -> int:
    if module == "quadimpact":
        return 0
    for i, (_, prefixes) in enumerate(LAYERS):
        if any(module == p or module.startswith(p + ".") for p in prefixes):
            return i
    raise AssertionError(f"{module} is in no layer: add it to LAYERS in tests/test_layering.py")


def base_violations(found: list[Import]) -> list[str]:
    """Rule 1: core imports only core; the base modules only what BASE_ALLOWED says."""
    bad = []
    for imp in found:
        in_core = imp.module == "quadimpact.core" or imp.module.startswith("quadimpact.core.")
        if in_core and not imp.target.startswith("quadimpact.core"):
            bad.append(f"{imp}: core imports nothing outside quadimpact.core")
        if imp.module in BASE_ALLOWED and imp.target not in BASE_ALLOWED[imp.module]:
            allowed = ", ".join(BASE_ALLOWED[imp.module]) or "nothing of quadimpact"
            bad.append(f"{imp}: {imp.module} may import {allowed}")
    return bad


def layer_violations(found: list[Import]) -> list[str]:
    """Rule 3: no import of a layer above the importing module's."""
    order = " < ".join(name for name, _ in LAYERS)
    bad = []
    for imp in found:
        own, other = layer_of(imp.module), layer_of(imp.target)
        if other > own:
            bad.append(
                f"{imp}: layer '{LAYERS[own][0]}' may not import layer '{LAYERS[other][0]}' "
                f"(order: {order})"
            )
    return bad


def cycles(found: list[Import]) -> list[str]:
    """Rule 2: one line per import cycle (Tarjan's strongly connected components)."""
    graph: dict[str, dict[str, Import]] = {}
    for imp in found:
        graph.setdefault(imp.module, {}).setdefault(imp.target, imp)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, {}):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                components.append(component)

    for v in sorted(graph):
        if v not in index:
            visit(v)
    out = []
    for component in components:
        members = set(component)
        # one cycle through the component, import by import
        start = min(component)
        path, seen, v = [], {start}, start
        while True:
            w = min(t for t in graph[v] if t in members)
            path.append(str(graph[v][w]))
            if w in seen:
                break
            seen.add(w)
            v = w
        out.append("import cycle: " + "; ".join(path))
    return out


# ------------------------------------------------------------------ the package
@pytest.fixture(scope="module")
def package_imports() -> list[Import]:
    return imports(package_sources())


def test_core_and_the_base_modules_import_nothing_above(package_imports) -> None:
    bad = base_violations(package_imports)
    assert not bad, "\n".join(bad)


def test_no_import_cycles(package_imports) -> None:
    bad = cycles(package_imports)
    assert not bad, "\n".join(bad)


def test_no_module_imports_a_layer_above_its_own(package_imports) -> None:
    bad = layer_violations(package_imports)
    assert not bad, "\n".join(bad)


def test_every_module_is_in_a_layer_and_the_parse_sees_imports(package_imports) -> None:
    sources = package_sources()
    for name in sources:
        layer_of(name)
    targets = {(imp.module, imp.target) for imp in package_imports}
    # function-level, relative, and lazily exported imports are all seen
    # from quadimpact import simulate
    assert ("quadimpact.sweep.worker", "quadimpact.simulation") in targets
    assert ("quadimpact.results.result", "quadimpact.results.figures") in targets  # in a function
    assert ("quadimpact.core.step", "quadimpact.core.interval") in targets


# ------------------------------------------------------------------ the checks can fail
def _fake(**modules: str) -> dict[str, tuple[bool, str]]:
    return {name.replace("__", "."): (False, source) for name, source in modules.items()}


def test_the_checks_name_the_offending_import() -> None:
    found = imports(
        _fake(
            quadimpact__core__kernel="import numpy\nfrom quadimpact.errors import InputError\n",
            quadimpact__errors="",
            quadimpact__results__files="def f():\n    from quadimpact.simulation import tables\n",
            quadimpact__simulation__tables="from ..results import files\n",
            quadimpact__simulation="",
            quadimpact__results="",
            quadimpact__core="",
        )
    )
    assert base_violations(found) == [
        "quadimpact.core.kernel (line 2) imports quadimpact.errors: "
        "core imports nothing outside quadimpact.core"
    ]
    (layer,) = layer_violations(found)
    assert layer.startswith(
        "quadimpact.results.files (line 2) imports quadimpact.simulation.tables: "
        "layer 'results' may not import layer 'simulation'"
    )
    (cycle,) = cycles(found)
    assert "quadimpact.results.files (line 2) imports quadimpact.simulation.tables" in cycle
    assert "quadimpact.simulation.tables (line 1) imports quadimpact.results.files" in cycle
