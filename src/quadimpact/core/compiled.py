"""How the compiled core is compiled: without reference counting, except where it allocates.

Numba passes a record of ``core/records.py`` (a named tuple of arrays) to a
compiled function by value and, with its reference counting on, increments
and decrements the count of every array in the record at every call, each an
atomic operation. The run loop calls functions taking the records (``Model``,
``Data``, ``Output``, ``Work``: 40-50 arrays) tens of times per integration
step, so with reference counting these atomic operations took about half of
the loop's time (measured with ``perf``: ``NRT_incref`` and ``NRT_decref``).

So the functions of the loop are compiled without reference counting
(:func:`compiled`). Such a function reads and writes the arrays it is given
and views of them, and calls other functions; it must not allocate an array
(the compiler rejects it: "NRT required but not enabled") nor return or store
one (nothing would own it). The few core functions that allocate or return
arrays (the entry points that allocate the tick's work space, some estimator
and controller helpers, the ring-solid search's stacks) use
:func:`allocating`; ``records.py`` and ``run.py``, which build and hand out
records, keep Numba's default (reference counted).

A function compiled with neither inherits the setting of the function it is
first compiled from, which would make its behaviour depend on the order of
compilation; so every other compiled function of ``quadimpact.core`` uses one
of the two (helpers inlined into their callers excepted), and none marked
``compiled`` returns an array (``tests/core/test_core_shape.py``). A user's
plug-in is compiled with reference counting of its own (a controller or
estimator step alone, called by address: ``core/plugin_call.py``; a sensor or
a geometry by ``core.kernel.make_kernel``), so it may allocate.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from typing import Any

from numba import njit, types
from numba.core import codegen, errors, event
from numba.core.caching import FunctionCache
from numba.core.registry import CPUDispatcher

__all__ = ["allocating", "compiled", "link_once_installed"]


# ---------------------------------------------------------------- linked once
# Numba finalises each compiled function as a library of its own: it links in the
# code of every function it calls (their libraries, each holding its own callees),
# optimises the whole with LLVM and generates its machine code. Along the loop's
# call chain (run, advance, tick, integrate_interval, ...) each function so paid
# again for everything below it. Here a core function compiled from inside another
# compilation is finalised alone: its own code optimised and generated, its callees
# left to the process's JIT linker (they are compiled, in this process, before it).
# The function compiled from Python (an entry point: run, start, advance, the
# approach's solve...) links in the code of all the functions below it once, which
# LLVM optimises as a whole, as before; that library alone goes to the disk cache.

_COMPILING: list[object] = []  # the dispatchers being compiled, outermost first


class _CompileStack(event.Listener):
    def on_start(self, ev: event.Event) -> None:
        _COMPILING.append(ev.data["dispatcher"])

    def on_end(self, ev: event.Event) -> None:
        _COMPILING.pop()


def _closure(libraries: list) -> list:
    """``libraries`` and, through each one finalised alone, the libraries it calls."""
    seen: list = []
    todo = list(libraries)
    while todo:
        library = todo.pop(0)
        if library in seen:
            continue
        seen.append(library)
        if getattr(library, "_alone", False):
            todo.extend(library._linking_libraries)
    return seen


class _LinkOnceLibrary(codegen.JITCodeLibrary):
    """Numba's JIT library, finalised alone when it is a core function compiled from a caller."""

    def finalize(self) -> None:
        if len(_COMPILING) > 1 and isinstance(_COMPILING[-1], TypedDispatcher):
            self._finalize_alone()
            return
        self._linking_libraries = _closure(self._linking_libraries)
        super().finalize()

    def _finalize_alone(self) -> None:
        """``CPUCodeLibrary.finalize`` without linking in the callees' code."""
        self._codegen._check_llvm_bugs()
        self._raise_if_finalized()
        self._alone = True
        for library in self._linking_libraries:
            self._reload_init.update(library._reload_init)
        self._optimize_final_module()
        self._final_module.verify()
        self._finalize_dynamic_globals()
        self._final_module._CPUCodeLibrary__library = weakref.proxy(self)  # object-cache hooks
        cleanup = self._codegen._add_module(self._final_module)
        if cleanup:
            weakref.finalize(self, cleanup)
        self._finalize_specific()
        self._finalized = True


class _EntryCache(FunctionCache):
    """Numba's disk cache of a function, for its compilations that link in their callees."""

    def save_overload(self, sig: Any, data: Any) -> None:
        if not getattr(getattr(data, "library", None), "_alone", False):
            super().save_overload(sig, data)


_NUMBA_PARTS = (
    "_optimize_final_module",
    "_finalize_dynamic_globals",
    "_finalize_specific",
    "_reload_init",
    "_linking_libraries",
)


def _install_link_once() -> bool:
    """Make Numba's CPU JIT finalise libraries as above; False where its internals differ."""
    probe = codegen.JITCodeLibrary
    if not all(hasattr(probe, n) for n in _NUMBA_PARTS[:3]) or not hasattr(
        codegen.JITCPUCodegen, "_library_class"
    ):
        return False
    if codegen.JITCPUCodegen._library_class is not _LinkOnceLibrary:
        codegen.JITCPUCodegen._library_class = _LinkOnceLibrary
        event.register("numba:compile", _CompileStack())
    return True


class TypedDispatcher(CPUDispatcher):
    """A core function compiled once per argument types, not per literal value.

    Numba types a call from compiled code with its constant arguments as
    literals (``locate(EV_GAP, ...)``: ``Literal[int](3)``) and compiles the
    callee again for each value, with everything it calls linked in and
    optimised again. This dispatcher compiles such a call for the plain types
    of its arguments (``int64``), so one specialisation serves every caller;
    where a function needs a literal to type (a constant index into a
    heterogeneous tuple), it falls back to Numba's literal typing. LLVM still
    propagates the constants where it inlines the call.
    """

    def get_call_template(self, args: tuple, kws: dict) -> tuple:
        """Numba's call template for the arguments' plain types, else their literal types."""
        plain = tuple(types.unliteral(a) for a in args)
        plain_kws = {k: types.unliteral(v) for k, v in kws.items()}
        if plain != tuple(args) or plain_kws != kws:
            try:
                return super().get_call_template(plain, plain_kws)
            except errors.TypingError:
                pass
        return super().get_call_template(args, kws)

    def enable_caching(self) -> None:
        """Numba's disk cache, without the compilations finalised alone (never called from
        Python: a caller that is has their code)."""
        self._cache = _EntryCache(self.py_func)


link_once_installed: bool = _install_link_once()
"""Whether core functions compiled from a caller are finalised alone (Numba's internals
as expected); if not, Numba's own finalisation is used, slower to compile, same results."""


def _decorator(nrt: bool, options: dict[str, Any]) -> Callable[[Callable], CPUDispatcher]:
    """``njit(cache=True, _nrt=nrt, **options)`` making a :class:`TypedDispatcher`.

    An inlined function (``inline="always"``) is typed inside each caller and
    keeps Numba's own dispatcher.
    """
    if options.get("inline", "never") != "never":
        return njit(cache=True, _nrt=nrt, **options)

    def decorate(fn: Callable) -> CPUDispatcher:
        target = {"nopython": True, "boundscheck": None, "_nrt": nrt, **options}
        dispatcher = TypedDispatcher(py_func=fn, locals={}, targetoptions=target)
        dispatcher.enable_caching()
        return dispatcher

    return decorate


def compiled(fn: Callable | None = None, **options: Any) -> Any:
    """``numba.njit`` for a function of the loop: cached, no reference counting.

    ``options`` go to ``njit`` (for example ``inline="always"``). Use as
    ``@compiled`` or ``@compiled(inline="always")``. Compiled once per
    argument types (:class:`TypedDispatcher`).
    """
    decorate = _decorator(False, options)
    return decorate if fn is None else decorate(fn)


def allocating(fn: Callable | None = None, **options: Any) -> Any:
    """``numba.njit`` for a function that allocates or returns arrays: cached, reference counted."""
    decorate = _decorator(True, options)
    return decorate if fn is None else decorate(fn)
