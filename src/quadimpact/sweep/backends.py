"""Where a sweep's runs execute: in this process, a local process pool, or Dask.

Each backend takes the chunks of missing runs (:func:`make_chunks`) and hands
the rows of finished runs to a ``sink`` as they complete; all call
:func:`~quadimpact.sweep.worker.run_items` (runs in groups, which :func:`run_chunk` collects).
The local pool is in :mod:`quadimpact.sweep.pool`."""

from __future__ import annotations

import contextlib
import math
import queue
import re
import time
from collections import deque
from collections.abc import Callable, Iterator
from typing import Any

from quadimpact.errors import InputError, format_value, one_line
from quadimpact.sweep.interrupt import StopFlag
from quadimpact.sweep.items import RunInputs
from quadimpact.sweep.limits import QUEUED_CHUNKS, RunLimits, seconds
from quadimpact.sweep.spec import SweepSpec
from quadimpact.sweep.worker import (
    Item,
    failed_rows,
    run_chunk_measured,
    run_items,
    warm_up,
    worker_info,
)

Sink = Callable[[list[dict[str, Any]]], None]
"""Takes the rows of finished runs (``[]``: a clock tick, so that waiting rows get written)."""


# --------------------------------------------------------------- backends
def make_chunks(spec: SweepSpec, todo: Any, size: int) -> Iterator[list[Item]]:
    """Items of the missing runs, ``size`` per chunk, built lazily (flat memory).

    Each item carries the run's swept values and the sweep's shared base
    (``sweep.items``), not its scenario mapping.
    """
    base = spec.sweep_base()
    chunk: list[Item] = []
    for run_id in todo:
        run_id = int(run_id)
        inputs = spec.inputs(run_id)
        chunk.append((run_id, RunInputs(base, inputs), spec.input_columns(inputs)))
        if len(chunk) == size:
            yield chunk
            chunk = []
    if chunk:
        yield chunk


def chunk_size(n_todo: int, slots: int) -> int:
    """Runs per chunk: up to 32, and about 8 chunks per worker (balanced ends)."""
    # ~5-30 ms per run: chunks of up to 32 runs keep the per-chunk overhead
    # (pickling, a message each way) small; the pool's workers report every
    # run, so the size only sets how work is shared out.
    return max(1, min(32, math.ceil(n_todo / (8 * max(1, slots)))))


def run_serial(chunks: Iterator[list[Item]], sink: Sink) -> None:
    """Run in this process, each run's row to ``sink`` as its group finishes.

    Ctrl-C keeps the rows sunk; a group holds about 0.1 s of runs
    (:func:`~quadimpact.sweep.worker.run_items`).
    """
    for chunk in chunks:
        for row, _cost in run_items(chunk):
            sink([row])


@contextlib.contextmanager
def dask_session(scheduler: Any) -> Iterator[tuple[Any, int]]:
    """Connect to the scheduler (or use the given client) and check its workers.

    Yields (client, total worker threads). A client made here is closed at the end.
    """
    try:
        from dask.distributed import Client
    except ImportError:
        raise InputError(
            "--scheduler needs Dask's distributed scheduler: pip install 'quadimpact[distributed]'"
        ) from None
    from quadimpact import __version__

    own = not isinstance(scheduler, Client)
    if own:
        if not isinstance(scheduler, str) or not re.match(r"^[a-z][a-z0-9+.-]*://\S+$", scheduler):
            raise InputError(
                "--scheduler: must be an address like tcp://HOST:PORT "
                f"(got {format_value(scheduler)})"
            )
        try:
            client = Client(scheduler, timeout="20s", set_as_default=False)
        except (OSError, TimeoutError) as exc:
            raise InputError(
                f"--scheduler {scheduler}: cannot connect to the Dask scheduler "
                f"({one_line(str(exc))})"
            ) from None
    else:
        client = scheduler
    try:
        try:
            client.wait_for_workers(1, timeout=60)
        except TimeoutError:
            raise InputError(f"--scheduler {scheduler}: no Dask worker connected") from None
        try:
            infos = client.run(worker_info)
        except Exception as exc:
            raise InputError(
                f"Dask workers cannot run quadimpact ({type(exc).__name__}: "
                f"{one_line(str(exc))}); install it in the workers' environment"
            ) from None
        bad = {w: i["version"] for w, i in infos.items() if i["version"] != __version__}
        if bad:
            worker, version = next(iter(bad.items()))
            raise InputError(
                f"Dask worker {worker} runs quadimpact {version}, this is {__version__}: "
                "the table would not be reproducible"
            )
        # load the kernel in every worker now: the chunks' clocks should not count it
        with contextlib.suppress(Exception):
            client.run(warm_up)
        yield client, sum(client.nthreads().values()) or 1
    finally:
        if own:
            client.close()


DASK_FIRST_NOTE_S = 5.0
"""Without any Dask worker for this long, say so (then every ``DASK_NOTE_EVERY_S``)."""
DASK_NOTE_EVERY_S = 30.0
DASK_POLL_S = 0.25
DASK_GATHER_S = 0.5
"""First wait for a finished chunk's rows (doubled at each new try of the same chunk, up to 64
times: a slow link still gets its rows through): a result whose worker died before it was
fetched is computed again by Dask, and the loop goes on meanwhile (its notes, clocks, Ctrl-C)."""


class _DaskTask:
    """A chunk on Dask: its runs, its losses, and the time it waited with workers present."""

    def __init__(self, items: list[Item], lost: int = 0, avoid: str | None = None) -> None:
        self.items = items
        self.lost = lost
        self.avoid = avoid
        self.active_s = 0.0
        self.fetches = 0  # tries to fetch its rows that timed out


class _Dask:
    """The Dask loop of :func:`run_dask`."""

    def __init__(self, client: Any, limits: RunLimits, sink: Sink, note: Callable[[str], None]):
        self.client = client
        self.limits = limits
        self.sink = sink
        self.note = note
        self.done: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self.pending: dict[Any, _DaskTask] = {}
        self.retry: deque[_DaskTask] = deque()
        self.threads = 0
        self.last_look = time.monotonic()
        self.without_workers = 0.0  # s without any worker, so far
        self.next_note = DASK_FIRST_NOTE_S
        self.last_result = time.monotonic()

    def submit(self, task: _DaskTask) -> None:
        workers = None
        if task.avoid is not None:
            others = [w for w in self.client.nthreads() if w != task.avoid]
            workers = others or None
        fut = self.client.submit(
            run_chunk_measured,
            task.items,
            pure=False,
            workers=workers,
            allow_other_workers=workers is not None,
        )
        self.pending[fut] = task
        fut.add_done_callback(self.done.put)

    def run(self, chunks: Iterator[list[Item]], stop: StopFlag) -> None:
        source: Iterator[list[Item]] | None = chunks
        self.look()
        while True:
            stop.check()
            while len(self.pending) < QUEUED_CHUNKS * max(1, self.threads):
                if self.retry:
                    task = self.retry.popleft()
                elif source is not None and (chunk := next(source, None)) is not None:
                    task = _DaskTask(chunk)
                else:
                    source = None
                    break
                self.submit(task)
            if not self.pending:
                return
            try:
                fut = self.done.get(timeout=DASK_POLL_S)
            except queue.Empty:
                fut = None
            stop.check()
            if fut is None:
                self.sink([])
            while fut is not None:
                if fut in self.pending:
                    self.finished(fut, self.pending.pop(fut))
                try:
                    fut = self.done.get_nowait()
                except queue.Empty:
                    fut = None
            if time.monotonic() - self.last_look >= 1.0:
                self.look()

    def finished(self, fut: Any, task: _DaskTask) -> None:
        if fut.status == "finished":
            try:
                rows, costs = fut.result(timeout=DASK_GATHER_S * 2 ** min(task.fetches, 6))
            except TimeoutError:  # its worker went before the rows were fetched ("Couldn't
                # gather ... rescheduling"): Dask runs the chunk again; it is awaited again,
                # without blocking the loop until a worker comes back
                task.fetches += 1
                self.pending[fut] = task
                fut.add_done_callback(self.done.put)
                return
            fut.release()
            for cost in costs:
                self.limits.record(cost)
            self.last_result = time.monotonic()
            self.sink(rows)
            return
        try:
            exc = fut.exception()
            why = f"{type(exc).__name__}: {one_line(str(exc))}"
        except Exception as error:  # cancelled...
            why = f"{type(error).__name__}: {one_line(str(error))}"
        fut.release()
        self.lost(task, f"Dask task failed ({why})", None)

    def lost(self, task: _DaskTask, why: str, avoid: str | None) -> None:
        """Redo a lost chunk's runs once each (elsewhere), then record them as failed."""
        if task.lost:
            reason = f"{why}, twice"
            self.note(f"warning: run {task.items[0][0]}: {reason}; recorded as failed")
            self.sink(failed_rows(task.items, reason))
            return
        first, last = task.items[0][0], task.items[-1][0]
        runs = f"run {first}" if first == last else f"runs {first}-{last}"
        self.note(f"warning: {runs}: {why}; redoing {'it' if first == last else 'them one by one'}")
        self.retry.extend(_DaskTask([item], lost=1, avoid=avoid) for item in task.items)

    def look(self) -> None:
        """Count the workers, advance the chunks' clocks, time out and say what is awaited."""
        now = time.monotonic()
        elapsed, self.last_look = now - self.last_look, now
        try:
            self.threads = sum(self.client.nthreads().values())
        except Exception:  # the scheduler is unreachable: as if no worker
            self.threads = 0
        if self.threads == 0:
            self.without_workers += elapsed
            if self.without_workers >= self.next_note:
                self.next_note = self.without_workers + DASK_NOTE_EVERY_S
                self.note(
                    f"waiting for Dask workers: none connected for {self.without_workers:.0f} s "
                    f"({len(self.pending)} chunks waiting; Ctrl-C stops, a rerun resumes)"
                )
            return
        self.without_workers, self.next_note = 0.0, DASK_FIRST_NOTE_S
        late = []
        for fut, task in self.pending.items():
            task.active_s += elapsed
            if task.active_s > self.limits.chunk_limit(task.items):
                late.append((fut, task))
        if late:
            where = _processing_workers(self.client)
            for fut, task in late:
                del self.pending[fut]
                self.client.cancel([fut])
                limit = self.limits.chunk_limit(task.items)
                self.lost(task, f"no result within {seconds(limit)} s", where.get(fut.key))
        if now - self.last_result >= DASK_NOTE_EVERY_S:
            self.last_result = now
            oldest = max((t.active_s for t in self.pending.values()), default=0.0)
            self.note(
                f"waiting for {len(self.pending)} Dask chunks on {self.threads} worker threads "
                f"(the oldest for {oldest:.0f} s)"
            )


def _processing_workers(client: Any) -> dict[Any, str]:
    """Task key -> the worker processing it."""
    try:
        return {key: w for w, keys in client.processing().items() for key in keys}
    except Exception:
        return {}


def run_dask(
    client: Any,
    chunks: Iterator[list[Item]],
    sink: Sink,
    *,
    limits: RunLimits,
    stop: StopFlag,
    note: Callable[[str], None],
) -> None:
    """Run the chunks on Dask (up to 3 per worker thread in flight), rows to ``sink``.

    A chunk that fails (its workers died: ``KilledWorker``) or exceeds its
    time limit is redone once, one run per task and away from the worker it
    was on; what is lost again is recorded as failed. Without workers it
    waits, and says so every 30 s.
    """
    loop = _Dask(client, limits, sink, note)
    try:
        with stop.polled():
            loop.run(chunks, stop)
    except BaseException:
        with contextlib.suppress(Exception):
            client.cancel(list(loop.pending))
        raise
