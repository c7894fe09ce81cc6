"""Sweeps: many runs of one base scenario, streamed to one Parquet table.

A sweep names a **base** scenario (the keys of a scenario file) and the runs
to make from it: a **grid** (every combination of the listed values, the
last field varying fastest), an explicit list of **runs**, a random
**sample** (``n`` points, a ``seed``, uniform ``ranges`` and/or ``choices``),
or random **trials** (``n`` trials, each drawn when it runs from a random
stream of its own, ``(seed, trial)``: memory flat in ``n``; an optional
``seed_field`` gets each trial's own integer seed; :mod:`quadimpact.sweep.trials`).
A grid can be combined with ``runs``, ``sample`` or ``trials``: every grid
point is then run with every entry. Fields are scenario fields (``heading_deg``,
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
    # [trials]                    # ... or random trials, each drawn when it runs
    # n = 1000000
    # seed = 0
    # ranges = { pitch_deg = [-45, 45], speed_m_s = [0.5, 2.5] }
    # seed_field = "seed"         # each trial's own seed (IMU noise...)

The whole sweep (every run's scenario and vehicle; with ``trials``, the
first trials and the bounds of the ranges) is validated before any run
starts; problems are one-line :class:`~quadimpact.errors.InputError`.

Output folder ``DIR``:

* ``runs.parquet``: one row per run, sorted by ``run_id`` (the run's index in
  the enumeration above): the swept inputs under their names, then the run's
  summary (``docs/RESULTS.md``) flattened: nested tables joined with ``__``
  (``approach__start_time_s``), lists as JSON strings (``leading_bumpers``,
  ``warnings``, ``subsequent_impacts``, ``crash_position_m``); the kernel's
  wall-clock time is left out, and the table is the same, bit for bit,
  however and wherever the sweep ran, except the two columns of what each run
  cost (:data:`COST_COLUMNS`, CPU time; :func:`without_costs` drops them).
  The column set and types are fixed
  (:data:`SUMMARY_COLUMNS`); a run that failed (numerically, or by raising
  while being prepared) is a row with ``status = "failed"`` and its
  ``reason``.
* ``sweep.json``: the sweep, so that running it again resumes it (and a
  different sweep in the same folder is refused).
* ``parts/``: completed runs while the sweep runs, in small Parquet files
  written atomically (a part is complete or absent) and named after their
  SHA-256; merged into ``runs.parquet`` at the end. A run again does only the
  missing runs, after checking every part (checksum, schema, every value)
  and ``runs.parquet``: what fails is redone, with a warning naming the file.

Runs execute in parallel on local worker processes (``workers``, default
the cores this process may use), in-process (``workers=1``), or on a Dask
cluster (``scheduler="tcp://host:port"``); all call the same pure function
(:func:`run_chunk`, in groups of runs). A run gets a time limit on workers
(``timeout``, default derived from its final time and the measured cost of
runs: :mod:`quadimpact.sweep.limits`); a run whose worker dies or exceeds it
is redone once on another worker, then recorded as failed with the reason.
Ctrl-C (any number of times) and SIGTERM stop the sweep promptly, keep what
finished and raise :class:`SweepInterrupted`; run the sweep again to resume.
Worker processes never outlive the sweep, even after ``kill -9``
(:mod:`quadimpact.sweep.pool`). More than :data:`LARGE_SWEEP_RUNS` runs need
``allow_large=True``. The details, with measurements: ``docs/SWEEPS.md``.
"""

from importlib import import_module
from typing import Any

# The public names are imported when first used, so that the light modules of this
# package (its values, its trials) load without the runner, the pool and pandas (the
# command line checks a study's options with them before anything heavy loads).
_EXPORTS = {
    "COST_COLUMNS": "quadimpact.sweep.store",
    "LARGE_SWEEP_RUNS": "quadimpact.sweep.runner",
    "SUMMARY_COLUMNS": "quadimpact.sweep.store",
    "SweepInterrupted": "quadimpact.sweep.interrupt",
    "SweepSpec": "quadimpact.sweep.spec",
    "WorkerError": "quadimpact.sweep.pool",
    "flatten_summary": "quadimpact.sweep.store",
    "load_sweep_file": "quadimpact.sweep.spec",
    "parse_values": "quadimpact.sweep.values",
    "read_runs": "quadimpact.sweep.store",
    "run_chunk": "quadimpact.sweep.worker",
    "run_sweep": "quadimpact.sweep.runner",
    "without_costs": "quadimpact.sweep.store",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        value = getattr(import_module(_EXPORTS[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'quadimpact.sweep' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
