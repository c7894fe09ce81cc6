"""A sensor component: everything one added sensor is, declared in one module.

A component module (``barometer.py`` is the example) holds, side by side:

* its **slot blocks**, each slot with a name, a width and a unit: ``config``
  (what the run packs: rates, noises, switches), ``state`` (what it carries
  between samples), ``measurement`` (what a controller or an estimator reads),
  ``noise`` (standard normal draws per IMU sample, from the run's seed) and
  ``record`` (the columns it adds to each row of the IMU table);
* its **settings model** (pydantic): the table a scenario gives it
  (``[instruments.<name>]``), with a default for every field;
* its **pack function**: settings and the run's context to the config block;
* its **compiled sample function**, called at every IMU sample.

It registers with one line in ``registry.py`` (a built-in) or with
:func:`~quadimpact.core.sensors.registry.register_sensor` (a plug-in). The
registry lays the components' blocks one after another (an address from each
declared size, as MuJoCo MJX computes ``sensor_adr`` from ``sensor_dim``) at
the end of the run's arrays: config after ``scfg``'s ``SC_*`` slots, state
after ``sst``'s, measurements after ``meas``'s, records after each IMU row's
``I_*`` columns; its noise draws get a block of ``cnoise``. A component sees
only its own blocks, as arrays indexed from 0 with its own slot offsets.

The sample function's arguments, all SI, inertial NED and body FRD::

    sample(t, x, xdot, C, veh, cfg, st, meas, noise, rec) -> None

``t`` the IMU sample's time (s); ``x`` the true state and ``xdot`` its
derivative (layout ``X_*``); ``C`` the body-to-inertial rotation of ``x``;
``veh`` the vehicle's slots (``V_*``); ``cfg``, ``st``, ``meas`` its config,
state and measurement blocks; ``noise`` its draws for this sample (empty
when the run has none left); ``rec`` its columns of this sample's IMU row
(empty when the table has no room). It is called at every IMU sample whether
or not the run has the sensor: a sensor that is off (its config block all
zeros, as when a scenario does not name it) must return at once. A sensor
slower than the IMU keeps its own schedule in its state and samples at the
first IMU sample at or after each of its times (:func:`sample_due`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from quadimpact.core.compiled import compiled

__all__ = [
    "LegacyColumns",
    "PackContext",
    "SensorComponent",
    "Slot",
    "offsets",
    "sample_due",
    "size",
]


@dataclass(frozen=True)
class Slot:
    """One named slot of a component's block: ``width`` numbers in ``unit``."""

    name: str
    width: int = 1
    unit: str = ""
    doc: str = ""


def offsets(slots: tuple[Slot, ...]) -> dict[str, int]:
    """Each slot's offset in its block (slots laid out in declaration order)."""
    out: dict[str, int] = {}
    at = 0
    for s in slots:
        if s.name in out or s.width < 1:
            raise ValueError(f"slot {s.name}: declared twice or with width < 1")
        out[s.name] = at
        at += s.width
    return out


def size(slots: tuple[Slot, ...]) -> int:
    """The numbers a block of ``slots`` takes."""
    return sum(s.width for s in slots)


@dataclass(frozen=True)
class LegacyColumns:
    """A legacy noise stream: columns ``start .. start + width`` of the frozen ``snoise``.

    Only the sensors that predate components declare one (the magnetometer,
    the pose sensor): their draws stay where they were, so every seeded run
    is bit for bit what it was. ``snoise`` is drawn from the added sensors'
    stream when one of the older sensors is noisy (``packing/estimator_block.py``).
    A new component never declares one: it draws from a stream of its own.
    """

    start: int
    width: int


@dataclass(frozen=True)
class SensorComponent:
    """An added sensor, as its module declares it.

    Parameters
    ----------
    name : str
        Its name in scenario files (``[instruments.<name>]``) and the prefix
        of its record columns (``<name>_<slot>``).
    settings : type
        Its settings model (a pydantic ``BaseModel``; every field defaulted).
    pack : callable
        ``pack(settings, context) -> sequence of floats``: the config block
        (``context``: :class:`PackContext`). Every slot of a sensor that is
        on must make the block differ from all zeros (zeros: off).
    sample : numba function
        The compiled sample function (module docstring).
    config, state, measurement, noise, record : tuple of Slot
        Its blocks.
    doc : str
        One line: what it measures.
    legacy_noise : LegacyColumns, optional
        Its draws are columns of the frozen ``snoise`` matrix, not a block of
        ``cnoise`` (only the sensors that predate components).
    columns : tuple of str, optional
        Its record columns' names, one per number, when they are among the
        IMU table's fixed columns (``mx``...: kept from before components):
        they are in every run's table at their place (NaN when off), not
        ``<name>_<slot>`` columns after the fixed ones.
    scenario_key : str, optional
        The run settings' field that holds its settings (``magnetometer``),
        when a scenario names it there and not in ``[instruments.<name>]``.
    """

    name: str
    settings: type
    pack: Callable[..., Any]
    sample: Callable[..., None]
    config: tuple[Slot, ...] = ()
    state: tuple[Slot, ...] = ()
    measurement: tuple[Slot, ...] = ()
    noise: tuple[Slot, ...] = ()
    record: tuple[Slot, ...] = ()
    doc: str = ""
    plugin: bool = field(default=False, compare=False)
    legacy_noise: LegacyColumns | None = None
    columns: tuple[str, ...] = ()
    scenario_key: str = ""

    def __post_init__(self) -> None:
        if self.legacy_noise is not None and self.legacy_noise.width != size(self.noise):
            raise ValueError(f"sensor {self.name}: its legacy noise columns must match its noise")
        if self.columns and len(self.columns) != size(self.record):
            raise ValueError(f"sensor {self.name}: one column name per record number")

    def sizes(self) -> tuple[int, int, int, int, int]:
        """Numbers of its config, state, measurement, noise and record blocks.

        The noise counts its block of ``cnoise``: 0 for a legacy stream.
        """
        return (
            size(self.config),
            size(self.state),
            size(self.measurement),
            0 if self.legacy_noise is not None else size(self.noise),
            size(self.record),
        )

    def record_columns(self) -> list[tuple[str, str]]:
        """Its record columns in order: ``(column name, unit)``, one per number."""
        if self.columns:
            units = [s.unit for s in self.record for _ in range(s.width)]
            return list(zip(self.columns, units, strict=True))
        out = []
        for s in self.record:
            if s.width == 1:
                out.append((f"{self.name}_{s.name}", s.unit))
            else:
                out += [(f"{self.name}_{s.name}_{k}", s.unit) for k in range(s.width)]
        return out


@compiled
def sample_due(t: float, st: np.ndarray, t0_slot: int, n_slot: int, rate: float) -> bool:
    """Whether a sensor of ``rate`` (Hz) samples at the IMU sample ``t`` (s).

    It samples at its first call (whose time it records in ``st[t0_slot]``)
    and then at the first IMU sample at or after each ``t0 + n / rate``, with
    ``n = st[n_slot]`` its samples so far (the caller counts them).
    """
    n = st[n_slot]
    if n == 0.0:
        st[t0_slot] = t
        return True
    return t >= st[t0_slot] + n / rate - 1e-12


@dataclass(frozen=True)
class PackContext:
    """What a component's pack function may read of the run.

    Attributes
    ----------
    gravity_m_s2 : float
        The vehicle's gravity, m/s^2.
    imu_rate_hz : float
        The IMU's sample rate (the rate the sample function is called at), Hz.
    duration_s : float
        The run's length, s.
    """

    gravity_m_s2: float
    imu_rate_hz: float
    duration_s: float
