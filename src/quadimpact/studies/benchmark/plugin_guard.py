"""The benchmark's guards around a plug-in: checked before any trial, stopped when it raises.

A row that flies a plug-in controller or estimator (docs/CONTROLLERS.md,
"When a plug-in fails"):

* is checked before any trial (:func:`check_rows`): the first run of each of
  its cells, its plug-ins checked by signature and flown for one tick
  (:func:`quadimpact.simulation.plugin_check.check_plugins`);
* stops the benchmark when one of its runs raised
  (:func:`stop_if_plugin_raised`): a one-line ``InputError`` naming the cell,
  the run and the plug-in's error, instead of failed runs counted as 0 %.
  The cells finished are kept; the failing cell's sweep is moved aside
  (``sweep-failed/``), so the same command, run again, resumes from it;
* has its loop's compilation timed apart from its trials' CPU time
  (:func:`compile_cpu_s`: the column ``compile_cpu_s`` of ``benchmark.csv``).
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path
from typing import TYPE_CHECKING, Any

from quadimpact.errors import InputError
from quadimpact.simulation.plugin_kernel import plugin_failure

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["FAILED_SWEEP", "check_rows", "compile_cpu_s", "stop_if_plugin_raised"]

#: Where the sweep of a cell whose plug-in raised is moved (beside ``sweep/``).
FAILED_SWEEP = "sweep-failed"
COMPILE_COLUMN = "cost__compile_cpu_s"


def check_rows(study: Any) -> int:
    """Check the plug-ins of every row that flies one, on the first run of each of its cells.

    Returns the number of cells checked (0: built-in rows only).

    Raises
    ------
    PluginError
        ``benchmark: <row> <task>/<sensors>: <the plug-in's error>``, one line.
    """
    from quadimpact.simulation.plugin_check import check_first_run
    from quadimpact.studies.benchmark.suite import SENSOR_SETS, TASKS, sensor_set

    checked = 0
    for row in study.rows():
        if not row.plugin:
            continue
        for task_name in study.tasks:
            for sensors in SENSOR_SETS:
                spec = row.spec(TASKS[task_name], study.quick, sensor_set(sensors), 1)
                check_first_run(spec, where=f"benchmark: {row.name} {task_name}/{sensors}: ")
                checked += 1
    return checked


def compile_cpu_s(runs: pd.DataFrame) -> float:
    """CPU time the cell's processes spent compiling a plug-in's loop, s (0: none)."""
    if COMPILE_COLUMN not in runs:
        return 0.0
    values = [float(v) for v in runs[COMPILE_COLUMN] if v is not None and v == v]
    return float(math.fsum(values))


def stop_if_plugin_raised(
    runs: pd.DataFrame, sweep_dir: Path, label: str, finished: int, out: Path
) -> None:
    """Stop the benchmark if a run of this cell failed because its plug-in raised.

    Parameters
    ----------
    runs : DataFrame
        The cell's sweep rows.
    sweep_dir : Path
        The cell's sweep folder: moved aside to ``sweep-failed/`` (replacing an
        older one) so that the same command, run again, flies the cell afresh.
    label : str
        The cell, as the progress notes name it (``"my-law wall/ideal"``).
    finished : int
        The cells finished before it (kept).
    out : Path
        The benchmark's folder.

    Raises
    ------
    InputError
        One line: the cell, the first run whose plug-in raised, its error, and
        that the same command resumes.
    """
    found = plugin_failure(runs)
    if found is None:
        return
    run_id, error = found
    aside = sweep_dir.with_name(FAILED_SWEEP)
    shutil.rmtree(aside, ignore_errors=True)
    if sweep_dir.is_dir():
        sweep_dir.rename(aside)
    raise InputError(
        f"benchmark: {label}, run {run_id}: {error}; the {finished} cells finished are kept "
        f"in {out}: the same command resumes once the plug-in is fixed"
    )
