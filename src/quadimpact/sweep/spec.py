"""A sweep's definition: :class:`SweepSpec` and sweep files (the swept values' parsing and
canonical forms: :mod:`quadimpact.sweep.values`)."""

from __future__ import annotations

import difflib
import hashlib
import math
import os
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

from quadimpact.errors import InputError, format_value, short_path
from quadimpact.inputs.toml_files import apply_overrides, locate_vehicle, read_toml_file
from quadimpact.sweep.items import SweepBase
from quadimpact.sweep.values import (
    MAX_RUNS,
    canonical,
    column_kind,
    column_value,
    first_duplicate,
    is_number,
    parse_values,
    plain,
)

#: A sweep with ``trials`` validates this many trials at each grid point, and their bounds.
TRIALS_CHECKED = 64


def _short(inputs: Mapping[str, Any]) -> str:
    return ", ".join(f"{k}={format_value(v)}" for k, v in inputs.items())


class SweepSpec:
    """A sweep: a base scenario and the runs made from it (see :mod:`quadimpact.sweep`).

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
    trials : mapping, optional
        ``{"n": int, "seed": int (default 0), "ranges": {field: [low, high]},
        "seed_field": str (optional)}``: ``n`` random trials, trial ``i``
        drawn from a random stream of its own (``(seed, i)``,
        :mod:`quadimpact.sweep.trials`), when it is needed: memory stays
        flat in ``n``. ``seed_field`` (e.g. ``"seed"``, a run's own seed)
        gets an integer in ``[0, 2**53)``.
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
        trials: Mapping[str, Any] | None = None,
        *,
        where: str = "sweep",
    ) -> None:
        self.where = where
        self.base = self._read_base(base)
        self._read_kind()
        self.grid: dict[str, list[Any]] = self._read_grid(grid)
        if sum(x is not None for x in (runs, sample, trials)) > 1:
            raise InputError(f"{where}: give one of runs, sample and trials, not two")
        self.runs: list[dict[str, Any]] | None = None if runs is None else self._read_runs(runs)
        self.sample: dict[str, Any] | None = None
        if sample is not None:
            self.sample = self._read_sample(sample)
        self.trials: dict[str, Any] | None = None
        if trials is not None:
            self.trials = self._read_trials(trials)
        if not self.grid and not self.runs and self.sample is None and self.trials is None:
            raise InputError(f"{where}: empty sweep: give a grid, runs, a sample or trials")
        self.columns: dict[str, str] = self._column_kinds()
        self._numbers_as_floats()
        self._sizes = [len(v) for v in self.grid.values()]
        self._inner = self._entries_per_point()
        n = math.prod(self._sizes) * self._inner
        if n > MAX_RUNS:
            raise InputError(f"{where}: {n} runs, more than {MAX_RUNS}")
        self.n_runs = n
        self._drawn: dict[str, list[Any]] | None = None
        self._derive = False  # set by validate(): runs copied from the validated base

    def _read_kind(self) -> None:
        """The base's scenario kind (default a wall approach; another refused) and the
        fields a sweep may vary: that kind's scenario fields and the vehicle's others."""
        from quadimpact.inputs.scenarios import _KINDS
        from quadimpact.inputs.vehicle import Vehicle

        kind = self.base.get("kind", "wall-approach")
        if not isinstance(kind, str) or kind not in _KINDS:
            known = ", ".join(repr(k) for k in _KINDS)
            raise InputError(
                f"{self.where}: base: kind: must be one of {known} (got {format_value(kind)})"
            )
        self._scenario_fields = [f for f in _KINDS[kind].model_fields if f != "kind"]
        self._vehicle_fields = [f for f in Vehicle.model_fields if f not in self._scenario_fields]
        self._kind_name = kind

    def _read_grid(self, grid: Any) -> dict[str, list[Any]]:
        """The grid's fields (each checked) and their values (:meth:`_grid_values`); empty
        without a grid."""
        read: dict[str, list[Any]] = {}
        if grid is not None:
            if not isinstance(grid, Mapping):
                raise InputError(f"{self.where}: grid: must be a table of field = values")
            for name, values in grid.items():
                self._check_field(str(name), "grid")
                read[str(name)] = self._grid_values(str(name), values)
        return read

    def _column_kinds(self) -> dict[str, str]:
        """The input columns, in order, and their kinds (:func:`column_kind` of the values
        each takes in the grid, the runs and a sample's choices; a drawn field's are
        numbers, a trial's seed too: exact below 2**53). A field both in the grid and in the
        runs, sample or trials is refused."""
        fields: dict[str, list[Any]] = {k: list(v) for k, v in self.grid.items()}
        for entry in self.runs or []:
            for k, v in entry.items():
                fields.setdefault(k, []).append(v)
        if self.sample is not None:
            for k in self.sample["ranges"]:
                fields[k] = [0.0]
            for k, v in self.sample["choices"].items():
                fields[k] = list(v)
        if self.trials is not None:
            for k in self._trial_fields():
                fields[k] = [0.0]  # drawn numbers (a seed too: exact below 2**53)
        inner = {k for e in self.runs or [] for k in e}
        if self.sample is not None:
            inner |= set(self.sample["ranges"]) | set(self.sample["choices"])
        if self.trials is not None:
            inner |= set(self._trial_fields())
        for k in self.grid:
            if k in inner:
                raise InputError(
                    f"{self.where}: {k}: swept both in the grid and in runs, sample or trials"
                )
        return {k: column_kind(v) for k, v in fields.items()}

    def _numbers_as_floats(self) -> None:
        """The numbers of the grid, the runs and a sample's choices as floats, in the
        columns of numbers (one type per column, so that equal sweeps compare equal)."""
        for k, values in self.grid.items():
            if self.columns[k] == "f":
                self.grid[k] = list(map(float, values))
        for entry in self.runs or []:
            for k, v in entry.items():
                if self.columns[k] == "f":
                    entry[k] = float(v)
        if self.sample is not None:
            for k, values in self.sample["choices"].items():
                if self.columns[k] == "f":
                    self.sample["choices"][k] = [float(v) for v in values]

    def _entries_per_point(self) -> int:
        """Runs per grid point: the runs listed, the sample's or the trials' ``n``, else 1."""
        if self.runs:
            return len(self.runs)
        if self.sample:
            return self.sample["n"]
        if self.trials:
            return self.trials["n"]
        return 1

    # ------------------------------------------------------------ reading
    def _read_base(self, base: Any) -> dict[str, Any]:
        if base is None:
            return {}
        if isinstance(base, (str, os.PathLike)):
            path = Path(base)  # "study.toml: base: scenario.toml: file not found"
            where = f"{self.where}: base: {short_path(path)}"
            return plain(locate_vehicle(read_toml_file(path, where), path.parent))
        if not isinstance(base, Mapping):
            raise InputError(f"{self.where}: base: must be a table of scenario fields or a path")
        return plain(dict(base))

    def _check_field(self, name: str, section: str) -> None:
        if name in self._scenario_fields or name in self._vehicle_fields:
            return
        if "." in name and name.split(".")[0] in self._scenario_fields:
            return  # a field of a table (instruments.barometer.noise_m): checked by validation
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
            out = plain(list(values))
        else:
            out = [plain(values)]
        if not out:
            raise InputError(f"{where}: no values")
        self._check_values(where, out)
        twice = first_duplicate(out)
        if twice is not None:
            raise InputError(f"{where}: value {format_value(twice)} is listed twice")
        return out

    @staticmethod
    def _check_values(where: str, values: Sequence[Any]) -> None:
        if set(map(type, values)) <= {int, str, bool}:
            return  # neither None nor a float (the fast path for long ranges)
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
            entry = plain(dict(entry))
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
        for key in ("ranges", "choices"):
            if not isinstance(sample.get(key) or {}, Mapping):
                raise InputError(f"{w}.{key}: must be a table of field = values "
                                 f"(got {format_value(sample[key])})")  # fmt: skip
        ranges: dict[str, list[float]] = {}
        for name, bounds in dict(sample.get("ranges") or {}).items():
            self._check_field(name, "sample.ranges")
            b = plain(bounds)
            if (
                not isinstance(b, list)
                or len(b) != 2
                or not all(is_number(x) and math.isfinite(x) for x in b)
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
            v = plain(values)
            if not isinstance(v, list) or not v:
                raise InputError(f"{w}.choices: {name}: must be a non-empty list of values")
            self._check_values(f"{w}.choices: {name}", v)
            if name in ranges:
                raise InputError(f"{w}: {name}: both in ranges and choices")
            choices[name] = v
        if not ranges and not choices:
            raise InputError(f"{w}: give ranges and/or choices to draw from")
        return {"n": n, "seed": seed, "ranges": ranges, "choices": choices}

    def _read_trials(self, trials: Any) -> dict[str, Any]:
        w = f"{self.where}: trials"
        if not isinstance(trials, Mapping):
            raise InputError(f"{w}: must be a table with n, seed, ranges and seed_field")
        unknown = set(trials) - {"n", "seed", "ranges", "seed_field"}
        if unknown:
            key = sorted(unknown)[0]
            raise InputError(f"{w}: {key}: unknown key (n, seed, ranges, seed_field)")
        probe = self._read_sample({"n": trials.get("n"), "seed": trials.get("seed", 0),
                                   "ranges": trials.get("ranges") or {}})  # fmt: skip
        seed_field = trials.get("seed_field")
        if seed_field is not None:
            if not isinstance(seed_field, str) or not seed_field:
                got = format_value(seed_field)
                raise InputError(f"{w}: seed_field: must be a field name (got {got})")
            self._check_field(seed_field, "trials.seed_field")
            if seed_field in probe["ranges"]:
                raise InputError(f"{w}: {seed_field}: both in ranges and seed_field")
        return {"n": probe["n"], "seed": probe["seed"], "ranges": probe["ranges"],
                "seed_field": seed_field}  # fmt: skip

    def _trial_fields(self) -> list[str]:
        assert self.trials is not None
        extra = [self.trials["seed_field"]] if self.trials["seed_field"] else []
        return [*self.trials["ranges"], *extra]

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
        elif self.trials is not None:
            values.update(self._trial(j))
        return values

    def _trial(self, j: int) -> dict[str, Any]:
        """Trial ``j``'s drawn values, numbers as the sweep stores them (floats)."""
        from quadimpact.sweep.trials import trial_draws

        t = self.trials
        assert t is not None
        drawn = trial_draws(t["seed"], j, t["ranges"], t["seed_field"])
        return {k: float(v) for k, v in drawn.items()}

    def scenario_dict(self, run_id: int, inputs: Mapping[str, Any] | None = None) -> dict[str, Any]:
        """The scenario mapping of run ``run_id`` (base + swept values)."""
        if inputs is None:
            inputs = self.inputs(run_id)
        return apply_overrides(self.base, inputs, self._vehicle_fields)

    def input_columns(self, inputs: Mapping[str, Any]) -> dict[str, Any]:
        """Row values of the input columns for one run's inputs."""
        return {k: column_value(inputs.get(k), kind) for k, kind in self.columns.items()}

    def validate(
        self, check: Callable[[int], None] | None = None, *, max_record_mb: float | None = None
    ) -> None:
        """Build and validate every run's scenario and vehicle (raises the first problem).

        A sweep with ``trials`` checks, at every grid point, its first
        :data:`TRIALS_CHECKED` trials and the bounds of its ranges
        (:func:`quadimpact.sweep.trials.trial_corners`: every trial's values lie
        within them), not each of possibly millions of trials; a trial that
        still fails becomes a failed row, with its reason, when it runs.

        Parameters
        ----------
        check : callable, optional
            Called with each run_id after it validated (progress hooks).
        max_record_mb : float, optional
            Largest raw record of a run, MB (``simulation.checks.check_record_size``;
            default its ``MAX_RECORD_MB``).

        Raises
        ------
        InputError
            ``<where>: run <i> (<swept values>): <field>: <rule> (got <value>)``.
        """
        from quadimpact.inputs.derive import ScenarioFactory, same_scenario
        from quadimpact.inputs.scenarios import scenario_from_dict
        from quadimpact.inputs.vehicle import load_vehicle
        from quadimpact.simulation.checks import (
            MAX_RECORD_MB,
            check_record_size,
            vehicle_feature_count,
        )

        limit = MAX_RECORD_MB if max_record_mb is None else float(max_record_mb)
        base = scenario_from_dict(self.base, where=f"{self.where}: base")
        base.build_vehicle(where=f"{self.where}: base")
        factory = ScenarioFactory(self.base, self._vehicle_fields)
        derive = factory.derives(self.columns)
        swept = [k for k in self.columns if k not in self._vehicle_fields]
        vehicles: dict[str, Any] = {}
        checked: set[str] = set()
        n_features: dict[str, int] = {}  # per vehicle and overrides (built once, not per run)
        self._derive = False
        for run_id, inputs in self._checked_runs():
            try:
                scenario = scenario_from_dict(self.scenario_dict(run_id, inputs), where="")
                if derive:  # the workers may copy this run from the base: is it the same?
                    derive = same_scenario(factory.scenario(inputs), scenario, swept)
                key = canonical([scenario.vehicle, plain(scenario.vehicle_overrides)])
                count = n_features.get(key)
                if count is None:
                    count = vehicle_feature_count(scenario)
                    if len(n_features) < 100_000:
                        n_features[key] = count
                check_record_size(scenario, limit, "--max-record-mb", n_features=count)
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
                which = f"run {run_id}" if run_id >= 0 else "the bounds of its trials"
                raise InputError(f"{self.where}: {which} ({_short(inputs)}): {message}") from None
            if check is not None and run_id >= 0:
                check(run_id)
        self._derive = derive

    def _checked_runs(self) -> Iterator[tuple[int, dict[str, Any]]]:
        """``(run_id, inputs)`` of the runs :meth:`validate` checks (``-1``: a bound of trials)."""
        if self.trials is None:
            for run_id in range(self.n_runs):
                yield run_id, self.inputs(run_id)
            return
        from quadimpact.sweep.trials import trial_corners

        first = min(self.trials["n"], TRIALS_CHECKED)
        corners = list(trial_corners(self.trials["ranges"], self.trials["seed_field"]))
        for point in range(self.n_runs // self._inner):
            for j in range(first):
                run_id = point * self._inner + j
                yield run_id, self.inputs(run_id)
            at_point = self.inputs(point * self._inner)
            for corner in corners:
                yield -1, {**at_point, **{k: float(v) for k, v in corner.items()}}

    def sweep_base(self) -> SweepBase:
        """What every run shares, for the workers (``sweep.items``).

        Its runs are copied from the validated base in the workers only after
        :meth:`validate` found every copy equal to the validated run.
        """
        return SweepBase(
            self.base, tuple(self._vehicle_fields), canonical(self.base), bool(self._derive)
        )

    # ---------------------------------------------------------- (de)serial
    def to_dict(self) -> dict[str, Any]:
        """The normalised sweep as plain data (what ``sweep.json`` stores)."""
        return {
            "base": self.base,
            "grid": self.grid,
            "runs": self.runs,
            "sample": self.sample,
            **({"trials": self.trials} if self.trials is not None else {}),
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], where: str = "sweep") -> SweepSpec:
        """Build a spec from :meth:`to_dict`'s output (or a sweep file's table)."""
        if not isinstance(data, Mapping):
            raise InputError(f"{where}: must be a table")
        keys = ["base", "grid", "runs", "sample", "trials"]
        unknown = set(data) - set(keys)
        if unknown:
            key = sorted(unknown)[0]
            close = difflib.get_close_matches(key, keys, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else f" ({', '.join(keys)})"
            raise InputError(f"{where}: {key}: unknown key{hint}")
        return cls(
            base=data.get("base"),
            grid=data.get("grid"),
            runs=data.get("runs"),
            sample=data.get("sample"),
            trials=data.get("trials"),
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
        return SweepSpec(self.base, merged, self.runs, self.sample, self.trials, where=self.where)

    def varying_fields(self) -> list[str]:
        """Grid fields with more than one value."""
        return [k for k, v in self.grid.items() if len(v) > 1]

    def fingerprint(self) -> str:
        """SHA-256 of the normalised sweep (and of the sampled values, if any)."""
        h = hashlib.sha256(canonical(self.to_dict()).encode())
        if self.sample is not None:
            h.update(canonical(self._draws()).encode())
        return h.hexdigest()

    def __eq__(self, other: object) -> bool:
        return isinstance(other, SweepSpec) and canonical(self.to_dict()) == canonical(
            other.to_dict()
        )

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        modes = {"runs": self.runs, "sample": self.sample, "trials": self.trials}
        mode = next((name for name, given in modes.items() if given), "grid")
        return f"SweepSpec({self.n_runs} runs, {mode}, grid={list(self.grid)})"


def load_sweep_file(path: str | os.PathLike[str]) -> SweepSpec:
    """Read a sweep TOML file: ``base`` (table or scenario path), ``grid``, and ``runs``,
    ``sample`` or ``trials``.

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
