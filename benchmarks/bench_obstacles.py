"""Cost of an impact trial against a pole and a box corner, against a wall trial, in one run.

Run: ``python benchmarks/bench_obstacles.py [--repeat N] [--json PATH]``.

Three impact trials of the Navi (docs/RECOVERY.md 5, docs/OBSTACLES.md 2),
the same but for the obstacle: 2 m/s along +X, pitch -20 deg, roll and yaw 0,
2 m up, the recovery controller flying the paper controller until the
detection (``pre_impact = "nominal"``), friction 0.3, 3 s:

* ``wall``: the wall plane ``X = 0``, the CM 0.3 m before it;
* ``pole``: a vertical pole of radius 0.1 m through the origin, 0.3 m before
  its surface, 5 cm off its centre line (the authors' pole study);
* ``box corner``: a 0.4-m cube turned so that a corner points at the vehicle
  (``examples/box_corner.toml``'s box), 0.3 m before it, 2 cm off.

For each: the kernel's wall time alone (``core.kernel.execute`` on a prepared
run; median and min over ``--repeat`` calls, the three interleaved so that
load changes hit them alike), steps, RHS evaluations and ns per RHS
evaluation; then the ratios pole / wall and box corner / wall of the
medians (target: no more than 1.5).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time

from quadimpact.core import layout as L
from quadimpact.core.interval_slots import IS_N_REJECTED, IS_N_RHS, IS_N_STEPS
from quadimpact.core.kernel import execute
from quadimpact.inputs.scenarios import scenario_from_dict
from quadimpact.simulation.setup import prepare

BASE = {
    "kind": "impact-trial",
    "vehicle": "navi",
    "controller": "recovery",
    "pre_impact": "nominal",
    "speed_m_s": 2.0,
    "pitch_deg": -20.0,
    "altitude_m": 2.0,
    "start_distance_m": 0.3,
}
CASES = {
    "wall": {},
    "pole": {
        "lateral_offset_m": 0.05,
        "obstacles": [
            {"kind": "cylinder", "name": "pole", "point_m": [0.0, 0.0, 0.0], "radius_m": 0.1}
        ],
    },
    "box corner": {
        "lateral_offset_m": 0.02,
        "obstacles": [
            {
                "kind": "box",
                "name": "box",
                "centre_m": [0.3464, 0.0, -2.0],
                "half_extents_m": [0.2, 0.2, 0.2],
                "euler_deg": [0.0, 45.0, -35.2643897],
            }
        ],
    },
}
TARGET_RATIO = 1.5


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=30)
    parser.add_argument("--json", type=str, default=None)
    args = parser.parse_args()
    setups = {k: prepare(scenario_from_dict({**BASE, **v})) for k, v in CASES.items()}
    models = {k: s.model() for k, s in setups.items()}
    for k, s in setups.items():  # warm up (compiles on a cold cache)
        execute(models[k], n_imu=s.n_imu, max_episodes=1024, kernel=s.kernel)
    times: dict[str, list[float]] = {k: [] for k in CASES}
    stats = {}
    for _ in range(args.repeat):
        for k, s in setups.items():
            t0 = time.perf_counter()
            rec = execute(models[k], n_imu=s.n_imu, max_episodes=1024, kernel=s.kernel)
            times[k].append(time.perf_counter() - t0)
            stats[k] = rec.stats
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, "
          f"Python {platform.python_version()}")  # fmt: skip
    print(f"{'trial':<12} {'median ms':>10} {'min ms':>8} {'steps':>7} {'rejected':>8} "
          f"{'RHS':>7} {'ns/RHS':>7} {'episodes':>8}")  # fmt: skip
    out: dict[str, dict[str, float]] = {}
    for k in CASES:
        st = stats[k]
        med = statistics.median(times[k])
        rhs = int(st[L.ST_STEPS + IS_N_RHS])
        out[k] = {
            "median_s": med,
            "min_s": min(times[k]),
            "steps": int(st[L.ST_STEPS + IS_N_STEPS]),
            "rejected": int(st[L.ST_STEPS + IS_N_REJECTED]),
            "rhs": rhs,
            "ns_per_rhs": 1e9 * med / max(rhs, 1),
            "episodes": int(st[L.ST_N_EPISODES]),
        }
        o = out[k]
        line = f"{k:<12} {1e3 * med:>10.2f} {1e3 * o['min_s']:>8.2f} {o['steps']:>7} "
        line += f"{o['rejected']:>8} {rhs:>7} {o['ns_per_rhs']:>7.0f} {o['episodes']:>8}"
        print(line)
    for k in ("pole", "box corner"):
        ratio = out[k]["median_s"] / out["wall"]["median_s"]
        out[k]["ratio_to_wall"] = ratio
        verdict = "ok" if ratio <= TARGET_RATIO else f"above the {TARGET_RATIO} target"
        print(f"{k} / wall: {ratio:.2f} ({verdict})")
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
