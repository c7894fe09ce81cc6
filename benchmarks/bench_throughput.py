"""Throughput: from a scenario to a summary, one run and many, against the compiled kernel.

Run: ``python benchmarks/bench_throughput.py [--quick] [--big N] [--json PATH]``

Machines differ, so every time is given beside a ratio measured in the same
process: to the compiled kernel's own time on the same runs. Measures:

1. ``simulate()`` of the paper example (psi = 45 deg, iota = 15 deg,
   V_c = 0.75 m/s) in both model variants, warm, one core: its time / the
   kernel-only time of its main run (``core.kernel.execute`` of the prepared
   setup's model). The approach's compiled shooting (``core/approach.py``:
   2 free-flight runs for a start at t = 0, about 11 for a late start) is
   kernel time too; it is reported apart.
2. The Figure 4 grid (246 runs) in both variants: wall time x worker processes
   / the sum of the same runs' kernel-only times (main runs and shooting runs),
   serial in-process (``sweep.worker.run_chunk``) and with ``run_sweep`` on
   all local cores, after a small first sweep that starts the fork server
   (its time is given apart).
3. The whole ``quadimpact sweep`` command for the Figure 4 grid (a fresh
   process: import, workers, the table), 2 cores.
4. ``quadimpact run`` of one scenario with its figures, warm cache (fresh process).
5. ``import quadimpact`` and ``quadimpact --help`` (fresh processes).
6. With ``--big N``: a sample sweep of N runs (default 100,000 in the issue's
   measure; it takes minutes) with the parent's peak memory.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parents[1]
GRID = {"heading_deg": [0, 45], "inclination_deg": "-20:20:1", "speed_m_s": [0.5, 0.75, 1.0]}


def _cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "quadimpact.cli", *args]


def _wall(cmd: list[str], repeat: int = 3, cwd: str | None = None) -> float:
    """Best wall time (s) of a command in a fresh process (after one warm-up)."""
    subprocess.run(cmd, capture_output=True, check=True, cwd=cwd)
    best = float("inf")
    for _ in range(repeat):
        t = time.perf_counter()
        subprocess.run(cmd, capture_output=True, check=True, cwd=cwd)
        best = min(best, time.perf_counter() - t)
    return best


class KernelClock:
    """Sums the wall time of every compiled run (main and shooting) while active."""

    def __init__(self) -> None:
        import dataclasses

        import quadimpact.core.kernel as run
        import quadimpact.simulation.approach as approach
        import quadimpact.simulation.batch as batch

        self.total = 0.0
        self._patches = []

        def timed(fn):
            def call(*a, **k):
                t = time.perf_counter()
                r = fn(*a, **k)
                self.total += time.perf_counter() - t
                return r

            return call

        # the main runs (a sweep's, through simulation.batch) and the approach's compiled
        # shooting (simulation.approach calls BUILTIN.approach for built-in controllers)
        timed_run = dataclasses.replace(run.BUILTIN, run=timed(run.BUILTIN.run))
        timed_shooting = dataclasses.replace(run.BUILTIN, approach=timed(run.BUILTIN.approach))
        self._patches = [(approach, "BUILTIN", timed_shooting), (batch, "BUILTIN", timed_run)]

    def __enter__(self) -> KernelClock:
        self._saved = [(m, n, getattr(m, n)) for m, n, _ in self._patches]
        for m, n, f in self._patches:
            setattr(m, n, f)
        return self

    def __exit__(self, *exc: object) -> None:
        for m, n, f in self._saved:
            setattr(m, n, f)


def bench_simulate(repeat: int) -> dict:
    from quadimpact import WallApproach, simulate
    from quadimpact.core.kernel import execute
    from quadimpact.simulation.setup import prepare

    res = {}
    for model in ("paper-replica", "default"):
        s = WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75, model=model)
        st = prepare(s)
        run = st.model()
        for _ in range(5):
            execute(run, n_imu=st.n_imu)
            simulate(s)
        k, m = [], []
        for _ in range(repeat):
            t = time.perf_counter()
            execute(run, n_imu=st.n_imu)
            k.append(time.perf_counter() - t)
            t = time.perf_counter()
            simulate(s)
            m.append(time.perf_counter() - t)
        with KernelClock() as clock:
            prepare(s)
        kernel, sim = min(k), min(m)
        res[model] = {
            "kernel_ms": kernel * 1e3,
            "simulate_ms": sim * 1e3,
            "ratio": sim / kernel,
            "shooting_kernel_ms": clock.total * 1e3,
            "ratio_to_all_kernel_time": sim / (kernel + clock.total),
        }
    return res


def bench_grid() -> dict:
    from quadimpact.sweep import SweepSpec, run_sweep
    from quadimpact.sweep.backends import make_chunks
    from quadimpact.sweep.worker import run_chunk

    res = {}
    workers = os.cpu_count() or 1
    with tempfile.TemporaryDirectory() as tmp:  # the pool's start apart (the first sweep's cost)
        t = time.perf_counter()
        run_sweep(SweepSpec(base={}, grid={"heading_deg": list(range(4 * workers))}),
                  Path(tmp) / "warm", workers=workers, progress=False)  # fmt: skip
        res["pool_start_s"] = time.perf_counter() - t
    for model in ("paper-replica", "default"):
        spec = SweepSpec(base={"model": model}, grid=GRID)
        items = next(make_chunks(spec, range(spec.n_runs), spec.n_runs))
        run_chunk(items[:20])
        with KernelClock() as clock:
            t = time.perf_counter()
            run_chunk(items)
            serial = time.perf_counter() - t
        with tempfile.TemporaryDirectory() as tmp:
            t = time.perf_counter()
            run_sweep(spec, Path(tmp) / "s", workers=workers, progress=False)
            pool = time.perf_counter() - t
        res[model] = {
            "runs": spec.n_runs,
            "serial_s": serial,
            "kernel_sum_s": clock.total,
            "serial_ratio": serial / clock.total,
            "pool_s": pool,
            "pool_workers": workers,
            "pool_ratio": pool * workers / clock.total,
        }
    return res


def bench_commands() -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        grid = ["--grid", "heading_deg=0,45", "--grid", "inclination_deg=-20:20:1",
                "--grid", "speed_m_s=0.5,0.75,1.0"]  # fmt: skip
        out = str(Path(tmp) / "fig4")
        # a fresh folder each time (a rerun would only resume)
        times = []
        for k in range(3):
            cmd = _cli("sweep", *grid, "--out", f"{out}{k}", "--no-progress")
            t = time.perf_counter()
            subprocess.run(cmd, capture_output=True, check=True)
            times.append(time.perf_counter() - t)
        run = _wall(_cli("run", "--heading", "45", "--inclination", "15", "--speed", "0.75",
                         "--out", str(Path(tmp) / "run")))  # fmt: skip
    return {
        "sweep_fig4_s": min(times),
        "run_with_figures_s": run,
        "import_s": _wall([sys.executable, "-c", "import quadimpact"], repeat=5),
        "help_s": _wall(_cli("--help"), repeat=5),
    }


def bench_big(n: int) -> dict:
    from quadimpact.sweep import SweepSpec, run_sweep

    spec = SweepSpec(
        base={"final_time_s": 3.0},
        sample={"n": n, "seed": 1, "ranges": {"inclination_deg": [-20, 20],
                                            "speed_m_s": [0.5, 1.0]},
                "choices": {"heading_deg": [0, 45]}},
    )  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        run_sweep(spec, Path(tmp) / "big", workers=os.cpu_count() or 1, progress=False)
        wall = time.perf_counter() - t
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return {"runs": n, "wall_s": wall, "runs_per_s": n / wall, "parent_peak_rss_mb": peak_mb}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats")
    parser.add_argument("--big", type=int, default=0, metavar="N", help="also an N-run sample")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    report = {
        "machine": {
            "cpus": os.cpu_count(),
            "python": sys.version.split()[0],
            "numpy": np.__version__,
        },  # fmt: skip
        "simulate": bench_simulate(20 if args.quick else 60),
        "grid": bench_grid(),
        "commands": bench_commands(),
    }
    if args.big:
        report["big"] = bench_big(args.big)
    for model, r in report["simulate"].items():
        print(f"simulate {model:14s} {r['simulate_ms']:6.2f} ms / kernel {r['kernel_ms']:5.2f} ms"
              f" = {r['ratio']:.2f}x (shooting {r['shooting_kernel_ms']:.2f} ms;"
              f" / all kernel time {r['ratio_to_all_kernel_time']:.2f}x)")  # fmt: skip
    grid = dict(report["grid"])
    print(f"first sweep on {os.cpu_count()} workers (the fork server starts and loads the kernel):"
          f" {grid.pop('pool_start_s'):.2f} s")  # fmt: skip
    for model, r in grid.items():
        print(f"grid {model:14s} {r['runs']} runs: serial {r['serial_s']:.2f} s"
              f" ({r['serial_ratio']:.2f}x kernel {r['kernel_sum_s']:.2f} s); {r['pool_workers']}"
              f" workers {r['pool_s']:.2f} s ({r['pool_ratio']:.2f}x)")  # fmt: skip
    c = report["commands"]
    print(f"quadimpact sweep (Figure 4 grid) {c['sweep_fig4_s']:.2f} s; quadimpact run with "
          f"figures {c['run_with_figures_s']:.2f} s; import {c['import_s']:.2f} s; "
          f"--help {c['help_s']:.2f} s")  # fmt: skip
    if args.big:
        b = report["big"]
        print(f"{b['runs']}-run sample sweep: {b['wall_s']:.0f} s ({b['runs_per_s']:.0f} runs/s),"
              f" parent peak RSS {b['parent_peak_rss_mb']:.0f} MB")  # fmt: skip
    if args.json:
        args.json.write_text(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
