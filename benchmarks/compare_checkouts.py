"""Before/after timing of two quadimpact checkouts, measured in the same run.

Run: ``python benchmarks/compare_checkouts.py --before /path/to/other/checkout
[--rounds 3] [--repeat 60] [--trials 1000] [--cold] [--json PATH]``

Machines differ and a busy machine drifts, so the two versions are measured
alternately, round after round, each in a fresh interpreter that imports that
checkout's ``src`` (``PYTHONPATH``) with Numba's on-disk cache warm (a
warm-up run first). Each round times, for the paper's example (psi = 45 deg,
iota = 15 deg, V_c = 0.75 m/s) in both model variants:

* the kernel alone (``core.kernel.execute`` on a prepared setup, without its
  IMU; either checkout's API): median of ``--repeat`` calls;
* the whole ``simulate()``: median of ``--repeat // 5`` calls;

and a recovery sample: the first ``--trials`` trials of the recovery study
(``quadimpact recovery``'s seeded Navi trials), each prepared, run and
summarised in process (``simulation.batch.BatchRunner``, what a sweep worker
does), in total. Every measure is taken both in wall time and in the
process's CPU time (``time.process_time``), which a loaded machine disturbs
less. ``--cold`` also times, once per checkout, a first ``simulate()`` in a
fresh process with an empty Numba cache (``NUMBA_CACHE_DIR``): the compile
time a new user waits, imports included.

The report gives, per measure, the median over rounds of each version and
the ratio after / before.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]

SNIPPET = r"""
import json, statistics, sys, time
from quadimpact import WallApproach, simulate
try:
    from quadimpact.simulation.setup import prepare
except ImportError:
    from quadimpact.scenario import prepare
try:  # the layout since the architecture's step 2, or the one before it
    from quadimpact.core.kernel import execute
    from quadimpact.studies.recovery.recovery_study import RecoveryStudy
except ImportError:
    from quadimpact.core.run import execute
    from quadimpact.recovery.study import RecoveryStudy
from quadimpact.inputs.scenarios import scenario_from_dict
from quadimpact.simulation.batch import BatchRunner
repeat, trials = int(sys.argv[1]), int(sys.argv[2])


def timed(fn):
    w, c = time.perf_counter(), time.process_time()
    fn()
    return time.perf_counter() - w, time.process_time() - c


res = {}
for model in ("paper-replica", "default"):
    s = WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75, model=model)
    st = prepare(s)
    if hasattr(st, "model"):  # the core records: execute(model), the run without its IMU
        m = st.model(scfg=None, noise=None)
        kernel = lambda: execute(m)
    else:  # earlier checkouts: execute(x0, t0, tf, veh, surf, opts, ctrl, t_out)
        args = (st.x0, st.t0, st.tf, st.veh, st.surf, st.opts, st.ctrl, st.output_times())
        kernel = lambda: execute(*args)
    kernel()
    simulate(s)
    ks = [timed(kernel) for _ in range(repeat)]
    ss = [timed(lambda: simulate(s)) for _ in range(max(5, repeat // 5))]
    res[model] = {
        "kernel_ms": statistics.median(k[0] for k in ks) * 1e3,
        "kernel_cpu_ms": statistics.median(k[1] for k in ks) * 1e3,
        "simulate_ms": statistics.median(x[0] for x in ss) * 1e3,
        "simulate_cpu_ms": statistics.median(x[1] for x in ss) * 1e3,
    }
if trials:
    spec = RecoveryStudy(n=trials).sweep_spec()
    scenarios = [scenario_from_dict(spec.scenario_dict(i)) for i in range(trials)]
    runner = BatchRunner()
    runner.summary(scenarios[0])
    wall, cpu = timed(lambda: [runner.summary(x) for x in scenarios])
    res["recovery"] = {"trials_s": wall, "trials_cpu_s": cpu}
print(json.dumps(res))
"""

COLD = r"""
import time
t = time.perf_counter()
from quadimpact import WallApproach, simulate
simulate(WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75))
print(time.perf_counter() - t)
"""


def _env(checkout: Path, **extra: str) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(checkout / "src")
    env.update(extra)
    return env


def measure(checkout: Path, repeat: int, trials: int) -> dict:
    """One round in a fresh interpreter importing ``checkout/src``."""
    proc = subprocess.run(
        [sys.executable, "-c", SNIPPET, str(repeat), str(trials)],
        env=_env(checkout), capture_output=True, text=True, check=True, cwd=checkout,
    )  # fmt: skip
    return json.loads(proc.stdout.strip().splitlines()[-1])


def cold_start_s(checkout: Path) -> float:
    """Seconds to a first ``simulate()`` in a fresh process with an empty Numba cache."""
    with tempfile.TemporaryDirectory() as cache:
        start = time.perf_counter()
        subprocess.run(
            [sys.executable, "-c", COLD], env=_env(checkout, NUMBA_CACHE_DIR=cache),
            capture_output=True, text=True, check=True, cwd=checkout,
        )  # fmt: skip
        return time.perf_counter() - start


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, required=True, help="the other checkout")
    parser.add_argument("--after", type=Path, default=HERE, help="default: this checkout")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--repeat", type=int, default=60)
    parser.add_argument("--trials", type=int, default=1000, help="recovery trials (0: none)")
    parser.add_argument("--cold", action="store_true", help="also time a cold-cache start")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    rounds: dict[str, list[dict]] = {"before": [], "after": []}
    for path in (args.before, args.after):
        measure(path, 2, min(args.trials, 2))  # warm the Numba cache of that checkout
    for _ in range(args.rounds):
        rounds["before"].append(measure(args.before, args.repeat, args.trials))
        rounds["after"].append(measure(args.after, args.repeat, args.trials))
    report: dict[str, dict] = {}
    print(f"{'measure':40s} {'before':>10s} {'after':>10s} {'after/before':>13s}")
    measures = [
        (model, key)
        for model in ("paper-replica", "default")
        for key in ("kernel_ms", "kernel_cpu_ms", "simulate_ms", "simulate_cpu_ms")
    ]
    if args.trials:
        measures += [("recovery", "trials_s"), ("recovery", "trials_cpu_s")]
    for group, key in measures:
        b = statistics.median(r[group][key] for r in rounds["before"])
        a = statistics.median(r[group][key] for r in rounds["after"])
        report[f"{group} {key}"] = {"before": b, "after": a, "ratio": a / b}
        print(f"{group + ' ' + key:40s} {b:10.3f} {a:10.3f} {a / b:13.3f}")
    if args.cold:
        b, a = cold_start_s(args.before), cold_start_s(args.after)
        report["cold start s"] = {"before": b, "after": a, "ratio": a / b}
        print(f"{'cold start (compile), s':40s} {b:10.1f} {a:10.1f} {a / b:13.3f}")
    if args.json:
        args.json.write_text(json.dumps({"rounds": rounds, "summary": report}, indent=2))


if __name__ == "__main__":
    main()
