"""Scenarios derived from one validated base: a sweep's runs without validating each again.

A sweep's runs are its base scenario with a few fields changed (the swept
values). The sweep validates every run once, before any starts
(``SweepSpec.validate``); a worker then builds each run's scenario from the
base, validated once per worker, with :class:`ScenarioFactory`: a copy of the
validated base with the swept values in place (``model_copy``), without
running the validators again (about 5 us instead of 15-150 us a run).

That copy is the validated scenario only when every swept field is *plain*: a
number, a string, a boolean or a literal, whose validated value is the value
itself (an integer field takes the integer of a whole float, as its
validator does), or a vehicle field (it goes to ``vehicle_overrides``, a plain
table). :meth:`ScenarioFactory.derives` says so for a set of swept fields, and
``SweepSpec.validate`` checks, run by run, that the copy equals the validated
scenario (values and types); a sweep where it does not (a validator that
rewrites a field from another) has its runs validated in the workers as
before.
"""

from __future__ import annotations

import types
import typing
from collections.abc import Iterable, Mapping
from typing import Any, Literal

from quadimpact.inputs.scenarios import Scenario, scenario_from_dict
from quadimpact.inputs.toml_files import apply_overrides

__all__ = ["ScenarioFactory", "same_scenario"]

_PLAIN = (bool, int, float, str)


def _plain_types(annotation: Any) -> tuple[type, ...] | None:
    """The plain types a field of this annotation takes, or None if it is not plain."""
    if annotation in _PLAIN:
        return (annotation,)
    origin = typing.get_origin(annotation)
    if origin is Literal:
        values = typing.get_args(annotation)
        return tuple({type(v) for v in values}) if all(type(v) in _PLAIN for v in values) else None
    if origin is typing.Annotated:
        return _plain_types(typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType):
        out: list[type] = []
        for arg in typing.get_args(annotation):
            if arg is type(None):
                out.append(type(None))
                continue
            inner = _plain_types(arg)
            if inner is None:
                return None
            out += inner
        return tuple(out)
    return None


def _coerce(value: Any, kinds: tuple[type, ...]) -> Any:
    """``value`` as a field of these plain types holds it once validated."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if float in kinds:
        return float(value)
    if int in kinds:
        return int(value)
    return value


class ScenarioFactory:
    """The scenarios of one sweep: its base validated once, each run's swept values on top.

    Parameters
    ----------
    base : mapping
        The sweep's base scenario (the fields of a scenario file).
    vehicle_fields : iterable of str
        The swept fields that are vehicle parameters (they go to
        ``vehicle_overrides``).
    """

    def __init__(self, base: Mapping[str, Any], vehicle_fields: Iterable[str] = ()) -> None:
        self.data = dict(base)
        self.base: Scenario = scenario_from_dict(self.data, where="base")
        self.vehicle_fields = frozenset(vehicle_fields)
        fields = type(self.base).model_fields
        self._kinds = {
            name: kinds
            for name, info in fields.items()
            if (kinds := _plain_types(info.annotation)) is not None
        }

    def derives(self, names: Iterable[str]) -> bool:
        """Whether runs that set these fields can be copied from the base (all plain)."""
        return all(n in self.vehicle_fields or n in self._kinds for n in names)

    def scenario(self, values: Mapping[str, Any]) -> Scenario:
        """The run's scenario: the validated base with ``values`` in place (no validation).

        Only for values of fields that :meth:`derives` accepts, and that were
        validated with the base (by the sweep) before.
        """
        update: dict[str, Any] = {}
        overrides: dict[str, Any] | None = None
        for name, value in values.items():
            if name in self.vehicle_fields:
                if overrides is None:
                    overrides = dict(self.base.vehicle_overrides)
                overrides[name] = value
            else:
                update[name] = _coerce(value, self._kinds[name])
        if overrides is not None:
            update["vehicle_overrides"] = overrides
        return self.base.model_copy(update=update)

    def validated(self, values: Mapping[str, Any], where: str = "scenario") -> Scenario:
        """The run's scenario validated in full (the base mapping with ``values`` applied)."""
        data = apply_overrides(self.data, values, self.vehicle_fields)
        return scenario_from_dict(data, where=where)


def same_scenario(a: Scenario, b: Scenario, names: Iterable[str]) -> bool:
    """``a == b``, and the fields ``names`` of the same types (``1 == 1.0`` is not enough)."""
    if a != b:
        return False
    fields = type(a).model_fields
    return all(type(getattr(a, n)) is type(getattr(b, n)) for n in names if n in fields)
