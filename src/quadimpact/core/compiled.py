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

from numba import njit

__all__ = ["allocating", "compiled"]


def compiled(fn: Callable | None = None, **options: Any) -> Any:
    """``numba.njit`` for a function of the loop: cached, no reference counting.

    ``options`` go to ``njit`` (for example ``inline="always"``). Use as
    ``@compiled`` or ``@compiled(inline="always")``.
    """
    decorate = njit(cache=True, _nrt=False, **options)
    return decorate if fn is None else decorate(fn)


def allocating(fn: Callable | None = None, **options: Any) -> Any:
    """``numba.njit`` for a function that allocates or returns arrays: cached, reference counted."""
    decorate = njit(cache=True, _nrt=True, **options)
    return decorate if fn is None else decorate(fn)
