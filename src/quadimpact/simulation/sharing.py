"""What runs share, kept per process: the resolved shared part of a run and its cache.

A run's resolved description (``simulation/resolve.py``) is two parts: the
part its initial state, attitude and seed do not change (a
:class:`~quadimpact.inputs.resolved.ResolvedShared`: the vehicle, surfaces,
options, the controller and estimator with their parameters, the IMU) and
the run's own part; its packing follows the same split
(``packing/run_model.py``). The shared
part of an impact trial or a wall approach is kept here (:func:`kept_shared`)
under the scenario's fields but its state fields (:data:`TRIAL_STATE_FIELDS`,
:data:`WALL_STATE_FIELDS`), so the trials of a study and the runs of a sweep
over headings, inclinations and speeds pack only what differs between them,
with the same functions: the same arrays, bit for bit.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from quadimpact.inputs.controllers import controller_entry
from quadimpact.inputs.estimators import estimator_entry

if TYPE_CHECKING:
    from quadimpact.inputs.resolved import ResolvedShared
    from quadimpact.inputs.scenarios import ImpactTrial, WallApproach

__all__ = [
    "KEPT_LIMIT",
    "TRIAL_STATE_FIELDS",
    "WALL_STATE_FIELDS",
    "clear_kept",
    "kept_shared",
]


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
only: trials that differ in these alone share their resolved shared part."""

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
only: approaches that differ in these alone share their resolved shared part."""

_EXCLUDED = {
    "impact-trial": frozenset(TRIAL_STATE_FIELDS),
    "wall-approach": frozenset(WALL_STATE_FIELDS),
}
_KEPT: dict[str, ResolvedShared] = {}
KEPT_LIMIT = 8
"""The most shared parts a process keeps (the oldest goes first)."""


def kept_shared(
    s: WallApproach | ImpactTrial, make: Callable[[], ResolvedShared], vehicle: Any = None
) -> ResolvedShared:
    """The resolved shared part of a run, made (``make()``) once per process for its other fields.

    Kept (at most :data:`KEPT_LIMIT`) under the scenario's JSON without its
    state fields, and used again only with the same vehicle object (a vehicle
    file changed on disk loads as a new one) and the same registry entries.
    Every value of a run is computed by the same functions either way: a kept
    resolution gives the same run, bit for bit. ``vehicle``: ``s.build_vehicle()``
    when the caller has it.
    """
    v = s.build_vehicle() if vehicle is None else vehicle
    key = s.model_dump_json(exclude=_EXCLUDED[s.kind])
    shared = _KEPT.get(key)
    entries = (controller_entry(s.controller), estimator_entry(s.estimator))
    if (
        shared is not None
        and shared.vehicle is v
        and shared.controller.entry is entries[0]
        and shared.estimator.entry is entries[1]
    ):
        return shared
    shared = make()
    if len(_KEPT) >= KEPT_LIMIT:
        _KEPT.pop(next(iter(_KEPT)))
    _KEPT[key] = shared
    return shared


def clear_kept() -> None:
    """Forget every kept shared part of this process (the next run resolves and packs afresh)."""
    _KEPT.clear()
