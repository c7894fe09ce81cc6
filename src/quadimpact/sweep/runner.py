"""``run_sweep``: the sweep driver (validate, lock the folder, run what is missing, merge)."""

from __future__ import annotations

import contextlib
import os
import sys
import time
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

from quadimpact.core import announce_compilation
from quadimpact.errors import InputError, format_value
from quadimpact.results.files import check_out_dir
from quadimpact.sweep.backends import (
    Sink,
    chunk_size,
    dask_session,
    make_chunks,
    run_dask,
    run_serial,
)
from quadimpact.sweep.interrupt import StopFlag, SweepInterrupted, signal_name, stop_signals
from quadimpact.sweep.limits import RunLimits
from quadimpact.sweep.pool import (
    WorkerError,
    pool_context,
    run_pool,
    server_cpu_s,
    server_ready,
    server_started,
    start_server,
)
from quadimpact.sweep.progress import Progress
from quadimpact.sweep.spec import SweepSpec
from quadimpact.sweep.store import (
    PartWriter,
    check_folder,
    consolidate,
    finished_before,
    folder_lock,
    read_runs,
    scan_done,
    schema_of,
)
from quadimpact.sweep.values import LARGE_RUNS, check_size
from quadimpact.sweep.worker import frozen_heap, warm_up

LARGE_SWEEP_RUNS = LARGE_RUNS
"""Sweeps with more runs than this need ``allow_large=True`` (``--allow-large``)."""
FINISH_HERE_S = 1.0
"""A default sweep finishes in this process when its runs left would take less than this, s."""
FINISH_HERE_WARM_S = 0.25
"""The same when this process's pool server is already warm (an earlier sweep, or
:func:`warm_pool`): workers then start in milliseconds, s."""
MEASURE_S = 0.25
"""A default sweep measures the idle cores over its first runs for this long, s."""
WARM_HANDOVER_RUNS = 16
"""From this many runs on, a default sweep whose pool server is already warm hands
every run to the pool (after measuring the idle cores) instead of timing runs here."""
WARM_WAIT_S = 0.5
"""Longest such a sweep waits for a server this process started earlier to be warm, s
(this process's own kernel load takes about as long)."""
START_HERE_MAX_S = 3.0
"""Longest a default sweep runs in this process waiting for the pool's server to warm up, s."""
VALIDATION_NOTE_RUNS = 100_000
"""From this many runs on, say that the runs are being checked (it takes a while)."""


# --------------------------------------------------------------- run_sweep
def default_workers() -> int:
    """The default number of local worker processes: the cores this process may use."""
    try:
        return len(os.sched_getaffinity(0)) or 1
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def _refuse_in_a_starting_worker() -> None:
    """Stop a worker that, starting up, runs the main script again and reaches a sweep.

    A worker process (forkserver or spawn) imports the main script before it
    can work; a script without ``if __name__ == "__main__":`` then calls
    ``run_sweep`` inside the worker. Say so in one line, first, and end the
    worker quietly (instead of a traceback per worker).
    """
    import multiprocessing

    if getattr(multiprocessing.current_process(), "_inheriting", False):
        print(
            "quadimpact: error: a sweep worker, starting up, ran the script's top level "
            'again: guard the code that runs the sweep with `if __name__ == "__main__":` '
            "(docs/SWEEPS.md, 'A sweep run from a script')",
            file=sys.stderr,
            flush=True,
        )
        raise SystemExit(1)


#: Most local worker processes per core: more only share the same cores and the memory.
MAX_WORKERS_PER_CORE = 4


def cap_workers(workers: int) -> tuple[int, str]:
    """``workers`` capped at :data:`MAX_WORKERS_PER_CORE` per core, and a note if it was.

    Each worker process holds its own compiled kernel and buffers (about 150
    MB); a thousand of them on two cores gain nothing and take the memory.
    """
    cores = default_workers()
    cap = MAX_WORKERS_PER_CORE * cores
    if workers <= cap:
        return workers, ""
    return cap, (
        f"--workers {workers}: capped at {cap} ({MAX_WORKERS_PER_CORE} per core on the {cores} "
        "core(s) this process may use; more processes only share the same cores and memory)"
    )


def _resolve_workers(workers: int | None) -> int:
    if workers is None:
        return default_workers()
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InputError(f"--workers: must be an integer >= 1 (got {format_value(workers)})")
    capped, note = cap_workers(workers)
    if note:
        _note(note)
    return capped


def _note(message: str, bar: Progress | None = None) -> None:
    line = f"quadimpact: {message}"
    if bar is not None:
        bar.note(line)
    else:
        print(line, file=sys.stderr, flush=True)


def run_sweep(
    spec: SweepSpec | Mapping[str, Any],
    out_dir: str | os.PathLike[str],
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    *,
    load: bool = True,
    timeout: float | None = None,
    allow_large: bool = False,
    max_record_mb: float | None = None,
    on_placed: Callable[[], None] | None = None,
) -> Any:
    """Run a sweep into ``out_dir`` (resuming whatever is already there) and return its table.

    Parameters
    ----------
    spec : SweepSpec or mapping
        The sweep (a mapping is passed to :meth:`SweepSpec.from_dict`).
    out_dir : path-like
        Output folder (created): ``runs.parquet``, ``sweep.json``, ``parts/``.
        If it holds an unfinished run of the same sweep, only the missing runs
        are done (parts that fail their checks are redone, with a warning
        naming the file); a different sweep there is refused.
    workers : int, optional
        Local worker processes; 1 runs in this process. Default: the cores
        this process may use (:func:`default_workers`), after a measured
        start in this process: the first runs are done here while the pool's
        server loads the kernel, and a sweep whose runs left would take less
        than :data:`FINISH_HERE_S` here is finished here (no process started).
    scheduler : str or dask.distributed.Client, optional
        Address of a running Dask scheduler (``"tcp://host:port"``), or a
        client: the runs go to its workers instead (``workers`` must then be
        left out). Needs ``pip install 'quadimpact[distributed]'``.
    progress : bool
        Progress on stderr (a live line on a terminal, a few lines otherwise).
    load : bool, keyword
        Return the table (default); ``False`` returns only the run information
        dict below (for very large sweeps: read columns of ``runs.parquet`` as
        needed).
    timeout : float, keyword, optional
        Longest time a run may take on a worker, s (``--timeout``); default
        derived from each run's final time and the measured cost of runs
        (:mod:`quadimpact.sweep.limits`). A run over it has its worker killed
        and is redone once on another worker, then recorded as failed. Not
        applied to runs in this process (``workers=1``).
    allow_large : bool, keyword
        Allow more than :data:`LARGE_SWEEP_RUNS` runs.
    max_record_mb : float, keyword
        Largest raw record one run may allocate, MB (default
        ``simulation.checks.MAX_RECORD_MB``): a run above it is refused before
        any starts.
    on_placed : callable, keyword, optional
        Called once, with no argument, when the sweep has decided where its
        runs go (after the default's measured start; at once for given
        workers, Dask, a serial sweep or nothing left to run): a task meant
        to run beside the sweep (a study's example trial) starts then, so
        that the default's measurement of the idle cores does not count it.

    Returns
    -------
    pandas.DataFrame or dict
        ``runs.parquet`` (see :func:`read_runs`), sorted by ``run_id``;
        ``table.attrs["sweep"]`` holds ``n_runs``, ``n_already_done``,
        ``n_ran``, ``elapsed_s``, ``backend``, ``out_dir``.

    Raises
    ------
    InputError
        A bad sweep (before anything runs), a folder holding another sweep,
        a bad ``workers``/``scheduler``/``timeout``, too many runs.
    SweepInterrupted
        SIGINT (Ctrl-C) or SIGTERM came (any number of times): the workers
        are stopped, the finished runs saved; running the sweep again resumes.
    WorkerError
        Worker processes could not be started (the finished runs are saved).
    """
    _refuse_in_a_starting_worker()
    start = time.perf_counter()
    sweep = _checked_sweep(spec, out_dir, workers, scheduler, timeout, allow_large, on_placed)
    n_before, backend = sweep.run(progress, max_record_mb)
    info = _run_info(sweep.spec.n_runs, n_before, time.perf_counter() - start, backend, sweep.out)
    if not load:
        return info
    table = read_runs(sweep.out)
    table.attrs["sweep"] = info
    return table


def _checked_sweep(
    spec: SweepSpec | Mapping[str, Any],
    out_dir: str | os.PathLike[str],
    workers: int | None,
    scheduler: Any,
    timeout: float | None,
    allow_large: bool,
    on_placed: Callable[[], None] | None,
) -> _FolderSweep:
    """:func:`run_sweep`'s arguments checked, before anything runs: the sweep (a mapping
    read by :meth:`SweepSpec.from_dict`), ``workers`` or ``scheduler`` (not both; workers
    capped), the ``timeout`` (s), the number of runs and the folder; the sweep to run."""
    if not isinstance(spec, SweepSpec):
        spec = SweepSpec.from_dict(spec)
    if scheduler is not None and workers is not None:
        raise InputError("give workers or scheduler, not both")
    n_workers = 1 if scheduler is not None else _resolve_workers(workers)
    limits = RunLimits(timeout)
    check_size(spec.n_runs, allow_large, spec.where)
    out = check_out_dir(Path(out_dir), "sweep", where="")
    return _FolderSweep(spec, out, workers, n_workers, scheduler, limits, on_placed)


def _run_info(n_runs: int, n_before: int, elapsed_s: float, backend: str, out: Path) -> dict:
    """What :func:`run_sweep` returns about the sweep (its table's ``attrs["sweep"]``): its
    runs, those found done before and those run now, the time it took (s), where the runs
    went (``backend``) and its folder."""
    return {
        "n_runs": n_runs,
        "n_already_done": n_before,
        "n_ran": n_runs - n_before,
        "elapsed_s": elapsed_s,
        "backend": backend,
        "out_dir": str(out),
    }


class _FolderSweep:
    """A sweep run into its folder (:func:`run_sweep`'s work once its arguments are checked).

    ``workers`` as given (None: the default's measured start), ``n_workers``
    the local processes resolved from it (1 with a Dask ``scheduler``),
    ``limits`` the workers' time limits, ``on_placed`` called once where the
    runs go is decided. ``saved`` is the finished runs in the folder as far as
    known, said when the sweep stops.
    """

    def __init__(
        self,
        spec: SweepSpec,
        out: Path,
        workers: int | None,
        n_workers: int,
        scheduler: Any,
        limits: RunLimits,
        on_placed: Callable[[], None] | None,
    ) -> None:
        self.spec, self.out, self.workers, self.n_workers = spec, out, workers, n_workers
        self.scheduler, self.limits = scheduler, limits
        self._pending = [on_placed] if on_placed is not None else []
        self.saved = 0
        self.client: Any = None  # the Dask client (None: local), once the session is open
        self.threads = 0

    def placed(self) -> None:
        """Call ``on_placed`` the first time only."""
        while self._pending:
            self._pending.pop()()

    def run(self, progress: bool, max_record_mb: float | None) -> tuple[int, str]:
        """Check the runs, lock the folder, run what is missing, merge ``runs.parquet``.

        Returns the runs found done before and where the runs went (``"none"``:
        nothing left to run). A stop (a signal, workers that could not start)
        is raised again saying how many runs are saved (:func:`_stopped`).
        """
        spec, out = self.spec, self.out
        try:
            with stop_signals() as stop, contextlib.ExitStack() as stack:
                schema = self._open(stack, progress, max_record_mb)
                done, last_part = scan_done(
                    out, spec.n_runs, schema, lambda m: _note(f"warning: {m}")
                )
                n_before = self.saved = int(done.sum())
                backend = "none"
                if n_before < spec.n_runs:
                    todo = (i for i in range(spec.n_runs) if not done[i])
                    writer = PartWriter(out / "parts", schema, last_part)
                    backend = self._run_missing(todo, n_before, writer, stop, progress)
                self.placed()  # nothing was left to run
                consolidate(out, schema, spec.n_runs)
                if self.client is None:
                    mark_sweep_end()
        except (SweepInterrupted, WorkerError) as exc:
            raise _stopped(exc, self.saved, spec.n_runs, out) from None
        return n_before, backend

    def _open(
        self, stack: contextlib.ExitStack, progress: bool, max_record_mb: float | None
    ) -> Any:
        """Everything before the first run: the pool's server started early (given workers),
        the runs checked (:meth:`SweepSpec.validate`), the Dask session opened, the folder
        locked and checked to hold this sweep; returns the table's schema."""
        spec, out = self.spec, self.out
        pool = self.workers is not None and self.n_workers > 1 and spec.n_runs > 1
        if pool and not finished_before(out):
            start_server(pool_context())  # it loads the kernel while the runs are checked
        if progress and spec.n_runs >= VALIDATION_NOTE_RUNS:
            _note(f"checking the {spec.n_runs} runs of the sweep before any starts")
        spec.validate(max_record_mb=max_record_mb)
        schema = schema_of(spec)
        if self.scheduler is not None:
            self.client, self.threads = stack.enter_context(dask_session(self.scheduler))
        (out / "parts").mkdir(parents=True, exist_ok=True)
        stack.enter_context(folder_lock(out))
        check_folder(out, spec, schema)
        return schema

    def _run_missing(
        self, todo: Iterator[int], n_before: int, writer: PartWriter, stop: StopFlag, progress: bool
    ) -> str:
        """The runs not done yet (``todo``) run and written as parts by ``writer``, with the
        progress bar; every finished run is kept, also on Ctrl-C or an error. Returns where
        they went (:meth:`_place`)."""
        if self.client is None:  # here or the local workers: said before the progress bar
            announce_compilation()
        bar = Progress(self.spec.n_runs, n_before, enabled=progress)

        def sink(rows: list[dict[str, Any]]) -> None:
            writer.add(rows)
            if rows:
                bar.update(len(rows))

        try:
            # the trials run here do not pay for scanning what the process held before
            # (a study's earlier tables): docs/PERFORMANCE.md, "The slowest trial"
            with frozen_heap() if self.client is None else contextlib.nullcontext():
                return self._place(todo, self.spec.n_runs - n_before, sink, stop, bar)
        finally:
            writer.flush()  # also on Ctrl-C or an error: keep every finished run
            bar.close()
            self.saved = n_before + writer.rows_written

    def _place(
        self, todo: Iterator[int], n_todo: int, sink: Sink, stop: StopFlag, bar: Progress
    ) -> str:
        """Run the ``n_todo`` runs of ``todo`` on Dask, in this process or on the local
        pool (after the default's measured start, :func:`_start_here`); returns where they
        went, in words (``backend``)."""
        spec, limits = self.spec, self.limits

        def note(message: str) -> None:
            _note(message, bar)

        if self.client is not None:
            self.placed()
            chunks = make_chunks(spec, todo, chunk_size(n_todo, self.threads))
            run_dask(self.client, chunks, sink, limits=limits, stop=stop, note=note)
            return f"dask, {self.threads} threads"
        if self.n_workers == 1 or n_todo == 1:
            self.placed()
            warm_up()  # the kernel loaded before the first trial, not in its CPU time
            run_serial(make_chunks(spec, todo, 16), sink)
            return "serial"
        n_here, n_workers = 0, self.n_workers
        if self.workers is None:  # the default: a measured start here
            n_here, n_workers = _start_here(spec, todo, n_todo, sink, n_workers, self.placed)
        self.placed()  # given workers: at once
        n_left = n_todo - n_here
        if n_left:
            n_workers = min(n_workers, n_left)
            chunks = make_chunks(spec, todo, chunk_size(n_left, n_workers))
            run_pool(chunks, n_workers, sink, limits=limits, stop=stop, note=note)
        if not n_left:
            return "serial"
        if not n_here:
            return f"{n_workers} processes"
        return f"{n_workers} processes, the first {n_here} runs in this one"


def _start_here(
    spec: SweepSpec,
    todo: Iterator[int],
    n_todo: int,
    sink: Sink,
    cores: int,
    placed: Callable[[], None] = lambda: None,
) -> tuple[int, int]:
    """The default start of a sweep on several cores: measured runs in this process.

    Where the pool's server is already warm (:func:`warm_pool`, an earlier
    sweep) and at least :data:`WARM_HANDOVER_RUNS` runs are left, it only
    measures the idle cores (:func:`_warm_pool_size`) and hands every run to
    the pool if another core is idle (a server started earlier and still
    warming up is waited for, at most :data:`WARM_WAIT_S`). Otherwise the
    sweep process loads the kernel and does runs, timing them and measuring
    how idle the cores it may use are (``/proc/stat``; the CPU its own
    warming server uses counts as idle, :func:`own_server_idle`). It
    finishes the sweep itself when the runs left would take less than
    :data:`FINISH_HERE_S` here (:data:`FINISH_HERE_WARM_S` when the pool's
    server is already warm), or when after :data:`MEASURE_S` fewer than
    one other core is idle (a pool would only compete with the other work
    for the same cores). Otherwise it starts the pool's fork server with one
    worker per idle core (and this one) and goes on here until the server has
    loaded its own kernel (``pool.server_ready``; at most
    :data:`START_HERE_MAX_S`), so that no time is lost waiting for it.
    ``docs/SWEEPS.md`` has the measurements.

    ``placed`` is called once the choice is made (pool or here), before the
    runs that follow it.

    Returns
    -------
    (int, int)
        Runs done here, and the pool's workers for the rest (1: none left).
    """
    ctx = pool_context()
    # a server this process already warmed (an earlier sweep, warm_pool) starts workers at once
    warm = ctx.get_start_method() == "forkserver" and server_ready(ctx)
    if not warm and n_todo >= WARM_HANDOVER_RUNS and server_started(ctx):
        # started early (warm_pool) and still warming: it is usually ready sooner than
        # this process could load its own kernel
        end = time.perf_counter() + WARM_WAIT_S
        while not warm and time.perf_counter() < end:
            time.sleep(0.02)
            warm = server_ready(ctx)
    if warm and n_todo >= WARM_HANDOVER_RUNS:
        workers = _warm_pool_size(cores)
        if workers > 1:  # no run here: the pool starts now, and this process loads no kernel
            placed()
            return 0, workers
    warm_up()
    finish_here_s = FINISH_HERE_WARM_S if warm else FINISH_HERE_S
    started: float | None = None
    workers = 1
    busy, n_here = 0.0, 0
    t0, sample0, server0 = time.perf_counter(), cpu_sample(), server_cpu_s(ctx)
    for chunk in make_chunks(spec, todo, 1):  # one id at a time from the shared iterator
        t = time.perf_counter()
        run_serial(iter([chunk]), sink)
        now = time.perf_counter()
        busy += now - t
        n_here += 1
        if (n_todo - n_here) * busy / n_here < finish_here_s:
            break  # less than that left: finish here
        if started is None:
            if now - t0 < MEASURE_S:
                continue
            idle = idle_cores(sample0, cpu_sample())
            workers = pool_size(own_server_idle(idle, server0, server_cpu_s(ctx), now - t0), cores)
            if workers < 2:
                break  # the other cores are busy: finish here
            start_server(ctx)  # it loads the kernel while the runs go on here
            started = now
            placed()
        elif server_ready(ctx) or now - started > START_HERE_MAX_S:
            return n_here, workers
    placed()
    run_serial(make_chunks(spec, todo, 16), sink)
    return n_todo, 1


#: Longest time since this process's last sweep ended over which the next warm sweep
#: measures the idle cores (:func:`_warm_pool_size`), s; an older end is not used.
LAST_SWEEP_WINDOW_S = 10.0
#: (when, :func:`cpu_sample`, this process's CPU s) at the end of its last local sweep or
#: study tasks (:func:`mark_sweep_end`); None before any.
_last_sweep_end: tuple[float, dict[int, tuple[int, int]] | None, float] | None = None


def mark_sweep_end() -> None:
    """Note that this process's local sweep (or study tasks) just ended: the next warm
    sweep measures the idle cores from now on (:func:`_warm_pool_size`)."""
    global _last_sweep_end
    _last_sweep_end = (time.perf_counter(), cpu_sample(), time.process_time())


def _warm_pool_size(cores: int) -> int:
    """Workers for a default sweep whose pool server is already warm: measured idle.

    The cores' idle time over at least :data:`MEASURE_S`, the CPU this process
    used meanwhile counted as idle, and its own core taken off: a busy machine
    still gets one process. The window starts when this process's last sweep
    ended (:func:`mark_sweep_end`, at most :data:`LAST_SWEEP_WINDOW_S` ago):
    a study's sweeps, one after the other, wait only for what is left of
    :data:`MEASURE_S` after the work between them; otherwise it starts now and
    this process waits. Workers forked from a warm server start in
    milliseconds, so no run is timed here first.
    """
    now = time.perf_counter()
    mark = _last_sweep_end
    if mark is None or not 0.0 <= now - mark[0] <= LAST_SWEEP_WINDOW_S or mark[1] is None:
        mark = (now, cpu_sample(), time.process_time())
    t0, before, own0 = mark
    wait = MEASURE_S - (time.perf_counter() - t0)
    if wait > 0.0:
        time.sleep(wait)
    window = time.perf_counter() - t0
    idle = idle_cores(before, cpu_sample())
    if idle is None:
        return pool_size(None, cores)
    own = (time.process_time() - own0) / window if window >= MEASURE_S > 0.0 else 0.0
    return pool_size(max(0.0, idle + own - 1.0), cores)


def warm_pool(workers: int | None = None, scheduler: Any = None) -> None:
    """Start the local pool's fork server now, for the default sweeps to come (a study).

    A program that will run several sweeps (``quadimpact reproduce``) calls
    this first: the server imports the simulator and loads the kernel on
    another core while the program goes on, so that its sweeps find it warm
    and use the pool from :data:`FINISH_HERE_WARM_S` of work on. Nothing
    happens for a Dask ``scheduler``, one worker, or where there is no fork
    server. The server ends with this process, as for any sweep.
    """
    if scheduler is not None or (workers is not None and workers < 2) or default_workers() < 2:
        return
    _refuse_in_a_starting_worker()
    ctx = pool_context()
    if ctx.get_start_method() == "forkserver":
        start_server(ctx)


def own_server_idle(
    idle: float | None, server_before_s: float | None, server_after_s: float | None, window_s: float
) -> float | None:
    """Idle CPUs over a window, counting the CPU this process's own fork server used as idle.

    A server started early (:func:`warm_pool`) may still be importing while a
    default sweep measures the idle cores: its core is busy with the sweep's
    own work, which the pool will take over, not with someone else's.
    ``server_*_s``: the server's CPU time at the window's ends (None: no
    server, or unknown: ``idle`` as measured).
    """
    if idle is None or server_before_s is None or server_after_s is None or window_s <= 0.0:
        return idle
    return idle + max(0.0, server_after_s - server_before_s) / window_s


def pool_size(idle: float | None, cores: int) -> int:
    """Workers for a default sweep: this core and every other idle one (half idle counts).

    ``idle`` is the idle CPUs measured while this process was busy (None:
    unknown, then every core).
    """
    if idle is None:
        return cores
    return max(1, min(cores, int(idle + 1.5)))


def cpu_sample() -> dict[int, tuple[int, int]] | None:
    """(idle, total) clock ticks of each CPU this process may use (``/proc/stat``; else None)."""
    try:
        cpus = os.sched_getaffinity(0)
        sample = {}
        with open("/proc/stat", encoding="ascii") as f:
            for line in f:
                if line.startswith("cpu") and line[3].isdigit():
                    name, *fields = line.split()
                    ticks = [int(v) for v in fields[:8]]
                    if int(name[3:]) in cpus:
                        sample[int(name[3:])] = (ticks[3] + ticks[4], sum(ticks))
        return sample or None
    except (OSError, AttributeError, ValueError, IndexError):
        return None


def idle_cores(
    before: dict[int, tuple[int, int]] | None, after: dict[int, tuple[int, int]] | None
) -> float | None:
    """How many of those CPUs were idle between two :func:`cpu_sample` (None: unknown)."""
    if not before or not after:
        return None
    idle = 0.0
    for cpu in before.keys() & after.keys():
        ticks = after[cpu][1] - before[cpu][1]
        if ticks <= 0:
            return None
        idle += (after[cpu][0] - before[cpu][0]) / ticks
    return idle


def _stopped(
    exc: SweepInterrupted | WorkerError, saved: int, n_runs: int, out: Path
) -> SweepInterrupted | WorkerError:
    """The same error, saying what is saved and that running the sweep again resumes it.

    The new error also has the attributes ``cause`` (the original message),
    ``saved`` (finished runs in the folder), ``n_runs`` and ``out_dir``.
    """
    resume = f"{saved} of {n_runs} runs saved in {out}; run the sweep again to resume"
    if isinstance(exc, SweepInterrupted):
        error: SweepInterrupted | WorkerError = SweepInterrupted(
            exc.signum, f"sweep interrupted by {signal_name(exc.signum)}: {resume}"
        )
    else:
        error = WorkerError(f"{exc}; {resume}")
    error.cause, error.saved, error.n_runs, error.out_dir = str(exc), saved, n_runs, out  # type: ignore[union-attr]
    return error
