"""Recovery benchmark: the Monte Carlo's wall time and results, and the friction check.

Run: ``python benchmarks/bench_recovery.py [--n 10000] [--n-variants 2000]
[--n-friction 1000] [--workers 2] [--out DIR] [--skip-studies] [--skip-variants]
[--skip-friction] [--json PATH]``.

1. **Navi Monte Carlo**, ``--n`` trials (default 10,000) of the authors'
   distribution (``quadimpact.studies.recovery.recovery_study.RecoveryStudy``, seed 0), in the
   ``default`` and ``recovery-replica`` variants, each with
   ``quadimpact.studies.recovery.recovery_study.run_study`` on ``--workers`` local processes
   (default 2) without the example run: the sweep's wall time (target
   <= 120 s per 10,000 trials) and the whole study's (table, figures and
   report), the success rate (recovered / all trials) with its 95 % Wilson
   interval, recovered / detected, success by 10-deg inclination bin, median
   and 90th percentile of the time to recover and the height loss, the
   numbers not detected and falsely detected. Before them, the CPU time per
   trial in this process (``--n-cpu`` trials through ``quadimpact.sweep.run_chunk``,
   the workers' function), which does not depend on the machine's load: the
   wall time of 10,000 trials on two otherwise idle cores is about
   5,000 times it.
2. **Variants** at ``--n-variants`` trials (default 2,000; the same first
   trials as above): the Spiri (with the Navi's slew limit), the ``noisy``
   IMU and the ``hold`` pre-impact behaviour, each in both model variants.
3. **Friction regularisation check**: the contact law regularises Coulomb
   friction with ``v_reg`` (``quadimpact.packing.constants.FRICTION_V_REG_M_S``,
   kernel slot ``O_V_REG``). The first ``--n-friction`` trials (default
   1,000) are run with v_reg = 1e-2 (the default), 3e-3, 1e-3 and 1e-4 m/s
   in both variants (the packed option changed on the prepared run:
   ``simulation.setup.prepare`` then ``simulation.simulate.run_setup``):
   per v_reg, how many trials change ``recovered`` against the default and
   against the smallest v_reg, the distribution of the change of the stage-4
   time (trials recovered in both), and the integrator steps per trial.

A study folder under ``--out`` is kept, so running again with the same
``--out`` resumes (its sweep time is then that of the resumed part: use a
fresh folder to time). Timings are wall-clock on a shared machine.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

V_REGS = (1e-2, 3e-3, 1e-3, 1e-4)
TARGET_S_PER_10K = 120.0
MODELS = ("default", "recovery-replica")


def machine() -> dict[str, Any]:
    from bench_sweep import machine_info  # beside this script

    return {**machine_info(), "load_average": os.getloadavg()}


# ------------------------------------------------------------- the studies
def study_numbers(name: str, study: Any, out: Path, workers: int) -> dict[str, Any]:
    from quadimpact.studies.recovery.recovery_study import run_study

    t0 = time.perf_counter()
    r = run_study(study, out / name, workers=workers, example=False)
    total = time.perf_counter() - t0
    n = r.numbers
    s, sd = n["success"], n["success_detected"]
    row = {
        "name": name,
        "n": n["n"],
        "sweep_s": r.run_info["elapsed_s"],
        "n_ran": r.run_info["n_ran"],
        "backend": r.run_info["backend"],
        "study_s": total,
        "success": [s.k, s.n, s.value, s.low, s.high],
        "success_detected": [sd.k, sd.n, sd.value, sd.low, sd.high],
        "classes": n["classes"],
        "by_inclination": n["by_inclination"][
            ["bin", "n", "recovered", "rate", "low", "high"]
        ].to_dict("records"),
        "time_to_recover_s": n["time_to_recover_s"],
        "height_loss_m": n["height_loss_m"],
        "horizontal_drift_m": n["horizontal_drift_m"],
    }
    print_study(row)
    return row


def pct(x: float) -> str:
    return "   -  " if not math.isfinite(x) else f"{100 * x:5.1f}%"


def print_study(r: dict[str, Any]) -> None:
    k, n, v, lo, hi = r["success"]
    kd, nd, vd, lod, hid = r["success_detected"]
    c = r["classes"]
    per10k = r["sweep_s"] * 1e4 / r["n"] if r["n_ran"] == r["n"] else math.nan
    print(f"\n== {r['name']}: {r['n']} trials")
    print(f"  sweep {r['sweep_s']:.1f} s ({r['backend']}, {r['n_ran']} run now; "
          f"{per10k:.0f} s per 10,000, target {TARGET_S_PER_10K:.0f}); whole study "
          f"{r['study_s']:.1f} s")  # fmt: skip
    print(f"  success  {k}/{n} = {pct(v)} [{pct(lo)}, {pct(hi)}]   "
          f"recovered/detected {kd}/{nd} = {pct(vd)} [{pct(lod)}, {pct(hid)}]")  # fmt: skip
    print(f"  not detected {c['not detected']}, false detections {c['false detection']}, "
          f"not recovered {c['not recovered']}, failed {c['failed']}")  # fmt: skip
    for key in ("time_to_recover_s", "height_loss_m", "horizontal_drift_m"):
        q = r[key]
        print(f"  {key:<20} median {q['median']:.3f}  p90 {q['p90']:.3f}  max {q['max']:.3f}")
    print("  inclination bin   n     rate    95 % interval")
    for b in r["by_inclination"]:
        print(f"  {b['bin']:<14} {b['n']:5d}  {pct(b['rate'])}  [{pct(b['low'])}, "
              f"{pct(b['high'])}]")  # fmt: skip


def cpu_per_trial(model: str, n: int) -> float:
    """CPU seconds per trial in this process (``run_chunk``, the sweep workers' function)."""
    from quadimpact.studies.recovery.recovery_study import RecoveryStudy
    from quadimpact.sweep import run_chunk

    spec = RecoveryStudy(n=n, model=model).sweep_spec()
    items = [(i, spec.scenario_dict(i), spec.input_columns(spec.inputs(i))) for i in range(n)]
    run_chunk(items[:2])  # warm
    t0 = time.process_time()
    run_chunk(items)
    return (time.process_time() - t0) / n


# --------------------------------------------------------- friction check
def _vreg_chunk(items: list[tuple[int, dict, float]]) -> list[dict[str, Any]]:
    from quadimpact.core import layout as L
    from quadimpact.inputs.scenarios import scenario_from_dict
    from quadimpact.simulation.setup import prepare
    from quadimpact.simulation.simulate import run_setup

    rows = []
    for run_id, data, v_reg in items:
        scenario = scenario_from_dict(data)
        setup = prepare(scenario)
        setup.opts[L.O_V_REG] = v_reg
        s = run_setup(setup, scenario).summary
        rows.append({
            "run_id": run_id, "v_reg": v_reg, "status": s["status"],
            "recovered": bool(s["recovered"]), "t_stage4_s": s["t_stage4_s"],
            "steps": s["integrator"]["steps"], "rhs": s["integrator"]["rhs_evaluations"],
        })  # fmt: skip
    return rows


def friction_check(n: int, workers: int) -> dict[str, Any]:
    import numpy as np
    import pandas as pd

    from quadimpact.packing.constants import FRICTION_V_REG_M_S
    from quadimpact.studies.recovery.recovery_study import RecoveryStudy

    assert FRICTION_V_REG_M_S == V_REGS[0], "the default v_reg is the first of V_REGS"
    out: dict[str, Any] = {}
    for model in MODELS:
        spec = RecoveryStudy(n=n, model=model).sweep_spec()
        items = [(i, spec.scenario_dict(i), v) for v in V_REGS for i in range(n)]
        chunks = [items[i : i + 25] for i in range(0, len(items), 25)]
        t0 = time.perf_counter()
        with ProcessPoolExecutor(workers) as pool:
            rows = [row for chunk in pool.map(_vreg_chunk, chunks) for row in chunk]
        elapsed = time.perf_counter() - t0
        t = pd.DataFrame(rows)
        wide = t.pivot(index="run_id", columns="v_reg", values="recovered")
        t4 = t.pivot(index="run_id", columns="v_reg", values="t_stage4_s").astype(float)
        steps = t.pivot(index="run_id", columns="v_reg", values="steps")
        ref, fine = V_REGS[0], V_REGS[-1]
        per = []
        print(f"\n== friction check, {model}: {n} trials x v_reg {V_REGS} ({elapsed:.0f} s)")
        print(
            "  v_reg     recovered  changed vs 1e-2  changed vs 1e-4  |dt4| median / p90 / "
            "max vs 1e-2 (s)  steps median / mean"
        )
        for v in V_REGS:
            both = wide[ref] & wide[v]
            d = (t4[v] - t4[ref])[both].abs().to_numpy()
            entry = {
                "v_reg": v,
                "recovered": int(wide[v].sum()),
                "changed_vs_default": int((wide[v] != wide[ref]).sum()),
                "changed_vs_finest": int((wide[v] != wide[fine]).sum()),
                "dt4_median_s": float(np.median(d)) if d.size else math.nan,
                "dt4_p90_s": float(np.quantile(d, 0.9)) if d.size else math.nan,
                "dt4_max_s": float(d.max()) if d.size else math.nan,
                "dt4_nonzero": int((d > 1e-9).sum()),
                "dt4_over_one_tick": int((d > 0.005 + 1e-9).sum()),
                "dt4_over_50ms": int((d > 0.05).sum()),
                "steps_median": float(steps[v].median()),
                "steps_mean": float(steps[v].mean()),
                "failed": int((t[t["v_reg"] == v]["status"] == "failed").sum()),
                "t4_median_s": float(t4[v].median()),
                "t4_p90_s": float(t4[v].quantile(0.9)),
            }
            per.append(entry)
            print(f"  {v:<8g}  {entry['recovered']:9d}  {entry['changed_vs_default']:15d}  "
                  f"{entry['changed_vs_finest']:15d}  {entry['dt4_median_s']:.4f} / "
                  f"{entry['dt4_p90_s']:.4f} / {entry['dt4_max_s']:.4f}   "
                  f"{entry['steps_median']:.0f} / {entry['steps_mean']:.0f}")  # fmt: skip
        print(
            "  stage-4 time changed vs 1e-2 (of the trials recovered in both): "
            + ", ".join(
                f"{e['v_reg']:g}: {e['dt4_nonzero']} by a tick or more, "
                f"{e['dt4_over_one_tick']} by more than a tick, "
                f"{e['dt4_over_50ms']} by more than 50 ms"
                for e in per[1:]
            )
        )
        print(
            "  stage-4 time over the recovered trials, median / p90 (s): "
            + ", ".join(
                f"{e['v_reg']:g}: {e['t4_median_s']:.3f} / {e['t4_p90_s']:.3f}" for e in per
            )
        )
        out[model] = {"elapsed_s": elapsed, "rows": per}
    return out


# -------------------------------------------------------------------- main
def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=10_000, help="Navi trials per variant")
    ap.add_argument("--n-variants", type=int, default=2_000, help="Spiri / noisy / hold trials")
    ap.add_argument("--n-friction", type=int, default=1_000, help="friction-check trials")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--n-cpu", type=int, default=300, help="trials of the CPU-time measure")
    ap.add_argument("--out", type=Path, help="keep the study folders here (default: temporary)")
    ap.add_argument("--skip-studies", action="store_true", help="only the friction check")
    ap.add_argument("--skip-variants", action="store_true")
    ap.add_argument("--skip-friction", action="store_true")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()

    from quadimpact.studies.recovery.recovery_study import RecoveryStudy

    info = machine()
    print(f"machine: {info['cpu_count']} cores ({info['cpu_model']}), Python {info['python']}, "
          f"load average {', '.join(f'{x:.1f}' for x in info['load_average'])}")  # fmt: skip
    results: dict[str, Any] = {"machine": info, "studies": [], "cpu_per_trial_s": {}}
    for m in () if args.skip_studies else MODELS:
        cpu = cpu_per_trial(m, args.n_cpu)
        results["cpu_per_trial_s"][m] = cpu
        print(f"CPU per trial, {m}: {1e3 * cpu:.1f} ms (in-process, {args.n_cpu} trials): "
              f"{cpu * 1e4 / 2:.0f} s per 10,000 trials on 2 free cores")  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        out = args.out or Path(tmp)
        out.mkdir(parents=True, exist_ok=True)
        runs = (
            []
            if args.skip_studies
            else [(f"navi-{m}-{args.n}", RecoveryStudy(n=args.n, model=m)) for m in MODELS]
        )
        if not (args.skip_variants or args.skip_studies):
            nv = args.n_variants
            for m in MODELS:
                runs += [
                    (f"spiri-{m}-{nv}", RecoveryStudy(vehicle="spiri", n=nv, model=m)),
                    (f"navi-noisy-{m}-{nv}", RecoveryStudy(n=nv, model=m, imu="noisy")),
                    (f"navi-hold-{m}-{nv}", RecoveryStudy(n=nv, model=m, pre_impact="hold")),
                ]
        for name, study in runs:
            results["studies"].append(study_numbers(name, study, out, args.workers))
    if not args.skip_friction:
        results["friction"] = friction_check(args.n_friction, args.workers)
    if args.json:
        args.json.write_text(json.dumps(results, indent=1, default=float) + "\n")


if __name__ == "__main__":
    main()
