"""Input files: the one TOML reader, where a relative vehicle path is looked up,
and how overrides (command-line flags, swept values) go on top of a file's values.

Every input file (vehicle, scenario, sweep, the crash scenarios) is read by
:func:`read_toml_file`, so that every failure is the same one-line
:class:`~quadimpact.errors.InputError` naming the file. A scenario or sweep
file may name its vehicle by a path relative to itself
(:func:`locate_vehicle`). :func:`apply_overrides` puts new field values over a
scenario's: ``quadimpact run``'s flags over the scenario file, a sweep's
swept values over its base scenario.
"""

from __future__ import annotations

import tomllib
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from quadimpact.errors import InputError, format_value, one_line, short_path

__all__ = ["MAX_DEPTH", "apply_overrides", "locate_vehicle", "read_toml_file"]

#: Deepest nesting of tables and lists in an input file (the deepest input,
#: a sweep run's vehicle inertia matrix, has 5 levels).
MAX_DEPTH = 16


def read_toml_file(path: Any, where: str | None = None) -> dict[str, Any]:
    """Read a TOML file, turning every failure into a one-line :class:`InputError`.

    Parameters
    ----------
    path : str or pathlib.Path or importlib.resources.abc.Traversable
        The file (a packaged resource too, e.g. a bundled vehicle).
    where : str, optional
        Start of error messages; default the path.

    Returns
    -------
    dict
        The parsed table.

    Raises
    ------
    InputError
        ``<where>: file not found`` (or ``is a directory, not a file``),
        ``<where>: cannot read file (...)``, ``<where>: invalid TOML: ...`` (with
        line and column; also an integer of more than 4300 digits), tables
        and lists nested deeper than :data:`MAX_DEPTH`. A long path is cut in
        the middle.
    """
    if isinstance(path, str):
        path = Path(path)
    where = short_path(path) if where is None else where
    try:
        if not path.is_file():
            reason = "is a directory, not a file" if path.is_dir() else "file not found"
            raise InputError(f"{where}: {reason}")
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = getattr(exc, "strerror", None) or str(exc)
        raise InputError(f"{where}: cannot read file ({reason})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{where}: invalid TOML: {exc}") from None
    except RecursionError:
        raise InputError(f"{where}: invalid TOML: nested too deeply") from None
    except ValueError as exc:  # e.g. an integer of more than 4300 digits
        raise InputError(f"{where}: invalid TOML: {one_line(str(exc)).split(';')[0]}") from None
    depth = _depth(data)
    if depth > MAX_DEPTH:
        raise InputError(
            f"{where}: tables and lists nested {depth} deep; no input has more than "
            f"{MAX_DEPTH} levels"
        )
    return data


def _depth(data: Any) -> int:
    """How deep tables and lists nest in ``data`` (a scalar: 0), without recursion."""
    deepest, stack = 0, [(data, 1)]
    while stack:
        value, level = stack.pop()
        if isinstance(value, (Mapping, list)):
            deepest = max(deepest, level)
            children = value.values() if isinstance(value, Mapping) else value
            if level <= MAX_DEPTH:  # deeper than that is refused: no need to look further
                stack.extend((child, level + 1) for child in children)
    return deepest


def locate_vehicle(data: Mapping[str, Any], folder: str | Path) -> dict[str, Any]:
    """The scenario fields with a relative ``vehicle`` path looked up beside the file.

    The rule for every file that names a vehicle (scenario files, a sweep's
    base): a relative ``vehicle`` path naming a file in ``folder`` (the folder
    of the file that names it) becomes that file's absolute path; anything
    else (a bundled name, an absolute path, a path with no file beside) is
    left as it is, and resolved by :func:`~quadimpact.inputs.vehicle.load_vehicle`.

    Parameters
    ----------
    data : mapping
        Scenario fields (the file's table).
    folder : path
        The folder of that file.

    Returns
    -------
    dict
        A copy of ``data``.
    """
    out = dict(data)
    vehicle = out.get("vehicle")
    if isinstance(vehicle, str) and not Path(vehicle).is_absolute():
        beside = Path(folder) / vehicle
        if beside.is_file():
            out["vehicle"] = str(beside.resolve())
    return out


def _set_nested(out: dict[str, Any], path: list[str], value: Any) -> None:
    """Set ``out[a][b]...[z] = value`` for the dotted path ``a.b...z``, copying each table
    on the way (a preset name such as ``imu = "noisy"`` becomes ``{preset = "noisy"}``)."""
    head, rest = path[0], path[1:]
    if not rest:
        out[head] = value
        return
    table = out.get(head)
    if isinstance(table, str):
        table = {"preset": table}
    elif table is None or table is True:
        table = {}
    elif not isinstance(table, Mapping):
        raise InputError(f"{'.'.join(path)}: {head} is not a table (got {format_value(table)})")
    table = dict(table)
    _set_nested(table, rest, value)
    out[head] = table


def apply_overrides(
    data: Mapping[str, Any], fields: Mapping[str, Any], vehicle_fields: Iterable[str] = ()
) -> dict[str, Any]:
    """Scenario fields with new values on top: the one place overrides are applied.

    Parameters
    ----------
    data : mapping
        Scenario fields (a file's values, a sweep's base).
    fields : mapping
        New values, field -> value (``quadimpact run``'s flags, a sweep run's
        swept values). A ``vehicle_overrides`` value replaces the base's table.
        A dotted name sets a field of a table (``instruments.barometer.noise_m``).
    vehicle_fields : iterable of str
        Fields that are vehicle parameters: they go to ``vehicle_overrides``
        (added to the base's) instead of the scenario.

    Returns
    -------
    dict
        A new mapping; ``data`` is not changed.
    """
    out = dict(data)
    vehicle_fields = set(vehicle_fields)
    overrides = dict(out.get("vehicle_overrides") or {})
    if "vehicle_overrides" in fields:
        given = fields["vehicle_overrides"]
        if given is not None and not isinstance(given, Mapping):
            raise InputError(
                "vehicle_overrides: must be a table of vehicle field = value "
                f"(got {format_value(given)}); to sweep a vehicle field, name it "
                "(e.g. --grid restitution=0.5,0.9)"
            )
        overrides = dict(given or {})
    for name, value in fields.items():
        if name == "vehicle_overrides":
            continue
        if name in vehicle_fields:
            overrides[name] = value
        elif "." in name:  # a field of a table: instruments.barometer.noise_m, imu.rate_hz
            _set_nested(out, name.split("."), value)
        else:
            out[name] = value
    if overrides:
        out["vehicle_overrides"] = overrides
    return out
