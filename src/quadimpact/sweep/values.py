"""A sweep's values: swept values written as text, their plain and canonical forms, and
how they are stored and compared.

:func:`parse_values` reads one field's values (``"0,45"``, ``"-20:20:1"``, in
exact decimal arithmetic); :func:`plain` and :func:`canonical` give the plain
Python (JSON-able) value and its canonical JSON text, which the sweep's
fingerprint and the run store key on; :func:`column_kind` and
:func:`column_value` say how a swept field is stored in ``runs.parquet``;
:func:`first_duplicate` finds a value listed twice (``0`` and ``0.0`` are one
value, ``-0.0`` another). Used by :class:`quadimpact.sweep.spec.SweepSpec`.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Iterable, Sequence
from decimal import Decimal
from typing import Any

from quadimpact.errors import InputError, format_value
from quadimpact.results.files import to_jsonable

__all__ = [
    "LARGE_RUNS",
    "MAX_RUNS",
    "check_size",
    "canonical",
    "column_kind",
    "column_value",
    "first_duplicate",
    "is_number",
    "parse_values",
    "plain",
    "value_key",
]

MAX_RUNS = 10_000_000
"""Largest number of runs in one sweep."""
LARGE_RUNS = 1_000_000
"""Sweeps (and studies) with more runs than this need ``allow_large=True`` (``--allow-large``)."""


def check_size(n_runs: int, allow_large: bool, what: str) -> None:
    """Refuse, before anything is planned, a sweep or study too large to run as asked.

    Parameters
    ----------
    n_runs : int
        The runs it would make.
    allow_large : bool
        More than :data:`LARGE_RUNS` runs were confirmed (``--allow-large``).
    what : str
        What sets the size, for the message (``"--n 2000000"``, a sweep file's name).

    Raises
    ------
    InputError
        More than :data:`MAX_RUNS` runs, or more than :data:`LARGE_RUNS` unconfirmed.
    """
    if n_runs > MAX_RUNS:
        raise InputError(f"{what}: {n_runs} runs, more than {MAX_RUNS} (the most one sweep holds)")
    if n_runs > LARGE_RUNS and not allow_large:
        raise InputError(
            f"{what}: {n_runs} runs, more than {LARGE_RUNS}: confirm with --allow-large "
            "(allow_large=True) to run it"
        )


_INT_RE = re.compile(r"^[+-]?\d+$")
_NUM_RE = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")


def _scalar(text: str) -> Any:
    """One comma-list item: int, float, true/false, or a string (quotes optional)."""
    if _INT_RE.match(text):
        return int(text)
    if _NUM_RE.match(text):
        return float(text)
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    if len(text) >= 2 and text[0] == text[-1] and text[0] in "'\"":
        return text[1:-1]
    return text


def _range(text: str, where: str) -> list[Any]:
    """Inclusive ``start:stop:step`` in exact arithmetic (no float drift).

    The three numbers are scaled to integers by a common power of ten, so that
    value ``k`` is the exact ratio ``(start + k step) 10^d / 10^d``, rounded
    once to the nearest float (Python's integer division is correctly
    rounded): ``0:0.3:0.1`` ends at 0.3. Linear in the number of values.
    """
    parts = [p.strip() for p in text.split(":")]
    if len(parts) != 3:
        raise InputError(f"{where}a range is start:stop:step (got {text!r})")
    if not all(_NUM_RE.match(p) for p in parts):
        raise InputError(f"{where}range start, stop and step must be numbers (got {text!r})")
    numbers = [Decimal(p) for p in parts]
    digits = max(0, *(-int(n.as_tuple().exponent) for n in numbers))
    scale = 10**digits
    start, stop, step = (int(n.scaleb(digits)) for n in numbers)
    if step == 0:
        raise InputError(f"{where}range step must not be 0 (got {text!r})")
    count = (stop - start) // step + 1
    if count < 1:
        raise InputError(
            f"{where}empty range: the step must lead from start to stop (got {text!r})"
        )
    if count > MAX_RUNS:
        raise InputError(f"{where}range has {count} values, more than {MAX_RUNS} (got {text!r})")
    scaled = range(start, start + count * step, step)
    if all(_INT_RE.match(p) for p in parts):
        return list(scaled)
    return [k / scale for k in scaled]


def parse_values(text: str, field: str = "") -> list[Any]:
    """Values of one swept field written as text (``--grid FIELD=VALUES``, TOML strings).

    Parameters
    ----------
    text : str
        A comma list (``"0,45"``, ``"paper-replica,default"``) whose items are
        numbers, ``true``/``false``, strings, or inclusive ranges
        ``start:stop:step`` (``"-20:20:1"``: -20, -19, ..., 20). Range values
        are ``start + k step`` computed in decimal arithmetic, so
        ``"0.5:1:0.25"`` gives exactly 0.5, 0.75, 1.0 and ``"0:0.3:0.1"`` ends at
        0.3, not 0.30000000000000004. Ranges of integers give ints.
    field : str, optional
        Field name for error messages.

    Returns
    -------
    list
        The values, in order.

    Raises
    ------
    InputError
        Empty text or item, malformed range, zero step, empty range.
    """
    where = f"{field}: " if field else ""
    if not isinstance(text, str):
        raise InputError(f"{where}values must be text (got {format_value(text)})")
    items = [p.strip() for p in text.split(",")]
    if not text.strip() or not all(items):
        raise InputError(f"{where}empty value in the list (got {text!r})")
    values: list[Any] = []
    for item in items:
        if ":" in item and not (item[0] in "'\"" and item[-1] == item[0]):
            values.extend(_range(item, where))
        else:
            values.append(_scalar(item))
    return values


def plain(value: Any) -> Any:
    """NumPy values, tuples, paths... as plain Python values (JSON-able); NaN kept."""
    return to_jsonable(value, finite=False, strict=False)


def canonical(value: Any) -> str:
    """A plain value's canonical JSON text (keys sorted, no spaces; NaN refused): what a
    sweep's fingerprint, its equality and the store's keys compare."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"), allow_nan=False)


def is_number(v: Any) -> bool:
    """Whether ``v`` is an int or a float (not a bool)."""
    return isinstance(v, (int, float)) and not isinstance(v, bool)


_PLAIN_TYPES = {bool: "b", int: "f", float: "f", str: "s"}


def column_kind(values: Iterable[Any]) -> str:
    """How a swept field's values are stored in ``runs.parquet``: ``"b"`` booleans,
    ``"f"`` numbers (as floats), ``"s"`` strings, ``"j"`` anything else (canonical JSON)."""
    values = list(values)
    kinds = {_PLAIN_TYPES.get(t, "?") for t in set(map(type, values))}
    if len(kinds) == 1 and "?" not in kinds:  # plain values of one kind (the fast path)
        return kinds.pop()
    if all(isinstance(v, bool) for v in values):
        return "b"
    if all(is_number(v) for v in values):
        return "f"
    if all(isinstance(v, str) for v in values):
        return "s"
    return "j"


def column_value(value: Any, kind: str) -> Any:
    """A swept value as stored in its ``runs.parquet`` column."""
    if value is None:
        return None
    if kind == "f":
        return float(value)
    if kind == "j":
        return canonical(value)
    return value


def value_key(value: Any) -> Any:
    """A hashable key under which two swept values are the same value.

    Numbers compare as floats (``0`` and ``0.0`` are one value; ``-0.0``
    stays apart from ``0.0``, as in the canonical JSON), anything else by its
    canonical JSON text.
    """
    if is_number(value):
        number = float(value)
        return ("number", number, math.copysign(1.0, number))
    return ("json", canonical(value))


def first_duplicate(values: Sequence[Any]) -> Any:
    """The first value listed a second time (see :func:`value_key`), or None; linear time."""
    if set(map(type, values)) <= {int, float}:
        # plain numbers: floats in a set (which also merges -0.0 and 0.0, so a
        # smaller set only means "look closer")
        if len(set(map(float, values))) == len(values):
            return None
    seen: set[Any] = set()
    for v in values:
        key = value_key(v)
        if key in seen:
            return v
        seen.add(key)
    return None
