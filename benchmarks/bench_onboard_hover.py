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
the ideal sensors instead. ``--paired`` (with ``--policy``) flies the law too, on
the same trials, and compares the drifts trial by trial on the trials where both
hold a hover: the median of the policy's drift minus the law's, with a 95 %
bootstrap interval (2,000 resamples of the trials, seed 0)::

    python benchmarks/bench_onboard_hover.py --n 200
    python benchmarks/bench_onboard_hover.py --n 1000 --policy learned --paired
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
    ap.add_argument("--paired", action="store_true", help="also the law, trial by trial")
    args = ap.parse_args()
    if args.paired:
        if not args.policy:
            ap.error("--paired needs --policy")
        law = _drifts(args, None)
        pol = _drifts(args, args.policy)
        _report(args, None, *law)
        _report(args, args.policy, *pol)
        _paired(law[0], pol[0])
        return
    _report(args, args.policy, *_drifts(args, args.policy))


def _drifts(args: argparse.Namespace, policy: str | None) -> tuple[dict, dict, float, float]:
    """Per trial index: the drift (m) and the velocity errors of each held hover; the
    suite's end (s) and the seconds taken."""
    spec = Subject("default").spec(TASKS["wall"], True, sensor_set(args.sensors), limit=args.n)
    params = _params(args.params)
    drifts, verrs = {}, {}
    suite_end = float("nan")
    t0 = time.perf_counter()
    for i in range(args.n):
        d = spec.scenario_dict(i)
        suite_end = float(d["final_time_s"])
        d["final_time_s"] = suite_end + WATCH_S
        if params:
            d["estimator_params"] = {**d.get("estimator_params", {}), **params}
        if policy:
            d["controller_params"] = {**d.get("controller_params", {}), "policy": policy}
        r = simulate(scenario_from_dict(d))
        s = r.summary
        start = s.get("time_to_held_hover_s")
        if start is None or not np.isfinite(start):
            continue
        t_h = float(s["first_contact_s"]) + float(start)
        if t_h + 0.5 > suite_end:  # the suite's held hover: held 0.5 s within its run
            continue
        ts = r.timeseries
        w = ts[(ts["t_s"] >= t_h) & (ts["t_s"] <= t_h + WATCH_S)]
        xy = w[["x_m", "y_m"]].to_numpy()
        drifts[i] = float(np.linalg.norm(xy - xy[0], axis=1).max())
        imu = r.imu
        e = imu.loc[(imu["t_s"] >= t_h) & (imu["t_s"] <= t_h + WATCH_S), "velocity_error_m_s"]
        verrs[i] = e.to_numpy()
    return drifts, verrs, suite_end, time.perf_counter() - t0


def _report(args: argparse.Namespace, policy: str | None, drifts_by: dict, verrs_by: dict,
            suite_end: float, seconds: float) -> None:  # fmt: skip
    drifts, verrs = list(drifts_by.values()), list(verrs_by.values())
    held = len(drifts)
    params = _params(args.params)
    if not drifts:
        print(f"{args.n} quick wall trials: no held hover begun in the suite's run")
        return
    dr = np.array(drifts)
    ve = np.concatenate(verrs) if verrs else np.array([np.nan])
    what = f"{args.sensors} {params or ''} {'policy ' + policy if policy else 'the law'}"
    print(f"{args.n} quick wall trials, {what}: {held} held hovers "
          f"begun by {suite_end - 0.5:.1f} s ({seconds:.0f} s)")  # fmt: skip
    print(f"drift over the {WATCH_S:.0f} s after the hover begins: median {np.median(dr):.3f} m, "
          f"p90 {np.quantile(dr, 0.9):.3f} m (target p90 < 0.3 m)")  # fmt: skip
    print(f"velocity error over those {WATCH_S:.0f} s: median {np.median(ve):.3f} m/s, p90 "
          f"{np.quantile(ve, 0.9):.3f} m/s (targets 0.1 and 0.3 m/s)")  # fmt: skip


def _paired(law: dict, pol: dict) -> None:
    """The policy's drift minus the law's on the trials where both hold a hover."""
    both = sorted(set(law) & set(pol))
    if not both:
        print("paired: no trial in which both hold a hover")
        return
    d = np.array([pol[i] - law[i] for i in both])
    rng = np.random.default_rng(0)
    boot = np.median(d[rng.integers(0, d.size, (2000, d.size))], axis=1)
    lo, hi = np.quantile(boot, [0.025, 0.975])
    print(f"paired, {d.size} trials held by both: policy - law drift median {np.median(d):+.4f} m "
          f"[95 % {lo:+.4f}, {hi:+.4f}]; the policy drifts less in {int((d < 0).sum())}, "
          f"more in {int((d > 0).sum())}")  # fmt: skip


if __name__ == "__main__":
    main()
