"""``run_sweep``: the sweep driver (validate, lock the folder, run what is missing, merge)."""

from __future__ import annotations

import contextlib
import os
import sys
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from quadimpact.errors import InputError, format_value
from quadimpact.results.files import check_out_dir
from quadimpact.sweep.backends import (
    chunk_size,
    dask_session,
    make_chunks,
    run_dask,
    run_pool,
    run_serial,
)
from quadimpact.sweep.progress import Progress
from quadimpact.sweep.spec import SweepSpec
from quadimpact.sweep.store import (
    PartWriter,
    check_folder,
    consolidate,
    folder_lock,
    read_runs,
    scan_done,
    schema_of,
)


# --------------------------------------------------------------- run_sweep
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
            "again: guard the code that runs the sweep with `if __name__ == \"__main__\":` "
            "(README, 'Sweeps from Python')",
            file=sys.stderr,
            flush=True,
        )
        raise SystemExit(1)


def _resolve_workers(workers: int | None) -> int:
    if workers is None:
        return os.cpu_count() or 1
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InputError(f"--workers: must be an integer >= 1 (got {format_value(workers)})")
    return workers


def run_sweep(
    spec: SweepSpec | Mapping[str, Any],
    out_dir: str | os.PathLike[str],
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    *,
    load: bool = True,
) -> Any:
    """Run a sweep into ``out_dir`` (resuming whatever is already there) and return its table.

    Parameters
    ----------
    spec : SweepSpec or mapping
        The sweep (a mapping is passed to :meth:`SweepSpec.from_dict`).
    out_dir : path-like
        Output folder (created): ``runs.parquet``, ``sweep.json``, ``parts/``.
        If it holds an unfinished run of the same sweep, only the missing runs
        are done; a different sweep there is refused.
    workers : int, optional
        Local processes; default all cores (``os.cpu_count()``); 1 runs in
        this process.
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
        a bad ``workers``/``scheduler``.
    """
    _refuse_in_a_starting_worker()
    start = time.perf_counter()
    if not isinstance(spec, SweepSpec):
        spec = SweepSpec.from_dict(spec)
    if scheduler is not None and workers is not None:
        raise InputError("give workers or scheduler, not both")
    n_workers = 1 if scheduler is not None else _resolve_workers(workers)
    spec.validate()
    schema = schema_of(spec)

    out = check_out_dir(Path(out_dir), "sweep", where="")

    def warn(message: str) -> None:
        print(f"quadimpact: warning: {message}", file=sys.stderr)

    with contextlib.ExitStack() as stack:
        client, threads = (
            stack.enter_context(dask_session(scheduler)) if scheduler is not None else (None, 0)
        )
        (out / "parts").mkdir(parents=True, exist_ok=True)
        stack.enter_context(folder_lock(out))
        check_folder(out, spec, schema)
        done, last_part = scan_done(out, spec.n_runs, warn)
        n_before = int(done.sum())
        todo = (i for i in range(spec.n_runs) if not done[i])
        n_todo = spec.n_runs - n_before
        backend = "none"
        if n_todo:
            writer = PartWriter(out / "parts", schema, last_part)
            bar = Progress(spec.n_runs, n_before, enabled=progress)

            def sink(rows: list[dict[str, Any]]) -> None:
                writer.add(rows)
                if rows:
                    bar.update(len(rows))

            try:
                if client is not None:
                    backend = f"dask, {threads} threads"
                    chunks = make_chunks(spec, todo, chunk_size(n_todo, threads))
                    run_dask(client, threads, chunks, sink)
                elif n_workers == 1 or n_todo == 1:
                    backend = "serial"
                    run_serial(make_chunks(spec, todo, 16), sink)
                else:
                    n_workers = min(n_workers, n_todo)
                    backend = f"{n_workers} processes"
                    chunks = make_chunks(spec, todo, chunk_size(n_todo, n_workers))
                    run_pool(chunks, n_workers, sink)
            finally:
                writer.flush()  # also on Ctrl-C: keep every finished run
                bar.close()
        consolidate(out, schema, spec.n_runs)

    info = {
        "n_runs": spec.n_runs,
        "n_already_done": n_before,
        "n_ran": spec.n_runs - n_before,
        "elapsed_s": time.perf_counter() - start,
        "backend": backend,
        "out_dir": str(out),
    }
    if not load:
        return info
    table = read_runs(out)
    table.attrs["sweep"] = info
    return table

