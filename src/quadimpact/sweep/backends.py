"""Where a sweep's runs execute: in this process, a local process pool, or Dask.

Each backend takes the chunks of missing runs (:func:`make_chunks`) and hands every
chunk's rows to a ``sink`` as they complete; all call :func:`run_chunk`."""

from __future__ import annotations

import contextlib
import math
import re
from collections import deque
from collections.abc import Callable, Iterator, Mapping
from typing import Any

from quadimpact.errors import InputError, format_value, one_line
from quadimpact.sweep.spec import SweepSpec
from quadimpact.sweep.store import FLUSH_SECONDS, failed_row
from quadimpact.sweep.worker import Item, init_pool_worker, run_chunk, worker_info


# --------------------------------------------------------------- backends
def make_chunks(spec: SweepSpec, todo: Any, size: int) -> Iterator[list[Item]]:
    """Items of the missing runs, ``size`` per chunk, built lazily (flat memory)."""
    chunk: list[Item] = []
    for run_id in todo:
        run_id = int(run_id)
        inputs = spec.inputs(run_id)
        chunk.append((run_id, spec.scenario_dict(run_id, inputs), spec.input_columns(inputs)))
        if len(chunk) == size:
            yield chunk
            chunk = []
    if chunk:
        yield chunk


def chunk_size(n_todo: int, slots: int) -> int:
    # ~5-10 ms per run: chunks of up to 32 runs keep the per-task overhead
    # (pickling, IPC) small, and about 8 chunks per worker keep them balanced.
    return max(1, min(32, math.ceil(n_todo / (8 * max(1, slots)))))


def run_serial(chunks: Iterator[list[Item]], sink: Callable[[list[dict]], None]) -> None:
    for chunk in chunks:
        sink(run_chunk(chunk))


def _pool_context() -> Any:
    """Start method of the local worker pool.

    ``forkserver``: workers are forked from a clean single-threaded server
    process started once per parent (not from the parent, which may hold
    pyarrow, Dask or matplotlib threads and locks that ``fork`` would copy in
    a held state), and that server imports :mod:`quadimpact.sweep._preload`
    first, which loads the simulator and the compiled kernel; so every pool
    after the first starts in milliseconds with the kernel ready (``spawn``
    would pay ~1 s of imports and cache loading per worker, per pool).
    ``spawn`` where forkserver does not exist.
    """
    import multiprocessing as mp

    if "forkserver" in mp.get_all_start_methods():
        ctx = mp.get_context("forkserver")
        ctx.set_forkserver_preload(["quadimpact.sweep._preload"])
        return ctx
    return mp.get_context("spawn")


def run_pool(
    chunks: Iterator[list[Item]], workers: int, sink: Callable[[list[dict]], None]
) -> None:
    """Run the chunks on a local process pool, at most 3 chunks per worker in flight.

    If a worker dies (a crash in native code, the OOM killer...), the pool is
    broken: its unfinished chunks are redone one run at a time in a new pool,
    and a run that kills a worker on its own is recorded as failed. If
    workers die before finishing anything and a bare worker cannot start
    either, the environment is at fault: RuntimeError.
    """
    ctx = _pool_context()
    retry: deque[list[Item]] = deque()
    source = iter(chunks)
    while True:
        lost, completed = _pool_pass(ctx, workers, source, retry, sink)
        if lost is None:
            return
        if completed == 0 and not _pool_starts(ctx):
            raise RuntimeError(
                "sweep worker processes die at start-up (see the messages above); a script "
                "that runs a sweep must guard its top level with `if __name__ == "
                '"__main__":`, and code read from stdin cannot start workers (use workers=1)'
            )
        for chunk in lost:
            if isinstance(chunk, _Isolated):
                run_id, _data, inputs = chunk[0]
                reason = "worker process died while running it (crash in native code?)"
                sink([{"run_id": run_id, **inputs, **failed_row(reason, inputs)}])
            else:
                retry.extend(_Isolated([item]) for item in chunk)


def _pool_pass(
    ctx: Any,
    workers: int,
    source: Iterator[list[Item]],
    retry: deque[list[Item]],
    sink: Callable[[list[dict]], None],
) -> tuple[list[list[Item]] | None, int]:
    """One pool, until the work is done (None) or the pool breaks (its unfinished chunks)."""
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool

    executor = ProcessPoolExecutor(workers, mp_context=ctx, initializer=init_pool_worker)
    pending: dict[Any, list[Item]] = {}
    completed = 0
    clean = False
    try:
        while True:
            # runs redone after a crash go one at a time, so that a crash names its run
            while len(pending) < (1 if retry or _has_isolated(pending) else 3 * workers):
                chunk = retry.popleft() if retry else next(source, None)
                if chunk is None:
                    break
                try:
                    pending[executor.submit(run_chunk, chunk)] = chunk
                except BrokenProcessPool:
                    return [chunk, *pending.values()], completed
            if not pending:
                clean = True
                return None, completed
            done, _ = wait(list(pending), timeout=FLUSH_SECONDS / 2, return_when=FIRST_COMPLETED)
            if not done:
                sink([])  # no run finished for a while: write what is waiting
            for fut in done:
                try:
                    rows = fut.result()
                except BrokenProcessPool:
                    return list(pending.values()), completed
                del pending[fut]
                sink(rows)
                completed += 1
    finally:
        for fut in pending:
            fut.cancel()
        executor.shutdown(wait=clean, cancel_futures=True)


def _pool_starts(ctx: Any) -> bool:
    """Whether a one-worker pool can start and run a trivial task."""
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    with ProcessPoolExecutor(1, mp_context=ctx, initializer=init_pool_worker) as executor:
        try:
            executor.submit(worker_info).result(timeout=300)
        except BrokenProcessPool:
            return False
    return True


class _Isolated(list):
    """A one-run chunk resubmitted after a worker died."""


def _has_isolated(pending: Mapping[Any, list[Item]]) -> bool:
    return any(isinstance(chunk, _Isolated) for chunk in pending.values())


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
        yield client, sum(client.nthreads().values()) or 1
    finally:
        if own:
            client.close()


def run_dask(
    client: Any, threads: int, chunks: Iterator[list[Item]], sink: Callable[[list[dict]], None]
) -> None:
    """Submit the chunks (at most 3 per worker thread in flight), write them as they complete."""
    from dask.distributed import as_completed

    max_pending = 3 * threads
    queue = as_completed(loop=client.loop)
    pending: dict[Any, list[Item]] = {}

    def submit_more() -> None:
        while len(pending) < max_pending:
            chunk = next(chunks, None)
            if chunk is None:
                return
            fut = client.submit(run_chunk, chunk, pure=False)
            pending[fut] = chunk
            queue.add(fut)

    submit_more()
    try:
        for fut in queue:
            chunk = pending.pop(fut)
            try:
                rows = fut.result()
            except Exception as exc:  # worker lost too often (KilledWorker...)
                reason = f"Dask task failed: {type(exc).__name__}: {one_line(str(exc))}"
                rows = [
                    {"run_id": rid, **inp, **failed_row(reason, inp)} for rid, _d, inp in chunk
                ]
            fut.release()
            sink(rows)
            submit_more()
    except BaseException:
        client.cancel(list(pending))
        raise


