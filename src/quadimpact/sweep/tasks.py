"""Independent tasks of a study on the local cores (the crashes of Table III, for instance).

A sweep runs many scenarios through one function (``worker.run_items``); a
study also has a few larger pieces of work that do not depend on each other
(each crash of Table III: its runs, their files and figures, its small
sweeps). :func:`run_tasks` runs such pieces on worker processes forked from
the sweeps' own fork server (``pool.pool_context``: the simulator already
imported and the kernel loaded), with the same guarantees as a sweep:

* the results come back in the order of the tasks, whatever finished first,
  so a study's tables do not depend on the number of processes;
* an error in a task is raised in the caller (the first one, by task order
  among those that failed before the stop), after the other workers are
  stopped;
* Ctrl-C or SIGTERM (:func:`~quadimpact.sweep.interrupt.stop_signals`) stops
  at once: the workers are killed and reaped before the interruption is
  raised; a killed caller takes its workers with it (they die with the fork
  server, which dies with the caller).

A task runs its own sweeps in its process (``workers=1``): no pool inside a
pool.
"""

from __future__ import annotations

import signal
import sys
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from quadimpact.core import announce_compilation, silence_compilation_notice
from quadimpact.sweep.interrupt import stop_signals
from quadimpact.sweep.pool import WorkerError, pool_context, start_server
from quadimpact.sweep.worker import set_parent_death_signal

POLL_S = 0.2
"""How often the caller looks for a stop signal while tasks run, s."""


def _start_task_worker() -> None:
    """Initialise a task worker: it dies with its parent (the fork server) and leaves
    Ctrl-C to the caller, which stops it itself."""
    if sys.platform.startswith("linux"):
        set_parent_death_signal(signal.SIGKILL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    silence_compilation_notice()  # run_tasks said it, once


def _kill_workers(executor: ProcessPoolExecutor) -> None:
    """SIGKILL every worker of ``executor`` (a stopped one too) and reap it."""
    processes = list((getattr(executor, "_processes", None) or {}).values())
    for proc in processes:
        if proc.is_alive():
            proc.kill()
    for proc in processes:
        proc.join(timeout=5)


def run_tasks(
    fn: Callable[..., Any],
    tasks: Sequence[tuple[Any, ...]],
    workers: int,
    on_done: Callable[[int, Any], None] | None = None,
) -> list[Any]:
    """``[fn(*args) for args in tasks]``, on up to ``workers`` local processes.

    Parameters
    ----------
    fn : callable
        A module-level function (it is sent to the workers by name).
    tasks : sequence of tuple
        The arguments of each call (picklable).
    workers : int
        Processes; 1 (or a single task) runs the calls here, in order.
    on_done : callable, optional
        Called here as ``on_done(index, result)`` when each task finishes (in
        the order they finish), e.g. to say so.

    Returns
    -------
    list
        The results, in the order of ``tasks``.
    """
    if workers <= 1 or len(tasks) <= 1:
        results = []
        for i, args in enumerate(tasks):
            results.append(fn(*args))
            if on_done is not None:
                on_done(i, results[-1])
        return results
    from quadimpact.sweep.runner import _refuse_in_a_starting_worker

    _refuse_in_a_starting_worker()
    ctx = pool_context()
    start_server(ctx)
    announce_compilation()  # the workers compile, silently: said here, once
    results: list[Any] = [None] * len(tasks)
    executor = ProcessPoolExecutor(
        max_workers=min(workers, len(tasks)), mp_context=ctx, initializer=_start_task_worker
    )
    try:
        with stop_signals() as stop, stop.polled():
            pending: dict[Future, int] = {executor.submit(fn, *a): i for i, a in enumerate(tasks)}
            while pending:
                done, _ = wait(pending, timeout=POLL_S, return_when=FIRST_COMPLETED)
                stop.check()
                for fut in sorted(done, key=pending.__getitem__):
                    i = pending.pop(fut)
                    try:
                        results[i] = fut.result()  # a task's error: raised here
                    except BrokenProcessPool as exc:
                        raise WorkerError(f"a worker process of the study died ({exc})") from None
                    if on_done is not None:
                        on_done(i, results[i])
    except BaseException:
        _kill_workers(executor)
        executor.shutdown(wait=True, cancel_futures=True)
        raise
    executor.shutdown(wait=True)
    from quadimpact.sweep.runner import mark_sweep_end

    mark_sweep_end()  # the next warm sweep measures the idle cores from here
    return results
