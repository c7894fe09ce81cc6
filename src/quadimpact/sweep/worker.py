"""What runs in a sweep worker: :func:`run_chunk` (the same pure function on every
backend), the warm-up that loads the compiled kernel, the pool workers'
set-up, and the forkserver's preload (:func:`preload`)."""

from __future__ import annotations

import contextlib
import os
import signal
import sys
from collections.abc import Sequence
from typing import Any

from quadimpact.sweep.store import failed_row, flatten_summary

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
    from quadimpact.inputs.scenarios import scenario_from_dict
    from quadimpact.simulation.batch import simulate_batch

    rows: list[dict[str, Any] | None] = [None] * len(items)
    valid: list[tuple[int, Any]] = []
    for k, (run_id, scenario_data, inputs) in enumerate(items):
        try:
            valid.append((k, scenario_from_dict(scenario_data, where=f"run {run_id}")))
        except Exception as exc:  # a failed run is a row; the sweep goes on
            rows[k] = failed_row(f"{type(exc).__name__}: {exc}", inputs)
    errors: dict[int, str] = {}

    def failed(i: int, exc: BaseException) -> dict[str, Any]:
        errors[i] = f"{type(exc).__name__}: {exc}"
        return {}

    summaries = simulate_batch([s for _, s in valid], on_error=failed)
    for i, ((k, _), summary) in enumerate(zip(valid, summaries, strict=True)):
        inputs = items[k][2]
        if i in errors:
            rows[k] = failed_row(errors[i], inputs)
        else:
            rows[k] = flatten_summary(summary, skip=inputs)
    return [
        {"run_id": int(run_id), **inputs, **row}
        for (run_id, _, inputs), row in zip(items, rows, strict=True)
    ]


SINGLE_THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
"""Thread pools of the numerical libraries, one thread each in the workers
(which are one process per core already)."""

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


def init_pool_worker() -> None:
    # Ctrl-C goes to the whole process group: the parent decides (it stops
    # submitting, saves what finished); workers just finish their chunk.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    with contextlib.suppress(Exception):
        warm_up()


def worker_info() -> dict[str, Any]:
    from quadimpact import __version__

    return {"version": __version__, "python": sys.version.split()[0]}


def preload() -> None:
    """Ready the forkserver of the local pools, so that every worker forked from it starts ready.

    Called by :mod:`quadimpact.sweep._preload`, which the forkserver imports
    first (see ``backends._pool_context``): one thread per numerical library
    (set before NumPy loads; nothing this package imports before it loads
    NumPy), then :func:`warm_up`. Never raises: a worker that finds the kernel
    not loaded loads it itself, and a failing preload must not break the
    forkserver (Ctrl-C during start-up included).
    """
    for var in SINGLE_THREAD_VARS:
        os.environ.setdefault(var, "1")
    with contextlib.suppress(BaseException):
        warm_up()
