"""The local worker pool of a sweep: processes forked from a warm server, one pipe each.

Each worker (:func:`~quadimpact.sweep.worker.pool_worker`) gets chunks of
runs over its own pipe, runs them in groups of about 0.1 s of runs
(:func:`~quadimpact.sweep.worker.run_items`), says when a group starts and
how many runs it holds, and sends back one message per finished run, so the
parent knows which runs each worker is on and since when (it reads the pipes
at most every :data:`GATHER_S`, the rows of that time together):

* **time limits**: a run whose compiled loop goes on longer than its limit
  (:class:`~quadimpact.sweep.limits.RunLimits`) has its worker killed (a
  stopped worker included); its group's preparations and summaries, about
  a millisecond a run, count toward the first and the last run's limit;
* **lost runs**: when a worker dies or is killed, the runs it finished are
  kept, the run it was on and the unfinished others of its group are each
  redone once, alone, on another worker (the run that killed it dies again
  alone and is recorded as failed, with the reason; the others finish), and
  the rest of its chunks go back to the queue;
* **stopping**: no threads, no queues: on Ctrl-C, SIGTERM or an error the
  parent kills its workers and waits for them (:meth:`Pool.close`).

Workers are forked from a server process (multiprocessing's ``forkserver``)
that imported the simulator and loaded the compiled kernel once
(:mod:`quadimpact.sweep._preload`), so they start in milliseconds; ``spawn``
where there is no fork server. On Linux the server dies with the sweep
process and the workers with the server (``PR_SET_PDEATHSIG``), so a
``kill -9`` of the sweep leaves no process and no temporary folder behind;
elsewhere an idle worker ends when its pipe closes.
"""

from __future__ import annotations

import os
import time
from collections import deque
from collections.abc import Callable, Iterator
from multiprocessing.connection import wait
from typing import Any

from quadimpact.sweep.interrupt import StopFlag, SweepInterrupted, signal_name
from quadimpact.sweep.limits import RunLimits, seconds
from quadimpact.sweep.worker import SERVER_READY, WATCH_ENV, Item, failed_rows, pool_worker

START_TIMEOUT_S = 300.0
"""How long a new worker may take to start and load the kernel, s."""
START_ATTEMPTS = 3
"""Worker starts that may fail in a row before the sweep gives up."""
CHUNKS_PER_WORKER = 2
"""Chunks sent ahead to each worker (the next one waits in its pipe)."""
POLL_S = 0.25
"""Longest wait between two looks at the stop flag and the clocks, s."""
GATHER_S = 0.05
"""Shortest time between two reads of the workers' pipes, s. The runs that finish
meanwhile are read together: this process wakes up about once per ``GATHER_S`` instead
of once per run, and so takes less of the cores the workers run on. A run's clock
(its time limit) is read up to this late."""
WAIT_NOTE_S = 30.0
"""Without a finished run for this long, say what the sweep is waiting for, s."""


class WorkerError(RuntimeError):
    """The sweep's worker processes cannot be started (or keep dying at start-up)."""


def pool_context() -> Any:
    """The multiprocessing context of the pool: ``forkserver`` with the preload, else ``spawn``.

    ``forkserver``: workers are forked from a clean single-threaded server
    process (not from the sweep process, which may hold pyarrow, Dask or
    matplotlib threads and locks that ``fork`` would copy in a held state),
    started once per sweep process, that imports
    :mod:`quadimpact.sweep._preload` first; ``spawn`` would pay about a
    second of imports and cache loading per worker.
    """
    import multiprocessing as mp

    if "forkserver" in mp.get_all_start_methods():
        ctx = mp.get_context("forkserver")
        ctx.set_forkserver_preload(["quadimpact.sweep._preload"])
        return ctx
    return mp.get_context("spawn")


def start_server(ctx: Any) -> None:
    """Start the fork server now, if not running (it warms up while the sweep gets ready).

    It is told this process's pid and multiprocessing temporary folder
    (:data:`~quadimpact.sweep.worker.WATCH_ENV`, in its environment only), so
    that it can end, and clean up, when this process is killed. Idempotent;
    a server that died is started again.
    """
    if ctx.get_start_method() != "forkserver":
        return
    from multiprocessing import forkserver, util

    os.environ[WATCH_ENV] = f"{os.getpid()}:{util.get_temp_dir()}"
    try:
        forkserver.ensure_running()
    finally:
        os.environ.pop(WATCH_ENV, None)


def server_ready(ctx: Any) -> bool:
    """Whether new workers start ready: the fork server has loaded the kernel (or no server)."""
    if ctx.get_start_method() != "forkserver":
        return True
    from multiprocessing import util

    return os.path.exists(os.path.join(util.get_temp_dir(), SERVER_READY))


def _server_pid(ctx: Any) -> int | None:
    """The pid of the fork server this process started (None: none, or not a fork server)."""
    if ctx.get_start_method() != "forkserver":
        return None
    from multiprocessing import forkserver

    return getattr(forkserver._forkserver, "_forkserver_pid", None) or None


def server_started(ctx: Any) -> bool:
    """Whether this process has started a fork server (warm or still warming up)."""
    return _server_pid(ctx) is not None


def process_cpu_s(pid: int) -> float | None:
    """CPU time (s) process ``pid`` has used so far: its own user and system time, not
    its children's (``/proc/<pid>/stat``; None off Linux or where it cannot be read)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as f:
            fields = f.read().rsplit(")", 1)[1].split()  # the fields after the command's name
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime, stime
    except (OSError, ValueError, IndexError, AttributeError):
        return None


def server_cpu_s(ctx: Any) -> float | None:
    """CPU time (s) this process's fork server has used so far (None: no server, or unknown)."""
    pid = _server_pid(ctx)
    return None if pid is None else process_cpu_s(pid)


class _Task:
    """Runs to do, in order; ``lost`` > 0 marks a lone run being redone after a loss.

    ``started``: its worker said it began (a run only counts as lost, or late,
    when it was really running).
    """

    def __init__(self, items: list[Item], lost: int = 0) -> None:
        self.items = items
        self.lost = lost
        self.started = False


class _Worker:
    """One worker process, its pipe, the tasks sent to it and the clock of its current run."""

    def __init__(self, ctx: Any) -> None:
        ours, theirs = ctx.Pipe(duplex=True)
        self.proc = ctx.Process(target=pool_worker, args=(theirs,), daemon=True)
        self.conn = ours
        try:
            start_server(ctx)
            self.proc.start()
        except BaseException:
            ours.close()
            raise
        finally:
            theirs.close()  # the worker has its own copy: EOF for it when the sweep ends
        self.pid: int = self.proc.pid
        self.ready = False
        self.tasks: deque[_Task] = deque()
        self.n_done = 0  # runs of tasks[0] already reported
        self.group = 1  # runs of tasks[0] from n_done on in its group in progress
        self.loop = 0  # which of them is in its compiled loop (or was last)
        self.since = time.monotonic()  # start, or the last report

    def current(self) -> Item | None:
        """The run this worker is on (None when idle, or when it did not begin its chunk): the
        run of its group in its compiled loop, or that was last (the group's first before)."""
        group = self.in_flight()
        return group[min(self.loop, len(group) - 1)] if group else None

    def in_flight(self) -> list[Item]:
        """The runs of the group this worker is on ([] when idle or not begun)."""
        if self.ready and self.tasks and self.tasks[0].started:
            return self.tasks[0].items[self.n_done : self.n_done + max(1, self.group)]
        return []

    def kill(self) -> None:
        """SIGKILL (a stopped process too), then reap."""
        if self.proc.is_alive():
            self.proc.kill()
        self.proc.join(timeout=5)

    def close(self) -> None:
        self.conn.close()
        if self.proc.exitcode is not None:
            self.proc.close()


class Pool:
    """Local worker processes running a sweep's chunks (see the module).

    Parameters
    ----------
    workers : int
        Worker processes.
    limits : RunLimits
        Time limit of each run; learns the runs' costs.
    sink : callable
        Takes the rows of finished runs (``[]``: a clock tick, to write what waits).
    note : callable
        Prints a one-line message (what happened, what is awaited).
    """

    def __init__(
        self,
        workers: int,
        limits: RunLimits,
        sink: Callable[[list[dict[str, Any]]], None],
        note: Callable[[str], None],
    ) -> None:
        self.ctx = pool_context()
        self.n = workers
        self.limits = limits
        self.sink = sink
        self.note = note
        self.workers: list[_Worker] = []
        self.queue: deque[_Task] = deque()  # runs given back, before new chunks
        self.start_failures = 0
        self.ever_ready = False
        self.last_progress = time.monotonic()
        self.last_note = 0.0
        self.woke = 0.0  # when the last wait for the workers returned (monotonic s)

    # ------------------------------------------------------------ running
    def run(self, chunks: Iterator[list[Item]], stop: StopFlag) -> None:
        """Run every chunk; raises SweepInterrupted as soon as ``stop`` is set."""
        source: Iterator[list[Item]] | None = iter(chunks)
        while True:
            stop.check()
            while len(self.workers) < self.n:
                self._start_worker()
            for w in self.workers:
                while w.ready and len(w.tasks) < CHUNKS_PER_WORKER:
                    task = self.queue.popleft() if self.queue else None
                    if task is None and source is not None:
                        chunk = next(source, None)
                        task = _Task(chunk) if chunk is not None else None
                        if task is None:
                            source = None
                    if task is None:
                        break
                    self._send(w, task)
            if source is None and not self.queue and not any(w.tasks for w in self.workers):
                return
            self._wait(stop)
            self._check_clocks()
            if time.monotonic() - self.last_progress >= WAIT_NOTE_S:
                self._note_waiting()

    def _start_worker(self) -> None:
        try:
            self.workers.append(_Worker(self.ctx))
        except (OSError, EOFError, ValueError) as exc:
            self._start_failed(f"{type(exc).__name__}: {exc}")
            time.sleep(0.2)

    def _start_failed(self, why: str) -> None:
        self.start_failures += 1
        if self.start_failures < START_ATTEMPTS:
            return
        if self.ever_ready:
            raise WorkerError(f"sweep worker processes keep dying at start-up ({why})")
        raise WorkerError(
            f"sweep worker processes cannot start ({why}); a script that runs a sweep "
            'must guard its top level with `if __name__ == "__main__":`, and code read '
            "from stdin cannot start workers (use workers=1)"
        )

    def _send(self, w: _Worker, task: _Task) -> None:
        task.started = False
        if not w.tasks:
            w.since = time.monotonic()  # it should begin at once
        w.tasks.append(task)
        try:
            w.conn.send(task.items)
        except (OSError, ValueError):
            pass  # it died: its sentinel says so next

    def _wait(self, stop: StopFlag) -> None:
        gap = self.woke + GATHER_S - time.monotonic()
        if gap > 0.0:
            time.sleep(gap)  # let more runs finish: their rows are read in one wake-up
        waitables: dict[Any, _Worker] = {}
        for w in self.workers:
            waitables[w.conn] = w
            waitables[w.proc.sentinel] = w
        ready = wait(list(waitables), timeout=POLL_S)
        self.woke = time.monotonic()
        stop.check()  # a signal to the process group reaches the workers too: stop first
        if not ready:
            self.sink([])
        for w in {waitables[r] for r in ready}:
            if w in self.workers:
                self._read(w)

    def _read(self, w: _Worker) -> None:
        """Every message waiting from ``w``; a dead worker's runs are handled as lost."""
        self._take_messages(w)
        if not w.proc.is_alive():
            self._lost(w, _death(w))

    def _take_messages(self, w: _Worker) -> None:
        """Handle what ``w`` sent (without waiting): ready, the start of a chunk, rows.

        The rows read go to the sink together, once every message waiting is handled.
        """
        rows: list[dict[str, Any]] = []
        try:
            while True:
                try:
                    if not w.conn.poll():
                        return
                    kind, *body = w.conn.recv()
                except Exception:  # EOF, or a message cut short by the worker's death
                    return
                w.since = time.monotonic()
                if kind == "ready":
                    w.ready = self.ever_ready = True
                    self.start_failures = 0
                elif kind == "start":
                    w.tasks[0].started = True
                    w.group, w.loop = 1, 0
                elif kind == "group":
                    w.group, w.loop = int(body[0]), 0
                elif kind == "loop":
                    w.loop = int(body[0])
                elif kind == "rows":  # a group's rows, in order
                    rows.extend(self._row(w, row, cost) for row, cost in body[0])
        finally:
            if rows:
                self.sink(rows)

    def _row(self, w: _Worker, row: dict[str, Any], cost: Any) -> dict[str, Any]:
        """Count a finished run of ``w`` (its cost for the limits); its row."""
        task = w.tasks[0]
        self.limits.record(cost)
        w.n_done += 1
        w.group, w.loop = max(1, w.group - 1), max(0, w.loop - 1)
        self.last_progress = w.since
        if w.n_done == len(task.items):
            w.tasks.popleft()
            w.n_done = 0
            w.group, w.loop = 1, 0
        return row

    def _check_clocks(self) -> None:
        now = time.monotonic()
        for w in list(self.workers):
            if not w.ready:
                if now - w.since > START_TIMEOUT_S:
                    w.kill()
                    self._lost(w, f"did not start within {START_TIMEOUT_S:.0f} s")
                continue
            item = w.current() or (w.tasks[0].items[0] if w.tasks else None)
            if item is not None and now - w.since > self.limits.run_limit(item):
                limit = self.limits.run_limit(item)
                w.kill()
                self._lost(w, f"gave no result within {seconds(limit)} s", timed_out=limit)

    def _lost(self, w: _Worker, why: str, timed_out: float | None = None) -> None:
        """``w`` is dead: redo its current run once elsewhere, give its other runs back."""
        self.workers.remove(w)
        w.kill()
        w.close()
        if not w.ready:
            self.note(f"warning: sweep worker process {w.pid} {why} before it started")
            self._start_failed(f"a worker {why} at start-up")
        back: list[_Task] = []
        if w.ready and not w.tasks:
            self.note(f"warning: sweep worker process {w.pid} {why}; starting another")
        elif w.tasks and not w.tasks[0].started:
            self.note(
                f"warning: sweep worker process {w.pid} {why} before it began its next runs; "
                "they go to another worker"
            )
            back.extend(w.tasks)  # nothing of it ran: no loss to count
        elif w.tasks:
            head = w.tasks.popleft()
            k = w.n_done + max(1, w.group)
            group, rest = head.items[w.n_done : k], head.items[k:]
            run_id = group[min(w.loop, len(group) - 1)][0]
            if head.lost:  # a lone run redone: it was the one
                if timed_out is not None:
                    reason = (
                        f"no result within {seconds(timed_out)} s, twice ({self.limits.describe()})"
                    )
                else:
                    reason = "worker process died while running it, twice (crash in native code?)"
                self.note(f"warning: run {run_id}: {reason}; recorded as failed")
                self.sink(failed_rows(group[:1], reason))
            else:
                if len(group) == 1:
                    what = "the run is redone on another worker"
                else:  # the others of its group, unfinished, are redone alone too
                    ids = ", ".join(str(item[0]) for item in group)
                    what = (
                        f"it and the other runs of its group ({ids}) are each redone alone "
                        "on another worker"
                    )
                self.note(f"warning: sweep worker process {w.pid} {why} in run {run_id}; {what}")
                back.extend(_Task([item], lost=1) for item in group)
            if rest:
                back.append(_Task(list(rest)))
            back.extend(w.tasks)
        self.queue.extendleft(reversed(back))

    def _note_waiting(self) -> None:
        now = time.monotonic()
        if now - self.last_note < WAIT_NOTE_S:
            return
        self.last_note = now
        busy = [(w, w.current()) for w in self.workers if w.current() is not None]
        if busy:
            runs = ", ".join(
                f"run {item[0]} for {now - w.since:.0f} s "
                f"(limit {seconds(self.limits.run_limit(item))} s)"
                for w, item in busy
            )
            self.note(f"waiting for {len(busy)} run{'s' if len(busy) != 1 else ''}: {runs}")
        else:
            self.note(f"waiting for {len(self.workers)} worker processes to start")

    # ------------------------------------------------------------ closing
    def drain(self) -> None:
        """Take the rows already sent (finished runs waiting in the pipes), without waiting."""
        for w in list(self.workers):
            self._take_messages(w)

    def close(self, graceful: bool) -> None:
        """End every worker: asked to (``graceful``), else killed; always reaped."""
        for w in self.workers:
            if graceful:
                try:
                    w.conn.send(None)
                except (OSError, ValueError):
                    pass
            else:
                w.proc.kill() if w.proc.is_alive() else None
        deadline = time.monotonic() + 5
        for w in self.workers:
            w.proc.join(timeout=max(0.0, deadline - time.monotonic()))
            w.kill()
            w.close()
        self.workers = []


def _death(w: _Worker) -> str:
    w.proc.join(timeout=1)
    code = w.proc.exitcode
    if code is None:
        return "stopped answering"
    if code < 0:
        return f"died (killed by {signal_name(-code)})"
    if code == 255:  # what multiprocessing reports when the fork server is gone too
        return "died"
    return f"died (exit status {code})"


def run_pool(
    chunks: Iterator[list[Item]],
    workers: int,
    sink: Callable[[list[dict[str, Any]]], None],
    *,
    limits: RunLimits,
    stop: StopFlag,
    note: Callable[[str], None],
) -> None:
    """Run the chunks on ``workers`` local processes (see the module); rows go to ``sink``.

    Raises
    ------
    SweepInterrupted
        A stop signal came (the workers are killed first).
    WorkerError
        Workers cannot be started.
    """
    pool = Pool(workers, limits, sink, note)
    done = False
    try:
        with stop.polled():
            try:
                pool.run(chunks, stop)
            except SweepInterrupted:
                pool.drain()  # the runs that finished are kept
                raise
        done = True
    finally:
        pool.close(graceful=done)
