"""What a sweep sends to its workers for each run: the run's swept values, not its scenario.

A run of a sweep is its base scenario with the run's swept values on top. The
items a backend hands out (``(run_id, RunInputs, input columns)``) carry the
swept values and a reference to the sweep's :class:`SweepBase`, which every
item of a chunk shares (so it is pickled once per chunk). A worker validates
the base once (``inputs.derive.ScenarioFactory``, kept per process) and
builds each run's scenario from it without validating it again when the
sweep's own check found that the copy is the validated scenario
(``SweepBase.derive``); otherwise it validates the run's scenario mapping in
full, as a plain mapping item (``(run_id, scenario mapping, input columns)``)
always is.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from quadimpact.inputs.toml_files import apply_overrides

__all__ = ["RunInputs", "SweepBase", "scenario_of"]


class SweepBase:
    """What every run of a sweep shares: its base, its vehicle fields, how to build its runs.

    ``key`` (the base's canonical JSON text) names the base in the workers'
    caches; ``derive``: the runs may be copied from the validated base
    (checked by ``SweepSpec.validate``).
    """

    __slots__ = ("base", "vehicle_fields", "key", "derive")

    def __init__(
        self, base: Mapping[str, Any], vehicle_fields: tuple[str, ...], key: str, derive: bool
    ) -> None:
        self.base = base
        self.vehicle_fields = vehicle_fields
        self.key = key
        self.derive = derive

    def __getstate__(self) -> tuple[Any, ...]:
        return (self.base, self.vehicle_fields, self.key, self.derive)

    def __setstate__(self, state: tuple[Any, ...]) -> None:
        self.base, self.vehicle_fields, self.key, self.derive = state


class RunInputs:
    """A run's swept values and its sweep's :class:`SweepBase` (an item's second element)."""

    __slots__ = ("sweep", "values")

    def __init__(self, sweep: SweepBase, values: Mapping[str, Any]) -> None:
        self.sweep = sweep
        self.values = values

    def __getstate__(self) -> tuple[Any, ...]:
        return (self.sweep, self.values)

    def __setstate__(self, state: tuple[Any, ...]) -> None:
        self.sweep, self.values = state

    def scenario_dict(self) -> dict[str, Any]:
        """The run's scenario mapping (base and swept values)."""
        return apply_overrides(self.sweep.base, self.values, self.sweep.vehicle_fields)

    def get(self, name: str, default: Any = None) -> Any:
        """A scenario field of the run (its swept value, else the base's)."""
        if name in self.values and name not in self.sweep.vehicle_fields:
            return self.values[name]
        return self.sweep.base.get(name, default)


_FACTORIES: dict[str, Any] = {}
_FACTORIES_LIMIT = 8


def scenario_of(data: RunInputs | Mapping[str, Any], where: str) -> Any:
    """The validated scenario of an item's second element (see the module)."""
    from quadimpact.inputs.scenarios import scenario_from_dict

    if not isinstance(data, RunInputs):
        return scenario_from_dict(data, where=where)
    if not data.sweep.derive:
        return scenario_from_dict(data.scenario_dict(), where=where)
    factory = _FACTORIES.get(data.sweep.key)
    if factory is None:
        from quadimpact.inputs.derive import ScenarioFactory

        if len(_FACTORIES) >= _FACTORIES_LIMIT:
            _FACTORIES.pop(next(iter(_FACTORIES)))
        factory = _FACTORIES[data.sweep.key] = ScenarioFactory(
            data.sweep.base, data.sweep.vehicle_fields
        )
    return factory.scenario(data.values)
