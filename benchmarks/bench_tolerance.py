"""The measurement behind the default integrator tolerances.

Run: ``python benchmarks/bench_tolerance.py [--repeat N] [--json PATH]``.
For the paper's example (psi = 45 deg, iota = 15 deg, V_c = 0.75 m/s) in both
model variants and rtol = 1e-5 ... 1e-11 with atol = rtol / 100 it prints

* delta_init (initial-impact penetration of the leading bumper), m;
* its relative change when both tolerances are tightened tenfold;
* its relative error against a reference run at rtol = 1e-12, atol = 1e-14;
* the crash time, the number of subsequent impacts;
* accepted steps, right-hand-side evaluations and the kernel time (median of
  ``--repeat`` calls of ``core.kernel.execute`` on the prepared setup).

The tolerances apply to the approach shooting runs as well as the main run.
The row of the current defaults (``quadimpact.packing.constants.DEFAULT_RTOL`` /
``DEFAULT_ATOL``) is marked with ``*``; if the defaults are not on the grid
they get a row of their own.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time
from pathlib import Path

from quadimpact import WallApproach, simulate
from quadimpact.core.kernel import execute
from quadimpact.packing.constants import DEFAULT_ATOL, DEFAULT_RTOL
from quadimpact.simulation.setup import prepare

EXAMPLE = {"heading_deg": 45.0, "inclination_deg": 15.0, "speed_m_s": 0.75}
MODELS = ("paper-replica", "default")
GRID = [float(f"1e-{k}") for k in range(5, 12)]  # rtol 1e-5 .. 1e-11
REFERENCE = (1e-12, 1e-14)


def key(rtol: float, atol: float) -> tuple[str, str]:
    return (f"{rtol:.6e}", f"{atol:.6e}")


def measure(model: str, rtol: float, atol: float, repeat: int) -> dict:
    sc = WallApproach(**EXAMPLE, model=model, rtol=rtol, atol=atol)
    r = simulate(sc)
    s = r.summary
    setup = prepare(sc)
    run = setup.model(scfg=None, noise=None)  # the main run without its IMU
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        execute(run)
        times.append(time.perf_counter() - t)
    nan = float("nan")
    return {
        "rtol": rtol,
        "atol": atol,
        "status": s["status"],
        "delta_init_m": s["delta_init_m"] if s["delta_init_m"] is not None else nan,
        "crash_time_s": s["crash_time_s"] if s["crash_time_s"] is not None else nan,
        "n_subsequent_impacts": s["n_subsequent_impacts"],
        "steps": s["integrator"]["steps"],
        "rhs_evaluations": s["integrator"]["rhs_evaluations"],
        "kernel_s": statistics.median(times),
    }


def rel(a: float, b: float) -> float:
    return abs(a - b) / abs(b) if b else float("nan")


def run_model(model: str, repeat: int) -> list[dict]:
    pairs = [(r, r / 100.0) for r in GRID]
    if key(DEFAULT_RTOL, DEFAULT_ATOL) not in {key(*p) for p in pairs}:
        pairs.append((DEFAULT_RTOL, DEFAULT_ATOL))
    cache: dict[tuple[str, str], dict] = {}

    def get(rtol: float, atol: float) -> dict:
        k = key(rtol, atol)
        # the rounded key, so that rtol / 10 is passed as 1e-9, not 1.0000000000000001e-09
        if k not in cache:
            cache[k] = measure(model, float(k[0]), float(k[1]), repeat)
        return cache[k]

    ref = get(*REFERENCE)
    rows = []
    for rtol, atol in pairs:
        m = dict(get(rtol, atol))
        tight = get(rtol / 10.0, atol / 10.0)
        m["rel_change_tenfold"] = rel(m["delta_init_m"], tight["delta_init_m"])
        m["rel_error_ref"] = rel(m["delta_init_m"], ref["delta_init_m"])
        m["crash_time_error_s"] = abs(m["crash_time_s"] - ref["crash_time_s"])
        m["is_default"] = key(rtol, atol) == key(DEFAULT_RTOL, DEFAULT_ATOL)
        rows.append(m)
    ref_row = dict(ref, rel_change_tenfold=math.nan, rel_error_ref=0.0, crash_time_error_s=0.0)
    ref_row["is_default"] = False
    ref_row["is_reference"] = True
    rows.append(ref_row)
    return rows


def table(model: str, rows: list[dict]) -> str:
    head = (
        f"{'':1} {'rtol':>7} {'atol':>7} {'delta_init m':>14} {'chg x10 tight':>13}"
        f" {'err vs ref':>10} {'crash t s':>12} {'crash err s':>11} {'subs':>4}"
        f" {'steps':>6} {'rhs':>6}"
        f" {'kernel ms':>9}"
    )
    out = [f"model = {model}", head, "-" * len(head)]
    for m in rows:
        mark = "*" if m["is_default"] else ("R" if m.get("is_reference") else " ")
        chg = "" if math.isnan(m["rel_change_tenfold"]) else f"{m['rel_change_tenfold']:.1e}"
        err = "ref" if m.get("is_reference") else f"{m['rel_error_ref']:.1e}"
        cerr = "ref" if m.get("is_reference") else f"{m['crash_time_error_s']:.1e}"
        out.append(
            f"{mark:1} {m['rtol']:>7.0e} {m['atol']:>7.0e} {m['delta_init_m']:>14.11f}"
            f" {chg:>13} {err:>10} {m['crash_time_s']:>12.9f} {cerr:>11}"
            f" {m['n_subsequent_impacts']:>4d}"
            f" {m['steps']:>6d} {m['rhs_evaluations']:>6d} {m['kernel_s'] * 1e3:>9.2f}"
            + ("" if m["status"] != "failed" else "  FAILED")
        )
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=5, help="kernel timing repeats (default 5)")
    p.add_argument("--json", type=Path, help="also write all numbers to this JSON file")
    a = p.parse_args(argv)
    if a.repeat < 1:
        p.error("--repeat must be >= 1")
    simulate(WallApproach(**EXAMPLE))  # warm-up: load or compile the kernel

    print(
        "Tolerance study: paper example psi=45 deg, iota=15 deg, V_c=0.75 m/s; atol = rtol/100.\n"
        "chg x10 tight: |delta_init(rtol/10, atol/10) - delta_init| relative;"
        f" err vs ref: relative to rtol={REFERENCE[0]:g}, atol={REFERENCE[1]:g} (row R).\n"
        f"* = current defaults (DEFAULT_RTOL={DEFAULT_RTOL:g}, DEFAULT_ATOL={DEFAULT_ATOL:g});"
        " crash err: |crash t - reference|;\n"
        "subs = subsequent impacts; kernel = median of main-run execute() calls.\n"
    )
    results = {}
    for model in MODELS:
        rows = run_model(model, a.repeat)
        results[model] = rows
        print(table(model, rows))
        print()
    if a.json:
        payload = {
            "example": EXAMPLE,
            "defaults": {"rtol": DEFAULT_RTOL, "atol": DEFAULT_ATOL},
            "reference": {"rtol": REFERENCE[0], "atol": REFERENCE[1]},
            "results": results,
        }
        a.json.write_text(json.dumps(payload, indent=2, allow_nan=True))
    return 0


if __name__ == "__main__":
    sys.exit(main())
