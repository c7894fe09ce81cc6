"""The benchmark: its spec, its run over every row, task and sensor set, and its tables.

:class:`BenchmarkStudy` is the thing benchmarked (a
:class:`~quadimpact.studies.benchmark.subject.Subject`), the suite's tasks it
flies (all, or those asked for), full or ``quick``, and whether the reference
rows run beside it. :func:`run_benchmark` claims the folder (``study.json``
first: the same command resumes, another is refused), then for every row,
task and sensor set (a cell, :mod:`~quadimpact.studies.benchmark.cells`):

* reads its trials table from the cache when its row flies only built-in
  code and the cache holds it (same suite, same quadimpact, same sweep), else
* runs its sweep in ``DIR/cells/<row>/<task>-<sensors>/`` (resumable, on the
  local pool or a Dask cluster like any sweep) and keeps its table in the cache;

and writes, in ``DIR``:

* ``cells/<row>/<task>-<sensors>.parquet``: every cell's trials table;
* ``benchmark.csv`` and ``benchmark.parquet``: one line per row, task and
  sensor set with every number (:func:`~quadimpact.studies.benchmark.cells.cell_numbers`),
  the row's description and the suite's version; the authors' published
  figures as lines of their own (``source = "published"``, with where);
* ``report.md`` and ``leaderboard.png``
  (:mod:`~quadimpact.studies.benchmark.benchmark_report`).
"""

from __future__ import annotations

import json
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from quadimpact import __version__
from quadimpact.errors import InputError
from quadimpact.results.files import atomic_write
from quadimpact.studies.benchmark import plugin_guard as guard
from quadimpact.studies.benchmark.cells import (
    CellCache,
    cell_key,
    cell_numbers,
    cell_table,
    code_digest,
)
from quadimpact.studies.benchmark.subject import PUBLISHED, REFERENCES, Subject
from quadimpact.studies.benchmark.suite import (
    SUITE_VERSION,
    TASKS,
    Suite,
    parse_sensor_sets,
    sensor_set,
    suite,
)
from quadimpact.studies.study_folder import StudyFolder, describe_run

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["BENCHMARK_CSV", "BenchmarkResult", "BenchmarkStudy", "run_benchmark"]

BENCHMARK_CSV = "benchmark.csv"
BENCHMARK_PARQUET = "benchmark.parquet"
CELLS_DIR = "cells"


@dataclass(frozen=True)
class BenchmarkStudy:
    """A benchmark: what it benchmarks, on which tasks, how large.

    Attributes
    ----------
    subject : Subject
        The thing benchmarked (default: the default law).
    quick : bool
        The quick suite (the wall's first 1,000 trials; the grids' every 3rd
        pitch and every 5th offset).
    tasks : tuple of str
        The suite's tasks flown (default all: ``wall``, ``pole``, ``edge``).
    references : bool
        Fly the reference rows beside the subject (default True).
    limit : int or None
        Only the first ``limit`` trials or points of each task: a smoke test,
        not a benchmark (every output says so).
    suite : str
        The suite's version (default the latest, :data:`SUITE_VERSION`): ``"1"``
        counts the published criteria, ``"2"`` the held hover.
    sensors : tuple of str or None
        The sensor sets flown (None: the suite's own; an extra set of the
        suite, such as suite 2's ``impact``, only when named).
    """

    subject: Subject = field(default_factory=lambda: Subject("default"))
    quick: bool = False
    tasks: tuple[str, ...] = tuple(TASKS)
    references: bool = True
    limit: int | None = None
    suite: str = SUITE_VERSION
    sensors: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "suite", suite(self.suite).version)
        if self.sensors is not None:
            names = parse_sensor_sets(",".join(self.sensors), self.suite)
            object.__setattr__(self, "sensors", names)
        if self.limit is not None and (isinstance(self.limit, bool) or self.limit < 1):
            raise InputError(f"limit: must be an integer >= 1 (got {self.limit!r})")
        if not self.tasks:
            raise InputError("--tasks: give at least one task")
        for name in self.tasks:
            if name not in TASKS:
                raise InputError(f"--tasks: unknown task {name!r} (the suite's: "
                                 f"{', '.join(TASKS)})")  # fmt: skip

    @property
    def definition(self) -> Suite:
        """The suite flown."""
        return suite(self.suite)

    def sensor_sets(self) -> tuple[str, ...]:
        """The sensor sets flown, in table order."""
        return self.sensors if self.sensors is not None else self.definition.sensor_sets

    def rows(self) -> list[Subject]:
        """The subject, then the reference rows (one the subject stands for is left out)."""
        rows = [self.subject]
        if self.references:
            rows += [r for r in REFERENCES if r.name != self.subject.name]
        return rows

    def identity(self) -> dict[str, Any]:
        """What decides the benchmark's runs (``study.json``; a rerun resumes only the same)."""
        return {
            "suite_version": self.suite,
            **({"sensors": list(self.sensors)} if self.sensors is not None else {}),
            "quick": self.quick,
            "tasks": list(self.tasks),
            "references": self.references,
            "subject": self.subject.describe(),
            **({"limit": self.limit} if self.limit is not None else {}),
            **({"plugin_sensor_presets": presets} if (presets := self._plugin_presets()) else {}),
        }

    def _plugin_presets(self) -> dict[str, Any]:
        """The plug-in presets of sensors flown, with their contents (JSON-ready)."""
        from quadimpact.inputs.sensors import SENSOR_PRESETS

        names = [n for n in self.sensor_sets() if sensor_set(n).plugin]
        return {n: json.loads(json.dumps(SENSOR_PRESETS[n], default=str)) for n in names}


@dataclass
class BenchmarkResult:
    """What :func:`run_benchmark` produced."""

    out_dir: Path
    table: pd.DataFrame
    report: Path
    figures: list[Path]
    cells: list[dict[str, Any]]
    elapsed_s: float


_FLAGS = {"quick": "--quick", "tasks": "--tasks", "references": "--no-references",
          "subject": "the thing benchmarked", "suite_version": "--suite",
          "sensors": "--sensors"}  # fmt: skip


def study_folder(study: BenchmarkStudy, out_dir: str | os.PathLike[str]) -> StudyFolder:
    """The benchmark's folder."""
    return StudyFolder(Path(out_dir), "benchmark", study.identity(), where="", flags=_FLAGS)


def _note(message: str, progress: bool) -> None:
    if progress:
        print(f"quadimpact: benchmark: {message}", file=sys.stderr, flush=True)


def run_benchmark(
    study: BenchmarkStudy,
    out_dir: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    cache: Path | None = None,
    allow_large: bool = False,
) -> BenchmarkResult:
    """Run the benchmark into ``out_dir`` (module docstring) and report it.

    Parameters
    ----------
    study : BenchmarkStudy
    out_dir : path-like
        The benchmark's folder (resumable).
    workers, scheduler, progress, allow_large
        As :func:`quadimpact.sweep.run_sweep`'s, for every cell's sweep.
    cache : Path or None
        The cache folder of the cells of built-in rows (None: no cache).

    Raises
    ------
    InputError
        A folder holding something else (or another benchmark), bad workers
        or scheduler; a plug-in that fails its pre-flight check, or raised in
        a run (the cells finished kept: :mod:`~quadimpact.studies.benchmark.plugin_guard`).
    """
    from quadimpact.simulation.plugin_kernel import compile_cpu_total
    from quadimpact.studies.benchmark import benchmark_report as report
    from quadimpact.sweep import read_runs, run_sweep

    start = time.perf_counter()
    folder = study_folder(study, out_dir)
    compiled = compile_cpu_total()
    if guard.check_rows(study):  # a plug-in checked before any trial (one line, exit 2)
        _note("the plug-in passed its pre-flight check (signature, one tick)", progress)
    # the pre-flight compiled the plug-in's step in this process: its cost goes to the
    # first cell a plug-in row flies here (the runs in this process find it compiled)
    preflight_compile_s = compile_cpu_total() - compiled
    out = folder.claim()
    store = CellCache(cache)
    done: dict[str, tuple[pd.DataFrame, dict[str, Any]]] = {}  # by key: run or read once
    cells: list[dict[str, Any]] = []
    tables: dict[tuple[str, str, str], pd.DataFrame] = {}  # by (row, task, sensors)
    version = study.suite
    for row in study.rows():
        for task_name in study.tasks:
            task = TASKS[task_name]
            for sensors in study.sensor_sets():
                spec = row.spec(task, study.quick, sensor_set(sensors), study.limit, version)
                key = cell_key(spec, version)
                label = f"{row.name} {task.name}/{sensors}"
                # a plug-in's sensor preset is not cached: its name does not say what it is
                cacheable = row.cacheable and not sensor_set(sensors).plugin
                cached = store.get(key) if cacheable else None
                if key in done:
                    table, facts = done[key]
                    source = facts["source"]
                elif cached is not None:
                    table, facts = cached
                    facts = {**facts, "source": "cache"}
                    _note(f"{label}: {len(table)} trials from the cache", progress)
                else:
                    where = out / CELLS_DIR / row.name / f"{task.name}-{sensors}"
                    _note(f"{label}: {spec.n_runs} runs", progress)
                    info = run_sweep(
                        spec, where / "sweep", workers=workers, scheduler=scheduler,
                        progress=progress, load=False, allow_large=allow_large,
                    )  # fmt: skip
                    runs = read_runs(where / "sweep")
                    guard.stop_if_plugin_raised(runs, where / "sweep", label, len(cells), out)
                    table = cell_table(runs, spec, task, version)
                    facts = {
                        "source": "run", "run": describe_run(info), "key": key,
                        "quadimpact_version": __version__, "code": code_digest(),
                        "suite_version": version, "compile_cpu_s": guard.compile_cpu_s(runs),
                    }  # fmt: skip
                    if not cacheable:
                        facts["compile_cpu_s"] += preflight_compile_s
                        preflight_compile_s = 0.0
                    if facts["compile_cpu_s"] > 0.0:
                        _note(f"{label}: {facts['compile_cpu_s']:.1f} s of CPU compiling the "
                              "plug-in's loop (compile_cpu_s, not in cpu_ms_per_trial)",
                              progress)  # fmt: skip
                    if cacheable:
                        where_from = {"row": row.name, "task": task.name, "sensors": sensors}
                        store.put(key, table, {**facts, **where_from, "quick": study.quick})
                source = facts["source"]
                done[key] = (table, facts)
                path = out / CELLS_DIR / row.name / f"{task.name}-{sensors}.parquet"
                path.parent.mkdir(parents=True, exist_ok=True)
                atomic_write(path, lambda tmp, t=table: t.to_parquet(tmp, index=False))
                cells.append({
                    **row.describe(), "task": task.name, "sensors": sensors,
                    "estimator": sensor_set(sensors, row.estimator).estimator,
                    "source": source, "sweep_s": facts.get("run", {}).get("sweep_s"),
                    "compile_cpu_s": facts.get("compile_cpu_s", 0.0) if source == "run" else 0.0,
                    **cell_numbers(table, version),
                })  # fmt: skip
                tables[(row.name, task.name, sensors)] = table
    if study.definition.held_hover:
        add_paired_differences(cells, tables)
    table = _benchmark_table(cells, study)
    atomic_write(out / BENCHMARK_CSV, lambda tmp: table.to_csv(tmp, index=False))
    atomic_write(out / BENCHMARK_PARQUET, lambda tmp: table.to_parquet(tmp, index=False))
    elapsed = time.perf_counter() - start
    figures = report.write_figures(table, out, study)
    description = {
        "quadimpact_version": __version__,
        "suite_version": version,
        "identity": study.identity(),
        "elapsed_s": elapsed,
        "cells": [
            {k: c[k] for k in ("row", "task", "sensors", "source", "sweep_s", "cpu_s")}
            for c in cells
        ],
    }
    md = report.render_report(table, study, description, out, [p.relative_to(out) for p in figures])
    report_path = folder.finish(description, md)
    return BenchmarkResult(out, table, report_path, figures, cells, elapsed)


def add_paired_differences(
    cells: list[dict[str, Any]], tables: dict[tuple[str, str, str], pd.DataFrame]
) -> None:
    """Each cell's paired difference of success to the ``default`` row's cell on the same
    trials (:mod:`~quadimpact.studies.benchmark.paired`): ``vs_default`` (points of
    success, the row minus the default), ``vs_default_low``, ``vs_default_high`` (its
    95 % interval), ``vs_default_only_row``, ``vs_default_only_default`` and
    ``vs_default_resolved``; none for the default row or without it."""
    from quadimpact.studies.benchmark.paired import paired_difference

    for cell in cells:
        mine = tables.get((cell["row"], cell["task"], cell["sensors"]))
        ref = tables.get(("default", cell["task"], cell["sensors"]))
        if cell["row"] == "default" or mine is None or ref is None or len(mine) != len(ref):
            continue
        both = mine["valid"].to_numpy(dtype=bool) & ref["valid"].to_numpy(dtype=bool)
        d = paired_difference(
            mine["success"].to_numpy(dtype=bool)[both], ref["success"].to_numpy(dtype=bool)[both]
        )
        cell.update({
            "vs_default": 100 * d.difference, "vs_default_low": 100 * d.low,
            "vs_default_high": 100 * d.high, "vs_default_only_row": d.only_first,
            "vs_default_only_default": d.only_second, "vs_default_resolved": d.resolved,
        })  # fmt: skip


def _benchmark_table(cells: list[dict[str, Any]], study: BenchmarkStudy) -> pd.DataFrame:
    """``benchmark.csv``: the cells' lines, then the authors' published figures (suite 2:
    as ``published_success``, the criterion they were measured by)."""
    import pandas as pd

    from quadimpact.studies.statistics import rate

    lines = [dict(c) for c in cells]
    held = study.definition.held_hover
    for p in PUBLISHED:
        if p.task not in study.tasks:
            continue
        r = rate(round(p.share * p.n), p.n)
        key = "published_success" if held else "success"
        lines.append({
            "row": p.row, "role": "published", "kind": "controller", "task": p.task,
            "sensors": "ideal", "source": "published", "note": p.source, "trials": p.n,
            "valid": p.n, f"{key}_k": r.k, key: p.share, f"{key}_low": r.low,
            f"{key}_high": r.high,
        })  # fmt: skip
    table = pd.DataFrame(lines)
    table.insert(0, "suite_version", study.suite)
    table.insert(1, "quadimpact_version", __version__)
    table.insert(2, "quick", study.quick)
    table.insert(3, "limit", study.limit)
    return table
