"""The sensor components' blocks: their config tail of ``scfg`` and their seeded draws.

Every registered component (``core/sensors/registry.py``) has its blocks in
every run: the ones the scenario names (``instruments``) are packed by their
own pack function, the others stay zeros (off). The tails' sizes go into
``scfg``'s header (``SC_TAIL_*``), from which the loop sizes its state,
measurement and IMU rows.

Draws: component ``c`` draws its ``(n_imu, noise size)`` standard normal
numbers from a stream of its own, ``SeedSequence(seed, spawn_key=(COMPONENT_STREAM,
crc32(name)))``, so its noise depends on the run's seed and its name only,
not on which other sensors the run has (nor on the IMU's or the added
sensors' draws, which are left exactly as they were).
"""

from __future__ import annotations

import zlib
from collections.abc import Mapping
from typing import Any

import numpy as np

from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.core.sensors.component import PackContext
from quadimpact.core.sensors.registry import addresses, components, tail_sizes

__all__ = ["COMPONENT_STREAM", "draw_component_noise", "named_components", "pack_components"]

COMPONENT_STREAM = 4  # the streams 1-3 are the added sensors' and estimator's


def pack_components(
    scfg: np.ndarray, instruments: Mapping[str, Any], context: PackContext
) -> np.ndarray:
    """``scfg`` with the components' config tail and the tails' sizes (a new array).

    ``instruments``: component name -> its validated settings (those the
    scenario names; the others are off).
    """
    n_cfg, n_st, n_meas, _, n_rec = tail_sizes()
    out = np.zeros(IMS.NSCFG + n_cfg)
    out[: IMS.NSCFG] = scfg[: IMS.NSCFG]
    out[IMS.SC_TAIL_ST] = n_st
    out[IMS.SC_TAIL_MEAS] = n_meas
    out[IMS.SC_TAIL_REC] = n_rec
    where = addresses()
    for c in components():
        if c.name not in instruments:
            continue
        lo, hi = where[c.name].config
        block = np.asarray(c.pack(instruments[c.name], context), dtype=np.float64)
        if block.shape != (hi - lo,):
            raise ValueError(
                f"sensor {c.name}: pack returned {block.shape[0]} numbers, "
                f"its config block declares {hi - lo}"
            )
        out[IMS.NSCFG + lo : IMS.NSCFG + hi] = block
    return out


def named_components(settings: Any, instruments: Mapping[str, Any]) -> dict[str, Any]:
    """The components a run has, name -> settings: its ``instruments`` and the older sensors.

    A component with a ``scenario_key`` (the magnetometer, the pose sensor)
    takes its settings from that field of the run's ``settings`` (``None``: absent).
    """
    out = dict(instruments)
    for c in components():
        if c.scenario_key:
            value = getattr(settings, c.scenario_key, None)
            if value is not None:
                out[c.name] = value
    return out


_DRAWING: list[Any] = [None, None]
"""The registry's components (the tuple of one call) and what :func:`_drawing` made of
them: kept while the registry holds the same components."""


def _drawing() -> tuple[int, dict[str, Any], tuple[Any, ...]]:
    """The noise tail's size, the components' addresses and the components that draw
    from a stream of their own (noise block, no legacy columns), once per registry.

    Each run's packing asks (``draw_component_noise``); the registry changes only
    when a sensor is registered, which makes a new tuple of components.
    """
    comps = components()
    kept = _DRAWING[0]
    same = kept is not None and len(kept) == len(comps)
    if not (same and all(a is b for a, b in zip(kept, comps, strict=True))):
        drawing = tuple(c for c in comps if c.sizes()[3] > 0 and c.legacy_noise is None)
        _DRAWING[:] = [comps, (tail_sizes()[3], addresses(comps), drawing)]
    return _DRAWING[1]


def draw_component_noise(instruments: Mapping[str, Any], seed: int, n_imu: int) -> np.ndarray:
    """The named components' standard normal draws, ``(n_imu, noise tail)``.

    ``(0, noise tail)`` when no named component draws any.
    """
    n_noise, where, drawing = _drawing()
    named = [c for c in drawing if c.name in instruments]
    if not named or n_imu <= 0:
        return np.zeros((0, n_noise))
    out = np.zeros((n_imu, n_noise))
    for c in named:
        lo, hi = where[c.name].noise
        key = (COMPONENT_STREAM, zlib.crc32(c.name.encode()))
        rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed, spawn_key=key)))
        out[:, lo:hi] = rng.standard_normal((n_imu, hi - lo))
    return out
