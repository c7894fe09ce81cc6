"""Where a benchmark command's time went, from the folder it wrote; the whole suite's estimate.

Run: ``python benchmarks/bench_suite_time.py DIR [--slow 5] [--json PATH]``
where ``DIR`` is the ``--out`` folder of ``quadimpact benchmark`` (quick or
whole). It reads every cell's trials (``cells/ROW/TASK-SENSORS/sweep/runs.parquet``,
the cells run by that command: a cached cell has no sweep there) and prints,
per row, task and sensor set:

* the trials, their CPU in all (``cost.total_cpu_s``: the trial from its
  scenario to its summary; its compiled loop's share apart);
* the median, 99th percentile and maximum CPU per trial (ms), the median as
  a ratio to the wall's of the same row and sensor set, the maximum as a
  multiple of the median (issue 59's bound: 20);
* the share of the cell's CPU spent in trials costing more than ``--slow``
  times its median (the slow tail);
* the cell's CPU in the whole suite: its mean per trial times the whole
  suite's trials of the task (10,000 on the wall, 3,266 per grid);
* below a cell whose slowest trial costs more than 20 times its median: that
  trial's id, its loop's CPU, its steps, rejected steps and contact onsets,
  and its status (why it cost so much).

A trial's CPU is its own: every process loads the compiled code before its
first trial (a warm-up run that is no trial), and a sweep's processes leave
the objects they held before the trials out of Python's full collections
(``sweep.worker.freeze_heap``). A trial that costs much more in all than in
its loop paid for something else of its process (docs/PERFORMANCE.md, "The
slowest trial").

The totals compare the trials' CPU with the command's: give the command's
own CPU and wall time (``/usr/bin/time -v``) to see what imports, compiling,
the cache, the report and the figures took (docs/PERFORMANCE.md, "Where the
time goes").
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from quadimpact.studies.benchmark.suite import TASKS

TARGET_OUTLIER = 20.0


def cells(folder: Path) -> list[tuple[str, str, str, pd.DataFrame]]:
    """(row, task, sensor set, trials) of every cell run into ``folder``."""
    found = []
    for path in sorted(folder.glob("cells/*/*/sweep/runs.parquet")):
        row, cell = path.parts[-4], path.parts[-3]
        task, _, sensors = cell.partition("-")
        cols = ["run_id", "cost__kernel_cpu_s", "cost__total_cpu_s", "integrator__steps",
                "integrator__rejected_steps", "n_episodes", "status", "reason"]  # fmt: skip
        found.append((row, task, sensors, pd.read_parquet(path, columns=cols)))
    return found


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("folder", type=Path, help="a `quadimpact benchmark --out` folder")
    p.add_argument("--slow", type=float, default=5.0, help="the slow tail: CPU > SLOW x median")
    p.add_argument("--json", type=Path, help="also write the figures to this JSON file")
    a = p.parse_args(argv)
    found = cells(a.folder)
    if not found:
        p.error(f"folder: no cell's trials under {a.folder}/cells (cached cells are not there)")
    whole = {name: task.size(False) for name, task in TASKS.items()}
    wall_median = {(r, s): float(d["cost__total_cpu_s"].median())
                   for r, t, s, d in found if t == "wall"}  # fmt: skip
    head = (f"{'row':<18}{'cell':<15}{'trials':>7}{'CPU s':>8}{'loop s':>8}{'median':>8}"
            f"{'p99':>8}{'max':>8}{'/wall':>7}{'max/med':>8}{'tail %':>7}"
            f"{'whole s':>9}")  # fmt: skip
    print(head + "\n" + "-" * len(head))
    rows, total, loops, tail, whole_cpu, n = [], 0.0, 0.0, 0.0, 0.0, 0
    for row, task, sensors, d in found:
        c = d["cost__total_cpu_s"].to_numpy()
        med = float(np.median(c))
        slow = c > a.slow * med
        ratio = med / wall_median[(row, sensors)] if (row, sensors) in wall_median else np.nan
        r = {"row": row, "task": task, "sensors": sensors, "trials": len(c),
             "cpu_s": float(c.sum()), "loop_cpu_s": float(d["cost__kernel_cpu_s"].sum()),
             "median_ms": med * 1e3, "p99_ms": float(np.quantile(c, 0.99)) * 1e3,
             "max_ms": float(c.max()) * 1e3, "median_to_wall": ratio,
             "max_to_median": float(c.max()) / med, "tail_share": float(c[slow].sum() / c.sum()),
             "whole_suite_cpu_s": float(c.mean()) * whole[task]}  # fmt: skip
        rows.append(r)
        total, loops, n = total + r["cpu_s"], loops + r["loop_cpu_s"], n + len(c)
        tail += float(c[slow].sum())
        whole_cpu += r["whole_suite_cpu_s"]
        flag = "" if r["max_to_median"] <= TARGET_OUTLIER else " *"
        print(f"{row:<18}{task + '-' + sensors:<15}{len(c):>7}{r['cpu_s']:>8.1f}"
              f"{r['loop_cpu_s']:>8.1f}{r['median_ms']:>8.2f}{r['p99_ms']:>8.1f}{r['max_ms']:>8.1f}"
              f"{ratio:>7.2f}{r['max_to_median']:>8.1f}{100 * r['tail_share']:>7.1f}"
              f"{r['whole_suite_cpu_s']:>9.1f}{flag}")  # fmt: skip
        if flag:
            w = d.iloc[int(np.argmax(c))]
            why = w["status"] + (f" ({w['reason']})" if w["reason"] else "")
            print(f"{'':<18}slowest: run {w['run_id']}, loop {1e3 * w['cost__kernel_cpu_s']:.1f} "
                  f"ms, {w['integrator__steps']} steps, {w['integrator__rejected_steps']} "
                  f"rejected, {w['n_episodes']} onsets, {why}")  # fmt: skip
    print(f"\n{n} trials: {total:.1f} s of CPU ({loops:.1f} s in their loops); "
          f"{100 * tail / total:.1f} % of it in trials costing more than {a.slow:g}x their "
          f"cell's median; on 2 idle cores {total / 2:.1f} s")  # fmt: skip
    print(f"the same rows and cells in the whole suite (per-trial means x {whole}): "
          f"{whole_cpu:.0f} s of CPU, {whole_cpu / 2 / 60:.1f} min on 2 idle cores")  # fmt: skip
    print(f"(* the slowest trial costs more than {TARGET_OUTLIER:g}x its cell's median)")
    if a.json:
        a.json.write_text(json.dumps({"cells": rows, "whole_suite_cpu_s": whole_cpu}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
