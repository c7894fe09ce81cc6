"""Many runs, summaries only: :func:`simulate_batch`.

What a sweep needs of each run is its summary. ``simulate_batch`` prepares
each scenario, runs the compiled loop into output buffers allocated once for
the whole batch (and grown when a run needs more), and computes each summary
from the raw arrays; no table is built. Its runs record no output rows: the
loop still samples at every output time, for the stats (the attitude
excursion, the last sample's state), but writes no row and skips the contact
geometry of every pair there (about a sixth of a recovery trial's loop),
which only the time-series table shows. Each run is the same computation as
:func:`quadimpact.simulate` (same kernel, same inputs), so the summaries are
the same bit for bit. A scenario that cannot run (it raises while being
prepared) gives a summary with ``status = "failed"`` and the reason; the
batch goes on.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from quadimpact.core.records import Model, Output, RawRecord, new_output, raw_record
from quadimpact.core.run import BUILTIN
from quadimpact.results.costs import cpu_time
from quadimpact.simulation.setup import RunSetup, prepare
from quadimpact.simulation.simulate import analyse

__all__ = ["BatchRunner", "simulate_batch"]


class _Buffers:
    """Outputs reused from run to run (reallocated by the core's factory when a run needs more)."""

    def __init__(self, max_episodes: int) -> None:
        self.max_episodes = int(max_episodes)
        self.o: Output | None = None

    def output(self, m: Model, n_imu: int) -> Output:
        """An :class:`Output` for the run ``m`` in the buffers (views of their first rows).

        No output rows (``new_output(..., rows=False)``): the summary reads the
        samples' attitude excursion and the last sample's state, which the loop
        keeps in its stats.
        """
        o = self.o
        if o is None or o.imu.shape[0] < n_imu:
            o = self.o = new_output(m, n_imu, self.max_episodes, contact_columns=False, rows=False)
        return o._replace(imu=o.imu[:n_imu])


def _run(setup: RunSetup, buffers: _Buffers) -> tuple[RawRecord, float, float]:
    """The compiled loop of one prepared run into the shared buffers; views of the filled parts.

    Also its wall and CPU times, s. The views are overwritten by the next run:
    what is kept of a run is its summary, plain Python values computed from
    them before the next run starts (no copy of the record).
    """
    m = setup.model()
    o = buffers.output(m, int(setup.n_imu))
    kernel = setup.kernel or BUILTIN
    start = time.perf_counter()
    cpu = cpu_time()
    kernel.run(m, o)
    cpu = cpu_time() - cpu
    wall = time.perf_counter() - start
    return raw_record(o), wall, cpu


class BatchRunner:
    """Runs scenarios one after another into output buffers it keeps (summaries only).

    What :func:`simulate_batch` and a sweep worker use: ``runner.summary(scenario)``
    is ``simulate(scenario).summary``, bit for bit, without building tables and
    without allocating the output arrays again for each run.
    """

    def __init__(self, max_episodes: int = 1024) -> None:
        self.buffers = _Buffers(max_episodes)

    def summary(self, scenario: Any) -> dict[str, Any]:
        """The summary of one validated scenario (raises as ``simulate`` does)."""
        setup = prepare(scenario)
        started = cpu_time()
        rec, wall, cpu = _run(setup, self.buffers)
        return analyse(setup, scenario, rec, wall, kernel_cpu_s=cpu, since=started).summary


def simulate_batch(
    scenarios: Sequence[Any],
    *,
    max_episodes: int = 1024,
    on_error: Callable[[int, BaseException], Mapping[str, Any]] | None = None,
) -> list[dict[str, Any]]:
    """Summaries of many runs (no tables), each as ``simulate(scenario).summary``.

    Parameters
    ----------
    scenarios : sequence of validated scenarios
        ``WallApproach``, ``FlightScenario`` or ``ImpactTrial`` objects.
    max_episodes : int, optional
        Episode buffer per run (as ``simulate``).
    on_error : callable, optional
        ``on_error(index, exception) -> summary`` for a scenario that raises while
        being prepared or run; default: a summary with ``status = "failed"`` and
        ``reason = "<ExceptionType>: <message>"`` and nothing else.

    Returns
    -------
    list of dict
        One summary per scenario, in order.
    """
    runner = BatchRunner(max_episodes)
    summaries: list[dict[str, Any]] = []
    for i, scenario in enumerate(scenarios):
        try:
            summaries.append(runner.summary(scenario))
        except Exception as exc:  # a run that cannot run is a failed summary; the batch goes on
            if on_error is not None:
                summaries.append(dict(on_error(i, exc)))
            else:
                summaries.append({"status": "failed", "reason": f"{type(exc).__name__}: {exc}"})
    return summaries
