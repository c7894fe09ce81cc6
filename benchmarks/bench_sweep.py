"""Sweep benchmark: the Figure 4 sweep's wall time, and a 10,000-run sweep's throughput and memory.

Run: ``python benchmarks/bench_sweep.py [--workers N] [--n 10000] [--skip-large] [--json PATH]``.

1. **Figure 4 sweep** (paper replica; heading 0 and 45 deg, inclination -20..20
   deg by 1, impact speed 0.5, 0.75, 1.0 m/s: 246 runs, 3-s scenarios):

   * *cold*: a fresh interpreter runs ``run_sweep`` (imports, the worker
     pool's start, Numba's cache loaded in the workers, validation, runs,
     merge); the time of ``run_sweep`` and of the whole process;
   * *warm*: in this process, after a 4-run warm-up sweep has started the
     worker pool's server and loaded the compiled kernel in it, the 246-run
     sweep into a new folder (``run_sweep`` wall time, target < 5 s), and the
     same in-process (``workers=1``) for the per-core rate.

2. **Large sweep**: a random sample of ``--n`` runs (default 10,000; default
   model; heading in [-45, 45] deg, inclination in [-20, 20] deg, speed in
   [0.5, 1.5] m/s; seed 1), run by a child process. Reported: throughput
   (runs/s over the whole ``run_sweep``, validation and merge included), the
   validation time, and memory: the child's peak RSS (``VmHWM``; its
   ``getrusage`` ``RUSAGE_SELF`` is in the JSON, but on Linux it also counts
   the memory of the benchmark process that launched it, kept across
   ``exec``), the workers' peak
   (``RUSAGE_CHILDREN`` of the child after it stopped the pool's fork server,
   which had reaped the workers: the largest peak among them; cross-checked
   with ``VmHWM`` of every descendant polled in ``/proc``), and the child's RSS
   at 10, 50 and 90 % of the runs (flat = streaming).

Timings are wall-clock on a shared machine: expect noise when other
processes run.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

FIG4 = {
    "base": {"model": "paper-replica"},
    "grid": {
        "heading_deg": [0, 45],
        "inclination_deg": "-20:20:1",
        "speed_m_s": [0.5, 0.75, 1.0],
    },
}
TARGET_FIG4_S = 5.0

COLD_SNIPPET = """
import json, sys, time
t0 = time.perf_counter()
from quadimpact.sweep import SweepSpec, run_sweep
spec = SweepSpec.from_dict(json.loads(sys.argv[1]))
workers = None if sys.argv[3] == "None" else int(sys.argv[3])
t1 = time.perf_counter()
info = run_sweep(spec, sys.argv[2], workers=workers, load=False)
t2 = time.perf_counter()
print(json.dumps({"import_s": t1 - t0, "run_sweep_s": t2 - t1, "backend": info["backend"]}))
"""

LARGE_SNIPPET = """
import json, resource, sys, time
from quadimpact.sweep import SweepSpec, run_sweep
n, workers, out = int(sys.argv[1]), sys.argv[2], sys.argv[3]
spec = SweepSpec(sample={"n": n, "seed": 1, "ranges": {
    "heading_deg": [-45, 45], "inclination_deg": [-20, 20], "speed_m_s": [0.5, 1.5]}})
t0 = time.perf_counter()
spec.validate()
t_validate = time.perf_counter() - t0
t0 = time.perf_counter()
info = run_sweep(spec, out, workers=None if workers == "None" else int(workers), load=False)
elapsed = time.perf_counter() - t0
# stop the pool's fork server (it has reaped the workers): RUSAGE_CHILDREN then
# covers it and, through it, the workers
try:
    from multiprocessing import forkserver
    forkserver._forkserver._stop()
except Exception:
    pass
import pyarrow.parquet as pq
statuses = pq.read_table(out + "/runs.parquet", columns=["status"]).column("status").to_pylist()
print(json.dumps({
    "n_runs": n, "run_sweep_s": elapsed, "validate_s": t_validate, "backend": info["backend"],
    "failed": statuses.count("failed"),
    "maxrss_self_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
    "vmhwm_self_mb": int([l for l in open("/proc/self/status")
                          if l.startswith("VmHWM:")][0].split()[1]) / 1024,
    "maxrss_children_mb": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024,
}))
"""


def machine_info() -> dict:
    model = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    import numba
    import numpy

    return {
        "cpu_count": os.cpu_count(),
        "cpu_model": model,
        "python": platform.python_version(),
        "numpy": numpy.__version__,
        "numba": numba.__version__,
    }


def _status_kb(pid: int, key: str) -> int | None:
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith(key + ":"):
                return int(line.split()[1])
    except (OSError, ValueError):
        return None
    return None


def _descendants(root: int) -> list[int]:
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            ppid = int(stat.rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            continue
        children.setdefault(ppid, []).append(int(entry.name))
    out, todo = [], [root]
    while todo:
        pid = todo.pop()
        for c in children.get(pid, []):
            out.append(c)
            todo.append(c)
    return out


def fig4_cold(workers: int | None) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        proc = subprocess.run(
            [sys.executable, "-c", COLD_SNIPPET, json.dumps(FIG4), f"{tmp}/out", str(workers)],
            capture_output=True,
            text=True,
            check=True,
        )
        total = time.perf_counter() - t0
    result = json.loads(proc.stdout.strip().splitlines()[-1])
    result["process_s"] = total
    return result


def fig4_warm(workers: int | None) -> dict:
    from quadimpact.sweep import SweepSpec, run_sweep

    spec = SweepSpec.from_dict(FIG4)
    with tempfile.TemporaryDirectory() as tmp:
        warm = SweepSpec(base={"final_time_s": 1.0}, grid={"inclination_deg": [0, 5, 10, 15]})
        t0 = time.perf_counter()
        run_sweep(warm, f"{tmp}/warm", workers=workers)
        warm_s = time.perf_counter() - t0
        t0 = time.perf_counter()
        info = run_sweep(spec, f"{tmp}/fig4", workers=workers, load=False)
        parallel = time.perf_counter() - t0
        t0 = time.perf_counter()
        run_sweep(spec, f"{tmp}/fig4-serial", workers=1, load=False)
        serial = time.perf_counter() - t0
    return {
        "warm_up_s": warm_s,
        "run_sweep_s": parallel,
        "backend": info["backend"],
        "serial_s": serial,
    }


def large(n: int, workers: int | None) -> dict:
    tmp = tempfile.mkdtemp(prefix="bench-sweep-")
    out = f"{tmp}/out"
    samples: list[tuple[int, int]] = []  # (rows done, child RSS kB)
    workers_hwm: dict[int, int] = {}
    proc = subprocess.Popen(
        [sys.executable, "-c", LARGE_SNIPPET, str(n), str(workers), out],
        stdout=subprocess.PIPE,
        text=True,
    )
    seen: dict[str, int] = {}
    stop = threading.Event()

    def poll() -> None:
        import pyarrow.parquet as pq

        while not stop.is_set():
            parts = Path(out) / "parts"
            if parts.is_dir():
                for p in list(parts.glob("part-*.parquet")):
                    if p.name not in seen:
                        try:
                            seen[p.name] = pq.read_metadata(p).num_rows
                        except Exception:
                            pass
            rss = _status_kb(proc.pid, "VmRSS")
            if rss is not None:
                samples.append((sum(seen.values()), rss))
            for pid in _descendants(proc.pid):
                hwm = _status_kb(pid, "VmHWM")
                if hwm is not None:
                    workers_hwm[pid] = max(workers_hwm.get(pid, 0), hwm)
            stop.wait(0.25)

    thread = threading.Thread(target=poll, daemon=True)
    thread.start()
    stdout, _ = proc.communicate()
    stop.set()
    thread.join()
    shutil.rmtree(tmp, ignore_errors=True)
    if proc.returncode != 0:
        raise SystemExit(f"large sweep failed with status {proc.returncode}")
    result = json.loads(stdout.strip().splitlines()[-1])
    result["runs_per_s"] = n / result["run_sweep_s"]
    result["workers_peak_rss_mb"] = max(workers_hwm.values(), default=0) / 1024
    result["n_descendants_seen"] = len(workers_hwm)
    marks = {}
    for frac in (0.1, 0.5, 0.9):
        hit = [rss for done, rss in samples if done >= frac * n]
        if hit:
            marks[f"{int(frac * 100)}%"] = hit[0] / 1024
    result["child_rss_mb_at"] = marks
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--workers", type=int, default=None, help="default: all cores")
    parser.add_argument("--n", type=int, default=10_000, help="runs of the large sweep")
    parser.add_argument("--skip-large", action="store_true", help="only the Figure 4 sweep")
    parser.add_argument("--json", type=Path, help="write every number to this JSON file")
    args = parser.parse_args()

    report: dict = {"machine": machine_info()}
    m = report["machine"]
    print(
        f"machine: {m['cpu_count']} CPUs ({m['cpu_model']}), Python {m['python']}, "
        f"NumPy {m['numpy']}, Numba {m['numba']}"
    )
    print(f"workers: {args.workers or 'all cores'}")

    cold = fig4_cold(args.workers)
    report["fig4_cold"] = cold
    print(
        f"Figure 4 sweep, 246 runs, cold process: run_sweep {cold['run_sweep_s']:.2f} s "
        f"(+ import {cold['import_s']:.2f} s; whole process {cold['process_s']:.2f} s; "
        f"{cold['backend']})"
    )
    warm = fig4_warm(args.workers)
    report["fig4_warm"] = warm
    verdict = "OK" if warm["run_sweep_s"] < TARGET_FIG4_S else "SLOW"
    print(
        f"Figure 4 sweep, 246 runs, after warm-up ({warm['warm_up_s']:.2f} s): "
        f"{warm['run_sweep_s']:.2f} s [target < {TARGET_FIG4_S:g} s: {verdict}] "
        f"= {246 / warm['run_sweep_s']:.0f} runs/s ({warm['backend']}); "
        f"in-process serial {warm['serial_s']:.2f} s = {246 / warm['serial_s']:.0f} runs/s"
    )

    if not args.skip_large:
        big = large(args.n, args.workers)
        report["large"] = big
        at = ", ".join(f"{k} {v:.0f} MB" for k, v in big["child_rss_mb_at"].items())
        print(
            f"{big['n_runs']}-run random sweep: {big['run_sweep_s']:.1f} s = "
            f"{big['runs_per_s']:.0f} runs/s ({big['backend']}; validation "
            f"{big['validate_s']:.2f} s; {big['failed']} failed)"
        )
        print(
            f"  peak RSS: parent {big['vmhwm_self_mb']:.0f} MB (VmHWM); "
            f"workers {big['maxrss_children_mb']:.0f} MB (getrusage CHILDREN), "
            f"{big['workers_peak_rss_mb']:.0f} MB (largest VmHWM of "
            f"{big['n_descendants_seen']} descendant processes)"
        )
        print(f"  parent RSS during the run: {at}")
    if args.json:
        args.json.write_text(json.dumps(report, indent=2) + "\n")


if __name__ == "__main__":
    main()
