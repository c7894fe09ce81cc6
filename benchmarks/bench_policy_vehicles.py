"""A learned policy against the default law on vehicles it was not trained on (issue 61).

Flies the first ``--n`` trials of the quick wall task of the benchmark's latest
suite (and, with ``--tasks wall,pole``, the quick grid) with the default law and
with the law plus the policy, on the same trials, for each vehicle and sensor
set, and prints each one's held-hover success (the benchmark's criterion) with
its 95 % interval and the paired difference::

    python benchmarks/bench_policy_vehicles.py --policy learned --out /tmp/robust

The vehicles: ``navi`` (what the policy was trained on), ``spiri``, and
``navi-heavy``, the Navi with 20 % more mass (``vehicle_overrides.mass_kg``). Trials the bumper
model cannot hold are counted out, as in every study.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from quadimpact.inputs.vehicle import load_vehicle
from quadimpact.studies.benchmark.cells import cell_numbers, cell_table
from quadimpact.studies.benchmark.paired import paired_difference
from quadimpact.studies.benchmark.subject import Subject
from quadimpact.studies.benchmark.suite import TASKS, sensor_set
from quadimpact.sweep import SweepSpec
from quadimpact.sweep.runner import run_sweep


def _vehicles() -> dict[str, dict]:
    """Name -> the scenario fields that fly that vehicle."""
    navi_mass_kg = load_vehicle("navi").mass_kg
    return {
        "navi": {"vehicle": "navi"},
        "spiri": {"vehicle": "spiri"},
        "navi-heavy": {
            "vehicle": "navi",
            "vehicle_overrides": {"mass_kg": 1.2 * navi_mass_kg},
        },
    }


def _fly(row: Subject, task: str, sensors: str, n: int, changes: dict, folder: Path, workers):
    spec = row.spec(TASKS[task], True, sensor_set(sensors, row.estimator), limit=n)
    spec = SweepSpec(
        base={**spec.base, **changes}, grid=spec.grid or None, runs=spec.runs,
        trials=spec.trials, where=row.name,
    )  # fmt: skip
    runs = run_sweep(spec, folder, workers=workers, progress=False)
    return cell_table(runs, spec, TASKS[task])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--policy", default="learned", help="learned or a policy file")
    ap.add_argument("--n", type=int, default=1000, help="trials per cell (the quick task's first)")
    ap.add_argument("--tasks", default="wall", help="comma-separated: wall, pole, edge")
    ap.add_argument("--sensors", default="onboard,ideal", help="comma-separated sensor sets")
    ap.add_argument("--vehicles", default=None, help="comma-separated (default: all three)")
    ap.add_argument("--out", type=Path, required=True, help="folder for the sweeps")
    ap.add_argument("--workers", type=int, default=None)
    args = ap.parse_args()
    vehicles = _vehicles()
    chosen = [v.strip() for v in (args.vehicles or ",".join(vehicles)).split(",")]
    law, policy = Subject("default"), Subject("policy", kind="policy", policy=args.policy)
    print(f"{'vehicle':18s} {'task':5s} {'sensors':8s} {'law':>22s} {'policy':>22s} "
          f"{'policy - law (paired)':>24s}  s")  # fmt: skip
    for vehicle in chosen:
        for task in [t.strip() for t in args.tasks.split(",")]:
            for sensors in [s.strip() for s in args.sensors.split(",")]:
                t0 = time.perf_counter()
                tables = {
                    r.name: _fly(r, task, sensors, args.n, vehicles[vehicle],
                                 args.out / f"{vehicle}-{task}-{sensors}-{r.name}", args.workers)
                    for r in (law, policy)
                }  # fmt: skip
                a, b = tables["default"], tables["policy"]
                both = a["valid"].astype(bool) & b["valid"].astype(bool)
                pa = a["success"].astype(bool)[both].to_numpy()
                pb = b["success"].astype(bool)[both].to_numpy()
                d = paired_difference(pb, pa)
                cells = []
                for t in (a, b):
                    x = cell_numbers(t)
                    cells.append(f"{100 * x['success']:.1f} [{100 * x['success_low']:.1f}, "
                                 f"{100 * x['success_high']:.1f}]")  # fmt: skip
                diff = f"{100 * d.difference:+.1f} [{100 * d.low:+.1f}, {100 * d.high:+.1f}]"
                print(f"{vehicle:18s} {task:5s} {sensors:8s} {cells[0]:>22s} {cells[1]:>22s} "
                      f"{diff:>24s}  {time.perf_counter() - t0:.0f}  ({int(both.sum())} valid)",
                      flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
