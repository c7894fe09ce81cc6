"""What runs in a sweep worker: :func:`run_chunk` (the same pure function on every
backend), the warm-up that loads the compiled kernel, the pool workers'
set-up, and the forkserver's preload (:func:`preload`)."""

from __future__ import annotations

import contextlib
import functools
import gc
import os
import signal
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from typing import Any, NamedTuple

from quadimpact.results.costs import COST_KEYS, cpu_time
from quadimpact.sweep.items import RunInputs, scenario_of
from quadimpact.sweep.store import failed_row, flatten_summary

TOTAL_COST = COST_KEYS[1]

Item = tuple[int, "RunInputs | dict[str, Any]", dict[str, Any]]
"""A run to do: (run_id, its swept values and sweep base or its scenario mapping,
input column values); see :mod:`quadimpact.sweep.items`."""


class RunCost(NamedTuple):
    """What a run cost where it ran (never in the table): for the run time limits."""

    wall_s: float
    """The whole run: preparation, the kernel, the analysis."""
    kernel_s: float
    """The kernel's main run alone (the summary's ``integrator.wall_time_s``)."""
    steps: int
    """Its accepted and rejected steps."""


_RUNNER: Any = None  # this process's BatchRunner (its output buffers serve every run)


def _runner() -> Any:
    global _RUNNER
    if _RUNNER is None:
        from quadimpact.simulation.batch import BatchRunner

        _RUNNER = BatchRunner()
    return _RUNNER


def run_items(
    items: Sequence[Item],
    on_group: Callable[[int], None] | None = None,
    on_loop: Callable[[int], None] | None = None,
) -> Iterator[tuple[dict[str, Any], RunCost]]:
    """The ``runs.parquet`` row of each run and what it cost, in order, runs done in groups.

    The runs go through :meth:`~quadimpact.simulation.batch.BatchRunner.run_group`
    (the summary of ``simulate``, bit for bit, without its tables), a group
    of about 0.1 s of runs at a time: the group's scenarios made and
    prepared, then run, then summarised, then its rows built (each pass warm
    in the CPU's caches). ``on_group(n)`` is told the size of each group before
    it starts and ``on_loop(k)`` when the group's run ``k`` starts its compiled
    loop (the pool's workers tell the sweep which runs are in flight and which
    one is running). A run's costs are its own passes' (``cost__total_cpu_s``:
    from its scenario to its row).
    """
    runner = _runner()
    i = 0
    while i < len(items):
        group = items[i : i + runner.group_size(len(items) - i)]
        if on_group is not None:
            on_group(len(group))
        makers = [functools.partial(scenario_of, data, f"run {rid}") for rid, data, _ in group]
        done_runs = runner.run_group(makers, before_loop=on_loop)
        for (run_id, _data, inputs), done in zip(group, done_runs, strict=True):
            yield _row(int(run_id), inputs, done)
        i += len(group)


def _row(run_id: int, inputs: dict[str, Any], done: Any) -> tuple[dict[str, Any], RunCost]:
    """A run's row from its :class:`~quadimpact.simulation.batch.GroupRun`, and its cost."""
    start = time.perf_counter()
    cpu_start = cpu_time()
    kernel_s, steps = 0.0, 0
    try:
        if done.error is not None:
            raise done.error
        summary = done.summary
        counters = summary.get("integrator") or {}
        kernel_s = float(counters.get("wall_time_s") or 0.0)
        steps = int(counters.get("steps") or 0) + int(counters.get("rejected_steps") or 0)
        row = flatten_summary(summary, skip=inputs)
        if TOTAL_COST in row:  # the whole run: its scenario and its row included
            row[TOTAL_COST] = done.cpu_s + (cpu_time() - cpu_start)
    except Exception as exc:  # a failed run is a row; the sweep goes on
        row = failed_row(f"{type(exc).__name__}: {exc}", inputs)
    wall = done.wall_s + (time.perf_counter() - start)
    return {"run_id": run_id, **inputs, **row}, RunCost(wall, kernel_s, steps)


def run_item(item: Item) -> tuple[dict[str, Any], RunCost]:
    """One run of a sweep alone: its ``runs.parquet`` row and what it cost (:func:`run_items`)."""
    return next(run_items([item]))


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
    return [row for row, _cost in run_items(items)]


def failed_rows(items: Sequence[Item], reason: str) -> list[dict[str, Any]]:
    """Rows of these runs with ``status = "failed"`` and the reason (lost runs)."""
    return [{"run_id": rid, **inp, **failed_row(reason, inp)} for rid, _data, inp in items]


def run_chunk_measured(items: Sequence[Item]) -> tuple[list[dict[str, Any]], list[RunCost]]:
    """:func:`run_chunk` and what each run cost (what Dask workers run)."""
    done = list(run_items(items))
    return [row for row, _ in done], [cost for _, cost in done]


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
    from quadimpact.inputs.scenarios import ImpactTrial, WallApproach
    from quadimpact.simulation.batch import BatchRunner

    # a short run of each kind through the summary path: every compiled function a
    # sweep's run calls is loaded here, once, not in each worker forked from here
    runner = BatchRunner()
    runner.summary(WallApproach(final_time_s=0.6, impact_time_s=0.1))
    runner.summary(ImpactTrial(controller="recovery", final_time_s=0.3))
    _WARM = True


def freeze_heap() -> None:
    """Leave every object this process holds now out of the garbage collector's scans.

    ``gc.freeze()``, once the simulator is imported and its kernel loaded
    (:func:`warm_up`). Python's full collection walks every object of the
    process. It comes when enough objects have survived since the last one,
    in whichever trial allocates the one too many. After the imports and the
    warm-up a process tracks about 144,000 objects, and a full collection
    costs about 70 ms of CPU, 0.01 ms once they are frozen. With a study's
    tables besides, it cost a trial 80 to 110 ms, over 20 times a wall trial's
    (docs/PERFORMANCE.md, "The slowest trial").
    Frozen objects are still freed when no longer referenced; only the cycle
    detector skips them. A worker forked from a frozen server inherits the
    freeze (and touches no page of the server's objects to scan them).
    """
    gc.freeze()


@contextlib.contextmanager
def frozen_heap() -> Iterator[None]:
    """The objects this process holds at entry left out of the collector's scans until exit.

    What a sweep does around the trials it runs in its own process (the
    default's measured start, ``workers=1``): the tables of earlier sweeps
    (a study's cells) are not scanned again by a collection that a trial
    happens to trigger. ``gc.unfreeze()`` at exit gives them back to the
    collector. Nothing is done where the process froze its heap itself or
    turned the collector off.
    """
    if gc.get_freeze_count() > 0 or not gc.isenabled():
        yield
        return
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


WATCH_SIGNAL: int | None = getattr(signal, "SIGUSR2", None)
"""The signal the pool's fork server gets when the sweep process that started it ends
(None where there is no SIGUSR2: no fork server there either)."""
WATCH_ENV = "QUADIMPACT_SWEEP_PARENT"
"""``<pid>:<multiprocessing temp dir>`` of the sweep process, for the fork server
it starts (read and removed by :func:`preload`)."""
SERVER_READY = "quadimpact-server-ready"
"""File the fork server creates in that temp dir once it has loaded the kernel."""
_PR_SET_PDEATHSIG = 1


def set_parent_death_signal(signum: int) -> bool:
    """Ask Linux to send ``signum`` to this process when its parent ends.

    ``prctl(PR_SET_PDEATHSIG)`` through ctypes; the signal also comes when
    the parent *thread* that started this process ends. Returns whether it
    is set (False off Linux or without a C library).
    """
    if not sys.platform.startswith("linux"):
        return False
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(_PR_SET_PDEATHSIG, int(signum), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def pool_worker(conn: Any) -> None:
    """The loop of a local pool worker (``pool.py``): chunks in, a few messages per group out.

    Messages to the sweep: ``("ready", pid)`` once the kernel is loaded, then
    per chunk ``("start",)``, and per group of runs (:func:`run_items`)
    ``("group", n)`` before its ``n`` runs start, ``("loop", k)`` as its run
    ``k`` starts its compiled loop, and ``("rows", [(row, cost), ...])`` with
    its ``n`` rows once the group is done (one message: the rows share their
    column names, which pickle then writes once; a third of the bytes and
    half the unpickling of a message per row). A chunk is a list of items; None
    (or the sweep's end of the pipe closing) ends the worker. The worker dies
    with its parent (the fork server, which dies with the sweep): SIGKILL, so
    that a stopped or busy worker goes too. Ctrl-C is ignored: the sweep
    decides, and stops its workers itself.
    """
    if sys.platform.startswith("linux"):
        set_parent_death_signal(signal.SIGKILL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    for signum in (signal.SIGTERM, WATCH_SIGNAL):
        if signum is not None:
            signal.signal(signum, signal.SIG_DFL)  # the fork server's handler is inherited
    with contextlib.suppress(Exception):
        _quiet_compilation()
        warm_up()
    freeze_heap()  # forked from a frozen server: what this worker imported since, if anything
    group: list[int] = [0]  # the size of the group running

    def group_starts(n: int) -> None:
        group[0] = n
        conn.send(("group", n))

    try:
        conn.send(("ready", os.getpid()))
        while True:
            chunk = conn.recv()
            if chunk is None:
                return
            conn.send(("start",))
            rows: list[tuple[dict[str, Any], RunCost]] = []
            for row, cost in run_items(
                chunk, on_group=group_starts, on_loop=lambda k: conn.send(("loop", k))
            ):
                rows.append((row, cost))
                if len(rows) == group[0]:  # the group's last row
                    conn.send(("rows", rows))
                    rows = []
    except (EOFError, OSError):  # the sweep is gone
        return


def _quiet_compilation() -> None:
    """No compilation notice from this worker process: the sweep or study it works for
    gives it (``core.announce_compilation``) before handing runs to its workers."""
    from quadimpact.core import silence_compilation_notice

    silence_compilation_notice()


def worker_info() -> dict[str, Any]:
    from quadimpact import __version__

    return {"version": __version__, "python": sys.version.split()[0]}


def preload() -> None:
    """Ready the fork server of the local pools, so that every worker forked from it starts ready.

    Called by :mod:`quadimpact.sweep._preload`, which the fork server imports
    first (see ``pool.start_server``): it ignores Ctrl-C (as will the workers
    it forks), follows the sweep process (below), sets one thread per
    numerical library (before NumPy loads; nothing this package imports
    before it loads NumPy), then :func:`warm_up`, imports the plug-ins named in
    ``QUADIMPACT_PLUGINS`` (:mod:`quadimpact.inputs.plugins`) and compiles their
    steps (``simulation.plugin_kernel.compile_registered_plugins``), and
    freezes its heap (:func:`freeze_heap`) before any worker is forked. Never
    raises: a worker that finds the kernel not loaded loads it itself, and a
    failing preload must not break the fork server (Ctrl-C during start-up
    included).
    """
    # Ctrl-C reaches the whole process group; the sweep decides. Set before the
    # server records its "old" handlers, so its workers start ignoring it too.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    tempdir = ""
    with contextlib.suppress(BaseException):
        tempdir = _follow_sweep()
    for var in SINGLE_THREAD_VARS:
        os.environ.setdefault(var, "1")
    with contextlib.suppress(BaseException):
        _quiet_compilation()  # the sweep says it, once (this server's workers inherit it)
        warm_up()
        # the plug-ins the sweep's process was given (--plugin): registered here, so in
        # every worker forked from here (a failing one leaves them out: their runs say so)
        with contextlib.suppress(BaseException):
            from quadimpact.inputs.plugins import load_env_plugins

            load_env_plugins()
            # their steps compiled here, once: every worker forked from here inherits them
            from quadimpact.simulation.plugin_kernel import compile_registered_plugins

            compile_registered_plugins()
        freeze_heap()  # before any worker is forked: their collections skip these objects
        if tempdir:  # tell the sweep that workers now start ready
            open(os.path.join(tempdir, SERVER_READY), "w").close()


def _follow_sweep() -> str:
    """End this fork server when the sweep process that started it ends (Linux).

    The sweep names itself in :data:`WATCH_ENV`; the server asks for
    :data:`WATCH_SIGNAL` at its parent's death and, when it comes and the
    parent is really gone (not just the thread that started the server),
    removes the sweep's multiprocessing temporary folder (it holds the
    server's socket, and nobody else is left to remove it) and exits, which
    ends its workers (their own parent-death signal). Returns that folder
    ('' without a sweep to follow).
    """
    value = os.environ.pop(WATCH_ENV, "")
    pid_text, _, tempdir = value.partition(":")
    if not pid_text.isdigit() or WATCH_SIGNAL is None:
        return ""
    sweep_pid = int(pid_text)

    def parent_gone(_signum: int, _frame: Any) -> None:
        if os.getppid() == sweep_pid:
            return  # a thread of the sweep ended, the sweep goes on
        if os.path.basename(tempdir).startswith("pymp-"):
            import shutil

            shutil.rmtree(tempdir, ignore_errors=True)
        os._exit(0)

    signal.signal(WATCH_SIGNAL, parent_gone)
    if set_parent_death_signal(WATCH_SIGNAL) and os.getppid() != sweep_pid:
        parent_gone(WATCH_SIGNAL, None)  # it ended before we asked
    return tempdir
