"""Plug-ins compiled and guarded: their compilation said and timed, their errors named.

A plug-in controller or estimator step is compiled alone, once per process,
for the one signature the loop calls (:func:`plugin_address`: a few seconds
of CPU, ``core/plugin_call.py``); the cached loop calls it by address. A
plug-in sensor or shape still has the loop compiled around it
(``core.kernel.make_kernel``, on the loop's first call in a process: about
15 s of CPU or more). Either way:

* the compilation is **announced** on stderr as it starts (once per process
  and plug-in: ``quadimpact: compiling plug-in 'X' ...``), in the command's
  process and in every sweep worker;
* its CPU time is **measured apart**: :func:`compile_cpu_total` is the
  process's total so far, which the run costs subtract
  (``simulation.setup.prepare``, ``simulation.batch``, ``simulation.simulate``)
  and report as the summary's ``cost.compile_cpu_s``;
* an exception raised inside the loop (only a plug-in raises there: the
  core's loop reports its numerical failures as a status) becomes a
  :class:`PluginError` naming the plug-in and its step, in one line
  (:func:`guarded`).

A sweep records such a run as failed with ``reason = "PluginError: ..."``;
:func:`plugin_failure` finds that reason in a sweep's rows (the benchmark
stops on it: docs/CONTROLLERS.md).
"""

from __future__ import annotations

import logging
import os
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from quadimpact.core.kernel import Kernel, loop_drivers
from quadimpact.core.plugin_call import entry_address
from quadimpact.errors import InputError, one_line
from quadimpact.results.costs import cpu_time

__all__ = [
    "PLUGIN_REASON",
    "PluginError",
    "PluginStep",
    "WRITES",
    "compile_cpu_total",
    "compile_registered_plugins",
    "guarded",
    "plugin_address",
    "plugin_failure",
    "typing_text",
]

WRITES = {
    "controller": "it writes the four rotor speeds (rad/s) into cmd",
    "estimator": "it writes the estimate into est",
}
"""What each kind of plug-in step gives the loop, instead of returning it."""

PLUGIN_REASON = "PluginError: "
"""How a sweep row's ``reason`` starts when a plug-in raised (``<type>: <message>``)."""

_log = logging.getLogger("quadimpact")
_COMPILE_CPU = [0.0]  # CPU time this process spent compiling plug-ins and their loops, s
_ADDRESSES: dict[int, tuple[Any, Any, int]] = {}  # id(step) -> (step, signature, address)


class PluginError(InputError):
    """A plug-in controller or estimator that cannot run: it raised, or its loop does not
    compile (one line naming the plug-in, its function and the rule)."""


@dataclass(frozen=True)
class PluginStep:
    """A plug-in's step as messages name it: its kind, registered name and function."""

    kind: str  # "controller" or "estimator"
    name: str
    function: str

    def __str__(self) -> str:
        return f"{self.kind} plug-in {self.name!r} ({self.function})"


def step_name(step: Any) -> str:
    """The Python name of a compiled step (``level_step``)."""
    py = getattr(step, "py_func", step)
    return getattr(py, "__name__", repr(py))


def compile_cpu_total() -> float:
    """CPU time (this process) spent compiling plug-ins and their loops so far, s."""
    return _COMPILE_CPU[0]


def compile_registered_plugins() -> list[PluginStep]:
    """Compile the step of every plug-in controller and estimator registered so far.

    For a process that forks workers (the local pool's fork server): each
    worker inherits the compiled steps, and their addresses, instead of
    compiling them again. A step that does not compile is left out: the run
    that needs it says why. Returns the plug-ins compiled.
    """
    from quadimpact.core.plugin_call import CONTROLLER_SIGNATURE, ESTIMATOR_SIGNATURE
    from quadimpact.inputs.controllers import controller_entry, controller_names
    from quadimpact.inputs.estimators import estimator_entry, estimator_names

    found = [("controller", controller_entry(n), CONTROLLER_SIGNATURE) for n in controller_names()]
    found += [("estimator", estimator_entry(n), ESTIMATOR_SIGNATURE) for n in estimator_names()]
    done = []
    for kind, entry, signature in found:
        if entry.step is None:
            continue
        who = PluginStep(kind, entry.name, step_name(entry.step))
        try:
            plugin_address(who, entry.step, signature)
        except PluginError:
            continue
        done.append(who)
    return done


def plugin_address(who: PluginStep, step: Any, signature: Any) -> int:
    """The entry address of a plug-in's step compiled alone for ``signature`` (once per process).

    The first call for a step announces its compilation on stderr and adds
    its CPU time to :func:`compile_cpu_total`; the step (a ``numba.njit``
    dispatcher, which owns the compiled code) is kept, so the address stays
    valid for the life of the process. A step that does not compile for the
    loop's records, or returns a value, is a :class:`PluginError`.
    """
    hit = _ADDRESSES.get(id(step))
    if hit is not None and hit[0] is step and hit[1] == signature:
        return hit[2]
    if tuple(signature.args) not in step.overloads:
        _log.warning(
            f"quadimpact: compiling plug-in {who.name!r} ({who.kind} step {who.function}) alone "
            f"(process {os.getpid()}, once per process: a few s of CPU, reported apart from the "
            "runs' as compile_cpu_s; the loop is the cached one) ..."
        )
    started = cpu_time()
    try:
        address = entry_address(step, signature)
    except TypeError as exc:  # compiled, but returns a value
        rule = f"a {who.kind} step returns nothing: {WRITES.get(who.kind, '')}"
        returned = one_line(str(exc)).split(";")[0]  # "returns <type>"
        raise PluginError(f"{who}: {returned}; {rule}") from None
    except Exception as exc:
        text = typing_text(exc) if _is_compile_error(exc) else one_line(str(exc))
        raise PluginError(f"{who}: does not compile for the loop's records: {text}") from None
    finally:
        _COMPILE_CPU[0] += cpu_time() - started
    _ADDRESSES[id(step)] = (step, signature, address)
    return address


def typing_text(exc: BaseException) -> str:
    """A Numba compile error's message in one line: its first line of substance and where."""
    lines = [ln.strip() for ln in str(exc).splitlines()]
    skip = ("Failed in ", "During:", "- Resolution failure", "Resolution failure", "File ")
    body = [i for i, ln in enumerate(lines) if ln and not ln.startswith(skip)]
    text = type(exc).__name__
    if body:
        i = body[0]
        text = lines[i].lstrip("> ").replace("Function(<built-in function getitem>)", "getitem")
        after = [ln for ln in lines[i + 1 :] if ln]
        if text.endswith(":") and after and after[0].startswith(">>>"):
            text += " " + after[0].lstrip("> ")
    where = re.search(r'File "([^"]+)", line (\d+)', str(exc))
    if where:
        text += f" ({os.path.basename(where.group(1))}, line {where.group(2)})"
    return one_line(text)


def _is_compile_error(exc: BaseException) -> bool:
    try:
        from numba.core.errors import NumbaError
    except ImportError:  # pragma: no cover (numba is a dependency)
        return False
    return isinstance(exc, NumbaError)


class _Guard:
    """What the entry points of one guarded kernel share: its plug-ins, the notice said."""

    def __init__(self, plugins: tuple[PluginStep, ...], compiles: bool) -> None:
        self.plugins = plugins
        self.announced = not compiles  # a loop that compiles nothing says nothing
        self.compiles = compiles

    def who(self) -> str:
        return " and ".join(str(p) for p in self.plugins)

    def announce(self) -> None:
        if self.announced:
            return
        self.announced = True
        names = " and ".join(repr(p.name) for p in self.plugins)
        _log.warning(
            f"quadimpact: compiling the loop for plug-in {names} (process {os.getpid()}, once "
            "per process: about 15 s of CPU, reported apart from the runs' as compile_cpu_s) ..."
        )

    def error(self, exc: Exception, entry: str) -> PluginError:
        if _is_compile_error(exc):
            return PluginError(
                f"{self.who()}: the loop does not compile around it ({entry}): {typing_text(exc)}"
            )
        raised = one_line(f"{type(exc).__name__}: {exc}".rstrip(": "))
        verb = "raised" if len(self.plugins) == 1 else "(one of them) raised"
        return PluginError(f"{self.who()} {verb} {raised}: a plug-in's step must not raise")

    def wrap(self, fn: Callable, entry: str) -> Callable:
        """``fn`` (a Numba dispatcher) compiled, announced and timed on its first call.

        A Python driver of the loop (``run``, ``approach``) is only guarded
        for errors: :func:`guarded` gives it the guarded ``start`` and ``advance``.
        """
        dispatcher = hasattr(fn, "overloads")

        def call(*args: Any, **kwargs: Any) -> Any:
            if self.compiles and dispatcher and not fn.overloads:  # the first call compiles
                self.announce()
                started = cpu_time()
                try:
                    fn.compile(tuple(fn.typeof_pyval(a) for a in args))
                except Exception as exc:
                    raise self.error(exc, entry) from None
                finally:
                    _COMPILE_CPU[0] += cpu_time() - started
            try:
                return fn(*args, **kwargs)
            except PluginError:
                raise  # said by the guarded entry point it called
            except Exception as exc:
                raise self.error(exc, entry) from None

        call.__name__ = getattr(fn, "__name__", entry)
        call.__wrapped__ = fn  # type: ignore[attr-defined]
        return call


def guarded(kernel: Kernel, plugins: Iterable[PluginStep], *, compiles: bool = True) -> Kernel:
    """``kernel`` with its entry points guarded (module docstring).

    ``compiles``: the kernel is compiled around the plug-ins (``make_kernel``),
    its compilation announced and timed on its first call; False for the
    cached loop, which calls plug-in steps by address (only their errors named).
    """
    guard = _Guard(tuple(plugins), compiles)
    start = guard.wrap(kernel.start, "start")
    advance = guard.wrap(kernel.advance, "advance")
    run, approach = kernel.run, kernel.approach
    if compiles:  # the Python drivers fly the guarded loop: its compile announced and timed
        run, approach = loop_drivers(start, advance)
    return Kernel(
        run=guard.wrap(run, "run"),
        start=start,
        advance=advance,
        approach=guard.wrap(approach, "approach"),
        step=kernel.step,
    )


def plugin_failure(runs: Any) -> tuple[int, str] | None:
    """The first run of a sweep table whose plug-in raised: ``(run_id, the error)``, or None.

    ``runs``: a sweep's rows (``runs.parquet``, with ``status``, ``reason`` and
    ``run_id``). Ordinary failures (numerical, of any row) are not a plug-in's.
    """
    if "reason" not in runs or "status" not in runs:
        return None
    failed = runs[(runs["status"] == "failed") & runs["reason"].fillna("").str.startswith(
        PLUGIN_REASON
    )]  # fmt: skip
    if failed.empty:
        return None
    first = failed.sort_values("run_id").iloc[0]
    return int(first["run_id"]), str(first["reason"]).removeprefix(PLUGIN_REASON)
