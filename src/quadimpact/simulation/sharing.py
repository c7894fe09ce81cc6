"""What runs share of their packing, kept per process: :class:`SharedSetup` and its cache.

A run's packing (``simulation/setup.py``) is two stages: the part its initial
state, attitude and seed do not change (a :class:`SharedSetup`: the vehicle,
features, surfaces, options, the controller without references, the IMU and
estimator without their random draws) and the run's own part. The shared
part of an impact trial or a wall approach is kept here (:func:`kept_shared`)
under the scenario's fields but its state fields (:data:`TRIAL_STATE_FIELDS`,
:data:`WALL_STATE_FIELDS`), so the trials of a study and the runs of a sweep
over headings, inclinations and speeds pack only what differs between them,
with the same functions: the same arrays, bit for bit.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from quadimpact.inputs.controllers import controller_entry
from quadimpact.inputs.estimators import estimator_entry

if TYPE_CHECKING:
    from quadimpact.inputs.scenarios import ImpactTrial, WallApproach
    from quadimpact.packing.run_model import SharedPacking

__all__ = [
    "KEPT_LIMIT",
    "TRIAL_STATE_FIELDS",
    "WALL_STATE_FIELDS",
    "SharedSetup",
    "clear_kept",
    "kept_shared",
]


@dataclass
class SharedSetup:
    """The part of a run's packing that its initial state and its seed do not change.

    ``simulation.setup``'s ``_shared`` packs it (the vehicle, features,
    surfaces, options, controller without references, the IMU and estimator
    without their random draws, the warnings); its ``_for_run`` completes a
    copy for one run.
    """

    setup: Any
    """The packed run (a ``simulation.setup.RunSetup``; not imported here, which
    ``setup.py`` imports) with ``x0`` 0, no references and no random draw."""
    packing: SharedPacking
    """The shared arrays and what a run's own part is packed from (``packing.run_model``)."""
    entries: tuple[Any, ...] = ()
    """The registry entries it was packed with (controller, estimator): a new
    registration under the same name packs again."""
    front: tuple[float, np.ndarray] | None = None
    """An impact trial toward an obstacle: ``setup.obstacle_front`` of it."""


TRIAL_STATE_FIELDS = (
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
    "speed_m_s",
    "seed",
    "start_distance_m",
    "altitude_m",
    "lateral_offset_m",
)
"""An impact trial's fields that set its initial state, references and random draws
only: trials that differ in these alone share their :class:`SharedSetup`."""

WALL_STATE_FIELDS = (
    "heading_deg",
    "inclination_deg",
    "speed_m_s",
    "impact_time_s",
    "altitude_m",
    "roll_deg",
    "pitch_deg",
    "start_altitude_m",
    "seed",
)
"""A wall approach's fields that set its attitude, references, approach and random draws
only: approaches that differ in these alone share their :class:`SharedSetup`."""

_EXCLUDED = {
    "impact-trial": frozenset(TRIAL_STATE_FIELDS),
    "wall-approach": frozenset(WALL_STATE_FIELDS),
}
_KEPT: dict[str, SharedSetup] = {}
KEPT_LIMIT = 8
"""The most shared packings a process keeps (the oldest goes first)."""


def kept_shared(
    s: WallApproach | ImpactTrial, pack: Callable[[], SharedSetup], vehicle: Any = None
) -> SharedSetup:
    """The :class:`SharedSetup` of a run, packed (``pack()``) once per process for its other fields.

    Kept (at most :data:`KEPT_LIMIT`) under the scenario's JSON without its
    state fields, and used again only with the same vehicle object (a vehicle
    file changed on disk loads as a new one) and the same registry entries.
    Every value of a run is computed by the same functions either way: a kept
    packing gives the same run, bit for bit. ``vehicle``: ``s.build_vehicle()``
    when the caller has it.
    """
    v = s.build_vehicle() if vehicle is None else vehicle
    key = s.model_dump_json(exclude=_EXCLUDED[s.kind])
    shared = _KEPT.get(key)
    entries = (controller_entry(s.controller), estimator_entry(s.estimator))
    if (
        shared is not None
        and shared.setup.vehicle is v
        and all(a is b for a, b in zip(shared.entries, entries, strict=True))
    ):
        return shared
    shared = pack()
    if len(_KEPT) >= KEPT_LIMIT:
        _KEPT.pop(next(iter(_KEPT)))
    _KEPT[key] = shared
    return shared


def clear_kept() -> None:
    """Forget every kept packing of this process (the next run packs afresh)."""
    _KEPT.clear()
