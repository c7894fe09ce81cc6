"""How long a sweep waits for a run before it gives up on its worker (``--timeout``).

A run is bounded by the kernel's step budget (``MAX_STEPS_PER_S`` =
20,000 steps per simulated second, at least ``MIN_STEP_BUDGET`` = 20,000,
then it ends with "step budget exhausted"), so the default limit of a run
is derived from its final time and from what runs cost on this machine::

    limit = max(60 s, 4 x (budget steps x slowest kernel cost per step
                           + slowest cost outside the kernel))

where the costs are the slowest measured so far in this sweep (before the
first measurement: 10 us per step, about three times a 2-core AMD EPYC's
3.5 us). A legitimate run, even one that exhausts its budget on a loaded
machine, stays below it, so that a timeout never changes the table; a stopped
or stuck worker is found within minutes (60 s for a 3-s scenario on that
machine). ``--timeout SECONDS`` replaces it with a fixed limit per run.

A local pool applies the limit to each run (its workers report every run);
Dask runs a chunk as one task, whose limit is three times the sum of its runs'
limits (up to three chunks per worker thread are queued) plus 30 s (a worker
that joins late loads the kernel with its first chunk), counted from its
submission while at least one worker is connected; Dask itself also drops a
worker that stops answering (``distributed.scheduler.worker-ttl``, 5 minutes
by default) and reschedules its tasks.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from quadimpact.errors import InputError, format_value
from quadimpact.sweep.worker import Item, RunCost

FLOOR_S = 60.0
"""The shortest default limit of a run, s."""
MARGIN = 4.0
"""Default limit over the budget-bound estimate of a run."""
PRIOR_STEP_S = 10e-6
"""Kernel cost per step assumed before any run of the sweep was measured, s."""
QUEUED_CHUNKS = 3
"""Chunks in flight per Dask worker thread (and the factor of a Dask chunk's limit)."""
DASK_START_S = 30.0
"""Added to a Dask chunk's limit: a worker that joins late loads the kernel with its first chunk."""


def check_timeout(timeout: Any) -> float | None:
    """``timeout`` as seconds (None: the default limits), or an InputError."""
    if timeout is None:
        return None
    if (
        isinstance(timeout, bool)
        or not isinstance(timeout, (int, float))
        or not 0 < timeout < float("inf")
    ):
        raise InputError(
            f"--timeout: must be a number of seconds > 0 (got {format_value(timeout)})"
        )
    return float(timeout)


def final_time_s(scenario: Mapping[str, Any] | Any) -> float:
    """A run's final time: its scenario's ``final_time_s`` or the scenarios' default.

    ``scenario``: a scenario mapping or an item's ``RunInputs``.
    """
    from quadimpact.inputs.scenarios import RunSettings

    value = scenario.get("final_time_s")
    if value is None:
        value = RunSettings.model_fields["final_time_s"].default
    return float(value)


class RunLimits:
    """The time limit of each run (see the module), learning the costs as runs complete.

    Parameters
    ----------
    timeout : float, optional
        A fixed limit per run, s (``--timeout``); default: derived from each
        run's final time and the measured costs.
    """

    def __init__(self, timeout: float | None = None) -> None:
        self.fixed = check_timeout(timeout)
        self.step_s: float | None = None
        self.outside_s = 0.0

    def record(self, cost: RunCost) -> None:
        """Take a completed run's cost into account."""
        if cost.steps >= 100:
            per_step = cost.kernel_s / cost.steps
            self.step_s = per_step if self.step_s is None else max(self.step_s, per_step)
        self.outside_s = max(self.outside_s, cost.wall_s - cost.kernel_s)

    def _estimate(self, item: Item) -> float:
        from quadimpact.packing.constants import MAX_STEPS_PER_S, MIN_STEP_BUDGET

        step = PRIOR_STEP_S if self.step_s is None else self.step_s
        budget = max(MIN_STEP_BUDGET, MAX_STEPS_PER_S * final_time_s(item[1]))
        return MARGIN * (budget * step + self.outside_s)

    def run_limit(self, item: Item) -> float:
        """How long one run may take on a worker, s."""
        if self.fixed is not None:
            return self.fixed
        return max(FLOOR_S, self._estimate(item))

    def chunk_limit(self, items: Sequence[Item]) -> float:
        """How long a Dask chunk may take from its submission, s."""
        if self.fixed is not None:
            return DASK_START_S + QUEUED_CHUNKS * self.fixed * len(items)
        return DASK_START_S + QUEUED_CHUNKS * max(FLOOR_S, sum(map(self._estimate, items)))

    def describe(self) -> str:
        """``--timeout 30 s`` or ``the default limit``, for messages."""
        if self.fixed is None:
            return "the default limit"
        return f"--timeout {seconds(self.fixed)} s"


def seconds(value: float) -> str:
    """A duration for messages: ``90``, ``2.5``, ``0.25``."""
    return f"{value:.0f}" if value >= 10 else f"{round(value, 2):g}"
