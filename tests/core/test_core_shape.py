"""The compiled core stays small-grained: few named arguments, a short tick.

Compiled functions take a handful of named records (``core/records.py``)
instead of long positional lists of arrays (two swapped arrays of the same
type would compile and run), and a control tick reads as a pipeline of stage
functions.
"""

from __future__ import annotations

import ast
from pathlib import Path

import quadimpact.core

CORE = Path(quadimpact.core.__file__).resolve().parent
MAX_PARAMETERS = 10
MAX_TICK_LINES = 80


def _compiled_functions() -> list[tuple[Path, ast.FunctionDef]]:
    found = []
    for path in sorted(CORE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.FunctionDef):
                continue
            for dec in node.decorator_list:
                target = dec.func if isinstance(dec, ast.Call) else dec
                if isinstance(target, ast.Name) and target.id == "njit":
                    found.append((path, node))
    return found


def test_no_compiled_function_takes_more_than_ten_parameters():
    functions = _compiled_functions()
    assert len(functions) > 50  # the whole core is found
    too_many = [
        f"{path.relative_to(CORE)}:{fn.name} ({len(fn.args.args)})"
        for path, fn in functions
        if len(fn.args.args) + len(fn.args.kwonlyargs) > MAX_PARAMETERS
    ]
    assert not too_many, too_many


def test_the_tick_is_a_short_pipeline_of_stages():
    (tick,) = [
        fn for path, fn in _compiled_functions() if path.name == "step.py" and fn.name == "tick"
    ]
    lines = tick.end_lineno - tick.lineno + 1
    assert lines < MAX_TICK_LINES, lines
    called = {
        n.func.id
        for n in ast.walk(tick)
        if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)
    }
    # the stages, in their own functions
    assert {
        "_crash_at_tick",
        "at_tick",
        "_command",
        "apply_command",
        "integrate_interval",
    } <= called
