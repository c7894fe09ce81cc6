"""Timing benchmark of the compiled core on the paper's example.

Run: ``python benchmarks/bench_run.py [--repeat N] [--json PATH] [--no-cold]``
(``make bench``). For the paper's example (psi = 45 deg, iota = 15 deg,
V_c = 0.75 m/s, 3-s scenario) in both model variants it reports

* kernel-only wall time: ``core.kernel.execute`` on a prepared ``RunSetup``
  (median and min over ``--repeat`` calls, after one warm-up call);
* full ``simulate()`` wall time (median; includes the approach shooting runs,
  the pandas tables and the summary);
* accepted / rejected steps, right-hand-side evaluations, control ticks and
  ns per RHS evaluation (kernel median / RHS evaluations);
* in CPU time (``time.thread_time``, which a loaded machine disturbs less),
  calls alternated: the kernel with its IMU record, ``simulate()``, and the
  ratio of the two (best and median: issue 59's target is 1.2); ``prepare``
  and its approach shooting, and how many free-flight runs the shooting flew;
  the rest, the Python (``simulate()`` less the kernel and the shooting, best
  of each, and its share of the kernel);
* cold start in fresh subprocesses: ``import quadimpact`` + the first
  ``simulate()``, (i) with Numba's on-disk cache warm (run twice, the second
  is reported) and (ii) with ``NUMBA_CACHE_DIR`` pointing to a fresh empty
  folder, so everything is compiled (the compile time);
* the machine: CPU count, CPU model, Python, NumPy and Numba versions.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

from quadimpact import WallApproach, simulate
from quadimpact.core import layout as L
from quadimpact.core.approach import AP_RUNS
from quadimpact.core.interval_slots import IS_N_REJECTED, IS_N_RHS, IS_N_STEPS
from quadimpact.core.kernel import execute
from quadimpact.simulation import approach as approach_py
from quadimpact.simulation import setup as setup_py
from quadimpact.simulation.setup import prepare

EXAMPLE = {"heading_deg": 45.0, "inclination_deg": 15.0, "speed_m_s": 0.75}
MODELS = ("paper-replica", "default")
# The example stops at its crash (~1.3 s); this case runs the whole 3 s (the
# ground is a contact surface, the vehicle bounces on it after the crash).
FULL_3S = "default, ground contact"
CASES = {
    "paper-replica": {"model": "paper-replica"},
    "default": {"model": "default"},
    FULL_3S: {"model": "default", "ground": "contact"},
}
TARGET_KERNEL_MS = 10.0
TARGET_COLD_CACHED_S = 5.0

# Executed in a fresh interpreter: time of `import quadimpact` + first simulate().
COLD_SNIPPET = """
import json, time
t0 = time.perf_counter()
import quadimpact
from quadimpact import WallApproach, simulate
t1 = time.perf_counter()
r = simulate(WallApproach(heading_deg={h}, inclination_deg={i}, speed_m_s={v}, model={m!r}))
t2 = time.perf_counter()
print(json.dumps({{"import_s": t1 - t0, "first_simulate_s": t2 - t1, "total_s": t2 - t0,
                  "status": r.summary["status"]}}))
"""


def machine_info() -> dict:
    cpu_model = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu_model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        affinity = len(os.sched_getaffinity(0))
    except AttributeError:
        affinity = None
    return {
        "cpu_count": os.cpu_count(),
        "cpu_affinity": affinity,
        "cpu_model": cpu_model,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "numba": numba.__version__,
        "platform": platform.platform(),
    }


def scenario(case: str) -> WallApproach:
    return WallApproach(**EXAMPLE, **CASES[case])


def bench_kernel(model: str, repeat: int) -> dict:
    setup = prepare(scenario(model))
    m = setup.model(scfg=None, noise=None)  # the run without its IMU
    st = execute(m).stats  # warm-up (loads or compiles the kernel)
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        st = execute(m).stats
        times.append(time.perf_counter() - t)
    med = statistics.median(times)
    n_rhs = int(st[L.ST_STEPS + IS_N_RHS])
    return {
        "kernel_median_s": med,
        "kernel_min_s": min(times),
        "steps": int(st[L.ST_STEPS + IS_N_STEPS]),
        "rejected_steps": int(st[L.ST_STEPS + IS_N_REJECTED]),
        "rhs_evaluations": n_rhs,
        "control_ticks": int(st[L.ST_N_TICKS]),
        "ns_per_rhs": med / n_rhs * 1e9 if n_rhs else float("nan"),
        "t_start_s": float(setup.t0),
        "t_end_s": float(st[L.ST_T_END]),
        "status": int(st[L.ST_STATUS]),
    }


def bench_simulate(model: str, repeat: int) -> dict:
    sc = scenario(model)
    simulate(sc)  # warm-up
    times = []
    kernel_times = []
    for _ in range(repeat):
        t = time.perf_counter()
        r = simulate(sc)
        times.append(time.perf_counter() - t)
        kernel_times.append(r.summary["integrator"]["wall_time_s"])
    return {
        "simulate_median_s": statistics.median(times),
        "simulate_min_s": min(times),
        "simulate_reported_kernel_median_s": statistics.median(kernel_times),
        "status": r.summary["status"],
        "crash_time_s": r.summary["crash_time_s"],
    }


def shooting_runs(case: str) -> int:
    """Free-flight runs the approach's shooting flies for ``case`` (``AP_RUNS``)."""
    seen: dict = {}
    real = setup_py.solve_approach

    def spy(**kw):
        seen.update(kw)
        return real(**kw)

    setup_py.solve_approach = spy
    try:
        prepare(scenario(case))
    finally:
        setup_py.solve_approach = real
    return int(approach_py.shooting_record(**seen)[AP_RUNS])


def bench_cpu(case: str, repeat: int) -> dict:
    """CPU time of the kernel (with its IMU record, as ``simulate()`` runs it), of
    ``simulate()`` and of ``prepare`` (its shooting apart), calls alternated."""
    sc = scenario(case)
    setup = prepare(sc)
    m = setup.model()
    simulate(sc)
    kernel, whole, prep, shoot = [], [], [], []
    for _ in range(repeat):
        t = time.thread_time()
        execute(m, n_imu=setup.n_imu, kernel=setup.kernel)
        kernel.append(time.thread_time() - t)
        t = time.thread_time()
        simulate(sc)
        whole.append(time.thread_time() - t)
        t = time.thread_time()
        s = prepare(sc)
        prep.append(time.thread_time() - t)
        shoot.append(s.kernel_cpu_s)
    return {
        "cpu_kernel_best_s": min(kernel),
        "cpu_kernel_median_s": statistics.median(kernel),
        "cpu_simulate_best_s": min(whole),
        "cpu_simulate_median_s": statistics.median(whole),
        "cpu_ratio_best": min(whole) / min(kernel),
        "cpu_ratio_median": statistics.median(whole) / statistics.median(kernel),
        "cpu_prepare_best_s": min(prep),
        "cpu_shooting_best_s": min(shoot),
        # what is neither loop: resolving, packing, checks, the summary (best of each)
        "cpu_python_best_s": min(whole) - min(kernel) - min(shoot),
        "shooting_runs": shooting_runs(case),
    }


def cold_start(model: str, cache_dir: str | None) -> dict:
    code = COLD_SNIPPET.format(
        h=EXAMPLE["heading_deg"], i=EXAMPLE["inclination_deg"], v=EXAMPLE["speed_m_s"], m=model
    )
    env = dict(os.environ)
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = cache_dir
    t = time.perf_counter()
    proc = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=False
    )
    process_s = time.perf_counter() - t
    if proc.returncode != 0:
        raise RuntimeError(f"cold-start subprocess failed:\n{proc.stderr}")
    res = json.loads(proc.stdout.strip().splitlines()[-1])
    res["process_s"] = process_s
    return res


def bench_cold(model: str) -> dict:
    cold_start(model, None)  # fills / refreshes the default on-disk cache
    cached = cold_start(model, None)
    with tempfile.TemporaryDirectory(prefix="quadimpact-numba-") as d:
        uncached = cold_start(model, d)
    return {"cached": cached, "uncached": uncached}


def fmt_ms(s: float) -> str:
    return f"{s * 1e3:.2f} ms"


def ms_pair(a: float, b: float) -> str:
    return f"{a * 1e3:.2f} / {b * 1e3:.2f} ms"


def python_share(r: dict) -> str:
    """The Python around the loops (best CPU time) and its share of the kernel's."""
    python = r["cpu_python_best_s"]
    return f"{fmt_ms(python)} ({python / r['cpu_kernel_best_s']:.2f})"


def report(info: dict, results: dict, repeat: int, cold: bool) -> str:
    lines = []
    lines.append(
        "quadimpact benchmark: paper example psi=45 deg, iota=15 deg, V_c=0.75 m/s,"
        " 3-s scenario (the first two stop at the crash; the last runs all 3 s)"
    )
    lines.append(
        f"machine: {info['cpu_model']}; os.cpu_count()={info['cpu_count']}"
        f" (affinity {info['cpu_affinity']}); single-threaded kernel"
    )
    lines.append(
        f"Python {info['python']}, NumPy {info['numpy']}, Numba {info['numba']}; repeats={repeat}"
    )
    lines.append("")
    w = 26
    head = f"{'':<34}" + "".join(f"{m:>{w}}" for m in results)
    lines.append(head)
    lines.append("-" * len(head))

    def row(label: str, fn) -> None:
        lines.append(f"{label:<34}" + "".join(f"{fn(r):>{w}}" for r in results.values()))

    row(f"kernel median (target < {TARGET_KERNEL_MS:g} ms)", lambda r: fmt_ms(r["kernel_median_s"]))
    row("kernel min", lambda r: fmt_ms(r["kernel_min_s"]))
    row("simulate() median", lambda r: fmt_ms(r["simulate_median_s"]))
    row("simulated span t0..t_end (s)", lambda r: f"{r['t_start_s']:.3f}..{r['t_end_s']:.3f}")
    row("accepted steps", lambda r: str(r["steps"]))
    row("rejected steps", lambda r: str(r["rejected_steps"]))
    row("RHS evaluations", lambda r: str(r["rhs_evaluations"]))
    row("control ticks", lambda r: str(r["control_ticks"]))
    row("ns per RHS evaluation", lambda r: f"{r['ns_per_rhs']:.0f}")
    lines.append("CPU time (thread_time), calls alternated:")
    row(
        "  kernel best / median",
        lambda r: ms_pair(r["cpu_kernel_best_s"], r["cpu_kernel_median_s"]),
    )
    row(
        "  simulate() best / median",
        lambda r: ms_pair(r["cpu_simulate_best_s"], r["cpu_simulate_median_s"]),
    )
    row(
        "  simulate()/kernel (target 1.2)",
        lambda r: f"{r['cpu_ratio_best']:.2f} / {r['cpu_ratio_median']:.2f}",
    )
    row("  prepare best", lambda r: fmt_ms(r["cpu_prepare_best_s"]))
    row("  of which shooting", lambda r: fmt_ms(r["cpu_shooting_best_s"]))
    row("  shooting runs", lambda r: str(r["shooting_runs"]))
    row("  Python (simulate-kernel-shooting)", python_share)
    if cold:
        results = {k: v for k, v in results.items() if "cold" in v}
        row(
            f"cold start, cache warm (< {TARGET_COLD_CACHED_S:g} s)",
            lambda r: f"{r['cold']['cached']['total_s']:.2f} s",
        )
        row("  of which import", lambda r: f"{r['cold']['cached']['import_s']:.2f} s")
        row("  whole process", lambda r: f"{r['cold']['cached']['process_s']:.2f} s")
        row("cold start, no cache (compile)", lambda r: f"{r['cold']['uncached']['total_s']:.2f} s")
        row("  whole process", lambda r: f"{r['cold']['uncached']['process_s']:.2f} s")
    lines.append("")
    ok_kernel = all(r["kernel_median_s"] * 1e3 < TARGET_KERNEL_MS for r in results.values())
    verdict = f"kernel target (< {TARGET_KERNEL_MS:g} ms): {'met' if ok_kernel else 'MISSED'}"
    if cold:
        ok_cold = all(
            r["cold"]["cached"]["total_s"] < TARGET_COLD_CACHED_S for r in results.values()
        )
        verdict += (
            f"; cold start with cache (< {TARGET_COLD_CACHED_S:g} s):"
            f" {'met' if ok_cold else 'MISSED'}"
        )
    lines.append(verdict)
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=50, help="timed repeats (default 50)")
    p.add_argument("--json", type=Path, help="also write all numbers to this JSON file")
    p.add_argument("--no-cold", action="store_true", help="skip the cold-start subprocesses")
    a = p.parse_args(argv)
    if a.repeat < 1:
        p.error("--repeat must be >= 1")

    info = machine_info()
    results = {}
    for case in CASES:
        r = bench_kernel(case, a.repeat)
        r.update(bench_simulate(case, a.repeat))
        r.update(bench_cpu(case, a.repeat))
        if not a.no_cold and case in MODELS:
            r["cold"] = bench_cold(case)
        results[case] = r
    print(report(info, results, a.repeat, not a.no_cold))
    if a.json:
        payload = {
            "example": EXAMPLE,
            "repeat": a.repeat,
            "targets": {"kernel_ms": TARGET_KERNEL_MS, "cold_cached_s": TARGET_COLD_CACHED_S},
            "machine": info,
            "results": results,
        }
        a.json.write_text(json.dumps(payload, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
