"""Where the ``onboard`` sensor set loses held hovers, sensor by sensor (issue 58 item 4).

Flies the first trials of the quick wall task (the benchmark's suite 3,
default law) with the ``lab`` set, the ``onboard`` set, the ``onboard``
set with one of its sensors made ideal in turn, and with a flow camera
2, 3 and 5 times less noisy, on the same trials, and
prints each variant's held-hover success with its 95 % interval and the
paired difference to ``onboard``::

    python benchmarks/bench_onboard_gap.py --n 300 --out /tmp/gap

Trials run in this process (``--workers 1``) or in a pool. ``--final-time S``
flies every variant for ``S`` seconds instead of the suite's 4 (the same
criterion: how much of a gap is time, a hover that begins late)::

    python benchmarks/bench_onboard_gap.py --n 1000 --variants lab --final-time 6 --out /tmp/gap6
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from quadimpact.studies.benchmark.cells import cell_numbers, cell_table
from quadimpact.studies.benchmark.paired import paired_difference
from quadimpact.studies.benchmark.subject import Subject
from quadimpact.studies.benchmark.suite import TASKS, sensor_set
from quadimpact.sweep import SweepSpec
from quadimpact.sweep.runner import run_sweep

EXACT_FLOW = {"noise_min_rad_s": 0.0, "noise_max_rad_s": 0.0}
ONBOARD = {"barometer": {}, "rangefinder": {"preset": "lidar"}, "optical_flow": {}}

#: variant -> (sensor set, changes to the scenario's base fields)
VARIANTS = {
    "lab": ("lab", {}),
    "onboard": ("onboard", {}),
    "flow without noise": (
        "onboard",
        {"instruments": {**ONBOARD, "optical_flow": EXACT_FLOW}},
    ),
    "flow without noise or delay": (
        "onboard",
        {"instruments": {**ONBOARD, "optical_flow": {**EXACT_FLOW, "delay_s": 0.0}}},
    ),
    "range and barometer without noise": (
        "onboard",
        {
            "instruments": {
                **ONBOARD,
                "barometer": {"noise_m": 0.0, "bias_walk_m_sqrt_s": 0.0},
                "rangefinder": {"preset": "lidar", "noise_m": 0.0, "noise_per_m": 0.0},
            }
        },
    ),  # fmt: skip
    "IMU without its impact disturbance": ("onboard", {"imu": "noisy"}),
    "IMU at the CM": ("onboard", {"imu": {"preset": "impact", "position": "cm"}}),
    **{
        f"flow noise / {k}": (
            "onboard",
            {
                "instruments": {
                    **ONBOARD,
                    "optical_flow": {"noise_min_rad_s": 0.15 / k, "noise_max_rad_s": 0.5 / k},
                }
            },
        )  # fmt: skip
        for k in (2, 3, 5)
    },
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=300, help="wall trials (the quick suite's first)")
    ap.add_argument("--task", default="wall", choices=("wall", "pole", "edge"))
    ap.add_argument("--out", type=Path, required=True, help="folder for the sweeps")
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument(
        "--variants",
        default=None,
        help="comma-separated variant names to fly (default: all); 'onboard' is always flown",
    )
    ap.add_argument(
        "--params",
        default=None,
        help="nav-ekf parameters for every onboard variant, as k=v,k=v (a filter setting "
        "measured against the same sensors)",
    )
    ap.add_argument(
        "--final-time",
        type=float,
        default=None,
        help="run length of every trial, s (default: the suite's)",
    )
    args = ap.parse_args()
    task = TASKS[args.task]
    chosen = VARIANTS
    if args.variants:
        names = ["onboard"] + [v.strip() for v in args.variants.split(",") if v.strip()]
        unknown = [v for v in names if v not in VARIANTS]
        if unknown:
            ap.error(f"--variants: unknown {unknown}; known: {list(VARIANTS)}")
        chosen = {v: VARIANTS[v] for v in dict.fromkeys(names)}
    params = {}
    if args.params:
        for item in args.params.split(","):
            k, _, v = item.partition("=")
            v = v.strip()
            try:
                params[k.strip()] = float(v)
            except ValueError:
                params[k.strip()] = {"true": True, "false": False}.get(v, v)
    rows = {}
    for name, (set_name, changes) in chosen.items():
        if params and set_name == "onboard":
            changes = {**changes, "estimator_params": params}
        if args.final_time is not None:
            changes = {**changes, "final_time_s": args.final_time}
        spec = Subject("default").spec(task, True, sensor_set(set_name), limit=args.n)
        spec = SweepSpec(
            base={**spec.base, **changes}, grid=spec.grid or None, runs=spec.runs,
            trials=spec.trials, where=name,
        )  # fmt: skip
        t0 = time.perf_counter()
        folder = args.out / f"{args.task}-{name.replace(' ', '-').replace('/', 'over')}"
        if args.final_time is not None:
            folder = folder.with_name(f"{folder.name}-{args.final_time:g}s")
        runs = run_sweep(spec, folder, workers=args.workers)
        table = cell_table(runs, spec, task)
        rows[name] = (table, cell_numbers(table), time.perf_counter() - t0)
    base = rows["onboard"][0]
    print(f"{'variant':38s} {'held hover':>24s} {'vs onboard (paired)':>26s}  wall s  CPU")
    for name, (table, numbers, seconds) in rows.items():
        share = f"{100 * numbers['success']:.1f} % [{100 * numbers['success_low']:.1f}, " \
            f"{100 * numbers['success_high']:.1f}]"  # fmt: skip
        ok = table["success"].astype(bool) & table["valid"].astype(bool)
        ref = base["success"].astype(bool) & base["valid"].astype(bool)
        both = table["valid"].astype(bool) & base["valid"].astype(bool)
        p = paired_difference(ok[both].to_numpy(), ref[both].to_numpy())
        diff = f"{100 * p.difference:+.1f} [{100 * p.low:+.1f}, {100 * p.high:+.1f}]"
        cpu = numbers["cpu_ms_per_trial"]
        print(f"{name:38s} {share:>24s} {diff:>26s}  {seconds:6.1f}  {cpu:5.1f} ms/trial")


if __name__ == "__main__":
    main()
