"""Sweeps: many runs of one base scenario, streamed to one Parquet table.

A sweep names a **base** scenario (the keys of a scenario file) and the runs
to make from it: a **grid** (every combination of the listed values, the
last field varying fastest), an explicit list of **runs**, or a random
**sample** (``n`` points, a ``seed``, uniform ``ranges`` and/or ``choices``).
A grid can be combined with ``runs`` or ``sample``: every grid point is then
run with every entry. Fields are scenario fields (``heading_deg``,
``inclination_deg``, ``speed_m_s``, ``final_time_s``, ``model``...) or vehicle
fields (``restitution``, ``contact_stiffness``, ``mass_kg``...), named as in
scenario and vehicle files; vehicle fields go to the run's
``vehicle_overrides``. A sweep file::

    [base]                        # or: base = "scenario.toml" (beside this file)
    model = "paper-replica"

    [grid]
    heading_deg = [0, 45]
    inclination_deg = "-20:20:1"  # inclusive range start:stop:step, or "0,45" lists
    speed_m_s = [0.5, 0.75, 1.0]

    # [[runs]]                    # explicit runs ...
    # inclination_deg = 5
    # [sample]                    # ... or a random sample
    # n = 1000
    # seed = 1
    # ranges = { inclination_deg = [-20, 20] }   # uniform in [low, high]
    # choices = { heading_deg = [0, 45] }        # one of the values

The whole sweep (every run's scenario and vehicle) is validated before any
run starts; problems are one-line :class:`~quadimpact.errors.InputError`.

Output folder ``DIR``:

* ``runs.parquet``: one row per run, sorted by ``run_id`` (the run's index in
  the enumeration above): the swept inputs under their names, then the run's
  summary (``docs/RESULTS.md``) flattened: nested tables joined with ``__``
  (``approach__start_time_s``), lists as JSON strings (``leading_bumpers``,
  ``warnings``, ``subsequent_impacts``, ``crash_position_m``); the kernel's
  wall-clock time is left out so that the table is the same, bit for bit,
  however and wherever the sweep ran. The column set and types are fixed
  (:data:`SUMMARY_COLUMNS`); a run that failed (numerically, or by raising
  while being prepared) is a row with ``status = "failed"`` and its
  ``reason``.
* ``sweep.json``: the sweep, so that running it again resumes it (and a
  different sweep in the same folder is refused).
* ``parts/``: completed runs while the sweep runs, in small Parquet files
  written atomically (a part is complete or absent); merged into
  ``runs.parquet`` at the end. A run again does only the missing runs.

Runs execute in parallel on local cores (``workers``), in-process
(``workers=1``), or on a Dask cluster (``scheduler="tcp://host:port"``); all
three call the same pure function :func:`run_chunk`.
"""

from __future__ import annotations

import contextlib
import difflib
import hashlib
import json
import math
import os
import re
import signal
import sys
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from decimal import ROUND_FLOOR, Decimal
from pathlib import Path
from typing import Any

from quadimpact.errors import InputError, format_value, one_line
from quadimpact.inputs.files import apply_overrides, locate_vehicle, read_toml_file
from quadimpact.results.files import atomic_write, to_jsonable

__all__ = [
    "SweepSpec",
    "SUMMARY_COLUMNS",
    "load_sweep_file",
    "parse_values",
    "read_runs",
    "run_chunk",
    "run_sweep",
    "flatten_summary",
]

MAX_RUNS = 10_000_000
"""Largest number of runs in one sweep."""
FLUSH_ROWS = 1024
"""A part file is written when this many completed runs are waiting..."""
FLUSH_SECONDS = 1.0
"""... or when the oldest waiting run completed this long ago (so a kill loses
the runs in flight plus at most about this much finished work)."""
CONSOLIDATE_WINDOW = 20_000
"""Rows per row group of ``runs.parquet`` (the merge reads one window at a time)."""
FORMAT_VERSION = 1

# Column kinds: f float64, i int64, b bool, s string, j JSON text.
_ARROW_KINDS = ("f", "i", "b", "s", "j")

SUMMARY_COLUMNS: tuple[tuple[str, str], ...] = (
    ("status", "s"),
    ("reason", "s"),
    ("warnings", "j"),
    ("model", "s"),
    ("model_options__yaw_reaction", "s"),
    ("model_options__bumper1_yaw_twice", "b"),
    ("model_options__initial_rotor_speeds", "s"),
    ("model_options__attitude_mapping", "s"),
    ("model_options__crash_rule", "s"),
    ("model_options__approach_start", "s"),
    ("controller", "s"),
    ("vehicle", "s"),
    ("delta_init_m", "f"),
    ("peak_force_n", "f"),
    ("initial_impact_duration_s", "f"),
    ("first_contact_s", "f"),
    ("impact_speed_m_s", "f"),
    ("heading_deg", "f"),
    ("inclination_deg", "f"),
    ("impact_heading_deg", "f"),
    ("impact_inclination_deg", "f"),
    ("leading_bumpers", "j"),
    ("aft_bumpers", "j"),
    ("response_type", "s"),
    ("n_episodes", "i"),
    ("n_grazes", "i"),
    ("n_subsequent_impacts", "i"),
    ("n_subsequent_episodes", "i"),
    ("subsequent_impacts", "j"),
    ("crash_time_s", "f"),
    ("power_off_time_s", "f"),
    ("crash_position_m", "j"),
    ("max_penetration_m", "f"),
    ("bumper_model_valid", "b"),
    ("t_start_s", "f"),
    ("t_final_s", "f"),
    ("references__altitude_m", "f"),
    ("references__roll_rad", "f"),
    ("references__pitch_rad", "f"),
    ("references__yaw_rad", "f"),
    ("quadimpact_version", "s"),
    ("wall_distance_m", "f"),
    ("crash_distance_from_wall_m", "f"),
    ("approach__start_time_s", "f"),
    ("approach__start_x_m", "f"),
    ("approach__start_speed_m_s", "f"),
    ("approach__late_start", "b"),
    ("approach__speed_residual_m_s", "f"),
    ("requested__heading_deg", "f"),
    ("requested__inclination_deg", "f"),
    ("requested__speed_m_s", "f"),
    ("requested__impact_time_s", "f"),
    ("attitude_excursion__roll_excursion_deg", "f"),
    ("attitude_excursion__pitch_excursion_deg", "f"),
    ("attitude_excursion__yaw_excursion_deg", "f"),
    ("attitude_excursion__tilt_max_deg", "f"),
    ("outcome", "s"),
    ("integrator__steps", "i"),
    ("integrator__rejected_steps", "i"),
    ("integrator__rhs_evaluations", "i"),
    ("integrator__control_ticks", "i"),
    ("integrator__output_rows", "i"),
    ("summary_extra", "j"),
)
"""Summary columns of ``runs.parquet`` and their kinds (``f`` float64, ``i``
nullable int64, ``b`` nullable bool, ``s`` string, ``j`` JSON text). Summary
keys not listed land, as JSON, in ``summary_extra`` (null when none), so the
schema never depends on what a run returned."""

_SUMMARY_KIND = dict(SUMMARY_COLUMNS)


def _is_time_measurement(key: str) -> bool:
    """Flattened summary keys that measure wall-clock time (not deterministic)."""
    return key.startswith("integrator__") and "time" in key


# ------------------------------------------------------------------ values
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
    """Inclusive ``start:stop:step`` in exact decimal arithmetic (no float drift)."""
    parts = [p.strip() for p in text.split(":")]
    if len(parts) != 3:
        raise InputError(f"{where}a range is start:stop:step (got {text!r})")
    if not all(_NUM_RE.match(p) for p in parts):
        raise InputError(f"{where}range start, stop and step must be numbers (got {text!r})")
    start, stop, step = (Decimal(p) for p in parts)
    if step == 0:
        raise InputError(f"{where}range step must not be 0 (got {text!r})")
    count = int(((stop - start) / step).to_integral_value(rounding=ROUND_FLOOR)) + 1
    if count < 1:
        raise InputError(
            f"{where}empty range: the step must lead from start to stop (got {text!r})"
        )
    if count > MAX_RUNS:
        raise InputError(f"{where}range has {count} values, more than {MAX_RUNS} (got {text!r})")
    integral = all(_INT_RE.match(p) for p in parts)
    values = (start + k * step for k in range(count))
    return [int(v) if integral else float(v) for v in values]


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


# --------------------------------------------------------------- the spec
def _plain(value: Any) -> Any:
    """NumPy values, tuples, paths... as plain Python values (JSON-able); NaN kept."""
    return to_jsonable(value, finite=False, strict=False)


def _canonical(value: Any) -> str:
    return json.dumps(value, sort_keys=True, separators=(",", ":"), allow_nan=False)


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _column_kind(values: Iterable[Any]) -> str:
    values = list(values)
    if all(isinstance(v, bool) for v in values):
        return "b"
    if all(_is_number(v) for v in values):
        return "f"
    if all(isinstance(v, str) for v in values):
        return "s"
    return "j"


def _column_value(value: Any, kind: str) -> Any:
    """A swept value as stored in its ``runs.parquet`` column."""
    if value is None:
        return None
    if kind == "f":
        return float(value)
    if kind == "j":
        return _canonical(value)
    return value


def _short(inputs: Mapping[str, Any]) -> str:
    return ", ".join(f"{k}={format_value(v)}" for k, v in inputs.items())


class SweepSpec:
    """A sweep: a base scenario and the runs made from it (see the module docstring).

    Parameters
    ----------
    base : mapping or path, optional
        Scenario fields, as in a scenario file (``kind``, ``model``,
        ``vehicle_overrides``...), or the path of a scenario TOML file. Default:
        the paper's wall approach with its defaults.
    grid : mapping, optional
        Field -> values: a list, a single value, or text for
        :func:`parse_values` (``"-20:20:1"``, ``"0,45"``). Every combination is
        run; the last field varies fastest.
    runs : sequence of mappings, optional
        Explicit runs, each a mapping field -> value (fields left out keep the
        base's value).
    sample : mapping, optional
        ``{"n": int, "seed": int (default 0), "ranges": {field: [low, high]},
        "choices": {field: [values]}}``: ``n`` random points, each field uniform
        in ``[low, high]`` or drawn uniformly from ``choices`` (NumPy's PCG64
        generator seeded with ``seed``).
    where : str, optional
        Start of error messages (the sweep file's name).

    Raises
    ------
    InputError
        Unknown field, bad values, empty sweep, bad base scenario. Each run's
        scenario is checked by :meth:`validate` (``run_sweep`` calls it).

    Notes
    -----
    Run ``i`` is grid point ``i // m`` combined with entry ``i % m`` of the
    runs or sample (``m`` entries; ``m = 1`` without them). Numeric swept
    values are stored (and passed to the scenario) as floats.
    """

    def __init__(
        self,
        base: Mapping[str, Any] | str | os.PathLike[str] | None = None,
        grid: Mapping[str, Any] | None = None,
        runs: Sequence[Mapping[str, Any]] | None = None,
        sample: Mapping[str, Any] | None = None,
        *,
        where: str = "sweep",
    ) -> None:
        from quadimpact.inputs.scenarios import _KINDS
        from quadimpact.inputs.vehicle import Vehicle

        self.where = where
        self.base = self._read_base(base)
        kind = self.base.get("kind", "wall-approach")
        if kind not in _KINDS:
            raise InputError(
                f"{where}: base: kind: must be 'wall-approach' or 'flight' (got {kind!r})"
            )
        self._scenario_fields = [f for f in _KINDS[kind].model_fields if f != "kind"]
        self._vehicle_fields = [f for f in Vehicle.model_fields if f not in self._scenario_fields]
        self._kind_name = kind

        self.grid: dict[str, list[Any]] = {}
        if grid is not None:
            if not isinstance(grid, Mapping):
                raise InputError(f"{where}: grid: must be a table of field = values")
            for name, values in grid.items():
                self._check_field(str(name), "grid")
                self.grid[str(name)] = self._grid_values(str(name), values)

        if runs is not None and sample is not None:
            raise InputError(f"{where}: give either runs or sample, not both")
        self.runs: list[dict[str, Any]] | None = None
        if runs is not None:
            self.runs = self._read_runs(runs)
        self.sample: dict[str, Any] | None = None
        if sample is not None:
            self.sample = self._read_sample(sample)
        if not self.grid and not self.runs and self.sample is None:
            raise InputError(f"{where}: empty sweep: give a grid, runs or a sample")

        # input columns, in order, and their kinds
        fields: dict[str, list[Any]] = {k: list(v) for k, v in self.grid.items()}
        for entry in self.runs or []:
            for k, v in entry.items():
                fields.setdefault(k, []).append(v)
        if self.sample is not None:
            for k in self.sample["ranges"]:
                fields[k] = [0.0]
            for k, v in self.sample["choices"].items():
                fields[k] = list(v)
        inner = {k for e in self.runs or [] for k in e}
        if self.sample is not None:
            inner |= set(self.sample["ranges"]) | set(self.sample["choices"])
        for k in self.grid:
            if k in inner:
                raise InputError(f"{where}: {k}: swept both in the grid and in runs/sample")
        self.columns: dict[str, str] = {k: _column_kind(v) for k, v in fields.items()}
        # numbers as floats (one type per column, so equal sweeps compare equal)
        for k, values in self.grid.items():
            self.grid[k] = [_column_value(v, "f") if self.columns[k] == "f" else v for v in values]
        for entry in self.runs or []:
            for k, v in entry.items():
                if self.columns[k] == "f":
                    entry[k] = float(v)
        if self.sample is not None:
            for k, values in self.sample["choices"].items():
                if self.columns[k] == "f":
                    self.sample["choices"][k] = [float(v) for v in values]

        self._sizes = [len(v) for v in self.grid.values()]
        self._inner = len(self.runs) if self.runs else (self.sample["n"] if self.sample else 1)
        n = math.prod(self._sizes) * self._inner
        if n > MAX_RUNS:
            raise InputError(f"{where}: {n} runs, more than {MAX_RUNS}")
        self.n_runs = n
        self._drawn: dict[str, list[Any]] | None = None

    # ------------------------------------------------------------ reading
    def _read_base(self, base: Any) -> dict[str, Any]:
        if base is None:
            return {}
        if isinstance(base, (str, os.PathLike)):
            path = Path(base)
            return _plain(locate_vehicle(read_toml_file(path), path.parent))
        if not isinstance(base, Mapping):
            raise InputError(f"{self.where}: base: must be a table of scenario fields or a path")
        return _plain(dict(base))

    def _check_field(self, name: str, section: str) -> None:
        if name in self._scenario_fields or name in self._vehicle_fields:
            return
        if name == "kind":
            raise InputError(f"{self.where}: {section}: kind: cannot be swept (set it in base)")
        known = self._scenario_fields + self._vehicle_fields
        close = difflib.get_close_matches(name, known, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise InputError(
            f"{self.where}: {section}: {name}: unknown field (not a {self._kind_name} scenario "
            f"field nor a vehicle field){hint}"
        )

    def _grid_values(self, name: str, values: Any) -> list[Any]:
        where = f"{self.where}: grid: {name}"
        if isinstance(values, str):
            out = parse_values(values, f"{self.where}: grid: {name}")
        elif isinstance(values, Mapping):
            raise InputError(f"{where}: must be a list of values or a 'start:stop:step' text")
        elif hasattr(values, "__iter__") and not isinstance(values, bytes):
            out = _plain(list(values))
        else:
            out = [_plain(values)]
        if not out:
            raise InputError(f"{where}: no values")
        self._check_values(where, out)
        seen: list[Any] = []
        for v in out:
            key = _canonical(float(v) if _is_number(v) else v)
            if key in seen:
                raise InputError(f"{where}: value {format_value(v)} is listed twice")
            seen.append(key)
        return out

    @staticmethod
    def _check_values(where: str, values: Iterable[Any]) -> None:
        for v in values:
            if v is None:
                raise InputError(f"{where}: values must not be empty (got None)")
            if isinstance(v, float) and not math.isfinite(v):
                raise InputError(f"{where}: values must be finite numbers (got {v})")

    def _read_runs(self, runs: Any) -> list[dict[str, Any]]:
        if isinstance(runs, (str, Mapping)) or not hasattr(runs, "__iter__"):
            raise InputError(f"{self.where}: runs: must be a list of tables ([[runs]])")
        out = []
        for i, entry in enumerate(runs):
            if not isinstance(entry, Mapping):
                raise InputError(f"{self.where}: runs[{i}]: must be a table of field = value")
            entry = _plain(dict(entry))
            for name, v in entry.items():
                self._check_field(name, f"runs[{i}]")
                self._check_values(f"{self.where}: runs[{i}]: {name}", [v])
            out.append(entry)
        if not out:
            raise InputError(f"{self.where}: runs: empty list")
        return out

    def _read_sample(self, sample: Any) -> dict[str, Any]:
        w = f"{self.where}: sample"
        if not isinstance(sample, Mapping):
            raise InputError(f"{w}: must be a table with n, seed, ranges and/or choices")
        unknown = set(sample) - {"n", "seed", "ranges", "choices"}
        if unknown:
            raise InputError(f"{w}: {sorted(unknown)[0]}: unknown key (n, seed, ranges, choices)")
        n, seed = sample.get("n"), sample.get("seed", 0)
        if not isinstance(n, int) or isinstance(n, bool) or not 1 <= n <= MAX_RUNS:
            raise InputError(
                f"{w}: n: must be an integer in [1, {MAX_RUNS}] (got {format_value(n)})"
            )
        if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
            raise InputError(f"{w}: seed: must be an integer >= 0 (got {format_value(seed)})")
        ranges: dict[str, list[float]] = {}
        for name, bounds in dict(sample.get("ranges") or {}).items():
            self._check_field(name, "sample.ranges")
            b = _plain(bounds)
            if (
                not isinstance(b, list)
                or len(b) != 2
                or not all(_is_number(x) and math.isfinite(x) for x in b)
                or not b[0] < b[1]
            ):
                raise InputError(
                    f"{w}.ranges: {name}: must be [low, high] numbers with low < high "
                    f"(got {format_value(bounds)})"
                )
            ranges[name] = [float(b[0]), float(b[1])]
        choices: dict[str, list[Any]] = {}
        for name, values in dict(sample.get("choices") or {}).items():
            self._check_field(name, "sample.choices")
            v = _plain(values)
            if not isinstance(v, list) or not v:
                raise InputError(f"{w}.choices: {name}: must be a non-empty list of values")
            self._check_values(f"{w}.choices: {name}", v)
            if name in ranges:
                raise InputError(f"{w}: {name}: both in ranges and choices")
            choices[name] = v
        if not ranges and not choices:
            raise InputError(f"{w}: give ranges and/or choices to draw from")
        return {"n": n, "seed": seed, "ranges": ranges, "choices": choices}

    # --------------------------------------------------------- enumeration
    def _draws(self) -> dict[str, list[Any]]:
        if self._drawn is None:
            import numpy as np

            assert self.sample is not None
            rng = np.random.Generator(np.random.PCG64(self.sample["seed"]))
            n = self.sample["n"]
            drawn: dict[str, list[Any]] = {}
            for name, (lo, hi) in self.sample["ranges"].items():
                drawn[name] = rng.uniform(lo, hi, size=n).tolist()
            for name, values in self.sample["choices"].items():
                drawn[name] = [values[j] for j in rng.integers(0, len(values), size=n).tolist()]
            self._drawn = drawn
        return self._drawn

    def inputs(self, run_id: int) -> dict[str, Any]:
        """The swept values of run ``run_id`` (field -> value)."""
        if not 0 <= run_id < self.n_runs:
            raise IndexError(run_id)
        g, j = divmod(run_id, self._inner)
        values: dict[str, Any] = {}
        idx = []
        for size in reversed(self._sizes):
            g, r = divmod(g, size)
            idx.append(r)
        for (name, vals), r in zip(self.grid.items(), reversed(idx), strict=True):
            values[name] = vals[r]
        if self.runs:
            values.update(self.runs[j])
        elif self.sample is not None:
            for name, drawn in self._draws().items():
                values[name] = drawn[j]
        return values

    def scenario_dict(self, run_id: int, inputs: Mapping[str, Any] | None = None) -> dict[str, Any]:
        """The scenario mapping of run ``run_id`` (base + swept values)."""
        if inputs is None:
            inputs = self.inputs(run_id)
        return apply_overrides(self.base, inputs, self._vehicle_fields)

    def input_columns(self, inputs: Mapping[str, Any]) -> dict[str, Any]:
        """Row values of the input columns for one run's inputs."""
        return {k: _column_value(inputs.get(k), kind) for k, kind in self.columns.items()}

    def validate(self, check: Callable[[int], None] | None = None) -> None:
        """Build and validate every run's scenario and vehicle (raises the first problem).

        Parameters
        ----------
        check : callable, optional
            Called with each run_id after it validated (progress hooks).

        Raises
        ------
        InputError
            ``<where>: run <i> (<swept values>): <field>: <rule> (got <value>)``.
        """
        from quadimpact.inputs.scenarios import scenario_from_dict
        from quadimpact.inputs.vehicle import load_vehicle

        base = scenario_from_dict(self.base, where=f"{self.where}: base")
        base.build_vehicle(where=f"{self.where}: base")
        vehicles: dict[str, Any] = {}
        checked: set[str] = set()
        for run_id in range(self.n_runs):
            inputs = self.inputs(run_id)
            try:
                scenario = scenario_from_dict(self.scenario_dict(run_id, inputs), where="")
                key = _canonical([scenario.vehicle, _plain(scenario.vehicle_overrides)])
                if key not in checked:
                    if scenario.vehicle not in vehicles:
                        vehicles[scenario.vehicle] = load_vehicle(scenario.vehicle)
                    vehicles[scenario.vehicle].apply_overrides(
                        dict(scenario.vehicle_overrides), where="", prefix=("vehicle_overrides",)
                    )
                    if len(checked) < 100_000:
                        checked.add(key)
            except InputError as exc:
                message = str(exc).removeprefix(": ")
                raise InputError(
                    f"{self.where}: run {run_id} ({_short(inputs)}): {message}"
                ) from None
            if check is not None:
                check(run_id)

    # ---------------------------------------------------------- (de)serial
    def to_dict(self) -> dict[str, Any]:
        """The normalised sweep as plain data (what ``sweep.json`` stores)."""
        return {
            "base": self.base,
            "grid": self.grid,
            "runs": self.runs,
            "sample": self.sample,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], where: str = "sweep") -> SweepSpec:
        """Build a spec from :meth:`to_dict`'s output (or a sweep file's table)."""
        if not isinstance(data, Mapping):
            raise InputError(f"{where}: must be a table")
        unknown = set(data) - {"base", "grid", "runs", "sample"}
        if unknown:
            key = sorted(unknown)[0]
            close = difflib.get_close_matches(key, ["base", "grid", "runs", "sample"], n=1)
            hint = f"; did you mean {close[0]!r}?" if close else " (base, grid, runs, sample)"
            raise InputError(f"{where}: {key}: unknown key{hint}")
        return cls(
            base=data.get("base"),
            grid=data.get("grid"),
            runs=data.get("runs"),
            sample=data.get("sample"),
            where=where,
        )

    @classmethod
    def from_file(cls, path: str | os.PathLike[str]) -> SweepSpec:
        """Read a sweep TOML file (see :func:`load_sweep_file`)."""
        return load_sweep_file(path)

    def with_grid(self, grid: Mapping[str, Any]) -> SweepSpec:
        """A copy whose grid has these fields replaced or added (``--grid`` on a file)."""
        merged = dict(self.grid)
        merged.update(grid)
        return SweepSpec(self.base, merged, self.runs, self.sample, where=self.where)

    def varying_fields(self) -> list[str]:
        """Grid fields with more than one value."""
        return [k for k, v in self.grid.items() if len(v) > 1]

    def fingerprint(self) -> str:
        """SHA-256 of the normalised sweep (and of the sampled values, if any)."""
        h = hashlib.sha256(_canonical(self.to_dict()).encode())
        if self.sample is not None:
            h.update(_canonical(self._draws()).encode())
        return h.hexdigest()

    def __eq__(self, other: object) -> bool:
        return isinstance(other, SweepSpec) and _canonical(self.to_dict()) == _canonical(
            other.to_dict()
        )

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        mode = "runs" if self.runs else "sample" if self.sample else "grid"
        return f"SweepSpec({self.n_runs} runs, {mode}, grid={list(self.grid)})"


def load_sweep_file(path: str | os.PathLike[str]) -> SweepSpec:
    """Read a sweep TOML file: ``base`` (table or scenario path), ``grid``, ``runs``, ``sample``.

    A relative ``base`` path (and a relative ``vehicle`` path in the base) is
    looked up beside the sweep file.

    Raises
    ------
    InputError
        Missing file, TOML syntax error, unknown key, bad field or value.
    """
    path = Path(path)
    data = read_toml_file(path)
    base = data.get("base")
    if isinstance(base, str):
        candidate = Path(base)
        if not candidate.is_absolute():
            candidate = path.parent / candidate
        data["base"] = candidate
    elif isinstance(base, Mapping):
        data["base"] = locate_vehicle(base, path.parent)
    return SweepSpec.from_dict(data, where=str(path))


# ------------------------------------------------------------ the worker
def flatten_summary(summary: Mapping[str, Any], skip: Iterable[str] = ()) -> dict[str, Any]:
    """One ``runs.parquet`` row (without run_id and inputs) from a run's summary.

    Nested tables are joined with ``__``; lists become JSON text; wall-clock
    timings are dropped; keys outside :data:`SUMMARY_COLUMNS` go, as JSON, to
    ``summary_extra``; missing keys are null. Values take their column's type.
    """
    flat: dict[str, Any] = {}

    def walk(prefix: str, value: Any) -> None:
        if isinstance(value, Mapping):
            for k, v in value.items():
                walk(f"{prefix}__{k}" if prefix else str(k), v)
        else:
            flat[prefix] = value

    walk("", summary)
    skip = set(skip)
    row: dict[str, Any] = {}
    extra: dict[str, Any] = {}
    for key, value in flat.items():
        if _is_time_measurement(key) or key in skip:
            continue
        kind = _SUMMARY_KIND.get(key)
        if kind is None or key == "summary_extra":
            extra[key] = _plain(value)
            continue
        row[key] = _typed(value, kind)
    for key, _kind in SUMMARY_COLUMNS:
        if key not in skip:
            row.setdefault(key, None)
    row["summary_extra"] = _canonical(extra) if extra else None
    return row


def _typed(value: Any, kind: str) -> Any:
    if value is None:
        return None
    value = _plain(value)
    if kind == "f":
        return None if isinstance(value, float) and math.isnan(value) else float(value)
    if kind == "i":
        return int(value)
    if kind == "b":
        return bool(value)
    if kind == "s":
        return str(value)
    return json.dumps(value, separators=(",", ":"))


def _failed_row(reason: str, skip: Iterable[str]) -> dict[str, Any]:
    from quadimpact import __version__

    row = flatten_summary({}, skip)
    if "status" in row:
        row["status"] = "failed"
    if "reason" in row:
        row["reason"] = one_line(reason)
    if "quadimpact_version" in row:
        row["quadimpact_version"] = __version__
    return row


Item = tuple[int, dict[str, Any], dict[str, Any]]
"""A run to do: (run_id, scenario mapping, input column values)."""


def run_chunk(items: Sequence[Item]) -> list[dict[str, Any]]:
    """Run a chunk of a sweep; the same pure function on every backend.

    Parameters
    ----------
    items : sequence of (run_id, scenario mapping, input column values)
        What to run (see :meth:`SweepSpec.scenario_dict`, :meth:`SweepSpec.input_columns`).

    Returns
    -------
    list of dict
        One ``runs.parquet`` row per item. A run that raises (bad vehicle,
        approach shooting that fails...) is a row with ``status = "failed"``
        and ``reason = "<ExceptionType>: <message>"``; a run that fails in the
        integrator has the kernel's status and reason.
    """
    from quadimpact import simulate
    from quadimpact.inputs.scenarios import scenario_from_dict

    rows = []
    for run_id, scenario_data, inputs in items:
        head = {"run_id": int(run_id), **inputs}
        try:
            scenario = scenario_from_dict(scenario_data, where=f"run {run_id}")
            summary = simulate(scenario).summary
            row = flatten_summary(summary, skip=inputs)
        except Exception as exc:  # a failed run is a row; the sweep goes on
            row = _failed_row(f"{type(exc).__name__}: {exc}", inputs)
        rows.append({**head, **row})
    return rows


_WARM = False


def warm_up() -> None:
    """Import the simulator and load the compiled kernel (Numba's disk cache) in this process."""
    global _WARM
    if _WARM:
        return
    from quadimpact import simulate  # noqa: F401  (the simulator: pandas, analysis...)
    from quadimpact.inputs.scenarios import WallApproach
    from quadimpact.simulation.setup import prepare

    prepare(WallApproach(final_time_s=0.6, impact_time_s=0.1))  # runs the kernel
    _WARM = True


def _init_pool_worker() -> None:
    # Ctrl-C goes to the whole process group: the parent decides (it stops
    # submitting, saves what finished); workers just finish their chunk.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    with contextlib.suppress(Exception):
        warm_up()


def _worker_info() -> dict[str, Any]:
    from quadimpact import __version__

    return {"version": __version__, "python": sys.version.split()[0]}


# ---------------------------------------------------------------- storage
def _schema(spec: SweepSpec) -> Any:
    import pyarrow as pa

    types = {
        "f": pa.float64(),
        "i": pa.int64(),
        "b": pa.bool_(),
        "s": pa.string(),
        "j": pa.string(),
    }
    fields = [pa.field("run_id", pa.int64(), nullable=False)]
    fields += [pa.field(k, types[kind]) for k, kind in spec.columns.items()]
    fields += [pa.field(k, types[kind]) for k, kind in SUMMARY_COLUMNS if k not in spec.columns]
    meta = {
        "quadimpact.sweep": _canonical(
            {"inputs": list(spec.columns), "n_runs": spec.n_runs, "format": FORMAT_VERSION}
        )
    }
    return pa.schema(fields, metadata=meta)


def _to_pandas(table: Any) -> Any:
    import pandas as pd
    import pyarrow as pa

    mapping = {pa.int64(): pd.Int64Dtype(), pa.bool_(): pd.BooleanDtype()}
    df = table.to_pandas(types_mapper=mapping.get)
    # run_id is never null: a plain int64 column
    if "run_id" in df:
        df["run_id"] = df["run_id"].astype("int64")
    return df


def read_runs(out_dir: str | os.PathLike[str]) -> Any:
    """Read ``DIR/runs.parquet`` as a pandas DataFrame (nullable ints and bools).

    Integer columns are ``Int64`` and booleans ``boolean`` (so a failed run's
    nulls never change a column's type); floats are float64 (null as NaN);
    text is object (null as None).
    """
    import pyarrow.parquet as pq

    path = Path(out_dir) / "runs.parquet"
    if not path.is_file():
        raise InputError(f"{path}: file not found")
    return _to_pandas(pq.read_table(path))


class _PartWriter:
    """Buffers finished rows and writes them as atomic part files."""

    def __init__(self, parts: Path, schema: Any, start_seq: int) -> None:
        self.parts = parts
        self.schema = schema
        self.seq = start_seq
        self.buffer: list[dict[str, Any]] = []
        self.oldest = 0.0
        self.rows_written = 0

    def add(self, rows: list[dict[str, Any]]) -> None:
        """Buffer ``rows`` (may be empty: a clock tick) and write a part when due."""
        if rows:
            if not self.buffer:
                self.oldest = time.monotonic()
            self.buffer.extend(rows)
        if self.buffer and (
            len(self.buffer) >= FLUSH_ROWS or time.monotonic() - self.oldest >= FLUSH_SECONDS
        ):
            self.flush()

    def flush(self) -> None:
        if not self.buffer:
            return
        import pyarrow as pa
        import pyarrow.parquet as pq

        table = pa.Table.from_pylist(self.buffer, schema=self.schema).sort_by("run_id")
        self.seq += 1
        path = self.parts / f"part-{self.seq:06d}.parquet"
        atomic_write(path, lambda tmp: pq.write_table(table, tmp), durable=True)
        self.rows_written += len(self.buffer)
        self.buffer = []


_PART_RE = re.compile(r"^part-(\d+)\.parquet$")


def _scan_done(out: Path, n_runs: int, warn: Callable[[str], None]) -> tuple[Any, int]:
    """Mask of run_ids already written (runs.parquet and parts), and the last part number."""
    import numpy as np
    import pyarrow.parquet as pq

    done = np.zeros(n_runs, dtype=bool)
    parts = out / "parts"
    last = 0
    sources = []
    if (out / "runs.parquet").is_file():
        sources.append(out / "runs.parquet")
    if parts.is_dir():
        for p in sorted(parts.iterdir()):
            if p.name.startswith(".") and p.name.endswith(".tmp"):
                p.unlink(missing_ok=True)  # left by a kill mid-write
            elif m := _PART_RE.match(p.name):
                last = max(last, int(m.group(1)))
                sources.append(p)
    for src in sources:
        try:
            ids = pq.read_table(src, columns=["run_id"]).column("run_id").to_numpy()
        except Exception as exc:  # unreadable: redo its runs
            warn(f"{src}: unreadable ({one_line(str(exc))}); its runs will be redone")
            src.unlink(missing_ok=True)
            continue
        ids = ids[(ids >= 0) & (ids < n_runs)]
        done[ids] = True
    return done, last


def _consolidate(out: Path, schema: Any, n_runs: int) -> None:
    """Merge runs.parquet and the parts into runs.parquet, sorted, one window at a time."""
    import numpy as np
    import pyarrow as pa
    import pyarrow.parquet as pq

    parts_dir = out / "parts"
    parts = (
        sorted(p for p in parts_dir.iterdir() if _PART_RE.match(p.name))
        if parts_dir.is_dir()
        else []
    )
    target = out / "runs.parquet"
    if not parts and target.is_file():
        meta = pq.read_metadata(target)
        if meta.num_rows == n_runs and pq.read_schema(target).equals(schema, check_metadata=False):
            return
    sources = ([target] if target.is_file() else []) + parts
    spans = []
    for src in sources:
        ids = pq.read_table(src, columns=["run_id"]).column("run_id").to_numpy()
        if len(ids):
            spans.append((src, int(ids.min()), int(ids.max())))
    def merge(tmp: Path) -> None:
        total = 0
        with pq.ParquetWriter(tmp, schema) as writer:
            for lo in range(0, n_runs, CONSOLIDATE_WINDOW):
                hi = lo + CONSOLIDATE_WINDOW
                pieces = []
                for src, a, b in spans:
                    if b < lo or a >= hi:
                        continue
                    t = pq.read_table(src, filters=[("run_id", ">=", lo), ("run_id", "<", hi)])
                    pieces.append(t.select(schema.names).cast(schema))
                if not pieces:
                    continue
                t = pa.concat_tables(pieces).sort_by("run_id")
                ids = t.column("run_id").to_numpy()
                keep = np.ones(len(ids), dtype=bool)
                keep[1:] = ids[1:] != ids[:-1]
                if not keep.all():
                    t = t.filter(pa.array(keep))
                total += t.num_rows
                writer.write_table(t, row_group_size=CONSOLIDATE_WINDOW)
        if total != n_runs:
            raise RuntimeError(f"{out}: merged {total} runs, expected {n_runs}")

    atomic_write(target, merge, durable=True)
    for p in parts:
        p.unlink(missing_ok=True)


def _check_folder(out: Path, spec: SweepSpec, schema: Any) -> None:
    """Write sweep.json, or check that the folder holds this very sweep."""
    from quadimpact import __version__

    record = {
        "format": FORMAT_VERSION,
        "quadimpact_version": __version__,
        "n_runs": spec.n_runs,
        "fingerprint": spec.fingerprint(),
        "columns": [[f.name, str(f.type)] for f in schema],
        "spec": spec.to_dict(),
    }
    path = out / "sweep.json"
    if path.is_file():
        try:
            old = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            raise InputError(
                f"{path}: unreadable ({exc}); delete the folder to start over"
            ) from None
        if old != json.loads(_canonical(record)):
            differs = [
                k
                for k in ("spec", "quadimpact_version", "n_runs", "columns", "fingerprint")
                if old.get(k) != json.loads(_canonical(record)).get(k)
            ]
            detail = differs[0] if differs else "format"
            if detail == "spec":
                keys = [
                    k
                    for k in ("base", "grid", "runs", "sample")
                    if (old.get("spec") or {}).get(k) != json.loads(_canonical(spec.to_dict()))[k]
                ]
                detail = "its " + ", ".join(keys or ["spec"])
            raise InputError(
                f"{out}: holds a different sweep ({detail} differs, see sweep.json); "
                "use another output folder, or delete this one to start over"
            )
        return
    if (out / "runs.parquet").exists() or any((out / "parts").glob("part-*.parquet")):
        raise InputError(f"{out}: has sweep results but no sweep.json; use another output folder")
    text = json.dumps(record, indent=1, sort_keys=True, allow_nan=False) + "\n"
    atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8"), durable=True)


@contextlib.contextmanager
def _folder_lock(out: Path) -> Iterator[None]:
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock
        yield
        return
    fd = os.open(out / ".lock", os.O_RDWR | os.O_CREAT, 0o644)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise InputError(f"{out}: another sweep is writing to this folder") from None
        yield
    finally:
        os.close(fd)


# --------------------------------------------------------------- progress
class Progress:
    """Runs done / total, rate and time left, on stderr.

    On a terminal one line is redrawn in place (at most 10 times a second);
    otherwise at most five lines are printed (start, 25/50/75 % and the end).
    """

    def __init__(self, total: int, done: int = 0, enabled: bool = True, stream: Any = None):
        self.stream = stream if stream is not None else sys.stderr
        self.total, self.done, self.start_done = total, done, done
        self.enabled = enabled and total > done
        isatty = getattr(self.stream, "isatty", None)
        self.tty = bool(isatty and isatty())
        self.t0 = time.monotonic()
        self.last = 0.0
        self.next_mark = 1
        self.drawn = -1
        if self.enabled and self.tty:
            self._draw()
        if self.enabled and not self.tty:
            resumed = f", {done} already done" if done else ""
            todo = total - done
            self._print(f"sweep: {todo} run{'s' if todo != 1 else ''} to do{resumed}\n")

    def _print(self, text: str) -> None:
        with contextlib.suppress(Exception):
            self.stream.write(text)
            self.stream.flush()

    def _line(self) -> str:
        elapsed = time.monotonic() - self.t0
        ran = self.done - self.start_done
        rate = ran / elapsed if elapsed > 0 else 0.0
        left = (self.total - self.done) / rate if rate > 0 else math.nan
        eta = "--:--" if math.isnan(left) else _clock(left)
        pct = 100.0 * self.done / self.total if self.total else 100.0
        return (
            f"sweep {self.done}/{self.total} runs ({pct:3.0f}%)  {rate:6.1f} runs/s  "
            f"elapsed {_clock(elapsed)}  left {eta}"
        )

    def update(self, n: int) -> None:
        self.done += n
        if not self.enabled:
            return
        now = time.monotonic()
        if self.tty:
            if now - self.last >= 0.1 or self.done >= self.total:
                self.last = now
                self._draw()
        else:
            while self.next_mark <= 3 and self.done * 4 >= self.next_mark * self.total:
                self.next_mark += 1
                if self.done < self.total:
                    self._print(self._line() + "\n")

    def _draw(self) -> None:
        self.drawn = self.done
        self._print("\r" + self._line() + "\x1b[K")

    def close(self) -> None:
        if not self.enabled:
            return
        if not self.tty:
            self._print(self._line() + "\n")
        elif self.drawn == self.done:
            self._print("\n")
        else:
            self._print("\r" + self._line() + "\x1b[K\n")
        self.enabled = False


def _clock(seconds: float) -> str:
    s = int(round(seconds))
    h, rem = divmod(s, 3600)
    m, s = divmod(rem, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


# --------------------------------------------------------------- backends
def _chunks(spec: SweepSpec, todo: Any, size: int) -> Iterator[list[Item]]:
    """Items of the missing runs, ``size`` per chunk, built lazily (flat memory)."""
    chunk: list[Item] = []
    for run_id in todo:
        run_id = int(run_id)
        inputs = spec.inputs(run_id)
        chunk.append((run_id, spec.scenario_dict(run_id, inputs), spec.input_columns(inputs)))
        if len(chunk) == size:
            yield chunk
            chunk = []
    if chunk:
        yield chunk


def _chunk_size(n_todo: int, slots: int) -> int:
    # ~5-10 ms per run: chunks of up to 32 runs keep the per-task overhead
    # (pickling, IPC) small, and about 8 chunks per worker keep them balanced.
    return max(1, min(32, math.ceil(n_todo / (8 * max(1, slots)))))


def _run_serial(chunks: Iterator[list[Item]], sink: Callable[[list[dict]], None]) -> None:
    for chunk in chunks:
        sink(run_chunk(chunk))


def _pool_context() -> Any:
    """Start method of the local worker pool.

    ``forkserver``: workers are forked from a clean single-threaded server
    process started once per parent (not from the parent, which may hold
    pyarrow, Dask or matplotlib threads and locks that ``fork`` would copy in
    a held state), and that server imports :mod:`quadimpact._sweep_preload`
    first, which loads the simulator and the compiled kernel; so every pool
    after the first starts in milliseconds with the kernel ready (``spawn``
    would pay ~1 s of imports and cache loading per worker, per pool).
    ``spawn`` where forkserver does not exist.
    """
    import multiprocessing as mp

    if "forkserver" in mp.get_all_start_methods():
        ctx = mp.get_context("forkserver")
        ctx.set_forkserver_preload(["quadimpact._sweep_preload"])
        return ctx
    return mp.get_context("spawn")


def _run_pool(
    chunks: Iterator[list[Item]], workers: int, sink: Callable[[list[dict]], None]
) -> None:
    """Run the chunks on a local process pool, at most 3 chunks per worker in flight.

    If a worker dies (a crash in native code, the OOM killer...), the pool is
    broken: its unfinished chunks are redone one run at a time in a new pool,
    and a run that kills a worker on its own is recorded as failed. If
    workers die before finishing anything and a bare worker cannot start
    either, the environment is at fault: RuntimeError.
    """
    ctx = _pool_context()
    retry: deque[list[Item]] = deque()
    source = iter(chunks)
    while True:
        lost, completed = _pool_pass(ctx, workers, source, retry, sink)
        if lost is None:
            return
        if completed == 0 and not _pool_starts(ctx):
            raise RuntimeError(
                "sweep worker processes die at start-up (see the messages above); a script "
                "that runs a sweep must guard its top level with `if __name__ == "
                '"__main__":`, and code read from stdin cannot start workers (use workers=1)'
            )
        for chunk in lost:
            if isinstance(chunk, _Isolated):
                run_id, _data, inputs = chunk[0]
                reason = "worker process died while running it (crash in native code?)"
                sink([{"run_id": run_id, **inputs, **_failed_row(reason, inputs)}])
            else:
                retry.extend(_Isolated([item]) for item in chunk)


def _pool_pass(
    ctx: Any,
    workers: int,
    source: Iterator[list[Item]],
    retry: deque[list[Item]],
    sink: Callable[[list[dict]], None],
) -> tuple[list[list[Item]] | None, int]:
    """One pool, until the work is done (None) or the pool breaks (its unfinished chunks)."""
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool

    executor = ProcessPoolExecutor(workers, mp_context=ctx, initializer=_init_pool_worker)
    pending: dict[Any, list[Item]] = {}
    completed = 0
    clean = False
    try:
        while True:
            # runs redone after a crash go one at a time, so that a crash names its run
            while len(pending) < (1 if retry or _has_isolated(pending) else 3 * workers):
                chunk = retry.popleft() if retry else next(source, None)
                if chunk is None:
                    break
                try:
                    pending[executor.submit(run_chunk, chunk)] = chunk
                except BrokenProcessPool:
                    return [chunk, *pending.values()], completed
            if not pending:
                clean = True
                return None, completed
            done, _ = wait(list(pending), timeout=FLUSH_SECONDS / 2, return_when=FIRST_COMPLETED)
            if not done:
                sink([])  # no run finished for a while: write what is waiting
            for fut in done:
                try:
                    rows = fut.result()
                except BrokenProcessPool:
                    return list(pending.values()), completed
                del pending[fut]
                sink(rows)
                completed += 1
    finally:
        for fut in pending:
            fut.cancel()
        executor.shutdown(wait=clean, cancel_futures=True)


def _pool_starts(ctx: Any) -> bool:
    """Whether a one-worker pool can start and run a trivial task."""
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    with ProcessPoolExecutor(1, mp_context=ctx, initializer=_init_pool_worker) as executor:
        try:
            executor.submit(_worker_info).result(timeout=300)
        except BrokenProcessPool:
            return False
    return True


class _Isolated(list):
    """A one-run chunk resubmitted after a worker died."""


def _has_isolated(pending: Mapping[Any, list[Item]]) -> bool:
    return any(isinstance(chunk, _Isolated) for chunk in pending.values())


@contextlib.contextmanager
def _dask_session(scheduler: Any) -> Iterator[tuple[Any, int]]:
    """Connect to the scheduler (or use the given client) and check its workers.

    Yields (client, total worker threads). A client made here is closed at the end.
    """
    try:
        from dask.distributed import Client
    except ImportError:
        raise InputError(
            "--scheduler needs Dask's distributed scheduler: pip install 'quadimpact[distributed]'"
        ) from None
    from quadimpact import __version__

    own = not isinstance(scheduler, Client)
    if own:
        if not isinstance(scheduler, str) or not re.match(r"^[a-z][a-z0-9+.-]*://\S+$", scheduler):
            raise InputError(
                "--scheduler: must be an address like tcp://HOST:PORT "
                f"(got {format_value(scheduler)})"
            )
        try:
            client = Client(scheduler, timeout="20s", set_as_default=False)
        except (OSError, TimeoutError) as exc:
            raise InputError(
                f"--scheduler {scheduler}: cannot connect to the Dask scheduler "
                f"({one_line(str(exc))})"
            ) from None
    else:
        client = scheduler
    try:
        try:
            client.wait_for_workers(1, timeout=60)
        except TimeoutError:
            raise InputError(f"--scheduler {scheduler}: no Dask worker connected") from None
        try:
            infos = client.run(_worker_info)
        except Exception as exc:
            raise InputError(
                f"Dask workers cannot run quadimpact ({type(exc).__name__}: "
                f"{one_line(str(exc))}); install it in the workers' environment"
            ) from None
        bad = {w: i["version"] for w, i in infos.items() if i["version"] != __version__}
        if bad:
            worker, version = next(iter(bad.items()))
            raise InputError(
                f"Dask worker {worker} runs quadimpact {version}, this is {__version__}: "
                "the table would not be reproducible"
            )
        yield client, sum(client.nthreads().values()) or 1
    finally:
        if own:
            client.close()


def _run_dask(
    client: Any, threads: int, chunks: Iterator[list[Item]], sink: Callable[[list[dict]], None]
) -> None:
    """Submit the chunks (at most 3 per worker thread in flight), write them as they complete."""
    from dask.distributed import as_completed

    max_pending = 3 * threads
    queue = as_completed(loop=client.loop)
    pending: dict[Any, list[Item]] = {}

    def submit_more() -> None:
        while len(pending) < max_pending:
            chunk = next(chunks, None)
            if chunk is None:
                return
            fut = client.submit(run_chunk, chunk, pure=False)
            pending[fut] = chunk
            queue.add(fut)

    submit_more()
    try:
        for fut in queue:
            chunk = pending.pop(fut)
            try:
                rows = fut.result()
            except Exception as exc:  # worker lost too often (KilledWorker...)
                reason = f"Dask task failed: {type(exc).__name__}: {one_line(str(exc))}"
                rows = [
                    {"run_id": rid, **inp, **_failed_row(reason, inp)} for rid, _d, inp in chunk
                ]
            fut.release()
            sink(rows)
            submit_more()
    except BaseException:
        client.cancel(list(pending))
        raise


# --------------------------------------------------------------- run_sweep
def _resolve_workers(workers: int | None) -> int:
    if workers is None:
        return os.cpu_count() or 1
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InputError(f"--workers: must be an integer >= 1 (got {format_value(workers)})")
    return workers


def run_sweep(
    spec: SweepSpec | Mapping[str, Any],
    out_dir: str | os.PathLike[str],
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    *,
    load: bool = True,
) -> Any:
    """Run a sweep into ``out_dir`` (resuming whatever is already there) and return its table.

    Parameters
    ----------
    spec : SweepSpec or mapping
        The sweep (a mapping is passed to :meth:`SweepSpec.from_dict`).
    out_dir : path-like
        Output folder (created): ``runs.parquet``, ``sweep.json``, ``parts/``.
        If it holds an unfinished run of the same sweep, only the missing runs
        are done; a different sweep there is refused.
    workers : int, optional
        Local processes; default all cores (``os.cpu_count()``); 1 runs in
        this process.
    scheduler : str or dask.distributed.Client, optional
        Address of a running Dask scheduler (``"tcp://host:port"``), or a
        client: the runs go to its workers instead (``workers`` must then be
        left out). Needs ``pip install 'quadimpact[distributed]'``.
    progress : bool
        Progress on stderr (a live line on a terminal, a few lines otherwise).
    load : bool, keyword
        Return the table (default); ``False`` returns only the run information
        dict below (for very large sweeps: read columns of ``runs.parquet`` as
        needed).

    Returns
    -------
    pandas.DataFrame or dict
        ``runs.parquet`` (see :func:`read_runs`), sorted by ``run_id``;
        ``table.attrs["sweep"]`` holds ``n_runs``, ``n_already_done``,
        ``n_ran``, ``elapsed_s``, ``backend``, ``out_dir``.

    Raises
    ------
    InputError
        A bad sweep (before anything runs), a folder holding another sweep,
        a bad ``workers``/``scheduler``.
    """
    start = time.perf_counter()
    if not isinstance(spec, SweepSpec):
        spec = SweepSpec.from_dict(spec)
    if scheduler is not None and workers is not None:
        raise InputError("give workers or scheduler, not both")
    n_workers = 1 if scheduler is not None else _resolve_workers(workers)
    spec.validate()
    schema = _schema(spec)

    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InputError(f"{out}: not a folder")

    def warn(message: str) -> None:
        print(f"quadimpact: warning: {message}", file=sys.stderr)

    with contextlib.ExitStack() as stack:
        client, threads = (
            stack.enter_context(_dask_session(scheduler)) if scheduler is not None else (None, 0)
        )
        (out / "parts").mkdir(parents=True, exist_ok=True)
        stack.enter_context(_folder_lock(out))
        _check_folder(out, spec, schema)
        done, last_part = _scan_done(out, spec.n_runs, warn)
        n_before = int(done.sum())
        todo = (i for i in range(spec.n_runs) if not done[i])
        n_todo = spec.n_runs - n_before
        backend = "none"
        if n_todo:
            writer = _PartWriter(out / "parts", schema, last_part)
            bar = Progress(spec.n_runs, n_before, enabled=progress)

            def sink(rows: list[dict[str, Any]]) -> None:
                writer.add(rows)
                if rows:
                    bar.update(len(rows))

            try:
                if client is not None:
                    backend = f"dask, {threads} threads"
                    chunks = _chunks(spec, todo, _chunk_size(n_todo, threads))
                    _run_dask(client, threads, chunks, sink)
                elif n_workers == 1 or n_todo == 1:
                    backend = "serial"
                    _run_serial(_chunks(spec, todo, 16), sink)
                else:
                    n_workers = min(n_workers, n_todo)
                    backend = f"{n_workers} processes"
                    _run_pool(_chunks(spec, todo, _chunk_size(n_todo, n_workers)), n_workers, sink)
            finally:
                writer.flush()  # also on Ctrl-C: keep every finished run
                bar.close()
        _consolidate(out, schema, spec.n_runs)

    info = {
        "n_runs": spec.n_runs,
        "n_already_done": n_before,
        "n_ran": spec.n_runs - n_before,
        "elapsed_s": time.perf_counter() - start,
        "backend": backend,
        "out_dir": str(out),
    }
    if not load:
        return info
    table = read_runs(out)
    table.attrs["sweep"] = info
    return table
