"""Judge a learned recovery policy against the staged law on held-out trials.

Run: ``python benchmarks/eval_policy.py --out DIR [--policy learned|FILE] [--quick]
[--workers 2]`` (docs/LEARNING.md 12 quotes its numbers).

Every trial is flown twice, by the default staged law and by the same law with
the policy's residual, on the same seeded conditions and the same sensor noise,
so the two compare trial by trial. The sets are the benchmark's own tasks
(``quadimpact benchmark``: none was used in training, ``policy_trials.py``):

* ``wall``: the authors' Monte Carlo, the benchmark's 10,000 trials (seed 0);
* ``pole``: the authors' whole pole grid, 3,266 points (sensors seeded 0);
* ``edge``: the same grid against the pillar's vertical edge (never trained on);

each with the ``impact`` sensors and the EKF (what the policy was trained
with) and with the ``ideal`` sensors; and, for robustness, 2,000 wall trials
with the ``impact`` sensors on vehicles it was not trained on: the Spiri, and
the Navi with 20 % more mass. ``--quick``: 1,000 wall trials, every 3rd pitch
and 5th offset of the grids, 500 robustness trials.

Per set: each controller's success share with its 95 % Wilson interval
(the studies' criteria: the wall's recovered valid trials, the grids' less
than 2 m lost), the paired difference with its 95 % interval, the trials
only one of them wins (with the first of each written as a scenario file to
fly again: ``quadimpact run DIR/examples/<file>.toml``), the share of
recovered trials that hover within 2 s of their recovery, the height lost,
and the CPU time per trial of each (its compiled loop and summary, this
process). Writes ``DIR/eval.md``, ``DIR/eval.json`` and ``DIR/<set>.csv``
(one row per trial).
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing as mp
import sys
import time
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import policy_trials as PT  # noqa: E402

NAVI_MASS_KG = 1.095
HOVER_WITHIN_S = 2.0
#: A trial's conditions, as the tables and the examples give them.
CONDITIONS = ("pitch_deg", "roll_deg", "yaw_deg", "speed_m_s", "lateral_offset_m", "seed")


def sets(quick: bool) -> dict[str, dict[str, Any]]:
    """The evaluation sets: name -> how to make its scenario mappings."""
    n_wall, n_robust = (1_000, 500) if quick else (10_000, 2_000)
    out: dict[str, dict[str, Any]] = {}
    for sensors in ("impact", "ideal"):
        out[f"wall/{sensors}"] = {"kind": "wall", "n": n_wall, "sensors": sensors}
        for grid in ("pole", "edge"):
            out[f"{grid}/{sensors}"] = {"kind": grid, "sensors": sensors, "quick": quick}
    out["wall/impact, spiri"] = {"kind": "wall", "n": n_robust, "sensors": "impact",
                                 "vehicle": "spiri"}  # fmt: skip
    out["wall/impact, navi +20 % mass"] = {"kind": "wall", "n": n_robust, "sensors": "impact",
                                           "mass_kg": 1.2 * NAVI_MASS_KG}  # fmt: skip
    return out


@cache
def _dicts(key: str) -> list[dict[str, Any]]:
    d = json.loads(key)
    if d["kind"] == "wall":
        return PT.wall_dicts(d["n"], 0, d["sensors"], d.get("vehicle"), d.get("mass_kg"))
    data = PT.grid_dicts(d["kind"], False, 0, d["sensors"])
    if not d.get("quick"):
        return data
    from quadimpact.studies.benchmark.suite import TASKS

    study = TASKS[d["kind"]].grid_study(True, PT._sensing("ideal"))
    keep = {(float(p), float(o)) for p in study.pitches() for o in study.offsets()}
    return [x for x in data if (float(x["pitch_deg"]), float(x["lateral_offset_m"])) in keep]


_W: dict[str, Any] = {}


def _init(policy: str) -> None:
    from quadimpact.inputs.policy_file import load_policy

    _W["block"] = load_policy(policy).block()
    _W["flyer"] = PT.Flyer()


def _fly(job: tuple[str, list[int]]) -> list[dict[str, Any]]:
    key, indices = job
    d = json.loads(key)
    data = _dicts(key)
    rows = []
    for i in indices:
        t = PT.prepare_trial(d["kind"], i, data[i])
        row: dict[str, Any] = {"index": i}
        for k in CONDITIONS:
            if k in data[i]:
                row[k] = data[i][k]
        if t is None:
            rows.append({**row, "prepared": False})
            continue
        for who, block in (("law", None), ("policy", _W["block"])):
            c0 = time.process_time()
            s = _W["flyer"].fly(t, block)
            cpu = time.process_time() - c0
            valid, ok, lost = PT.outcome(t, s)
            rec = s.get("time_to_recover_s")
            hov = s.get("time_to_hover_s")
            hover = (rec is not None and hov is not None
                     and hov - rec <= HOVER_WITHIN_S)  # fmt: skip
            row.update({
                f"{who}_valid": valid, f"{who}_ok": ok, f"{who}_lost_m": lost,
                f"{who}_recovered": bool(s.get("recovered")), f"{who}_hover": bool(hover),
                f"{who}_recover_s": rec, f"{who}_cpu_s": cpu,
            })  # fmt: skip
        rows.append({**row, "prepared": True})
    return rows


def _wilson(k: int, n: int) -> tuple[float, float, float]:
    from quadimpact.studies.statistics import rate

    r = rate(k, n)
    return r.value, r.low, r.high


def _paired(a: np.ndarray, b: np.ndarray) -> tuple[float, float, float]:
    d = a.astype(float) - b.astype(float)
    m = float(d.mean())
    half = 1.959964 * float(d.std(ddof=1)) / math.sqrt(len(d)) if len(d) > 1 else math.nan
    return m, m - half, m + half


def summarise(name: str, spec: dict[str, Any], rows: list[dict[str, Any]], out: Path) -> dict:
    import pandas as pd

    t = pd.DataFrame(rows).sort_values("index").reset_index(drop=True)
    t.to_csv(out / f"{name.replace('/', '-').replace(' ', '').replace(',', '-')}.csv", index=False)
    ok = t["prepared"].fillna(False).astype(bool)
    valid = (
        ok
        & t["law_valid"].fillna(False).astype(bool)
        & t["policy_valid"].fillna(False).astype(bool)
    )
    tv = t[valid]
    res: dict[str, Any] = {"set": name, **spec, "trials": len(t), "valid": int(valid.sum())}
    law = tv["law_ok"].astype(bool).to_numpy()
    pol = tv["policy_ok"].astype(bool).to_numpy()
    for who, x in (("law", law), ("policy", pol)):
        res[who] = dict(zip(("success", "low", "high"), _wilson(int(x.sum()), len(x)), strict=True))
        res[who]["k"] = int(x.sum())
        rec = tv[f"{who}_recovered"].astype(bool)
        res[who]["recovered"] = int(rec.sum())
        res[who]["hover_within_2s"] = (
            float(tv.loc[rec, f"{who}_hover"].astype(bool).mean()) if rec.any() else math.nan
        )
        lost = tv[f"{who}_lost_m"].astype(float)
        res[who]["lost_p50_m"] = float(np.nanpercentile(lost, 50))
        res[who]["lost_p90_m"] = float(np.nanpercentile(lost, 90))
        res[who]["cpu_ms_per_trial"] = 1e3 * float(t.loc[ok, f"{who}_cpu_s"].mean())
    m, lo, hi = _paired(pol, law)
    res["difference"] = {"points": 100 * m, "low": 100 * lo, "high": 100 * hi}
    res["only_law"] = int((law & ~pol).sum())
    res["only_policy"] = int((pol & ~law).sum())
    res["cpu_ratio"] = res["policy"]["cpu_ms_per_trial"] / res["law"]["cpu_ms_per_trial"]
    res["examples"] = {}
    data = _dicts(_key(spec))
    for label, mask in (("only_law", law & ~pol), ("only_policy", pol & ~law)):
        if mask.any():
            row = tv[mask].iloc[0]
            i = int(row["index"])
            stem = f"{name.replace('/', '-').replace(' ', '').replace(',', '-')}-{label}"
            _write_scenario(data[i], out / "examples" / f"{stem}.toml", policy=label)
            conditions = {k: row[k] for k in CONDITIONS if k in row and pd.notna(row[k])}
            res["examples"][label] = {
                "index": i,
                "file": f"examples/{stem}.toml",
                **conditions,
                "law_lost_m": float(row["law_lost_m"]),
                "policy_lost_m": float(row["policy_lost_m"]),
            }
    return res


def _write_scenario(data: dict[str, Any], path: Path, policy: str) -> None:
    """One trial as a scenario file (the law's; the policy's line commented in or out)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    lines = [f"# {policy.replace('_', ' ')}: fly it with and without the policy line below",
             "# quadimpact run THIS_FILE --out DIR"]  # fmt: skip
    tables = []
    for k, v in data.items():
        if isinstance(v, dict):
            tables.append((k, v))
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            tables.append((k, v))
        elif v is not None:
            lines.append(f"{k} = {json.dumps(v)}")
    for k, v in tables:
        if isinstance(v, dict):
            lines += [
                "",
                f"[{k}]",
                *(f"{a} = {json.dumps(b)}" for a, b in v.items() if b is not None),
            ]
        else:
            for item in v:
                lines += ["", f"[[{k}]]", *(f"{a} = {json.dumps(b)}" for a, b in item.items())]
    if not any(k == "controller_params" for k, _ in tables):
        lines += ["", "[controller_params]"]
    lines.append('policy = "learned"  # delete this line to fly the law alone')
    path.write_text("\n".join(lines) + "\n")


def _key(spec: dict[str, Any]) -> str:
    return json.dumps(spec, sort_keys=True)


def render(results: list[dict[str, Any]], meta: dict[str, Any]) -> str:
    def pct(x: float) -> str:
        return f"{100 * x:.1f}"

    lines = [
        "# The learned policy against the staged law",
        "",
        f"Policy `{meta['policy']}` (SHA-256 `{meta['sha256'][:16]}`...), quadimpact "
        f"{meta['quadimpact']}; {meta['minutes']:.1f} min on {meta['workers']} worker(s). Every "
        "trial flown by both on the same conditions and sensor noise (the benchmark's trials, "
        "none used in training). Success % [95 % Wilson]; difference = policy - law, "
        "paired, in points [95 %]; hover = recovered trials hovering within 2 s of recovery.",
        "",
        "| set | trials | law | policy | difference | only law | only policy | hover law "
        "| hover policy | lost p90 law / policy (m) | CPU ms/trial law / policy |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        a, b, d = r["law"], r["policy"], r["difference"]
        lines.append(
            f"| {r['set']} | {r['valid']} | {pct(a['success'])} [{pct(a['low'])}, "
            f"{pct(a['high'])}] | {pct(b['success'])} [{pct(b['low'])}, {pct(b['high'])}] | "
            f"{d['points']:+.1f} [{d['low']:+.1f}, {d['high']:+.1f}] | {r['only_law']} | "
            f"{r['only_policy']} | {pct(a['hover_within_2s'])} | {pct(b['hover_within_2s'])} | "
            f"{a['lost_p90_m']:.2f} / {b['lost_p90_m']:.2f} | {a['cpu_ms_per_trial']:.1f} / "
            f"{b['cpu_ms_per_trial']:.1f} |"
        )
    lines += ["", "## Examples (the first trial of each kind)", ""]
    for r in results:
        for label, ex in r["examples"].items():
            cond = ", ".join(
                f"{k} {v:g}" if isinstance(v, float) else f"{k} {v}"
                for k, v in ex.items()
                if k in CONDITIONS
            )
            lines.append(
                f"- {r['set']}, {label.replace('_', ' ')}: trial {ex['index']} ({cond}): height "
                f"lost {ex['law_lost_m']:.2f} m by the law, {ex['policy_lost_m']:.2f} m with the "
                f"policy; `{ex['file']}`."
            )
    return "\n".join(lines) + "\n"


def main() -> None:
    from quadimpact import __version__
    from quadimpact.inputs.policy_file import load_policy

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--policy", default="learned")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--sets", default="", help="Comma-separated set names (default: all).")
    ap.add_argument(
        "--limit", type=int, default=0, help="Only each set's first trials (a smoke test)."
    )
    a = ap.parse_args()
    a.out.mkdir(parents=True, exist_ok=True)
    policy = load_policy(a.policy)
    started = time.perf_counter()
    chosen = sets(a.quick)
    if a.sets:
        chosen = {k: v for k, v in chosen.items() if k in a.sets.split(",")}
    pool = mp.get_context("spawn").Pool(a.workers, initializer=_init, initargs=(a.policy,))
    results = []
    for name, spec in chosen.items():
        t0 = time.perf_counter()
        n = len(_dicts(_key(spec)))
        n = min(n, a.limit) if a.limit else n
        chunk = 100
        jobs = [(_key(spec), list(range(i, min(i + chunk, n)))) for i in range(0, n, chunk)]
        rows = [r for part in pool.imap_unordered(_fly, jobs) for r in part]
        res = summarise(name, spec, rows, a.out)
        res["wall_s"] = time.perf_counter() - t0
        results.append(res)
        print(f"{name}: law {100 * res['law']['success']:.1f} %, policy "
              f"{100 * res['policy']['success']:.1f} % ({res['difference']['points']:+.1f} pts), "
              f"{res['valid']} trials, {res['wall_s']:.0f} s", flush=True)  # fmt: skip
    pool.close()
    pool.join()
    meta = {"policy": a.policy, "sha256": policy.sha256, "quadimpact": __version__,
            "quick": a.quick, "workers": a.workers,
            "minutes": (time.perf_counter() - started) / 60, "training": policy.meta}  # fmt: skip
    (a.out / "eval.json").write_text(json.dumps({"meta": meta, "sets": results}, indent=1,
                                                default=float) + "\n")  # fmt: skip
    (a.out / "eval.md").write_text(render(results, meta))
    print(f"wrote {a.out / 'eval.md'}")


if __name__ == "__main__":
    main()
