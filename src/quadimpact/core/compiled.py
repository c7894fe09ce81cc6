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

from collections.abc import Callable
from typing import Any

from numba import njit, types
from numba.core import config, errors
from numba.core.registry import CPUDispatcher

__all__ = ["allocating", "compiled"]


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


def _decorator(nrt: bool, options: dict[str, Any]) -> Callable[[Callable], CPUDispatcher]:
    """``njit(cache=True, _nrt=nrt, **options)`` making a :class:`TypedDispatcher`.

    An inlined function (``inline="always"``) is typed inside each caller and
    keeps Numba's own dispatcher; with ``NUMBA_DISABLE_JIT`` every function
    stays Python (``njit`` returns it unchanged).
    """
    if options.get("inline", "never") != "never" or config.DISABLE_JIT:
        return njit(cache=True, _nrt=nrt, **options)

    def decorate(fn: Callable) -> CPUDispatcher:
        target = {
            "nopython": True,
            "boundscheck": None,
            "_nrt": nrt,
            "no_cfunc_wrapper": True,  # never called through a C pointer: no wrapper to compile
            **options,
        }
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
