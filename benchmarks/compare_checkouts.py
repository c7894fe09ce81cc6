"""Before/after timing of two quadimpact checkouts, measured in the same run.

Run: ``python benchmarks/compare_checkouts.py --before /path/to/other/checkout
[--rounds 3] [--repeat 60] [--json PATH]``

Machines differ and a busy machine drifts, so the two versions are measured
alternately, round after round, each in a fresh interpreter that imports that
checkout's ``src`` (``PYTHONPATH``) with Numba's on-disk cache warm (a
warm-up run first). Each round times, for the paper's example (psi = 45 deg,
iota = 15 deg, V_c = 0.75 m/s) in both model variants:

* the kernel alone (``core.run.execute`` on a prepared setup, without its
  IMU; either checkout's API): median of ``--repeat`` calls;
* the whole ``simulate()``: median of ``--repeat // 5`` calls.

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
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]

SNIPPET = r"""
import json, statistics, sys, time
from quadimpact import WallApproach, simulate
try:
    from quadimpact.simulation.setup import prepare
except ImportError:
    from quadimpact.scenario import prepare
from quadimpact.core.run import execute
repeat = int(sys.argv[1])
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
    ks, ss = [], []
    for _ in range(repeat):
        t = time.perf_counter(); kernel(); ks.append(time.perf_counter() - t)
    for _ in range(max(5, repeat // 5)):
        t = time.perf_counter(); simulate(s); ss.append(time.perf_counter() - t)
    res[model] = {"kernel_ms": statistics.median(ks) * 1e3,
                  "simulate_ms": statistics.median(ss) * 1e3}
print(json.dumps(res))
"""


def measure(checkout: Path, repeat: int) -> dict:
    """One round in a fresh interpreter importing ``checkout/src``."""
    env = dict(os.environ)
    env["PYTHONPATH"] = str(checkout / "src")
    proc = subprocess.run(
        [sys.executable, "-c", SNIPPET, str(repeat)],
        env=env, capture_output=True, text=True, check=True, cwd=checkout,
    )  # fmt: skip
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, required=True, help="the other checkout")
    parser.add_argument("--after", type=Path, default=HERE, help="default: this checkout")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--repeat", type=int, default=60)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    rounds: dict[str, list[dict]] = {"before": [], "after": []}
    for path in (args.before, args.after):
        measure(path, 2)  # warm the Numba cache of that checkout
    for _ in range(args.rounds):
        rounds["before"].append(measure(args.before, args.repeat))
        rounds["after"].append(measure(args.after, args.repeat))
    report: dict[str, dict] = {}
    print(f"{'measure':34s} {'before':>10s} {'after':>10s} {'after/before':>13s}")
    for model in ("paper-replica", "default"):
        for key in ("kernel_ms", "simulate_ms"):
            b = statistics.median(r[model][key] for r in rounds["before"])
            a = statistics.median(r[model][key] for r in rounds["after"])
            report[f"{model} {key}"] = {"before": b, "after": a, "ratio": a / b}
            print(f"{model + ' ' + key:34s} {b:10.3f} {a:10.3f} {a / b:13.3f}")
    if args.json:
        args.json.write_text(json.dumps({"rounds": rounds, "summary": report}, indent=2))


if __name__ == "__main__":
    main()
