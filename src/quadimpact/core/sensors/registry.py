"""The sensor components of a run: the registry, their addresses, the compiled dispatch.

**Adding a built-in sensor** is its module (``component.py`` says what it
declares; ``barometer.py`` is the example) and one line of :data:`BUILTIN`
below. **A plug-in sensor** is the same module outside the package, added
with :func:`register_sensor`; a run then compiles a loop of its own around
it (``core.kernel.make_kernel``), as a plug-in controller does.

Addresses: the components' blocks follow each other in registry order (the
built-ins, then the plug-ins in the order they were registered), each at the
sum of the sizes before it, at the end of the run's arrays: config from
``NSCFG`` in ``scfg``, state from ``NSST`` in ``sst``, measurements from
``NMEAS`` in ``meas``, records from ``NIMU`` in each IMU row, noise draws
from column 0 of ``cnoise``. So every registered component has its blocks in
every run (all zeros, off, unless the scenario names it), and a plug-in never
moves a built-in's addresses. :func:`measurement_address` gives a slot's
place in ``meas``, for a controller or an estimator that reads it.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from numba import literal_unroll
from numba.core.errors import NumbaExperimentalFeatureWarning

from quadimpact.core.compiled import compiled
from quadimpact.core.records import Data, Model, Output
from quadimpact.core.sensors import barometer, magnetometer, optical_flow, pose, rangefinder
from quadimpact.core.sensors.component import SensorComponent, offsets
from quadimpact.core.sensors.imu_slots import (
    NIMU,
    NSCFG,
    NSST,
    SS_N,
)
from quadimpact.core.sensors.measurement_slots import NMEAS

__all__ = [
    "BUILTIN",
    "Address",
    "active",
    "addresses",
    "component",
    "components",
    "config_address",
    "measurement_address",
    "record_address",
    "record_columns",
    "register_sensor",
    "sample_components",
    "tail_sizes",
]

# the loop calls each component's sample function through a tuple of functions
# (Numba's first-class functions, unrolled at compile time)
warnings.filterwarnings("ignore", category=NumbaExperimentalFeatureWarning)

BUILTIN: tuple[SensorComponent, ...] = (
    barometer.SENSOR,  # altitude, white noise, bias walk
    rangefinder.SENSOR,  # slant range to the ground along the body's down axis
    optical_flow.SENSOR,  # the ground image's angular rate, with quality and delay
    magnetometer.SENSOR,  # the Earth's field in body axes (draws: legacy snoise columns)
    pose.SENSOR,  # position and attitude from motion capture (draws: legacy snoise columns)
)
"""The built-in sensor components, one line each."""

_PLUGINS: list[SensorComponent] = []


@dataclass(frozen=True)
class Address:
    """Where one component's blocks start and end: ``(lo, hi)`` in each array's tail."""

    config: tuple[int, int]
    state: tuple[int, int]
    measurement: tuple[int, int]
    noise: tuple[int, int]
    record: tuple[int, int]


def components() -> tuple[SensorComponent, ...]:
    """Every registered component, in address order (built-ins first)."""
    return BUILTIN + tuple(_PLUGINS)


def component(name: str) -> SensorComponent:
    """The registered component called ``name``; ``KeyError`` lists the known ones."""
    for c in components():
        if c.name == name:
            return c
    known = ", ".join(repr(c.name) for c in components())
    raise KeyError(f"no sensor component {name!r} (registered: {known})")


def addresses(comps: tuple[SensorComponent, ...] | None = None) -> dict[str, Address]:
    """Each component's blocks in the arrays' tails (offsets from the tail's start).

    A legacy noise stream's span is its columns of ``snoise``, not of ``cnoise``.
    """
    at = [0, 0, 0, 0, 0]
    out = {}
    for c in components() if comps is None else comps:
        spans = []
        for k, n in enumerate(c.sizes()):
            spans.append((at[k], at[k] + n))
            at[k] += n
        legacy = c.legacy_noise
        if legacy is not None:
            spans[3] = (legacy.start, legacy.start + legacy.width)
        out[c.name] = Address(*spans)
    return out


def tail_sizes() -> tuple[int, int, int, int, int]:
    """Sizes of the config, state, measurement, noise and record tails of every run."""
    sizes = [0, 0, 0, 0, 0]
    for c in components():
        for k, n in enumerate(c.sizes()):
            sizes[k] += n
    return tuple(sizes)  # type: ignore[return-value]


def measurement_address(name: str, slot: str) -> int:
    """The index in the measurement record ``meas`` of component ``name``'s ``slot``."""
    c = component(name)
    return NMEAS + addresses()[name].measurement[0] + offsets(c.measurement)[slot]


def config_address(name: str, slot: str) -> int:
    """The index in the sensor settings ``scfg`` of component ``name``'s config ``slot``."""
    c = component(name)
    return NSCFG + addresses()[name].config[0] + offsets(c.config)[slot]


def record_address(name: str) -> int:
    """The column of a raw IMU row where component ``name``'s record columns start."""
    component(name)
    return NIMU + addresses()[name].record[0]


def active(scfg: np.ndarray) -> tuple[SensorComponent, ...]:
    """The components a run packed with ``scfg`` has (config block not all zeros)."""
    where = addresses()
    out = []
    for c in components():
        lo, hi = where[c.name].config
        block = scfg[NSCFG + lo : NSCFG + hi]
        if block.shape[0] == hi - lo and hi > lo and np.any(block != 0.0):
            out.append(c)
    return tuple(out)


def record_columns(scfg: np.ndarray) -> list[tuple[str, int, str]]:
    """The IMU table's columns of the run's components: ``(name, column of a raw row, unit)``.

    A component whose columns are among the table's fixed ones (``columns``) is not listed.
    """
    where = addresses()
    out = []
    for c in active(scfg):
        if c.columns:
            continue
        lo = where[c.name].record[0]
        for k, (name, unit) in enumerate(c.record_columns()):
            out.append((name, NIMU + lo + k, unit))
    return out


def register_sensor(comp: SensorComponent) -> None:
    """Add a plug-in sensor component (its blocks after every registered one).

    Raises
    ------
    TypeError
        Not a :class:`SensorComponent`, or its sample function not compiled.
    ValueError
        A component of that name is registered already (a built-in, or a
        plug-in registered with other blocks), or it declares a legacy
        noise stream, fixed columns or a scenario key.
    """
    if not isinstance(comp, SensorComponent):
        raise TypeError("register_sensor: expected a SensorComponent")
    if not hasattr(comp.sample, "py_func"):
        raise TypeError(f"sensor {comp.name}: sample must be a numba.njit function")
    if comp.legacy_noise is not None or comp.columns or comp.scenario_key:
        raise ValueError(
            f"sensor {comp.name}: legacy_noise, columns and scenario_key are for the "
            "sensors that predate components; a plug-in draws from a stream of its own"
        )
    for c in components():
        if c.name == comp.name:
            if c.plugin and c.sizes() == comp.sizes():
                _PLUGINS[_PLUGINS.index(c)] = _as_plugin(comp)  # a reloaded module
                return
            raise ValueError(f"register_sensor: {comp.name!r} is registered already")
    _PLUGINS.append(_as_plugin(comp))


def _as_plugin(comp: SensorComponent) -> SensorComponent:
    from dataclasses import replace

    return replace(comp, plugin=True)


def plugin_sensors() -> tuple[SensorComponent, ...]:
    """The plug-in components registered so far."""
    return tuple(_PLUGINS)


def entries(comps: tuple[SensorComponent, ...]) -> tuple:
    """The dispatch's tuple: per component its sample function, block bounds and noise source.

    The last number is 1 when its noise is a legacy stream (columns of ``snoise``).
    """
    out = []
    for c, a in zip(comps, addresses(comps).values(), strict=True):
        legacy = 1 if c.legacy_noise is not None else 0
        out.append((c.sample, *a.config, *a.state, *a.measurement, *a.noise, *a.record, legacy))
    return tuple(out)


ENTRIES = entries(BUILTIN)


@compiled
def _sample_one(
    e: tuple,
    t: float,
    xs: np.ndarray,
    xd: np.ndarray,
    C: np.ndarray,
    m: Model,
    d: Data,
    o: Output,
    i: int,
) -> None:
    """Component ``e`` (an entry of :data:`ENTRIES`) at the IMU sample ``i``, time ``t`` (s)."""
    scfg = m.scfg
    sst = d.sst
    meas = d.meas
    if scfg.shape[0] < NSCFG + e[2] or sst.shape[0] < NSST + e[4]:
        return
    if meas.shape[0] < NMEAS + e[6]:
        return
    empty = m.span[0:0]
    noise = empty
    if e[11] == 1:
        if 0 <= i < m.snoise.shape[0]:
            noise = m.snoise[i, e[7] : e[8]]
    elif 0 <= i < m.cnoise.shape[0] and m.cnoise.shape[1] >= e[8]:
        noise = m.cnoise[i, e[7] : e[8]]
    rec = empty
    if 0 <= i < o.imu.shape[0] and o.imu.shape[1] >= NIMU + e[10]:
        rec = o.imu[i, NIMU + e[9] : NIMU + e[10]]
    e[0](
        t,
        xs,
        xd,
        C,
        m.veh,
        scfg[NSCFG + e[1] : NSCFG + e[2]],
        sst[NSST + e[3] : NSST + e[4]],
        meas[NMEAS + e[5] : NMEAS + e[6]],
        noise,
        rec,
    )


@compiled
def sample_components(
    t: float, xs: np.ndarray, xd: np.ndarray, C: np.ndarray, m: Model, d: Data, o: Output
) -> None:
    """Every registered component's sample function at the IMU sample just taken at ``t`` (s).

    A run whose arrays lack a component's tail (packed before it was
    registered) skips it.
    """
    i = int(d.sst[SS_N]) - 1
    for e in literal_unroll(ENTRIES):
        _sample_one(e, t, xs, xd, C, m, d, o, i)
