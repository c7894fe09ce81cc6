"""CPU per benchmark trial, per task and sensor set, against the wall's; before and after.

Run: ``python benchmarks/bench_trial_cost.py [--before /path/to/other/checkout]
[--tasks wall,pole,edge] [--sensors ideal,lab,onboard] [--wall-trials N]
[--grid-points N] [--row NAME] [--rounds R] [--json PATH]``.

The benchmark's quick suite (docs/BENCHMARK.md), one of its reference rows
(``--row``: ``default``, the default; ``classic``, ``recovery-replica``,
``pole-replica``, ``baseline``): each task's trials (``wall``: the Monte
Carlo's first ``--wall-trials``, default all 1,000; ``pole`` and ``edge``: the
quick grid's 240 points, or its first ``--grid-points``) with each sensor set.
Every trial is made, prepared, run and summarised in one process, serially,
as a sweep's worker does (``simulation.batch.BatchRunner``); its cost is the
CPU time of its compiled loop (``cost.kernel_cpu_s``, what the benchmark's
tables keep), with its accepted and rejected steps and contact onsets.

It prints, per task and sensor set: the median, mean, 99th percentile and
maximum CPU per trial (ms), the median and mean as a ratio to the wall's of
the same sensor set (target: at most 1.5), the maximum as a multiple of the
cell's median (target: at most 20) and what the slowest trial did (steps,
rejected steps, onsets).

With ``--before`` the same trials are run by another checkout too (its
``src``, in a fresh interpreter with Numba's cache warm, as
``compare_checkouts.py`` does), the two alternated ``--rounds`` times so
that the drift of a shared machine falls on both; a trial's CPU is its
least over the rounds. A checkout whose compiled code is not in Numba's
cache compiles it first (minutes), outside the measured trials.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parents[1]
TASK_NAMES = ("wall", "pole", "edge")
SENSOR_SETS = ("ideal", "lab", "onboard")
TARGET_RATIO = 1.5  # a pole or edge trial against a wall trial (median and mean)
TARGET_OUTLIER = 20.0  # the slowest trial against its cell's median

SNIPPET = r"""
import json, sys
from quadimpact.inputs.scenarios import scenario_from_dict
from quadimpact.simulation.batch import BatchRunner
from quadimpact.studies.benchmark.subject import REFERENCES
from quadimpact.studies.benchmark.suite import SUITE_VERSION, TASKS, sensor_set

tasks, sensors, wall_n, grid_n, row = json.loads(sys.argv[1])
subject = next(r for r in REFERENCES if r.name == row)
runner = BatchRunner()
out = {}
for task in tasks:
    for s in sensors:
        limit = wall_n if task == "wall" else grid_n
        spec = subject.spec(TASKS[task], True, sensor_set(s), limit or None, SUITE_VERSION)
        n = spec.n_runs
        scenarios = [scenario_from_dict(spec.scenario_dict(i)) for i in range(n)]
        runner.summary(scenarios[0])  # warm: the first run loads the compiled code
        cell = {"cpu_s": [], "steps": [], "rejected": [], "onsets": [], "status": []}
        for sc in scenarios:
            sm = runner.summary(sc)
            cell["cpu_s"].append(sm["cost"]["kernel_cpu_s"])
            cell["steps"].append(sm["integrator"]["steps"])
            cell["rejected"].append(sm["integrator"]["rejected_steps"])
            cell["onsets"].append(sm["n_episodes"])
            why = " (" + sm["reason"] + ")" if sm.get("reason") else ""
            cell["status"].append(sm["status"] + why)
        out[task + "/" + s] = cell
print(json.dumps(out))
"""


def run_in_checkout(checkout: Path, snippet: str, what: list) -> dict:
    """``snippet`` run with the JSON of ``what`` in a fresh interpreter importing
    ``checkout/src``; its last line of output, read as JSON (``compare_trial_bits.py``
    uses it too)."""
    env = dict(os.environ)
    env["PYTHONPATH"] = str(checkout / "src")
    proc = subprocess.run(
        [sys.executable, "-c", snippet, json.dumps(what)],
        env=env, capture_output=True, text=True, cwd=checkout,
    )  # fmt: skip
    if proc.returncode != 0:
        raise SystemExit(f"{checkout}: the runs failed:\n{proc.stderr[-3000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def measure(checkout: Path, what: list) -> dict:
    """One pass over the trials in a fresh interpreter importing ``checkout/src``."""
    return run_in_checkout(checkout, SNIPPET, what)


def least_over_rounds(rounds: list[dict]) -> dict:
    """Each trial's least CPU over the rounds (the counts are the same in every round)."""
    merged = {}
    for key in rounds[0]:
        cell = dict(rounds[0][key])
        cell["cpu_s"] = np.min([r[key]["cpu_s"] for r in rounds], axis=0).tolist()
        merged[key] = cell
    return merged


def cell_stats(cell: dict) -> dict:
    """Median, mean, p99 and max CPU (ms) of a cell, and its slowest trial."""
    cpu = 1e3 * np.asarray(cell["cpu_s"], dtype=float)
    i = int(np.argmax(cpu))
    med = float(np.median(cpu))
    return {
        "n": int(cpu.size),
        "median_ms": med,
        "mean_ms": float(cpu.mean()),
        "p99_ms": float(np.percentile(cpu, 99)),
        "max_ms": float(cpu[i]),
        "max_x_median": float(cpu[i] / med),
        "median_steps": float(np.median(np.add(cell["steps"], cell["rejected"]))),
        "us_per_step": float(
            1e3 * np.median(cpu / np.maximum(np.add(cell["steps"], cell["rejected"]), 1))
        ),
        "slowest": {
            "index": i,
            "steps": int(cell["steps"][i]),
            "rejected": int(cell["rejected"][i]),
            "onsets": int(cell["onsets"][i]),
            "status": cell["status"][i],
        },
        "failed": int(sum(1 for s in cell["status"] if s.startswith("failed"))),
    }


def table(stats: dict, title: str) -> list[str]:
    """The printed table of one checkout."""
    lines = [
        title,
        f"{'cell':<14} {'n':>5} {'median':>7} {'mean':>7} {'p99':>7} {'max':>8} "
        f"{'med/wall':>8} {'mean/wall':>9} {'max/med':>7} {'steps':>6} {'us/step':>7}  "
        "slowest: steps+rejected, onsets",
    ]  # fmt: skip
    for key, s in stats.items():
        sensors = key.split("/")[1]
        wall = stats.get(f"wall/{sensors}")
        rm = s["median_ms"] / wall["median_ms"] if wall else float("nan")
        ra = s["mean_ms"] / wall["mean_ms"] if wall else float("nan")
        w = s["slowest"]
        lines.append(
            f"{key:<14} {s['n']:>5} {s['median_ms']:>7.2f} {s['mean_ms']:>7.2f} "
            f"{s['p99_ms']:>7.2f} {s['max_ms']:>8.1f} {rm:>8.2f} {ra:>9.2f} "
            f"{s['max_x_median']:>7.1f} {s['median_steps']:>6.0f} {s['us_per_step']:>7.2f}  "
            f"{w['steps']}+{w['rejected']}, {w['onsets']}"
            + (f"  [{s['failed']} failed]" if s["failed"] else "")
        )
    return lines


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, help="another checkout, measured alternately")
    parser.add_argument("--after", type=Path, default=HERE, help="default: this checkout")
    parser.add_argument("--tasks", default=",".join(TASK_NAMES))
    parser.add_argument("--sensors", default=",".join(SENSOR_SETS))
    parser.add_argument("--wall-trials", type=int, default=0, help="0: all 1,000")
    parser.add_argument("--grid-points", type=int, default=0, help="0: all 240")
    parser.add_argument("--row", default="default", help="a reference row of the benchmark")
    parser.add_argument("--rounds", type=int, default=1)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    what = [args.tasks.split(","), args.sensors.split(","), args.wall_trials,
            args.grid_points, args.row]  # fmt: skip
    checkouts = {"after": args.after}
    if args.before is not None:
        checkouts = {"before": args.before, "after": args.after}
    rounds: dict[str, list[dict]] = {k: [] for k in checkouts}
    for _ in range(max(args.rounds, 1)):
        for name, path in checkouts.items():
            rounds[name].append(measure(path, what))
    load = os.getloadavg()[0]
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, "
          f"Python {platform.python_version()}, 1-min load {load:.1f} at the end")  # fmt: skip
    report = {}
    for name, path in checkouts.items():
        stats = {k: cell_stats(c) for k, c in least_over_rounds(rounds[name]).items()}
        report[name] = {"checkout": str(path), "cells": stats}
        print("\n".join(table(stats, f"\n{name}: {path} (CPU per trial, ms)")))
    if "before" in report:
        print("\nafter / before, per cell: median, mean, max")
        for key, a in report["after"]["cells"].items():
            b = report["before"]["cells"][key]
            ratios = [a[k] / b[k] for k in ("median_ms", "mean_ms", "max_ms")]
            print(f"{key:<14} " + " ".join(f"{r:>6.2f}" for r in ratios))
    if args.json:
        args.json.write_text(json.dumps({"report": report, "rounds": rounds}, indent=1))


if __name__ == "__main__":
    main()
