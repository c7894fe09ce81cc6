"""A whole run, the kernels that run it, and its Python entry.

:func:`run` (Python; its parts compiled and cached on disk) is ``step.start`` plus ``step.advance``
to the end with the built-in controllers and geometry: it takes the run's
:class:`~quadimpact.core.records.Model` and fills its
:class:`~quadimpact.core.records.Output`. A :class:`Kernel` bundles the
compiled entry points of one loop (``run``, ``start``, ``advance`` and the
wall approach's shooting, ``approach``);
:data:`BUILTIN` is the cached one.

A plug-in controller or estimator needs no kernel of its own: its step is
compiled alone and the cached loop calls it by address (``ctrl[C_STEP]``,
``ecfg[EC_STEP]``; ``core/plugin_call.py``). :func:`make_kernel` compiles
the loop again around the plug-ins that do need it: a sensor sampled with
the IMU, the sensor and shape components registered as plug-ins, the rows of
the contact-geometry table registered at run time (``core.geometry``), and,
for code written against it, a controller step or an estimator bound in
place of the built-in dispatch. It uses :func:`specialise`, which rebuilds
every compiled core function that reaches a replaced global (Numba resolves
globals at compile time); such a kernel is compiled once per process and not
cached on disk.

:func:`execute` allocates the outputs, runs a kernel and returns the filled
parts as a :class:`~quadimpact.core.records.RawRecord`; ``quadimpact.simulation``
calls it. A run advanced tick by tick from Python
(``quadimpact.simulation.Simulation``) uses a kernel's ``start`` and ``advance``
on the same records.
"""

from __future__ import annotations

import functools
import inspect
import itertools
import math
import types
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from numba import njit
from numba.core.dispatcher import Dispatcher

from quadimpact.core import geometry as _geometry
from quadimpact.core.approach import solve_approach
from quadimpact.core.geometry import shapes as _shapes
from quadimpact.core.geometry.contact_record import no_contact
from quadimpact.core.records import Model, Output, RawRecord, new_data, new_output, raw_record
from quadimpact.core.sensors import registry as _sensor_registry
from quadimpact.core.shape_slots import (
    SH_KIND,
)
from quadimpact.core.step import advance, start

__all__ = ["BUILTIN", "Kernel", "execute", "loop_drivers", "make_kernel", "run", "specialise"]


def run(m: Model, o: Output) -> None:
    """Run ``m`` from ``(t0, x0)`` to ``tf`` with the built-in controllers and geometry.

    The loop state is allocated here and dropped at the end; everything the
    caller needs is in ``o``. Three compiled calls from Python (``new_data``,
    ``start``, ``advance``), not one compiled function: that would link a
    third copy of the whole loop into its machine code, about 10 s of the
    cold compile, against some 20 microseconds per run.
    """
    d = new_data(m)
    start(m, d, o)
    advance(-1, m, d, o)


def loop_drivers(start: Callable, advance: Callable) -> tuple[Callable, Callable]:
    """:func:`run` and the approach's shooting (``core.approach.solve_approach``) flown
    by a kernel's own ``start`` and ``advance``."""

    def run(m: Model, o: Output) -> None:
        d = new_data(m)
        start(m, d, o)
        advance(-1, m, d, o)

    return run, functools.partial(solve_approach, start=start, advance=advance)


@dataclass(frozen=True)
class Kernel:
    """The compiled entry points of one run loop.

    ``run(m, o)``, ``start(m, d, o)``, ``advance(n, m, d, o) -> ticks``,
    ``approach(m, o, wall, pairs, ap)`` (the wall approach's shooting, whose
    free-flight runs are this loop's: ``core/approach.py``); ``step``: the
    plug-in controller step compiled into it (None: built-ins).
    """

    run: Callable
    start: Callable
    advance: Callable
    approach: Callable
    step: Callable | None = None


BUILTIN = Kernel(run=run, start=start, advance=advance, approach=solve_approach)
"""The cached loop: built-in controllers, built-in geometry."""


# ---------------------------------------------------------------- plug-ins
def _global_names(code: types.CodeType) -> set[str]:
    names = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            names |= _global_names(const)
    return names


_COPIES = itertools.count(1)


def _rebound(fn: Dispatcher, scope_changes: Mapping[str, object]) -> Dispatcher:
    """A fresh (uncached) ``njit`` copy of ``fn`` with some module globals replaced.

    The copy gets a name of its own (``tick__plugin3``...): Numba names the
    compiled symbols after the function, and a copy named like the original
    could be linked in place of the original's cached code in the same
    process (the built-in loop would then call a plug-in).
    """
    py = fn.py_func
    scope = dict(py.__globals__)
    scope.update(scope_changes)
    name = f"{py.__name__}__plugin{next(_COPIES)}"
    copy = types.FunctionType(py.__code__, scope, name, py.__defaults__)
    copy.__qualname__ = name
    options = {k: v for k, v in fn.targetoptions.items() if k not in ("cache", "nopython")}
    return njit(**options)(copy)


def specialise(
    fn: Dispatcher,
    replacements: Mapping[str, object],
    memo: dict[Dispatcher, Dispatcher] | None = None,
) -> Dispatcher:
    """``fn`` compiled with the globals named in ``replacements`` replaced, at any depth.

    Every compiled function of ``quadimpact.core`` that ``fn`` calls and that
    (transitively) reads a replaced global is rebuilt the same way; the others
    are shared. ``memo`` shares the rebuilt functions between several roots.
    """
    memo = {} if memo is None else memo
    if fn in memo:
        return memo[fn]
    py = fn.py_func
    changes: dict[str, object] = {}
    for name in _global_names(py.__code__):
        if name not in py.__globals__:
            continue
        if name in replacements:
            changes[name] = replacements[name]
            continue
        target = py.__globals__[name]
        if isinstance(target, Dispatcher) and target.py_func.__module__.startswith(__package__):
            rebuilt = specialise(target, replacements, memo)
            if rebuilt is not target:
                changes[name] = rebuilt
    result = _rebound(fn, changes) if changes else fn
    memo[fn] = result
    return result


def _refcounted(fn: Dispatcher) -> Dispatcher:
    """A copy of a user's ``njit`` function compiled with reference counting.

    The loop is compiled without it (``core/compiled.py``), and a function
    compiled from inside it inherits that; a user's function may allocate
    arrays, so it is compiled with reference counting of its own.
    """
    options = {k: v for k, v in fn.targetoptions.items() if k not in ("cache", "nopython", "_nrt")}
    return njit(_nrt=True, **options)(fn.py_func)


def _checked_step(step: Callable) -> Callable:
    if not hasattr(step, "py_func"):
        raise TypeError("controller step: must be a numba.njit function")
    n_params = len(inspect.signature(step.py_func).parameters)
    if n_params != 7:
        raise TypeError(
            "controller step: expected step(t, meas, ctrl, mem, veh, dt, cmd); "
            f"got {n_params} parameters"
        )
    return _refcounted(step)


def _generated(source: str, scope: dict[str, object]) -> Callable:
    """``njit`` (inlined) of the function ``dispatch`` defined by ``source``."""
    exec(source, scope)  # noqa: S102 - generated from the registry's integer ids only
    return njit(inline="always")(scope["dispatch"])


def _contact_dispatch(entries: Mapping[int, Callable]) -> Callable:
    """``plugin_contact`` for the registered geometries: a branch per geometry id."""
    lines = ["def dispatch(g, x, C, feat, f, shapes, s):"]
    scope: dict[str, object] = {"no_contact": no_contact}
    for i, (gid, fn) in enumerate(sorted(entries.items())):
        scope[f"fn{i}"] = _refcounted(fn)
        lines += [f"    if g == {int(gid)}:", f"        return fn{i}(x, C, feat, f, shapes, s)"]
    lines.append("    return no_contact()")
    return _generated("\n".join(lines), scope)


def _distance_dispatch(entries: Mapping[int, Callable]) -> Callable:
    """``plugin_distance`` for the registered shape kinds: a branch per kind."""
    lines = ["def dispatch(px, py, pz, shapes, s):", "    kind = int(shapes[s, SH_KIND])"]
    scope: dict[str, object] = {"SH_KIND": SH_KIND, "inf": math.inf}
    for i, (kind, fn) in enumerate(sorted(entries.items())):
        scope[f"fn{i}"] = _refcounted(fn)
        lines += [f"    if kind == {int(kind)}:", f"        return fn{i}(px, py, pz, shapes, s)"]
    lines.append("    return inf")
    return _generated("\n".join(lines), scope)


def make_kernel(
    step: Callable | None = None,
    *,
    geometry: bool = False,
    sensor: Callable | None = None,
    estimator: Callable | None = None,
    sensors: bool = False,
    shapes: bool = False,
) -> Kernel:
    """Compile the run loop around plug-ins.

    Parameters
    ----------
    step : numba.njit function, optional
        A controller step ``step(t, meas, ctrl, mem, veh, dt, cmd)`` (the
        interface of ``core.controllers``), bound in place of the built-in
        dispatch.
    geometry : bool
        Compile in the rows of the contact-geometry table and the shape
        distances registered so far (``core.geometry.register_geometry``).
    sensor : numba.njit function, optional
        A sensor ``sensor(t, x, xdot, C, m, d)`` sampled with the IMU (at
        ``scfg[SC_RATE]``) from the true state ``x``, its derivative and
        rotation; it writes its readings into the measurement record's user
        block ``d.meas[MS_USER : MS_USER + N_USER_MEAS]``, which a controller
        reads (``core/sensing.py``).
    estimator : numba.njit function, optional
        An estimator ``estimator(t, dt, meas, ecfg, est)`` updated at every IMU
        sample, bound in place of ``core.estimators.plugin_estimator``; it runs
        when ``ecfg[EC_KIND]`` is ``EST_USER`` (docs/ESTIMATION.md).
    sensors : bool
        Compile in the sensor components registered as plug-ins so far
        (``core.sensors.registry.register_sensor``), after the built-in ones.
    shapes : bool
        Compile in the shape components registered as plug-ins so far
        (``core.geometry.register_shape``).

    Returns
    -------
    Kernel
        Compiled on first call (about 10 s for a controller; a geometry
        plug-in rebuilds most of the loop), not cached on disk.
    """
    replacements: dict[str, object] = {}
    if step is not None:
        step = _checked_step(step)
        replacements["controller_step"] = step
    if sensor is not None:
        if not hasattr(sensor, "py_func"):
            raise TypeError("sensor: must be a numba.njit function")
        replacements["plugin_sensor"] = _refcounted(sensor)
    if estimator is not None:
        if not hasattr(estimator, "py_func"):
            raise TypeError("estimator: must be a numba.njit function")
        n_params = len(inspect.signature(estimator.py_func).parameters)
        if n_params != 5:
            raise TypeError(
                f"estimator: expected estimator(t, dt, meas, ecfg, est); got {n_params} parameters"
            )
        replacements["plugin_estimator"] = _refcounted(estimator)
    if sensors:
        comps = _sensor_registry.components()
        entries = _sensor_registry.entries(comps)
        replacements["ENTRIES"] = tuple(
            (_refcounted(e[0]) if c.plugin else e[0], *e[1:])
            for c, e in zip(comps, entries, strict=True)
        )
    if shapes:
        user = {id(f) for c in _shapes.plugin_shapes() for f in (c.distance, *c.contacts.values())}

        def own(entries: tuple) -> tuple:
            return tuple((k, _refcounted(f) if id(f) in user else f) for k, f in entries)

        replacements["CONTACT_ENTRIES"] = own(_shapes.contact_entries())
        replacements["DISTANCE_ENTRIES"] = own(_shapes.distance_entries())
    if geometry:
        contact_fns = {g.id: g.fn for g in _geometry.plugin_geometries()}
        replacements["plugin_contact"] = _contact_dispatch(contact_fns)
        replacements["plugin_distance"] = _distance_dispatch(_geometry.plugin_distances())
    if not replacements:
        return BUILTIN
    memo: dict[Dispatcher, Dispatcher] = {}
    own_start = specialise(start, replacements, memo)
    own_advance = specialise(advance, replacements, memo)
    own_run, own_approach = loop_drivers(own_start, own_advance)
    return Kernel(
        run=own_run, start=own_start, advance=own_advance, approach=own_approach, step=step
    )


# ---------------------------------------------------------------- Python entry
def execute(
    m: Model, *, n_imu: int = 0, max_episodes: int = 1024, kernel: Kernel | None = None
) -> RawRecord:
    """Allocate the outputs of ``m``, run the compiled loop, return the filled parts.

    ``n_imu``: rows of the IMU record to keep; ``max_episodes``: size of the
    contact-episode buffer (episodes beyond it are counted in the stats).
    """
    o = new_output(m, int(n_imu), int(max_episodes))
    (kernel or BUILTIN).run(m, o)
    return raw_record(o)
