"""What a plug-in controller costs to compile and to fly, and what the simulator costs to compile.

Run: ``python benchmarks/bench_plugin_compile.py [--before CHECKOUT] [--rounds 2]
[--repeat 40] [--trials 20] [--cold] [--profile-cold] [--json PATH]``

Each measure runs in fresh interpreters that import a checkout's ``src``
(``PYTHONPATH``), with Numba's disk cache warm unless said otherwise. With
``--before`` the other checkout is measured alternately with this one, round
after round, so that a loaded machine disturbs both alike. The plug-in is
the built-in ``paper`` law registered again as a plug-in (``same-paper``:
its step calls ``paper_step``, its parameters packed by the built-in packer),
written to a new file in every process, so that it is new to that process;
a run of it gives the built-in run's numbers, bit for bit (checked here).

* **first run**: a fresh interpreter registers the plug-in and runs
  ``quadimpact run`` (the paper's example: heading 45 deg, inclination 15 deg,
  0.75 m/s, a wall approach; ``--out`` a temporary folder) with it, against
  the same command with the built-in law: wall and CPU time of the whole
  process, and the CPU time it reports as compiling plug-ins;
* **per process**: a fresh interpreter prepares, runs and summarises
  ``--trials`` impact trials (``simulate_batch``, what a sweep worker does)
  with the plug-in, against the built-in: the CPU the plug-in adds to a
  worker process, and the part of it reported as compile time
  (``compile_cpu_s``, apart from the trials' CPU);
* **loop**: in one process, the compiled loop alone (``core.kernel.execute``)
  on the example's prepared run, with the plug-in and with the built-in law,
  alternately, median of ``--repeat`` calls each: the ratio;
* **cold compile** (``--cold``): ``quadimpact compile --no-environments``
  with ``NUMBA_CACHE_DIR`` an empty temporary folder: the CPU time of
  compiling the whole simulator. ``--profile-cold`` adds, for this checkout,
  where that time goes: the compiled functions with the most compile time of
  their own (Numba's compile events, nested times subtracted) and how many
  specialisations of each were compiled.
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
import textwrap
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent
PYTHON = sys.executable

PLUGIN = """
from numba import njit
from quadimpact import register_controller
from quadimpact.core.controllers.paper import paper_step
from quadimpact.core.layout import CTRL_PAPER
from quadimpact.inputs.controllers import controller_entry
from quadimpact.packing.controller_block import BUILTIN_PACKERS


@njit
def same_paper_step(t, meas, ctrl, mem, veh, dt, cmd):
    paper_step(t, meas, ctrl, mem, veh, dt, cmd)


register_controller(
    "same-paper", step=same_paper_step, params=controller_entry("paper").params,
    pack=BUILTIN_PACKERS[CTRL_PAPER], replace=True,
)
"""

EXAMPLE = ["--heading", "45", "--inclination", "15", "--speed", "0.75"]

FIRST_RUN = """
import sys, tempfile, time, json
import importlib.util
plugin = sys.argv[1]
law = "paper"
if plugin != "-":
    spec = importlib.util.spec_from_file_location("bench_plugin", plugin)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    law = "same-paper"
from quadimpact.cli import main
out = tempfile.mkdtemp()
try:
    main(["run", *sys.argv[2:], "--controller", law, "--out", out + "/run"])
except SystemExit:
    pass
from quadimpact.simulation import plugin_kernel
print(json.dumps({"compile_cpu_s": plugin_kernel.compile_cpu_total(),
                  "cpu_s": time.process_time()}))
"""

PER_PROCESS = """
import sys, time, json, importlib.util
plugin, n = sys.argv[1], int(sys.argv[2])
law = "paper"
if plugin != "-":
    spec = importlib.util.spec_from_file_location("bench_plugin", plugin)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    law = "same-paper"
from quadimpact import ImpactTrial, simulate_batch
trials = [ImpactTrial(controller=law, pitch_deg=-20.0 + 2.0 * i, speed_m_s=1.5, seed=i)
          for i in range(n)]
rows = simulate_batch(trials)
def cost(row, key):
    part = row.get("cost") if isinstance(row.get("cost"), dict) else {}
    return float(part.get(key, row.get("cost__" + key, 0.0)))
print(json.dumps({
    "cpu_s": time.process_time(),
    "compile_cpu_s": sum(cost(r, "compile_cpu_s") for r in rows),
    "trial_cpu_s": sum(cost(r, "total_cpu_s") for r in rows),
    "outcomes": [str(r.get("outcome")) for r in rows],
}))
"""

LOOP = """
import sys, time, json, statistics, importlib.util
import numpy as np
plugin, repeat = sys.argv[1], int(sys.argv[2])
spec = importlib.util.spec_from_file_location("bench_plugin", plugin)
module = importlib.util.module_from_spec(spec)
spec.loader.exec_module(module)
from quadimpact import WallApproach
from quadimpact.core.kernel import BUILTIN, execute
from quadimpact.core.records import new_output
from quadimpact.simulation.setup import prepare
setups = {law: prepare(WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75,
                                    controller=law)) for law in ("paper", "same-paper")}
models = {law: s.model() for law, s in setups.items()}
outputs = {law: new_output(models[law], s.n_imu, 1024) for law, s in setups.items()}
def once(law):
    # the loop alone, on outputs allocated once (fresh pages would be timed otherwise)
    run = (setups[law].kernel or BUILTIN).run
    started = time.perf_counter()
    run(models[law], outputs[law])
    return time.perf_counter() - started, None
records = {law: execute(models[law], n_imu=s.n_imu, kernel=s.kernel)
           for law, s in setups.items()}  # the plug-in's loop compiles here (before)
same = all(np.array_equal(getattr(records["paper"], f), getattr(records["same-paper"], f),
                          equal_nan=True) for f in ("out", "episodes", "stats"))
times = {law: [] for law in setups}
for _ in range(repeat):
    for law in setups:
        times[law].append(once(law)[0])
print(json.dumps({"builtin_ms": 1e3 * statistics.median(times["paper"]),
                  "plugin_ms": 1e3 * statistics.median(times["same-paper"]),
                  "builtin_min_ms": 1e3 * min(times["paper"]),
                  "plugin_min_ms": 1e3 * min(times["same-paper"]),
                  "bit_identical": bool(same)}))
"""

COLD = """
import json, time
from quadimpact.cli import main
try:
    main(["compile", "--no-environments"])
except SystemExit:
    pass
print(json.dumps({"process_cpu_s": time.process_time()}))
"""

PROFILE = """
import sys, time, json, collections
from numba.core import event
stack, own, total, count = [], collections.Counter(), collections.Counter(), collections.Counter()
class Listener(event.Listener):
    def on_start(self, ev):
        stack.append([ev.data["dispatcher"].py_func.__module__ + "."
                      + ev.data["dispatcher"].py_func.__qualname__, time.process_time(), 0.0])
    def on_end(self, ev):
        name, started, nested = stack.pop()
        spent = time.process_time() - started
        own[name] += spent - nested
        total[name] += spent
        count[name] += 1
        if stack:
            stack[-1][2] += spent
event.register("numba:compile", Listener())
from quadimpact.cli import main
try:
    main(["compile", "--no-environments"])
except SystemExit:
    pass
print(json.dumps({"cpu_s": time.process_time(), "own": own.most_common(25),
                  "count": {k: count[k] for k, _ in own.most_common(25)},
                  "functions": len(count), "specialisations": sum(count.values())}))
"""


def _child(src: Path, code: str, *args: str, env: dict | None = None) -> tuple[dict, float, float]:
    """Run ``code`` in a fresh interpreter on checkout ``src``: its JSON line, wall s, CPU s."""
    environ = dict(os.environ, PYTHONPATH=str(src), **(env or {}))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    done = subprocess.run(
        [PYTHON, "-c", code, *args], env=environ, capture_output=True, text=True, check=False
    )
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    lines = [ln for ln in done.stdout.splitlines() if ln.startswith("{")]
    if done.returncode != 0 or not lines:
        raise RuntimeError(f"{src}: child failed:\n{done.stdout[-2000:]}\n{done.stderr[-3000:]}")
    return json.loads(lines[-1]), wall, cpu


def _plugin_file(folder: Path, i: int) -> Path:
    path = folder / f"same_paper_{i}.py"
    path.write_text(textwrap.dedent(PLUGIN))
    return path


def _first_run(src: Path, folder: Path, i: int) -> dict:
    """One fresh command with the plug-in and one with the built-in law."""
    row = {}
    _child(src, FIRST_RUN, "-", *EXAMPLE)  # warm: this checkout's cache, the disk
    for label, plugin in (("builtin", "-"), ("plugin", str(_plugin_file(folder, i)))):
        got, wall, cpu = _child(src, FIRST_RUN, plugin, *EXAMPLE)
        row[label] = {"wall_s": wall, "cpu_s": cpu, "compile_cpu_s": got["compile_cpu_s"]}
    return row


def _per_process(src: Path, folder: Path, i: int, trials: int) -> dict:
    row = {}
    for label, plugin in (("builtin", "-"), ("plugin", str(_plugin_file(folder, 100 + i)))):
        got, wall, cpu = _child(src, PER_PROCESS, plugin, str(trials))
        row[label] = {
            "wall_s": wall,
            "cpu_s": cpu,
            "compile_cpu_s": got["compile_cpu_s"],
            "trial_cpu_s": got["trial_cpu_s"],
            "outcomes": got["outcomes"],
        }
    return row


def _cold(src: Path, profile: bool) -> dict:
    """``quadimpact compile --no-environments`` in a fresh interpreter with an empty cache."""
    cache = tempfile.mkdtemp(prefix="bench-cold-")
    try:
        got, wall, cpu = _child(src, PROFILE if profile else COLD, env={"NUMBA_CACHE_DIR": cache})
    finally:
        shutil.rmtree(cache, ignore_errors=True)
    return {**got, "wall_s": wall, "cpu_s": cpu}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--before", type=Path, help="another checkout, measured alternately")
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=40)
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--cold", action="store_true")
    parser.add_argument("--profile-cold", action="store_true")
    parser.add_argument(
        "--skip", default="", help="comma list of parts to skip: first,process,loop"
    )
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    checkouts = {"after": HERE / "src"}
    if args.before is not None:
        checkouts = {"before": args.before.resolve() / "src", **checkouts}
    skip = set(filter(None, args.skip.split(",")))
    results: dict = {name: {"first": [], "process": [], "loop": []} for name in checkouts}
    folder = Path(tempfile.mkdtemp(prefix="bench-plugin-"))
    for r in range(args.rounds):
        for name, src in checkouts.items():
            if "first" not in skip:
                results[name]["first"].append(_first_run(src, folder, 10 * r))
            if "process" not in skip:
                results[name]["process"].append(_per_process(src, folder, r, args.trials))
            if "loop" not in skip:
                got, _, _ = _child(src, LOOP, str(_plugin_file(folder, 200 + r)), str(args.repeat))
                results[name]["loop"].append(got)
            print(f"round {r + 1} {name} done", file=sys.stderr, flush=True)
    for name, src in checkouts.items():
        if args.cold or args.profile_cold:
            results[name]["cold"] = _cold(src, args.profile_cold and name == "after")
    _report(results)
    if args.json:
        args.json.write_text(json.dumps(results, indent=2))


def _med(rows: list, *keys: str) -> float:
    values = []
    for row in rows:
        for k in keys:
            row = row[k]
        values.append(row)
    return statistics.median(values) if values else float("nan")


def _adds(rows: list, key: str) -> float:
    """Median plug-in value minus median built-in value of ``key``."""
    return _med(rows, "plugin", key) - _med(rows, "builtin", key)


def _report(results: dict) -> None:
    load = os.getloadavg()[0]
    print(f"machine: {os.cpu_count()} CPUs, load {load:.1f}; Python {sys.version.split()[0]}")
    for name, res in results.items():
        print(f"\n== {name}")
        if res["first"]:
            f = res["first"]
            print("first run (fresh interpreter, warm cache, quadimpact run of the paper example):")
            for label in ("builtin", "plugin"):
                print(
                    f"  {label:8s} wall {_med(f, label, 'wall_s'):6.2f} s  CPU "
                    f"{_med(f, label, 'cpu_s'):6.2f} s  (compiling plug-ins "
                    f"{_med(f, label, 'compile_cpu_s'):5.2f} s)"
                )
            print(
                f"  plug-in adds: wall {_adds(f, 'wall_s'):+.2f} s, CPU {_adds(f, 'cpu_s'):+.2f} s"
            )
        if res["process"]:
            p = res["process"]
            print("per worker process (fresh interpreter, impact trials via simulate_batch):")
            for label in ("builtin", "plugin"):
                print(
                    f"  {label:8s} CPU {_med(p, label, 'cpu_s'):6.2f} s  trials' CPU "
                    f"{_med(p, label, 'trial_cpu_s'):6.3f} s  compile (apart) "
                    f"{_med(p, label, 'compile_cpu_s'):5.2f} s"
                )
            same = all(row["builtin"]["outcomes"] == row["plugin"]["outcomes"] for row in p)
            print(
                f"  plug-in adds: CPU {_adds(p, 'cpu_s'):+.2f} s per process; same outcomes: {same}"
            )
        if res["loop"]:
            lp = res["loop"]
            b, q = _med(lp, "builtin_ms"), _med(lp, "plugin_ms")
            bm, qm = min(r["builtin_min_ms"] for r in lp), min(r["plugin_min_ms"] for r in lp)
            same = all(r["bit_identical"] for r in lp)
            print(
                f"loop alone (median): built-in {b:.3f} ms, plug-in {q:.3f} ms, ratio {q / b:.3f}; "
                f"best {bm:.3f} / {qm:.3f} ms, ratio {qm / bm:.3f}; bit-identical: {same}"
            )
        if "cold" in res:
            c = res["cold"]
            print(
                f"cold compile (quadimpact compile --no-environments, empty cache): "
                f"CPU {c['cpu_s']:.1f} s, wall {c['wall_s']:.1f} s"
            )
            if "own" in c:
                print(
                    f"  {c['functions']} functions, {c['specialisations']} specialisations "
                    "compiled; the most compile CPU of their own:"
                )
                for fn, s in c["own"]:
                    print(f"  {s:7.2f} s  x{c['count'][fn]:<3d} {fn}")


if __name__ == "__main__":
    main()
