"""Two checkouts' results compared trial by trial: quick-suite summaries and whole runs.

Run: ``python benchmarks/compare_trial_bits.py --before /path/to/other/checkout
[--rows default,pole-replica] [--sensors ideal,lab,onboard] [--every 8]
[--examples] [--json PATH]``.

Each checkout runs, in a fresh interpreter importing its ``src`` with
Numba's cache warm, a sample of the benchmark's quick suite
(docs/BENCHMARK.md): for every reference row in ``--rows`` and sensor set in
``--sensors``, every ``--every``-th wall trial and every
``(--every // 4)``-th grid point of the pole and the edge, each prepared,
run and summarised as a sweep's worker does
(``simulation.batch.BatchRunner``, no output rows). With ``--examples`` it
also runs ``simulate()`` on every ``examples/*.toml`` scenario and keeps
its summary and tables (time series with their contact columns, episodes):
the output rows' path.

The report says how many trials are the same bit for bit (floats by their
bits, NaN equal to NaN; what a run costs aside: keys named ``cost``,
``cpu``, ``wall``, ``elapsed``). For the others it gives the keys that
differ, the largest relative difference of a float, and how many differ in
a value that is not a float (a status, a success flag, a count): the check
of issue 59 item 4 for a change that moves results in their last bits
(success figures the same trial by trial on at least 99.5 % of trials).
Exits 1 when any trial or run differs.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
TIMES = ("cost", "cpu", "wall", "elapsed", "quadimpact_version", "created")

SNIPPET = r"""
import glob, json, math, sys
import numpy as np
from quadimpact.inputs.scenarios import scenario_from_dict
from quadimpact.simulation.batch import BatchRunner
from quadimpact.studies.benchmark.subject import REFERENCES
from quadimpact.studies.benchmark.suite import SUITE_VERSION, TASKS, sensor_set

rows, sensors, every, examples = json.loads(sys.argv[1])
runner = BatchRunner()


def plain(v):
    if isinstance(v, dict):
        return {str(k): plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [plain(x) for x in v]
    if isinstance(v, (float, np.floating)):
        f = float(v)
        return {"f": f.hex()} if math.isfinite(f) or math.isinf(f) else {"f": "nan"}
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (np.bool_,)):
        return bool(v)
    if v is None or isinstance(v, (str, int, bool)):
        return v
    return repr(v)


out = {}
for row in rows:
    subject = next(r for r in REFERENCES if r.name == row)
    for task in ("wall", "pole", "edge"):
        step = every if task == "wall" else max(1, every // 4)
        for s in sensors:
            spec = subject.spec(TASKS[task], True, sensor_set(s), None, SUITE_VERSION)
            for i in range(0, spec.n_runs, step):
                sc = scenario_from_dict(spec.scenario_dict(i))
                try:
                    out[f"{row}/{task}/{s}/{i}"] = plain(runner.summary(sc))
                except Exception as exc:  # noqa: BLE001 - the error is the result
                    out[f"{row}/{task}/{s}/{i}"] = "raised " + repr(exc)
if examples:
    from quadimpact import simulate
    from quadimpact.inputs.scenarios import load_scenario_file

    for path in sorted(glob.glob("examples/*.toml")):
        try:
            r = simulate(load_scenario_file(path))
        except Exception as exc:  # noqa: BLE001 - not every example is a scenario
            out["example " + path] = "raised " + type(exc).__name__
            continue
        item = {"summary": plain(r.summary)}
        for name in ("timeseries", "episodes", "imu"):
            df = getattr(r, name, None)
            if df is not None:
                item[name] = {c: plain(df[c].tolist()) for c in df.columns}
        out["example " + path] = item
print(json.dumps(out))
"""


def run(checkout: Path, what: list) -> dict:
    """The results of ``checkout`` (a fresh interpreter importing its ``src``)."""
    from bench_trial_cost import run_in_checkout  # benchmarks/ is the script's path

    return run_in_checkout(checkout, SNIPPET, what)


def _is_time(name: str) -> bool:
    return any(t in name.lower() for t in TIMES)


def differences(a: object, b: object, path: str = "") -> list[tuple[str, float | None]]:
    """``(key, relative difference or None)`` of every value that differs (costs aside).

    None: a difference that is not between two finite floats (a flag, a
    status, a count, a missing key).
    """
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) == {"f"} and set(b) == {"f"}:
            if a["f"] == b["f"]:
                return []
            try:
                x, y = float.fromhex(a["f"]), float.fromhex(b["f"])
            except ValueError:
                return [(path, None)]
            if not (math.isfinite(x) and math.isfinite(y)):
                return [(path, None)]
            return [(path, abs(x - y) / max(abs(x), abs(y), 1e-300))]
        found = []
        for k in sorted(set(a) | set(b)):
            if _is_time(k):
                continue
            if k not in a or k not in b:
                found.append((f"{path}.{k}", None))
                continue
            found += differences(a[k], b[k], f"{path}.{k}")
        return found
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [(path, None)]
        found = []
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            found += [(f"{path}[]", r) for _, r in differences(x, y, f"{path}[{i}]")]
        return found
    return [] if a == b else [(path, None)]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, required=True, help="the other checkout")
    parser.add_argument("--after", type=Path, default=HERE, help="default: this checkout")
    parser.add_argument("--rows", default="default", help="reference rows, comma-separated")
    parser.add_argument("--sensors", default="ideal", help="sensor sets, comma-separated")
    parser.add_argument("--every", type=int, default=8, help="every n-th wall trial")
    parser.add_argument("--examples", action="store_true", help="also simulate() examples/")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    what = [args.rows.split(","), args.sensors.split(","), args.every, args.examples]
    before = run(args.before.resolve(), what)
    after = run(args.after.resolve(), what)
    n_same = 0
    n_other = 0  # a difference that is not a float's last bits
    keys: dict[str, int] = {}
    worst = 0.0
    differing = []
    for name in before:
        diff = differences(before[name], after.get(name))
        if not diff:
            n_same += 1
            continue
        differing.append(name)
        if any(r is None for _, r in diff):
            n_other += 1
        for k, r in diff:
            keys[k] = keys.get(k, 0) + 1
            if r is not None:
                worst = max(worst, r)
    n = len(before)
    print(f"{n} trials and runs; {n_same} the same bit for bit; {n - n_same} differ")
    if differing:
        print(f"  of which {n_other} in a value that is not a float (status, flag, count)")
        print(f"  largest relative difference of a float: {worst:.3g}")
        for k, count in sorted(keys.items(), key=lambda kv: -kv[1])[:20]:
            print(f"  {count:5d}  {k}")
        print("  first differing: " + ", ".join(differing[:8]))
    if args.json:
        args.json.write_text(
            json.dumps({"n": n, "same": n_same, "other": n_other, "worst": worst, "keys": keys})
        )
    return 0 if n_same == n else 1


if __name__ == "__main__":
    raise SystemExit(main())
