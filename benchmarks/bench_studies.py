"""Studies against their physics: what a study costs beyond its compiled loop, before and after.

Run: ``python benchmarks/bench_studies.py [--before CHECKOUT] [--rounds 2] [--n 2000]
[--skip-trials] [--skip-commands] [--json PATH]``

Machines differ and a shared machine drifts, so every measure is a ratio to
the compiled loop's own CPU time on the same runs, measured in the same round;
with ``--before`` the two checkouts are measured alternately, round after
round, each in fresh interpreters that import that checkout's ``src``
(``PYTHONPATH``), so that the drift of a busy machine falls on both. The
measures (the targets of issue 21):

1. **Recovery trials**: ``quadimpact.studies.recovery.recovery_study.run_trials`` of the
   authors' study, ``--n`` trials on 2 local worker processes, in a fresh
   process: the CPU time of every process of the sweep (this one during the
   sweep, the pool's fork server and its workers, reaped at the end) over the
   trials' compiled-loop CPU time (target <= 1.15); also the sweep's wall time
   x 2 processes over it.
2. **``quadimpact recovery --n N``**, the whole command in a fresh process
   (``--workers 2``): its wall time over (kernel sum / 2) (target <= 1.4), and
   its CPU time (all processes) over the kernel sum; again with
   ``--no-example`` (the study without its example trial), where the
   checkout has that flag.
3. **``simulate()``** of the paper's example (psi 45 deg, iota 15 deg, V_c
   0.75 m/s, both variants): its CPU time over all its compiled-loop CPU time
   (the main run and the approach's shooting runs) (target <= 1.15).
4. **The Figure 4 sweep command** (``quadimpact sweep`` of the 246-run grid,
   paper replica, ``--workers 2``): wall time over (kernel sum / 2) (target
   <= 1.5), and CPU time over the kernel sum.

The kernel sums of 1, 2 and 4 are measured in each round by a separate pass
in one process for each checkout, in that checkout (``--kernel-from``: one
checkout's passes for all): each run prepared, then ``core.kernel.BUILTIN.run``
into the output a sweep's run fills (``simulation.batch``: no rows, or rows
without contact columns, as the checkout has it) timed with ``time.thread_time``; a
wall approach's shooting runs timed the same way (or, where the approach solve is
compiled, the solve's own CPU time, ``RunSetup.kernel_cpu_s``). A checkout whose sweeps run
a cheaper loop thus has a smaller denominator: compare the CPU seconds too.
Where the table has the cost columns, the sum of ``cost__kernel_cpu_s`` is
given beside it. Rows marked
"own kernel" divide by the same runs' own loop time instead
(``cost__kernel_cpu_s`` of their table, measured as they ran): a busy machine's drift
between the runs and the separate pass does not enter them. CPU
time is ``time.thread_time``/``process_time`` and the children's
``RUSAGE_CHILDREN`` (the fork server is stopped and reaped, so that its
workers' time is counted). About 4 minutes per round and checkout at the
default ``--n`` on a loaded 2-core machine.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parents[1]
FIG4 = ["--grid", "heading_deg=0,45", "--grid", "inclination_deg=-20:20:1",
        "--grid", "speed_m_s=0.5,0.75,1.0", "--grid", "model=paper-replica"]  # fmt: skip

# Every snippet runs in a fresh interpreter of one checkout (after this prelude) and
# prints one JSON line.
_PRELUDE = r"""
import json, os, resource, statistics, sys, time
def children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime
def summary_output(m, n_imu):
    # the output a sweep's run fills (simulation.batch): no rows where the checkout's
    # loop keeps what the summary reads in its stats, rows without contact columns
    # where it has them, else full rows
    import inspect
    from quadimpact.core.records import new_output
    params = inspect.signature(new_output).parameters
    if "rows" in params:
        return new_output(m, n_imu, 1024, contact_columns=False, rows=False)
    if "contact_columns" in params:
        return new_output(m, n_imu, 1024, contact_columns=False)
    return new_output(m, n_imu, 1024)
def stop_server():
    import multiprocessing.forkserver as fs
    server = getattr(fs, "_forkserver", None)
    if server is not None and getattr(server, "_forkserver_pid", None):
        try:
            server._stop()  # reaped: its workers' CPU time counts in RUSAGE_CHILDREN
        except OSError:  # its socket already removed by the sweep's clean-up
            pass
"""

TRIALS = r"""
def main():
    n, out = int(sys.argv[1]), sys.argv[2]
    from quadimpact.studies.recovery.recovery_study import RecoveryStudy, run_trials
    study = RecoveryStudy(n=n)
    c0, w0 = time.process_time(), time.perf_counter()
    spec, table, info = run_trials(study, out, workers=2)
    c1, w1 = time.process_time(), time.perf_counter()
    stop_server()
    res = {"n": n, "wall_s": w1 - w0, "parent_cpu_s": c1 - c0, "children_cpu_s": children_cpu(),
           "backend": info["backend"]}
    if "cost__kernel_cpu_s" in table:
        res["table_kernel_cpu_s"] = float(table["cost__kernel_cpu_s"].sum())
        res["table_total_cpu_s"] = float(table["cost__total_cpu_s"].sum())
    print(json.dumps(res))
if __name__ == "__main__":
    main()
"""

KERNEL_TRIALS = r"""
n = int(sys.argv[1])
from quadimpact.core.kernel import BUILTIN
from quadimpact.inputs.scenarios import scenario_from_dict
from quadimpact.studies.recovery.recovery_study import RecoveryStudy
from quadimpact.simulation.setup import prepare
spec = RecoveryStudy(n=n).sweep_spec()
total = 0.0
for i in range(n):
    setup = prepare(scenario_from_dict(spec.scenario_dict(i)))
    m = setup.model()
    o = summary_output(m, setup.n_imu)
    if i == 0:
        BUILTIN.run(m, o)  # loaded, not counted
    t = time.thread_time()
    BUILTIN.run(m, o)
    total += time.thread_time() - t
print(json.dumps({"n": n, "kernel_cpu_s": total}))
"""

KERNEL_FIG4 = r"""
import quadimpact.simulation.approach as approach
from quadimpact.core.kernel import BUILTIN, execute
from quadimpact.inputs.scenarios import WallApproach
from quadimpact.simulation.setup import prepare
shooting = [0.0]
patched = hasattr(approach, "execute")  # else the approach solve is compiled: setup.kernel_cpu_s
if patched:  # the shooting runs, timed where they are called
    real = approach.execute
    def timed(*a, **k):
        t = time.thread_time(); r = real(*a, **k); shooting[0] += time.thread_time() - t; return r
    approach.execute = timed
main = 0.0
first = True
for h in (0.0, 45.0):
    for i in range(-20, 21):
        for v in (0.5, 0.75, 1.0):
            s = WallApproach(heading_deg=h, inclination_deg=float(i), speed_m_s=v,
                             model="paper-replica")
            setup = prepare(s)
            m = setup.model()
            o = summary_output(m, setup.n_imu)
            if first:
                BUILTIN.run(m, o); first = False; shooting[0] = 0.0
                setup = prepare(s)
            if not patched:
                shooting[0] += setup.kernel_cpu_s
            t = time.thread_time()
            BUILTIN.run(m, o)
            main += time.thread_time() - t
print(json.dumps({"runs": 246, "kernel_cpu_s": main + shooting[0], "main_cpu_s": main,
                  "shooting_cpu_s": shooting[0]}))
"""

SIMULATE = r"""
repeat = int(sys.argv[1])
import quadimpact.simulation.approach as approach
from quadimpact import WallApproach, simulate
from quadimpact.core.kernel import execute
from quadimpact.simulation.setup import prepare
res = {}
for model in ("paper-replica", "default"):
    s = WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75, model=model)
    for _ in range(3):
        simulate(s)
    sims, mains, shoots = [], [], []
    for _ in range(repeat):
        t = time.thread_time(); simulate(s); sims.append(time.thread_time() - t)
        if hasattr(approach, "execute"):  # the shooting runs, timed where they are called
            spent = [0.0]
            real = approach.execute
            def timed(*a, **k):
                t = time.thread_time(); r = real(*a, **k); spent[0] += time.thread_time() - t
                return r
            approach.execute = timed
            try:
                setup = prepare(s)
            finally:
                approach.execute = real
            shoots.append(spent[0])
        else:  # the approach solve compiled: its time is recorded on the setup
            setup = prepare(s)
            shoots.append(setup.kernel_cpu_s)
        m = setup.model()
        t = time.thread_time(); execute(m, n_imu=setup.n_imu); mains.append(time.thread_time() - t)
    sim, main, shoot = (statistics.median(x) for x in (sims, mains, shoots))
    res[model] = {"simulate_ms": 1e3 * sim, "main_kernel_ms": 1e3 * main,
                  "shooting_kernel_ms": 1e3 * shoot, "ratio": sim / (main + shoot)}
print(json.dumps(res))
"""

COMMAND = r"""
if __name__ == "__main__":  # the pool's workers import this script: no command there
    import atexit
    atexit.register(stop_server)  # registered first: runs last, after the command's clean-up
    sys.argv = ["quadimpact", *sys.argv[1:]]
    from quadimpact.cli import main
    main()
"""


def _python(checkout: Path, code: str, *args: str, quiet: bool = True) -> dict[str, Any]:
    """Run ``code`` in a fresh interpreter importing ``checkout/src``; its last JSON line."""
    env = dict(os.environ, PYTHONPATH=str(checkout / "src"))
    with tempfile.TemporaryDirectory() as tmp:
        script = Path(tmp) / "snippet.py"  # a file: the pool's workers import the main module
        script.write_text(_PRELUDE + code)
        proc = subprocess.run([sys.executable, str(script), *args], env=env, cwd=tmp,
                              capture_output=True, text=True, check=False)  # fmt: skip
    if proc.returncode != 0:
        raise RuntimeError(f"{checkout}: snippet failed:\n{proc.stderr[-3000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def _command(checkout: Path, *args: str) -> dict[str, float]:
    """Wall and CPU time (all processes, the fork server reaped) of a ``quadimpact`` command."""
    env = dict(os.environ, PYTHONPATH=str(checkout / "src"))
    with tempfile.TemporaryDirectory() as tmp:
        script = Path(tmp) / "command.py"
        script.write_text(_PRELUDE + COMMAND)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t = time.perf_counter()
        proc = subprocess.run([sys.executable, str(script), *args, "--out", str(Path(tmp) / "o")],
                              env=env, cwd=tmp, capture_output=True, text=True)  # fmt: skip
        wall = time.perf_counter() - t
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if proc.returncode != 0:
            raise RuntimeError(f"{checkout}: {' '.join(args)} failed:\n{proc.stderr[-3000:]}")
        table = Path(tmp) / "o" / ("trials.parquet" if args[0] == "recovery" else "runs.parquet")
        kernel = None
        try:
            import pyarrow.parquet as pq

            t = pq.read_table(table)
            if "cost__kernel_cpu_s" in t.column_names:
                kernel = float(sum(v for v in t.column("cost__kernel_cpu_s").to_pylist() if v))
        except Exception:
            pass
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    return {"wall_s": wall, "cpu_s": cpu, "table_kernel_cpu_s": kernel}


def machine() -> dict[str, Any]:
    """The machine (``bench_sweep.machine_info``) and its load average at the start."""
    from bench_sweep import machine_info  # this folder is on the path of a script run

    return {**machine_info(), "load_average": os.getloadavg()}


def one_round(name: str, checkout: Path, args: argparse.Namespace, kernels: dict) -> dict:
    r: dict[str, Any] = {}
    if not args.skip_trials:
        with tempfile.TemporaryDirectory() as tmp:
            t = _python(checkout, TRIALS, str(args.n), str(Path(tmp) / "study"))
        k = kernels["trials"]
        t["cpu_s"] = t["parent_cpu_s"] + t["children_cpu_s"]
        t["cpu_ratio"] = t["cpu_s"] / k
        t["wall_ratio"] = t["wall_s"] * 2 / k
        if "table_kernel_cpu_s" in t:  # the same runs' own loops: no separate pass's drift
            t["cpu_ratio_own"] = t["cpu_s"] / t["table_kernel_cpu_s"]
        r["trials"] = t
    r["simulate"] = _python(checkout, SIMULATE, str(args.repeat))
    if not args.skip_commands:
        c = _command(checkout, "recovery", "--n", str(args.n), "--workers", "2", "--no-progress")
        c["wall_ratio"] = c["wall_s"] / (kernels["trials"] / 2)
        c["cpu_ratio"] = c["cpu_s"] / kernels["trials"]
        if c.get("table_kernel_cpu_s"):
            c["wall_ratio_own"] = c["wall_s"] / (c["table_kernel_cpu_s"] / 2)
        r["recovery_command"] = c
        try:  # the study alone: no example trial (a checkout without the flag: no row)
            c = _command(checkout, "recovery", "--n", str(args.n), "--workers", "2",
                         "--no-progress", "--no-example")  # fmt: skip
        except RuntimeError:
            c = None
        if c is not None:
            c["wall_ratio"] = c["wall_s"] / (kernels["trials"] / 2)
            c["cpu_ratio"] = c["cpu_s"] / kernels["trials"]
            if c.get("table_kernel_cpu_s"):
                c["wall_ratio_own"] = c["wall_s"] / (c["table_kernel_cpu_s"] / 2)
            r["recovery_no_example"] = c
        c = _command(checkout, "sweep", *FIG4, "--workers", "2", "--no-progress")
        c["wall_ratio"] = c["wall_s"] / (kernels["fig4"] / 2)
        c["cpu_ratio"] = c["cpu_s"] / kernels["fig4"]
        if c.get("table_kernel_cpu_s"):
            c["wall_ratio_own"] = c["wall_s"] / (c["table_kernel_cpu_s"] / 2)
        r["fig4_command"] = c
    print(f"  {name}: " + json.dumps(r), flush=True)
    return r


def _median(rounds: list[dict], *path: str) -> float:
    values = []
    for r in rounds:
        for key in path:
            r = r.get(key, {}) if isinstance(r, dict) else {}
        if isinstance(r, (int, float)):
            values.append(float(r))
    return statistics.median(values) if values else float("nan")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, help="another checkout, measured alternately")
    parser.add_argument("--after", type=Path, default=HERE, help="default: this checkout")
    parser.add_argument("--kernel-from", type=Path, help="checkout of every kernel pass "
                        "(default: each checkout its own)")  # fmt: skip
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--n", type=int, default=2000, help="recovery trials")
    parser.add_argument("--repeat", type=int, default=20, help="simulate() calls per variant")
    parser.add_argument("--skip-trials", action="store_true")
    parser.add_argument("--skip-commands", action="store_true")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    checkouts = {"after": args.after.resolve()}
    if args.before is not None:
        checkouts = {"before": args.before.resolve(), **checkouts}
    info = machine()
    print(f"machine: {info}", flush=True)
    for path in {*checkouts.values(), *([args.kernel_from] if args.kernel_from else [])}:
        _python(path.resolve(), SIMULATE, "1")  # compile or load each checkout's cache
    rounds: dict[str, list[dict]] = {k: [] for k in checkouts}
    kernel_rounds: list[dict] = []
    for k in range(args.rounds):
        for name, path in checkouts.items():
            source = args.kernel_from.resolve() if args.kernel_from else path
            kernels: dict[str, Any] = {"checkout": name}
            if not (args.skip_trials and args.skip_commands):
                kernels["trials"] = _python(source, KERNEL_TRIALS, str(args.n))["kernel_cpu_s"]
            if not args.skip_commands:
                kernels["fig4"] = _python(source, KERNEL_FIG4)["kernel_cpu_s"]
            kernel_rounds.append(kernels)
            print(f"round {k + 1}, {name}: kernel sums (CPU s) {kernels}", flush=True)
            rounds[name].append(one_round(name, path, args, kernels))
    print(f"\nmedians over {args.rounds} rounds (CPU and wall times in s; ratios to the "
          "compiled loop's CPU time of the same runs):")  # fmt: skip
    rows = [
        ("recovery trials: CPU all processes / kernel", ("trials", "cpu_ratio")),
        ("recovery trials: CPU all processes / own kernel", ("trials", "cpu_ratio_own")),
        ("recovery trials: sweep wall x 2 / kernel", ("trials", "wall_ratio")),
        ("recovery trials: CPU all processes (s)", ("trials", "cpu_s")),
        ("recovery trials: table's kernel sum (s)", ("trials", "table_kernel_cpu_s")),
        ("recovery trials: table's total sum (s)", ("trials", "table_total_cpu_s")),
        (f"recovery --n {args.n}: wall / (kernel / 2)", ("recovery_command", "wall_ratio")),
        (f"recovery --n {args.n}: wall / (own kernel / 2)", ("recovery_command", "wall_ratio_own")),
        (f"recovery --n {args.n}: CPU / kernel", ("recovery_command", "cpu_ratio")),
        (f"recovery --n {args.n}: wall (s)", ("recovery_command", "wall_s")),
        ("  --no-example: wall / (kernel / 2)", ("recovery_no_example", "wall_ratio")),
        ("  --no-example: wall / (own kernel / 2)", ("recovery_no_example", "wall_ratio_own")),
        ("  --no-example: CPU / kernel", ("recovery_no_example", "cpu_ratio")),
        ("  --no-example: wall (s)", ("recovery_no_example", "wall_s")),
        ("simulate() paper-replica / all kernel", ("simulate", "paper-replica", "ratio")),
        ("simulate() default / all kernel", ("simulate", "default", "ratio")),
        ("simulate() paper-replica (ms)", ("simulate", "paper-replica", "simulate_ms")),
        ("simulate() default (ms)", ("simulate", "default", "simulate_ms")),
        ("Figure 4 sweep command: wall / (kernel / 2)", ("fig4_command", "wall_ratio")),
        ("Figure 4 sweep command: wall / (own kernel / 2)", ("fig4_command", "wall_ratio_own")),
        ("Figure 4 sweep command: CPU / kernel", ("fig4_command", "cpu_ratio")),
        ("Figure 4 sweep command: wall (s)", ("fig4_command", "wall_s")),
    ]
    print(f"{'measure':48s}" + "".join(f"{k:>12s}" for k in checkouts))
    for label, path in rows:
        values = [_median(rounds[k], *path) for k in checkouts]
        if all(v != v for v in values):
            continue
        print(f"{label:48s}" + "".join(f"{v:12.3f}" for v in values))
    for key in ("trials", "fig4"):
        for name in checkouts:
            values = [r[key] for r in kernel_rounds if key in r and r["checkout"] == name]
            if values:
                text = ", ".join(f"{v:.2f}" for v in values)
                print(f"kernel sum {key}, {name}: {text} s CPU")
    if args.json:
        report = {"machine": info, "args": {k: str(v) for k, v in vars(args).items()},
                  "kernels": kernel_rounds, "rounds": rounds}  # fmt: skip
        args.json.write_text(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
