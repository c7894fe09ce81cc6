"""Sweep worker count: ``quadimpact sweep --workers 1``, ``--workers N`` and the default.

Run: ``python benchmarks/bench_sweep_workers.py [--runs 50,150,600] [--workers 2] [--repeat 3]
[--json PATH]``.

For each sweep size (a heading grid, 3-s paper-replica scenarios, about 10 ms a
run) it runs the command line in a fresh process, in turn with one worker
(in-process), with ``--workers N`` (the local pool) and without ``--workers``
(the default: a measured start in-process, then the pool if worth it),
``--repeat`` times, and reports the wall time of the whole command (median and
minimum) and the components the choice depends on:

* the pool's fork server: its start-up and warm-up (imports, the compiled
  kernel loaded from Numba's cache), which in-process runs pay as the kernel
  load of the command itself;
* the cost of a run in-process and in a pool worker;
* the sweep process's own CPU time while a pool runs (sending runs, receiving
  rows, writing parts).

Timings are wall-clock on a shared machine: the machine's load is printed with
each row; compare medians.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def heading_grid(n_runs: int) -> str:
    """``n_runs`` headings in [0, 360] deg: a step of 0.5, 0.1 or 0.01 deg."""
    step = next(s for s in (0.5, 0.1, 0.01) if (n_runs - 1) * s <= 360)
    return f"0:{(n_runs - 1) * step:.2f}:{step}"


def command_time(n_runs: int, workers: int, out: Path) -> dict:
    shutil.rmtree(out, ignore_errors=True)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "quadimpact.cli", "sweep",
         f"--grid=heading_deg={heading_grid(n_runs)}", "--grid=model=paper-replica",
         "--out", str(out), *(["--workers", str(workers)] if workers else []),
         "--no-progress", "--no-plots"],
        check=True, capture_output=True,
    )  # fmt: skip
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"wall_s": wall, "parent_cpu_s": cpu, "load": os.getloadavg()[0]}


def components() -> dict:
    """Fork-server warm-up, per-run cost in-process and in a worker (one process each)."""
    code = r"""
import json, time
t0 = time.perf_counter()
from quadimpact.sweep.pool import pool_context, start_server, Pool
from quadimpact.sweep.limits import RunLimits
from quadimpact.sweep.spec import SweepSpec
from quadimpact.sweep.backends import make_chunks
from quadimpact.sweep.worker import run_item, warm_up
from quadimpact.sweep.interrupt import StopFlag
spec = SweepSpec(base={"model": "paper-replica"}, grid={"heading_deg": "0:199:1"})
items = [i for c in make_chunks(spec, range(200), 200) for i in c]
t = time.perf_counter(); warm_up(); kernel_load = time.perf_counter() - t
t = time.perf_counter(); [run_item(i) for i in items]; serial = (time.perf_counter() - t) / 200
ctx = pool_context()
t = time.perf_counter(); start_server(ctx)
rows = []
pool = Pool(1, RunLimits(), rows.extend, print)
pool.run(iter([items[:1]]), StopFlag()); first = time.perf_counter() - t
t = time.perf_counter(); pool.run(iter([items[i:i + 20] for i in range(0, 200, 20)]), StopFlag())
worker = (time.perf_counter() - t) / 200
pool.close(graceful=True)
print(json.dumps({"kernel_load_s": kernel_load, "run_in_process_s": serial,
                  "pool_first_result_s": first, "run_in_worker_s": worker}))
"""
    proc = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", default="50,150,600", help="sweep sizes, comma-separated")
    parser.add_argument("--workers", type=int, default=2, help="pool size to compare with 1")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", type=Path, help="write every number to this JSON file")
    args = parser.parse_args()

    report: dict = {"cpu_count": os.cpu_count(), "components": components(), "sweeps": {}}
    c = report["components"]
    print(
        f"{os.cpu_count()} CPUs; kernel load in-process {c['kernel_load_s']:.2f} s; pool start "
        f"to the first result {c['pool_first_result_s']:.2f} s; a run in-process "
        f"{c['run_in_process_s'] * 1e3:.1f} ms, in a worker {c['run_in_worker_s'] * 1e3:.1f} ms"
    )
    with tempfile.TemporaryDirectory() as tmp:
        for n in (int(v) for v in args.runs.split(",")):
            rows: dict[int, list[dict]] = {1: [], args.workers: [], 0: []}  # 0: the default
            for _ in range(args.repeat):
                for w in rows:
                    rows[w].append(command_time(n, w, Path(tmp) / "out"))
            report["sweeps"][n] = rows
            parts = []
            for w, times in rows.items():
                walls = [t["wall_s"] for t in times]
                parts.append(
                    f"{f'--workers {w}' if w else 'default'}: "
                    f"median {statistics.median(walls):5.2f} s, "
                    f"min {min(walls):5.2f} s (sweep process CPU "
                    f"{statistics.median(t['parent_cpu_s'] for t in times):.2f} s)"
                )
            load = statistics.mean(t["load"] for ts in rows.values() for t in ts)
            print(f"{n:5d} runs: " + "; ".join(parts) + f"  [load {load:.1f}]")
    if args.json:
        args.json.write_text(json.dumps(report, indent=2) + "\n")


if __name__ == "__main__":
    main()
