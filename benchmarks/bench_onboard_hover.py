"""The held hovers of the ``onboard`` set: drift and velocity error after the hover begins.

Flies the first ``--n`` trials of the quick wall task of the benchmark's
suite 3 (default law, ``onboard`` sensors, ``nav-ekf``), each run 2 s longer
than the suite's 4 s so that every hover that begins in the run has 2 s to
be watched. Of the trials whose held hover begins within the suite's 4 s it
prints, against the issue's targets (docs/ESTIMATION.md 9):

* the true horizontal drift of the CM over the 2 s after the hover begins
  (the largest distance from where it began), median and 90th percentile;
* the velocity error of the estimate (``|v_hat - v|``, m/s) over the same
  2 s, all samples of all those trials pooled, median and 90th percentile.

``--params k=v,...`` sets ``nav-ekf`` parameters (as ``bench_onboard_gap.py``);
``--policy learned|FILE`` flies the law with a learned policy, ``--sensors ideal``
the ideal sensors instead::

    python benchmarks/bench_onboard_hover.py --n 200
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from quadimpact import simulate
from quadimpact.inputs.scenarios import scenario_from_dict
from quadimpact.studies.benchmark.subject import Subject
from quadimpact.studies.benchmark.suite import TASKS, sensor_set

WATCH_S = 2.0  # s after the hover begins


def _params(text: str | None) -> dict:
    out: dict = {}
    for item in (text or "").split(","):
        if not item.strip():
            continue
        k, _, v = item.partition("=")
        v = v.strip()
        try:
            out[k.strip()] = float(v)
        except ValueError:
            out[k.strip()] = {"true": True, "false": False}.get(v, v)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=200, help="quick wall trials (the task's first)")
    ap.add_argument("--params", default=None, help="nav-ekf parameters, k=v,k=v")
    ap.add_argument("--policy", default=None, help="a learned policy: learned or a file")
    ap.add_argument("--sensors", default="onboard", help="the benchmark's sensor set")
    args = ap.parse_args()
    spec = Subject("default").spec(TASKS["wall"], True, sensor_set(args.sensors), limit=args.n)
    params = _params(args.params)
    drifts, verrs = [], []
    held = 0
    t0 = time.perf_counter()
    for i in range(args.n):
        d = spec.scenario_dict(i)
        suite_end = float(d["final_time_s"])
        d["final_time_s"] = suite_end + WATCH_S
        if params:
            d["estimator_params"] = {**d.get("estimator_params", {}), **params}
        if args.policy:
            d["controller_params"] = {**d.get("controller_params", {}), "policy": args.policy}
        r = simulate(scenario_from_dict(d))
        s = r.summary
        start = s.get("time_to_held_hover_s")
        if start is None or not np.isfinite(start):
            continue
        t_h = float(s["first_contact_s"]) + float(start)
        if t_h + 0.5 > suite_end:  # the suite's held hover: held 0.5 s within its run
            continue
        held += 1
        ts = r.timeseries
        w = ts[(ts["t_s"] >= t_h) & (ts["t_s"] <= t_h + WATCH_S)]
        xy = w[["x_m", "y_m"]].to_numpy()
        drifts.append(float(np.linalg.norm(xy - xy[0], axis=1).max()))
        imu = r.imu
        e = imu.loc[(imu["t_s"] >= t_h) & (imu["t_s"] <= t_h + WATCH_S), "velocity_error_m_s"]
        verrs.append(e.to_numpy())
    seconds = time.perf_counter() - t0
    if not drifts:
        print(f"{args.n} quick wall trials: no held hover begun in the suite's run")
        return
    dr = np.array(drifts)
    ve = np.concatenate(verrs) if verrs else np.array([np.nan])
    what = f"{args.sensors} {params or ''} {'policy ' + args.policy if args.policy else 'the law'}"
    print(f"{args.n} quick wall trials, {what}: {held} held hovers "
          f"begun by {suite_end - 0.5:.1f} s ({seconds:.0f} s)")  # fmt: skip
    print(f"drift over the {WATCH_S:.0f} s after the hover begins: median {np.median(dr):.3f} m, "
          f"p90 {np.quantile(dr, 0.9):.3f} m (target p90 < 0.3 m)")  # fmt: skip
    print(f"velocity error over those {WATCH_S:.0f} s: median {np.median(ve):.3f} m/s, p90 "
          f"{np.quantile(ve, 0.9):.3f} m/s (targets 0.1 and 0.3 m/s)")  # fmt: skip


if __name__ == "__main__":
    main()
