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

Runs go in **groups** (:meth:`BatchRunner.run_group`): a group's scenarios
are all made and prepared, then all run, then all summarised, each pass one
after the other over the group. The compiled loop's run fills the CPU's caches
with its own code and data; the Python of a preparation or a summary that
follows it starts cold, and took about twice as long as the same code
repeated. In passes, each pass's code and data stay warm from one run to the
next: a recovery trial's Python took 0.8-1.0 ms instead of 1.4-1.6 ms
(400 trials in one process, groups of 8-32, eight measurements). A group
holds about :data:`GROUP_S` of runs (:meth:`BatchRunner.group_size`, from the runs so
far), at most :data:`GROUP_MAX`, so that a sweep's worker still reports its
runs within a fraction of a second. Each run is the same computation in the
same order of its own operations (only runs are interleaved), so the results
are the same bit for bit; each run's cost is its own passes' time.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from quadimpact.core.kernel import BUILTIN
from quadimpact.core.records import Model, Output, RawRecord, new_output, raw_record
from quadimpact.results.costs import cpu_time
from quadimpact.simulation.plugin_kernel import compile_cpu_total
from quadimpact.simulation.setup import RunSetup, prepare
from quadimpact.simulation.simulate import analyse

__all__ = ["GROUP_MAX", "GROUP_S", "BatchRunner", "GroupRun", "simulate_batch"]

GROUP_S = 0.1
"""Wall time of the runs of a group (:meth:`BatchRunner.group_size`), s."""
GROUP_MAX = 16
"""Most runs in a group."""


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
    compiled = compile_cpu_total()
    kernel.run(m, o)
    compiled = compile_cpu_total() - compiled  # a plug-in's loop compiled first: apart
    setup.compile_cpu_s += compiled
    cpu = cpu_time() - cpu - compiled
    wall = time.perf_counter() - start
    return raw_record(o), wall, cpu


@dataclass
class GroupRun:
    """One run of a group (:meth:`BatchRunner.run_group`): its summary or its error, and
    what it cost (its own passes only, not the other runs' of the group)."""

    summary: dict[str, Any] | None
    """``simulate(scenario).summary``, bit for bit (None when the run raised)."""
    error: Exception | None
    """What the run raised while made, prepared, run or summarised (None: it ran)."""
    cpu_s: float
    """CPU time of the run (this thread), s: its scenario, preparation, loop and summary."""
    wall_s: float
    """The same in wall time, s."""
    kernel_s: float
    """Wall time of its compiled loop's main run, s (the summary's ``integrator.wall_time_s``)."""


class _Prepared:
    """A run between the passes of its group (see :meth:`BatchRunner.run_group`)."""

    __slots__ = ("scenario", "setup", "rec", "cpu", "wall", "kernel_wall", "kernel_cpu", "error")

    def __init__(self) -> None:
        self.scenario: Any = None
        self.setup: RunSetup | None = None
        self.rec: RawRecord | None = None
        self.cpu = self.wall = self.kernel_wall = self.kernel_cpu = 0.0
        self.error: Exception | None = None


_NO_ROWS = np.zeros((0, 0))


class BatchRunner:
    """Runs scenarios into output buffers it keeps (summaries only), one by one or in groups.

    What :func:`simulate_batch` and a sweep worker use: ``runner.summary(scenario)``
    is ``simulate(scenario).summary``, bit for bit, without building tables and
    without allocating the output arrays again for each run;
    :meth:`run_group` does the same for several runs in passes (see the module).
    """

    def __init__(self, max_episodes: int = 1024) -> None:
        self.buffers = _Buffers(max_episodes)
        self.run_wall_s: float | None = None
        """Wall time of the last group's runs, mean per run, s (None before the first)."""

    def summary(self, scenario: Any) -> dict[str, Any]:
        """The summary of one validated scenario (raises as ``simulate`` does)."""
        setup = prepare(scenario)
        started = cpu_time()
        compiled = setup.compile_cpu_s
        rec, wall, cpu = _run(setup, self.buffers)
        started += setup.compile_cpu_s - compiled  # a plug-in's loop compiled: not the run's
        return analyse(setup, scenario, rec, wall, kernel_cpu_s=cpu, since=started).summary

    def group_size(self, limit: int = GROUP_MAX) -> int:
        """Runs for the next group: about :data:`GROUP_S` of them at the last group's pace
        (1 before any run), at most ``limit`` and :data:`GROUP_MAX`."""
        if self.run_wall_s is None:
            return 1
        n = int(GROUP_S / max(self.run_wall_s, 1e-6))
        return max(1, min(n, limit, GROUP_MAX))

    def run_group(
        self,
        makers: Sequence[Callable[[], Any]],
        before_loop: Callable[[int], None] | None = None,
    ) -> list[GroupRun]:
        """Make, prepare, run and summarise a group of runs, each step a pass over the group.

        Parameters
        ----------
        makers : sequence of callables
            Each returns a validated scenario (a sweep's item turned into its
            scenario: its time is the run's).
        before_loop : callable, optional
            ``before_loop(k)`` just before run ``k``'s compiled loop starts (a
            sweep's worker tells the sweep which run it is on).

        Returns
        -------
        list of GroupRun
            In order. A run that raises in any pass has its ``error`` and no
            summary; the others go on.
        """
        runs = [_Prepared() for _ in makers]
        for run, make in zip(runs, makers, strict=True):  # pass 1: scenarios and packings
            cpu, wall = cpu_time(), time.perf_counter()
            compiled = compile_cpu_total()
            try:
                run.scenario = make()
                run.setup = prepare(run.scenario)
            except Exception as exc:
                run.error = exc
            run.cpu += cpu_time() - cpu - (compile_cpu_total() - compiled)
            run.wall += time.perf_counter() - wall
        for k, run in enumerate(runs):  # pass 2: the compiled loops, what the summary reads kept
            if run.error is not None:
                continue
            if before_loop is not None:
                before_loop(k)
            cpu, wall = cpu_time(), time.perf_counter()
            compiled = compile_cpu_total()
            try:
                rec, run.kernel_wall, run.kernel_cpu = _run(run.setup, self.buffers)
                run.rec = RawRecord(_NO_ROWS, rec.episodes.copy(), rec.stats.copy(), _NO_ROWS)
            except Exception as exc:
                run.error = exc
            run.cpu += cpu_time() - cpu - (compile_cpu_total() - compiled)
            run.wall += time.perf_counter() - wall
        done = []
        ran = [run.wall for run in runs if run.error is None]
        for run in runs:  # pass 3: the summaries
            if run.error is not None:
                done.append(GroupRun(None, run.error, run.cpu, run.wall, run.kernel_wall))
                continue
            cpu, wall = cpu_time(), time.perf_counter()
            try:
                # its cost: its preparation (in the setup), and from its loop to now
                # less the other runs' passes in between
                summary = analyse(
                    run.setup, run.scenario, run.rec, run.kernel_wall,
                    kernel_cpu_s=run.kernel_cpu, since=cpu - (run.cpu - run.setup.prepare_cpu_s),
                ).summary  # fmt: skip
            except Exception as exc:
                summary, run.error = None, exc
            run.cpu += cpu_time() - cpu
            run.wall += time.perf_counter() - wall
            done.append(GroupRun(summary, run.error, run.cpu, run.wall, run.kernel_wall))
        if ran:
            self.run_wall_s = sum(ran) / len(ran)
        return done


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
    i = 0
    while i < len(scenarios):
        group = scenarios[i : i + runner.group_size()]
        for k, done in enumerate(runner.run_group([_given(s) for s in group])):
            if done.error is None:
                summaries.append(done.summary)
            elif on_error is not None:  # a run that cannot run is a failed summary
                summaries.append(dict(on_error(i + k, done.error)))
            else:
                error = done.error
                summaries.append({"status": "failed", "reason": f"{type(error).__name__}: {error}"})
        i += len(group)
    return summaries


def _given(scenario: Any) -> Callable[[], Any]:
    return lambda: scenario
