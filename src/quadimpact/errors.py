"""Errors raised for bad user input, with one-line messages.

Every problem with a vehicle file, a scenario file or a command-line flag is
reported as an :class:`InputError` whose message is a single line of the form::

    <where>: <field>: <rule> (got <value>)

for example ``scenario.toml: heading_deg: must be <= 180 (got 500)``. The
command-line interface prints that line and exits with status 2.

This module imports nothing heavy: the pydantic helpers take the exception
object they are given.
"""

from __future__ import annotations

import difflib
from collections.abc import Mapping, Sequence
from typing import Any

__all__ = ["InputError", "format_value", "input_error_from_validation", "one_line", "short_path"]

_MAX_VALUE_CHARS = 60
_MAX_PATH_CHARS = 80


class InputError(ValueError):
    """Bad user input (vehicle, scenario, flag, file), explained in one line.

    Parameters
    ----------
    message : str
        What is wrong and where, e.g.
        ``"vehicle spiri.toml: inertia_kg_m2: must be symmetric positive definite"``.
        Line breaks are folded so that the message is always a single line.
    """

    def __init__(self, message: str) -> None:
        super().__init__(one_line(message))


def one_line(text: str) -> str:
    """Fold any whitespace run containing a line break into a single space.

    Parameters
    ----------
    text : str
        Any message.

    Returns
    -------
    str
        The message on one line, stripped.
    """
    return " ".join(part.strip() for part in str(text).splitlines() if part.strip())


def format_value(value: Any) -> str:
    """Render a user value briefly for an error message.

    Strings are quoted; containers are shown as lists; anything longer than
    60 characters is cut with ``...``.

    Parameters
    ----------
    value : Any
        The offending input value.

    Returns
    -------
    str
        A short single-line rendering.
    """
    if hasattr(value, "tolist"):  # NumPy arrays and scalars
        value = value.tolist()
    if isinstance(value, tuple):
        value = list(value)
    text = repr(value) if isinstance(value, str) else str(value)
    text = one_line(text)
    if len(text) > _MAX_VALUE_CHARS:
        text = text[: _MAX_VALUE_CHARS - 3] + "..."
    return text


def short_path(path: Any) -> str:
    """A path for a one-line message: cut in the middle when longer than 80 characters.

    Parameters
    ----------
    path : str or path-like
        Any path.

    Returns
    -------
    str
        The path, or its two ends around ``...`` with its length in characters.
    """
    import os

    text = os.fspath(path) if isinstance(path, os.PathLike) else str(path)
    if len(text) <= _MAX_PATH_CHARS:
        return text
    half = (_MAX_PATH_CHARS - 5) // 2
    return f"{text[:half]}...{text[-half:]} ({len(text)} characters)"


def _rule(error: Mapping[str, Any]) -> tuple[str, bool]:
    """Plain-words rule of one pydantic error and whether to show the value."""
    kind = error.get("type", "")
    ctx = error.get("ctx") or {}
    if kind == "missing":
        return "is required", False
    if kind == "extra_forbidden":
        return "unknown key", False
    bounds = {
        "greater_than": ("must be >", "gt"),
        "greater_than_equal": ("must be >=", "ge"),
        "less_than": ("must be <", "lt"),
        "less_than_equal": ("must be <=", "le"),
    }
    if kind in bounds:
        words, key = bounds[kind]
        bound = ctx.get(key)
        if isinstance(bound, float) and bound.is_integer():
            bound = int(bound)
        return f"{words} {format_value(bound)}", True
    simple = {
        "finite_number": "must be a finite number",
        "float_type": "must be a number",
        "float_parsing": "must be a number",
        "int_type": "must be an integer",
        "int_parsing": "must be an integer",
        "int_from_float": "must be an integer",
        "string_type": "must be a string",
        "bool_type": "must be true or false",
        "bool_parsing": "must be true or false",
        "tuple_type": "must be a list",
        "list_type": "must be a list",
        "dict_type": "must be a table of key = value pairs",
        "model_type": "must be a table of key = value pairs",
        "model_attributes_type": "must be a table of key = value pairs",
    }
    if kind in simple:
        return simple[kind], True
    if kind == "literal_error":
        return f"must be one of {ctx.get('expected', '?')}", True
    if kind in ("too_short", "too_long"):
        lo, hi = ctx.get("min_length"), ctx.get("max_length")
        if lo is not None and lo == hi:
            return f"must have exactly {lo} items", True
        if kind == "too_short":
            return f"must have at least {lo} items", True
        return f"must have at most {hi} items", True
    if kind == "string_too_short":
        return "must not be empty", True
    if kind in ("value_error", "assertion_error") and "error" in ctx:
        message = str(ctx["error"])
        return message, "(got " not in message
    message = str(error.get("msg", "is invalid"))
    return message[:1].lower() + message[1:], True


def near_miss(key: str, candidates: Sequence[str]) -> str | None:
    """The candidate a mistyped ``key`` most likely meant, or ``None``.

    In order: the same name in another case; a name that is ``key`` plus a
    unit or qualifier suffix (``speed`` -> ``speed_m_s``, ``friction`` ->
    ``friction_coefficient``; the shortest); then the closest spelling
    (``restitusion`` -> ``restitution``).
    """
    key = str(key)
    names = [str(c) for c in candidates]
    lower = {n.lower(): n for n in names}
    if key.lower() in lower:
        return lower[key.lower()]
    longer = sorted((n for n in names if n.lower().startswith(key.lower() + "_")), key=len)
    if longer:
        return longer[0]
    close = difflib.get_close_matches(key, names, n=1, cutoff=0.7)
    return close[0] if close else None


def _suggest(model: Any, loc: Sequence[Any]) -> str:
    """A ``did you mean`` hint for an unknown key, if a close field name exists."""
    current = model
    for part in loc[:-1]:
        fields = getattr(current, "model_fields", None)
        if not fields or part not in fields:
            return ""
        current = fields[part].annotation
    fields = getattr(current, "model_fields", None)
    if not fields or not loc:
        return ""
    close = near_miss(str(loc[-1]), list(fields))
    return f"; did you mean {close!r}?" if close else ""


def _typo_of_missing(missing: Mapping[str, Any], errors: Sequence[Mapping[str, Any]]) -> str:
    """For a required key reported missing: the unknown key beside it that is its near miss."""
    loc = tuple(missing.get("loc", ()))
    if not loc:
        return ""
    extras = [
        str(e["loc"][-1])
        for e in errors
        if e.get("type") == "extra_forbidden" and tuple(e.get("loc", ()))[:-1] == loc[:-1]
    ]
    for extra in extras:
        if near_miss(extra, [str(loc[-1])]) is not None:
            return f" ({extra!r} is there: a misspelling of {str(loc[-1])!r}?)"
    return ""


def input_error_from_validation(
    exc: Any,
    where: str = "",
    *,
    prefix: Sequence[str | int] = (),
    rename: Mapping[str, str] | None = None,
    model: Any = None,
) -> InputError:
    """Turn a pydantic ``ValidationError`` into a one-line :class:`InputError`.

    Only the first error is reported: ``<where>: <field path>: <rule> (got <value>)``.

    Parameters
    ----------
    exc : pydantic.ValidationError
        The validation failure.
    where : str, optional
        Where the input came from, e.g. ``"scenario.toml"`` or ``"vehicle spiri.toml"``.
    prefix : sequence of str or int, optional
        Location parts prepended to the field path (e.g. ``("vehicle_overrides",)``).
    rename : mapping, optional
        Replacement names for top-level fields, e.g. ``{"heading_deg": "--heading"}``
        when the value came from a command-line flag.
    model : pydantic model class, optional
        Used to suggest a close field name for an unknown key.

    Returns
    -------
    InputError
        Raise it (``raise input_error_from_validation(e, where) from None``).
    """
    errors = exc.errors(include_url=False)
    if not errors:
        return InputError(f"{where}: invalid input" if where else "invalid input")
    error = errors[0]
    loc = list(prefix) + [part for part in error.get("loc", ())]
    if loc and rename and isinstance(loc[0], str) and loc[0] in rename:
        loc[0] = rename[loc[0]]
    field = ".".join(str(part) for part in loc)
    rule, show_value = _rule(error)
    if error.get("type") == "extra_forbidden" and model is not None:
        rule += _suggest(model, error.get("loc", ()))
    if error.get("type") == "missing":
        rule += _typo_of_missing(error, errors)
    parts = [p for p in (where, field) if p]
    text = ": ".join(parts + [rule])
    if show_value and "input" in error and error.get("loc"):  # not the whole table
        text += f" (got {format_value(error['input'])})"
    return InputError(text)
