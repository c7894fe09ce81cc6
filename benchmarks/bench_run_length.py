"""How long suite 2's trials must run: when the default law's held hover is complete.

Flies the default law on the quick suite's tasks with 6-s runs (suite 2's
trials otherwise: a ground that ends a run when touched) and prints, per task,
the share of trials whose held hover (docs/BENCHMARK.md 1.2) is complete by a
run length L, for L from 2.5 to 6 s, and the quantiles of the completion time.
Suite 2's run length (4 s, ``quadimpact.studies.benchmark.suite.RUN_LENGTH_S``)
is the shortest whole second at which the wall's share with the ideal sensors
is at least 95 %.

Run: ``python benchmarks/bench_run_length.py --out DIR [--sensors ideal|lab]
[--limit N]`` (the quick suite with ideal sensors: about 2 min of CPU).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from quadimpact.studies.benchmark.subject import REFERENCES
from quadimpact.studies.benchmark.suite import TASKS, sensor_set
from quadimpact.sweep import SweepSpec, read_runs, run_sweep

LENGTHS_S = (2.5, 3.0, 3.5, 4.0, 4.5, 5.0, 6.0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="Folder for the sweeps.")
    parser.add_argument("--sensors", default="ideal", choices=("ideal", "lab"))
    parser.add_argument("--limit", type=int, default=None, help="Only the first N runs.")
    args = parser.parse_args()
    default = next(r for r in REFERENCES if r.name == "default")
    for name, task in TASKS.items():
        spec = default.spec(task, True, sensor_set(args.sensors), args.limit)
        base = {**spec.base, "final_time_s": 6.0}
        spec = SweepSpec(base=base, grid=spec.grid or None, runs=spec.runs,
                         trials=spec.trials, where=name)  # fmt: skip
        where = Path(args.out) / f"{name}-{args.sensors}"
        run_sweep(spec, where, progress=False, load=False)
        r = read_runs(where)
        held = r["held_hover"].fillna(False).to_numpy(dtype=bool)
        done = (r["first_contact_s"] + r["time_to_held_hover_s"] + 0.5).to_numpy(dtype=float)
        shares = "  ".join(f"{L:g} s: {np.mean(held & (done <= L)):.3f}" for L in LENGTHS_S)
        q = np.nanpercentile(done[held], [50, 90, 99, 100]) if held.any() else [np.nan] * 4
        print(f"{name} {args.sensors} ({len(r)} trials): held hover complete by {shares}")
        print(f"    completion p50 / p90 / p99 / max: {' / '.join(f'{x:.2f}' for x in q)} s")


if __name__ == "__main__":
    main()
