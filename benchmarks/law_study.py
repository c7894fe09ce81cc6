"""The parameter study behind the default recovery law (docs/BENCHMARK.md 4).

Run: ``python benchmarks/law_study.py --out DIR [--phase screen|confirm|sensors|all]
[--workers 2]`` (resumable: the same command again resumes every sweep).

Candidate laws are sets of the ``recovery`` controller's parameters
(``[controller_params]``, docs/RECOVERY.md 3.5) in the default physics, each
flown with the benchmark tasks' own pre-impact behaviour (the wall: spun down
until the detection; the pole and the edge: the ``paper`` controller until the
detection). Every trial is **held out** from the benchmark's
(``quadimpact.studies.benchmark.suite``): the wall's trials come from seeds 1
and 2 (the benchmark's from 0), the grids' points lie between the benchmark's
(pitches at half degrees, offsets at odd half centimetres), so that the
choice is never made on the trials it is then measured on.

* ``screen``: :data:`ANCHORS` and :data:`N_RANDOM` candidates drawn (seed
  :data:`SPACE_SEED`) from :data:`SPACE`, on the hard part of each task,
  where every law's failures lie: 600 wall trials (seed 1) with the pitch
  drawn in [-45, -20] deg instead of [-45, 45] (toward the wall by 20 deg or
  more), and the grids' pitches beyond 24 deg (21 x 24 = 504 points each).
  Each task's success over the whole task is estimated as if the rest of it
  (the wall's other 65/90 of the pitches, the grids' 24 of 45 pitches)
  always succeeds, which the confirmation checks.
* ``confirm``: the :data:`N_CONFIRM` best of the screen by the mean of the
  three estimated successes, with the anchors, on whole held-out tasks: 4,000
  wall trials (seed 2, the authors' distribution) and the grids' 45 x 70 =
  3,150 held-out points each.
* ``sensors``: the :data:`N_SENSORS` best of the confirmation with the
  ``impact`` sensors and the EKF (the grids' points seeded from 1).
* ``sensing``: why the ``impact`` sensors cost what they cost (docs/BENCHMARK.md
  6): the chosen law (:data:`CHOSEN`) on held-out trials, :data:`SENSING_WALL_N`
  wall trials of seed 2 and the screen's steep pole and edge points, with each
  part of the sensing on or off on its own (:data:`SENSINGS`), every sensing on
  the same trials (the same noise); then the differences of :data:`PARTS`
  trial by trial (paired), with 95 % intervals.

Writes, in ``DIR``: each sweep (``<phase>/<set>/``: ``runs.parquet``, every
run's row, kept), ``<phase>.csv`` (one row per candidate: its parameters, its
success per set with 95 % Wilson intervals, and the estimates) and
``candidates.json`` (the candidates, in order), ``sensing.csv`` (each task and
sensing: success with its 95 % Wilson interval, the post-impact velocity
estimate's error, the normal estimate's error, the hover share, the height lost)
and ``sensing_parts.csv`` (the paired differences). The rule
of the choice: the confirmation's best mean success over the three tasks
(ideal sensors), checked to be the best too by the mean over both sensor sets
in the ``sensors`` phase; it was ``r10`` (:data:`CHOSEN`), the default law
since issue #45 (docs/BENCHMARK.md 4 has the tables).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path
from typing import Any

import numpy as np

G = 9.81
#: The staged law's parameters every candidate sets (the rest keep the controller's own).
SPACE: dict[str, list[Any]] = {
    "a_mag_m_s2": [0.0, 2.4, 4.8, 7.2, 9.81],
    "k_z12": [0.0, 2.5, 5.0, 10.0],  # k_z of stages 1 and 2 (stages 3 and 4: 10 1/s)
    "k_rate_r": [0.0, 2.0],  # yaw-rate gain (p and q: 20 1/s)
    "k_att_1_s": [15.0, 20.0, 30.0],
    "tilt_error_tol": [0.15, 0.3],
    "rate_tol_rad_s": [0.5, 1.0, 2.0],
    "level_test": ["euler", "tilt-error"],
    "w_tol_m_s": [0.2, 0.3],
    "lean_cut_deg": [None, 30.0, 35.0, 40.0, 45.0, 50.0],
    "lean_cut_force_m_s2": [0.0, G / 4, G / 2, 3 * G / 4],
}
SPACE_SEED = 45
N_RANDOM = 64
N_CONFIRM = 8
N_SENSORS = 4
CLASSIC = {
    "a_mag_m_s2": G, "k_z12": 0.0, "k_rate_r": 2.0, "k_att_1_s": 20.0, "tilt_error_tol": 0.3,
    "rate_tol_rad_s": 0.5, "level_test": "tilt-error", "w_tol_m_s": 0.3, "lean_cut_deg": None,
    "lean_cut_force_m_s2": 0.0,
}  # fmt: skip
POLE_LAW = {
    **CLASSIC, "a_mag_m_s2": 4.8, "tilt_error_tol": 0.15, "rate_tol_rad_s": 2.0,
    "level_test": "euler", "w_tol_m_s": 0.2,
}  # fmt: skip
#: Candidates every phase runs: the previous default law (``classic``), the authors' pole
#: law, and three found in preliminary runs on held-out points (docs/BENCHMARK.md 4).
ANCHORS: dict[str, dict[str, Any]] = {
    "classic": CLASSIC,
    "pole-law": POLE_LAW,
    "b5": {**POLE_LAW, "a_mag_m_s2": 2.4, "k_z12": 5.0, "k_rate_r": 0.0},
    "b5-lean40": {**POLE_LAW, "a_mag_m_s2": 2.4, "k_z12": 5.0, "k_rate_r": 0.0,
                  "lean_cut_deg": 40.0, "lean_cut_force_m_s2": G / 2},
    "b5-lean30": {**POLE_LAW, "a_mag_m_s2": 2.4, "k_z12": 5.0, "k_rate_r": 0.0,
                  "lean_cut_deg": 30.0, "lean_cut_force_m_s2": G / 2},
}  # fmt: skip
#: Wall trials of the screen, and the pitch range they are drawn in, deg.
SCREEN_WALL_N, SCREEN_WALL_PITCH = 600, (-45.0, -20.0)
CONFIRM_WALL_N = 4_000
#: Share of the authors' pitch range ([-45, 45]) outside the screen's.
WALL_EASY_SHARE = 65.0 / 90.0
STEEP_FROM_DEG = 24.5
#: The law the study chose (docs/BENCHMARK.md 4): the default since issue #45.
CHOSEN = "r10"
#: The ``sensing`` phase's sensings, each as the scenario fields it sets (``controller_params``
#: merged into the chosen law's): the benchmark's two sets, each part of the ``impact`` IMU
#: (its accelerometer and gyro impact disturbance, its bias walk) removed on its own, the
#: law without its stage 5, and what added information would give (a pose sensor, with and
#: without its attitude; the same IMU sampled at 1 kHz instead of every 200-Hz tick), and the
#: detector firing on 3 consecutive samples instead of 1 (a later, less disturbed normal); the
#: law without its lean cut.
_IMPACT_IMU = {"sensors": "impact"}
SENSINGS: dict[str, dict[str, Any]] = {
    "ideal": {},
    "impact, true state": _IMPACT_IMU,
    "impact without accel disturbance, true state": {
        **_IMPACT_IMU, "imu": {"preset": "impact", "impact_disturbance": {"accel_m_s2": 0.0}}},
    "noisy, ekf": {"sensors": "noisy", "estimator": "ekf"},
    "impact, ekf": {**_IMPACT_IMU, "estimator": "ekf"},
    "impact without accel disturbance, ekf": {
        **_IMPACT_IMU, "estimator": "ekf",
        "imu": {"preset": "impact", "impact_disturbance": {"accel_m_s2": 0.0}}},
    "impact without gyro disturbance, ekf": {
        **_IMPACT_IMU, "estimator": "ekf",
        "imu": {"preset": "impact", "impact_disturbance": {"gyro_rad_s": 0.0}}},
    "impact without bias walk, ekf": {
        **_IMPACT_IMU, "estimator": "ekf",
        "imu": {"preset": "impact", "gyro_bias_walk_rad_s_sqrt_s": 0.0}},
    "impact, ekf, no stage 5": {
        **_IMPACT_IMU, "estimator": "ekf", "controller_params": {"hover": False}},
    "indoor, ekf": {"sensors": "indoor", "estimator": "ekf"},
    "indoor position only, ekf": {
        "sensors": "indoor", "estimator": "ekf", "pose_sensor": {"attitude": False}},
    "impact at 1 kHz, true state": {**_IMPACT_IMU, "imu": {"preset": "impact", "rate_hz": 1000.0}},
    "impact at 1 kHz, ekf": {
        **_IMPACT_IMU, "estimator": "ekf", "imu": {"preset": "impact", "rate_hz": 1000.0}},
    "ideal, detection on 3 samples": {"detection": {"persistence": 3}},
    "impact, true state, detection on 3 samples": {
        **_IMPACT_IMU, "detection": {"persistence": 3}},
    "impact, ekf, detection on 3 samples": {
        **_IMPACT_IMU, "estimator": "ekf", "detection": {"persistence": 3}},
    "ideal, no lean cut": {"controller_params": {"lean_cut_deg": None}},
    "impact, true state, no lean cut": {**_IMPACT_IMU, "controller_params": {"lean_cut_deg": None}},
    "impact, ekf, no lean cut": {
        **_IMPACT_IMU, "estimator": "ekf", "controller_params": {"lean_cut_deg": None}},
}  # fmt: skip
#: The sensing phase's paired differences: (what it measures, sensing a, sensing b), a - b.
PARTS: list[tuple[str, str, str]] = [
    ("the whole gap", "ideal", "impact, ekf"),
    ("the impact IMU read as it is, true state", "ideal", "impact, true state"),
    ("  of which the accelerometer's disturbance", "impact without accel disturbance, true state",
     "impact, true state"),
    ("the EKF's estimate with the impact IMU", "impact, true state", "impact, ekf"),
    ("the EKF with the noisy IMU (no disturbance)", "ideal", "noisy, ekf"),
    ("removing the accelerometer's disturbance", "impact without accel disturbance, ekf",
     "impact, ekf"),
    ("removing the gyro's disturbance", "impact without gyro disturbance, ekf", "impact, ekf"),
    ("removing the bias walk", "impact without bias walk, ekf", "impact, ekf"),
    ("stage 5 off (no position hold)", "impact, ekf, no stage 5", "impact, ekf"),
    ("adding a pose sensor", "indoor, ekf", "impact, ekf"),
    ("adding a position sensor only", "indoor position only, ekf", "impact, ekf"),
    ("the IMU at 1 kHz, ekf", "impact at 1 kHz, ekf", "impact, ekf"),
    ("the IMU at 1 kHz, true state", "impact at 1 kHz, true state", "impact, true state"),
    ("detection on 3 samples, ideal", "ideal, detection on 3 samples", "ideal"),
    ("detection on 3 samples, true state", "impact, true state, detection on 3 samples",
     "impact, true state"),
    ("detection on 3 samples, ekf", "impact, ekf, detection on 3 samples", "impact, ekf"),
    ("the gap with detection on 3 samples", "ideal, detection on 3 samples",
     "impact, ekf, detection on 3 samples"),
    ("the lean cut, ideal", "ideal", "ideal, no lean cut"),
    ("the impact IMU read as it is, true state, no lean cut", "ideal, no lean cut",
     "impact, true state, no lean cut"),
    ("the gap without the lean cut", "ideal, no lean cut", "impact, ekf, no lean cut"),
    ("the lean cut, impact + ekf", "impact, ekf", "impact, ekf, no lean cut"),
]  # fmt: skip
#: Wall trials of the sensing phase (seed 2, the authors' distribution).
SENSING_WALL_N = 2_000
#: A run longer than this (s, in a worker) is stopped and counts as a failure.
TIMEOUT_S = 120.0


def candidates() -> dict[str, dict[str, Any]]:
    """The anchors, then the random candidates ``r00``... (seeded)."""
    rng = np.random.Generator(np.random.PCG64(SPACE_SEED))
    out = dict(ANCHORS)
    for i in range(N_RANDOM):
        out[f"r{i:02d}"] = {k: v[int(rng.integers(len(v)))] for k, v in SPACE.items()}
    return out


def controller_params(c: dict[str, Any]) -> dict[str, Any]:
    """A candidate as the ``recovery`` controller's parameters."""
    params = {
        "a_mag_m_s2": c["a_mag_m_s2"],
        "k_z_1_s": (c["k_z12"], c["k_z12"], 10.0, 10.0),
        "k_rate_1_s": (20.0, 20.0, c["k_rate_r"]),
        "k_att_1_s": c["k_att_1_s"],
        "tilt_error_tol": c["tilt_error_tol"],
        "rate_tol_rad_s": c["rate_tol_rad_s"],
        "level_test": c["level_test"],
        "euler_tol_rad": 0.2,
        "w_tol_m_s": c["w_tol_m_s"],
        "lean_cut_force_m_s2": c["lean_cut_force_m_s2"],
    }
    if c["lean_cut_deg"] is not None:
        params["lean_cut_deg"] = c["lean_cut_deg"]
    return params


def held_out_grid(steep: bool) -> dict[str, list[float]]:
    """Pitches at half degrees and offsets at odd half centimetres: none on the benchmark's grid."""
    pitches = [-(0.5 + k) for k in range(45)]
    if steep:
        pitches = [p for p in pitches if -p >= STEEP_FROM_DEG]
    step = 0.03 if steep else 0.01
    n = round(0.69 / step) + 1
    offsets = [round(-0.345 + step * k, 6) for k in range(n)]
    return {"pitch_deg": pitches, "lateral_offset_m": offsets}


def wall_spec(params: list[dict[str, Any]], n: int, seed: int, hard: bool, sensing: Any):
    """Wall trials (the authors' distribution; ``hard``: the screen's pitch range), every
    candidate on the same trials."""
    from quadimpact.studies.benchmark.suite import TASKS
    from quadimpact.studies.recovery.recovery_spec import DISTRIBUTION
    from quadimpact.sweep import SweepSpec

    base = TASKS["wall"].wall_study(True, sensing).base()
    ranges = {k: list(v) for k, v in DISTRIBUTION.items()}
    if hard:
        ranges["pitch_deg"] = list(SCREEN_WALL_PITCH)
    trials = {"n": n, "seed": seed, "ranges": ranges, "seed_field": "seed"}
    return SweepSpec(base=base, grid={"controller_params": params}, trials=trials, where="wall")


def grid_spec(name: str, params: list[dict[str, Any]], steep: bool, sensing: Any):
    """A grid task on held-out points, the recovery arm with every candidate at each point."""
    from quadimpact.studies.benchmark.suite import TASKS
    from quadimpact.sweep import SweepSpec
    from quadimpact.sweep.trials import trial_draws

    study = TASKS[name].grid_study(True, sensing)
    arm = study.arms()[1]
    arms = [{**arm, "controller_params": p} for p in params]
    grid = held_out_grid(steep)
    if sensing.sensors is None:
        return SweepSpec(base=study.base(), grid=grid, runs=arms, where=name)
    points = [(p, o) for p in grid["pitch_deg"] for o in grid["lateral_offset_m"]]
    runs = [
        {"pitch_deg": p, "lateral_offset_m": o, "seed": trial_draws(1, i, {}, "seed")["seed"], **a}
        for i, (p, o) in enumerate(points)
        for a in arms
    ]
    return SweepSpec(base=study.base(), runs=runs, where=name)


def success_by_candidate(spec: Any, out: Path, kind: str, n_cand: int, workers: int):
    """Run the sweep (resuming) and each candidate's successes and trials."""
    from quadimpact.studies.recovery import recovery_analysis as analysis
    from quadimpact.sweep import run_sweep

    t = run_sweep(spec, out, workers=workers, timeout=TIMEOUT_S)
    t = t.sort_values("run_id").reset_index(drop=True)
    if kind == "wall":
        n = len(t) // n_cand
        cand = t["run_id"].to_numpy() // n
        t["pitch_deg"] = t["pitch_deg"].astype(float)
        t["speed_m_s"] = t["speed_m_s"].astype(float)
        t = analysis.add_derived(t)
        ok = analysis.success_mask(t)
    else:
        cand = t["run_id"].to_numpy() % n_cand
        lost = 2.0 - t["final_altitude_m"].astype(float).to_numpy()
        ok = np.isfinite(lost) & (lost < 2.0) & (t["status"] != "failed").to_numpy()
    failed = (t["status"] == "failed").to_numpy()
    return [
        (int(ok[cand == i].sum()), int((cand == i).sum()), int(failed[cand == i].sum()))
        for i in range(n_cand)
    ]


def run_phase(phase: str, names: list[str], out: Path, workers: int) -> list[dict[str, Any]]:
    """Every candidate of ``names`` on the phase's sets; one table row each."""
    from quadimpact.studies.benchmark.suite import sensor_set
    from quadimpact.studies.statistics import rate

    every = candidates()
    params = [controller_params(every[n]) for n in names]
    sensing = sensor_set("impact" if phase == "sensors" else "ideal")
    screen = phase == "screen"
    sets = {
        "wall": wall_spec(params, SCREEN_WALL_N if screen else CONFIRM_WALL_N,
                          1 if screen else 2, screen, sensing),
        "pole": grid_spec("pole", params, screen, sensing),
        "edge": grid_spec("edge", params, screen, sensing),
    }  # fmt: skip
    rows = [{"candidate": n, **every[n]} for n in names]
    for set_name, spec in sets.items():
        start = time.perf_counter()
        kind = "wall" if set_name == "wall" else "grid"
        counts = success_by_candidate(spec, out / phase / set_name, kind, len(names), workers)
        print(f"{phase} {set_name}: {spec.n_runs} runs, {time.perf_counter() - start:.0f} s",
              flush=True)  # fmt: skip
        for row, (k, n, failed) in zip(rows, counts, strict=True):
            r = rate(k, n)
            row[f"{set_name}_k"], row[f"{set_name}_n"], row[f"{set_name}_failed"] = k, n, failed
            row[set_name], row[f"{set_name}_low"], row[f"{set_name}_high"] = r.value, r.low, r.high
    for row in rows:
        if screen:  # the rest of each task assumed to succeed (checked by the confirmation)
            row["wall_est"] = WALL_EASY_SHARE + (1 - WALL_EASY_SHARE) * row["wall"]
            steep = len(held_out_grid(True)["pitch_deg"])
            for g in ("pole", "edge"):
                row[f"{g}_est"] = (45 - steep + steep * row[g]) / 45
        else:
            for t in ("wall", "pole", "edge"):
                row[f"{t}_est"] = row[t]
        row["mean_est"] = (row["wall_est"] + row["pole_est"] + row["edge_est"]) / 3
    return rows


def sensing_spec(task: str, fields: dict[str, Any]) -> Any:
    """The sensing phase's sweep of ``task`` with one sensing (``fields``, :data:`SENSINGS`)."""
    from quadimpact.studies.benchmark.suite import TASKS, sensor_set
    from quadimpact.studies.recovery.recovery_spec import DISTRIBUTION
    from quadimpact.sweep import SweepSpec
    from quadimpact.sweep.trials import trial_draws

    law = controller_params(candidates()[CHOSEN])
    fields = {**fields, "controller_params": {**law, **fields.get("controller_params", {})}}
    if task == "wall":
        base = TASKS["wall"].wall_study(True, sensor_set("ideal")).base()
        if "sensors" in fields:  # the ideal study's own IMU gives way to the sensing's
            base.pop("imu", None)
        ranges = {k: list(v) for k, v in DISTRIBUTION.items()}
        trials = {"n": SENSING_WALL_N, "seed": 2, "ranges": ranges, "seed_field": "seed"}
        return SweepSpec(base={**base, **fields}, trials=trials, where="sensing wall")
    study = TASKS[task].grid_study(True, sensor_set("ideal"))
    grid = held_out_grid(True)
    points = [(p, o) for p in grid["pitch_deg"] for o in grid["lateral_offset_m"]]
    runs = [
        {"pitch_deg": p, "lateral_offset_m": o, **study.arms()[1], **fields,
         "seed": trial_draws(1, i, {}, "seed")["seed"]}
        for i, (p, o) in enumerate(points)
    ]  # fmt: skip
    return SweepSpec(base=study.base(), runs=runs, where=f"sensing {task}")


def sensing_outcomes(task: str, t: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per trial of a sensing sweep's table ``t`` (by run): success, validity, height lost (m)."""
    from quadimpact.studies.recovery import recovery_analysis as analysis
    from quadimpact.studies.recovery.recovery_spec import DISTRIBUTION
    from quadimpact.sweep.trials import trial_draws

    if task == "wall":
        draws = [trial_draws(2, i, DISTRIBUTION, "seed") for i in range(len(t))]
        for k in ("roll_deg", "pitch_deg", "yaw_deg", "speed_m_s"):
            t[k] = [d[k] for d in draws]
        t = analysis.add_derived(t)
        lost = t["height_loss_m"].astype(float).to_numpy()
        return analysis.success_mask(t), analysis.valid_mask(t), lost
    lost = 2.0 - t["final_altitude_m"].astype(float).to_numpy()
    ok = np.isfinite(lost) & (lost < 2.0) & (t["status"] != "failed").to_numpy()
    return ok, np.ones(len(t), bool), lost


def paired_difference(a: np.ndarray, b: np.ndarray) -> tuple[float, float, float]:
    """The mean of ``a - b`` (0/1 outcomes of the same trials) with its 95 % normal interval."""
    d = a.astype(float) - b.astype(float)
    m = float(d.mean())
    half = 1.959964 * float(d.std(ddof=1)) / math.sqrt(len(d))
    return m, m - half, m + half


def run_sensing(out: Path, workers: int) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """The chosen law on held-out trials with each sensing of :data:`SENSINGS`: one row per
    task and sensing, and one per task and part of :data:`PARTS`."""
    from quadimpact.studies.statistics import rate
    from quadimpact.sweep import run_sweep

    rows, parts = [], []
    for task in ("wall", "pole", "edge"):
        ok = {}
        for k, (name, fields) in enumerate(SENSINGS.items()):
            spec = sensing_spec(task, fields)
            t = run_sweep(spec, out / "sensing" / task / f"s{k:02d}", workers=workers,
                          timeout=TIMEOUT_S)  # fmt: skip
            t = t.sort_values("run_id").reset_index(drop=True)
            success, valid, lost = sensing_outcomes(task, t)
            ok[name] = success & valid
            r = rate(int(ok[name].sum()), int(valid.sum()))
            speed_err = t["est_velocity_rms_post_m_s"].astype(float)
            rows.append({
                "task": task, "sensing": name, "k": r.k, "n": r.n, "success": r.value,
                "low": r.low, "high": r.high,
                "velocity_error_p50_m_s": float(speed_err.median()),
                "normal_error_p50_deg": float(t["normal_error_deg"].astype(float).median()),
                "hover": float(t["time_to_hover_s"].astype(float).notna().mean()),
                "height_lost_p50_m": float(np.nanpercentile(lost, 50)),
                "height_lost_p90_m": float(np.nanpercentile(lost, 90)),
            })  # fmt: skip
            print(f"sensing {task} {name}: {100 * r.value:.1f} %", flush=True)
        for what, a, b in PARTS:
            m, low, high = paired_difference(ok[a], ok[b])
            parts.append({"task": task, "part": what.strip(), "a": a, "b": b,
                          "points": 100 * m, "low": 100 * low, "high": 100 * high,
                          "a_only": int((ok[a] & ~ok[b]).sum()),
                          "b_only": int((ok[b] & ~ok[a]).sum())})  # fmt: skip
    return rows, parts


def _best(rows: list[dict[str, Any]], n: int) -> list[str]:
    ranked = sorted(rows, key=lambda r: -r["mean_est"])
    return [r["candidate"] for r in ranked if r["candidate"] not in ANCHORS][:n]


def _write(rows: list[dict[str, Any]], path: Path) -> None:
    import pandas as pd

    pd.DataFrame(rows).sort_values("mean_est", ascending=False).to_csv(path, index=False)
    print(f"wrote {path}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, required=True, help="Study folder (resumable).")
    parser.add_argument(
        "--phase", choices=("screen", "confirm", "sensors", "sensing", "all"), default="all"
    )
    parser.add_argument("--workers", type=int, default=2, help="Worker processes.")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    every = candidates()
    (args.out / "candidates.json").write_text(json.dumps(every, indent=1) + "\n")
    phases = ["screen", "confirm", "sensors", "sensing"] if args.phase == "all" else [args.phase]
    import pandas as pd

    for phase in phases:
        if phase == "sensing":
            rows, parts = run_sensing(args.out, args.workers)
            for name, table in (("sensing.csv", rows), ("sensing_parts.csv", parts)):
                pd.DataFrame(table).to_csv(args.out / name, index=False)
                print(f"wrote {args.out / name}")
            continue
        if phase == "screen":
            names = list(every)
        else:
            before = "screen" if phase == "confirm" else "confirm"
            prior = pd.read_csv(args.out / f"{before}.csv").to_dict("records")
            keep = N_CONFIRM if phase == "confirm" else N_SENSORS
            names = [*ANCHORS, *_best(prior, keep)]
        rows = run_phase(phase, names, args.out, args.workers)
        _write(rows, args.out / f"{phase}.csv")


if __name__ == "__main__":
    main()
