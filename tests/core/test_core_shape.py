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


DECORATORS = {"njit", "compiled", "allocating"}  # core/compiled.py
REFCOUNTED_MODULES = {"records.py", "kernel.py"}  # build and hand out records: plain njit


def _decorator(fn: ast.FunctionDef) -> ast.expr | None:
    for dec in fn.decorator_list:
        target = dec.func if isinstance(dec, ast.Call) else dec
        if isinstance(target, ast.Name) and target.id in DECORATORS:
            return dec
    return None


def _compiled_functions() -> list[tuple[Path, ast.FunctionDef]]:
    found = []
    for path in sorted(CORE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef) and _decorator(node) is not None:
                found.append((path, node))
    return found


def _name(dec: ast.expr) -> str:
    return (dec.func if isinstance(dec, ast.Call) else dec).id


def _inlined(dec: ast.expr) -> bool:
    return isinstance(dec, ast.Call) and any(k.arg == "inline" for k in dec.keywords)


def test_every_loop_function_says_whether_it_counts_references():
    """``compiled`` (no reference counting) or ``allocating``; never inherited (core/compiled.py).

    A plain ``njit`` function compiled from inside the loop would inherit the
    loop's setting, so its code would depend on which caller compiled it first.
    Functions inlined into their callers take the caller's setting.
    """
    loose = [
        f"{path.relative_to(CORE)}:{fn.name}"
        for path, fn in _compiled_functions()
        if path.name not in REFCOUNTED_MODULES
        and _name(_decorator(fn)) == "njit"
        and not _inlined(_decorator(fn))
    ]
    assert not loose, loose


def _returns_arrays(fn: ast.FunctionDef) -> bool:
    arrays = ("np.ndarray", "Model", "Data", "Output", "Work", "Env")
    return fn.returns is not None and any(a in ast.unparse(fn.returns) for a in arrays)


def test_no_function_compiled_without_reference_counting_takes_an_array_returned_to_it():
    """A returned array is a new reference: a ``compiled`` caller would never release it.

    (A leak: the array, or the one it views, would never be freed.)
    """
    returning = {
        fn.name
        for _, fn in _compiled_functions()
        if _returns_arrays(fn) and not _inlined(_decorator(fn))  # inlined: no reference made
    }
    assert {"new_work", "data_row"} <= returning  # the check sees the records' factories
    calling = [
        f"{path.relative_to(CORE)}:{fn.name} calls {call.func.id}"
        for path, fn in _compiled_functions()
        if _name(_decorator(fn)) == "compiled"
        for call in ast.walk(fn)
        if isinstance(call, ast.Call)
        and isinstance(call.func, ast.Name)
        and call.func.id in returning
    ]
    assert not calling, calling


def test_no_function_compiled_without_reference_counting_returns_an_array():
    """Nothing would own a returned array: such functions must be ``allocating``."""
    arrays = ("np.ndarray", "Model", "Data", "Output", "Work")
    returning = [
        f"{path.relative_to(CORE)}:{fn.name}"
        for path, fn in _compiled_functions()
        if _name(_decorator(fn)) == "compiled"
        and fn.returns is not None
        and any(a in ast.unparse(fn.returns) for a in arrays)
    ]
    assert not returning, returning


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
