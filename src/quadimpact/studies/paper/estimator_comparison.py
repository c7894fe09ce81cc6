"""The estimators compared on the same seeded trials, beside the authors' figures.

Part of ``quadimpact reproduce``'s "Beyond the paper: recovery"
(docs/ESTIMATION.md 5): the first :data:`COMPARE_N` impact trials of the
Navi's Monte Carlo (the same conditions and IMU seeds) run with each of
:data:`ESTIMATORS` under the ``impact`` sensors (the noisy IMU with the
impact disturbance and a gyro bias walk); the numbers (success with its
interval, time to recover and to hover, height loss, the attitude error by
phase), one trial's attitude error over time around the impact per
estimator, and what fails, where and why. The authors' figures
(:data:`AUTHORS`) stand beside them.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pandas as pd

from quadimpact.results.estimate_figures import make_error_comparison
from quadimpact.results.figures import save_figure
from quadimpact.studies.recovery import recovery_analysis as analysis
from quadimpact.studies.recovery.recovery_study import RecoveryStudy, run_trials
from quadimpact.studies.statistics import rate_text

__all__ = ["AUTHORS", "COMPARE_N", "ESTIMATORS", "compare_estimators", "estimators_markdown"]

#: Trials per estimator (the first of the Navi's Monte Carlo, seed 0).
COMPARE_N = 1_000
#: The estimators compared, and the sensors they all have.
ESTIMATORS = ("ideal", "complementary", "ekf")
SENSORS = "impact"
#: The authors' figures: simulated Monte Carlo (attitude error RMS, deg) and the real vehicle.
AUTHORS = {
    "crash_rms_deg": {"complementary": 12.3, "ekf": 4.3},
    "run_rms_deg": {"complementary": 7.5, "ekf": 3.9},
    "real_time_to_recover_s": {"complementary": 0.99, "ekf": 0.82},
    "real_crashes": 53,
}
FIGURE = "recovery_estimators_error.png"


def compare_estimators(
    out: Path, par: dict[str, Any], n: int = COMPARE_N
) -> tuple[dict[str, Any], pd.DataFrame, Path]:
    """Run the comparison into ``out/recovery/estimator-<name>``; numbers, trials, figure.

    Returns ``(numbers, trials, figure)``: ``numbers[name]`` is
    :func:`quadimpact.studies.recovery.recovery_analysis.summarise` of that estimator's trials
    plus ``whole_run_rms_deg`` (quantiles of each trial's attitude-error RMS over the
    run); ``trials`` every trial, with an ``estimator``
    column.
    """
    numbers: dict[str, Any] = {}
    tables = []
    for name in ESTIMATORS:
        study = RecoveryStudy(n=n, estimator=name, sensors=SENSORS)
        table = run_trials(study, out / "recovery" / f"estimator-{name}", **par)[1]
        numbers[name] = analysis.summarise(table)
        numbers[name]["whole_run_rms_deg"] = analysis.quantiles(table["est_attitude_rms_run_deg"])
        tables.append(table.assign(study=f"estimator {name}"))
    trials = pd.concat(tables, ignore_index=True)
    figure = out / FIGURE
    save_figure(_example_figure(trials, n), figure)
    return numbers, trials, figure


def _example_trial(trials: pd.DataFrame) -> int:
    """The trial (run_id) nearest the median conditions among those every estimator recovers."""
    ok = trials.groupby("run_id")["recovered"].all()
    first = trials[trials["study"] == f"estimator {ESTIMATORS[0]}"]
    first = first[first["run_id"].isin(ok[ok].index)]
    return analysis.example_trial(first if len(first) else trials)


def _example_figure(trials: pd.DataFrame, n: int):
    from quadimpact.inputs.scenarios import ImpactTrial
    from quadimpact.simulation import simulate

    run_id = _example_trial(trials)
    row = trials[trials["run_id"] == run_id].iloc[0]
    conditions = {k: row[k].item() for k in ("roll_deg", "pitch_deg", "yaw_deg", "speed_m_s")}
    runs = {
        name: simulate(ImpactTrial(**conditions, seed=int(row["seed"]), estimator=name,
                                   sensors=SENSORS))
        for name in ESTIMATORS
    }  # fmt: skip
    return make_error_comparison(
        runs,
        title=f"Trial {run_id} (roll {conditions['roll_deg']:.1f}°, pitch "
        f"{conditions['pitch_deg']:.1f}°, {conditions['speed_m_s']:.2f} m/s): attitude error "
        "around the impact (dashed: stage 4)",
    )


def _q(x: dict[str, float], digits: int = 2) -> str:
    if not x or not x.get("n"):
        return "–"
    return f"{x['median']:.{digits}f} / {x['p90']:.{digits}f}"


def _fmt(x: Any, digits: int = 1) -> str:
    return (
        "–" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.{digits}f}"
    )


def estimators_markdown(numbers: dict[str, Any], n: int) -> list[str]:
    """The report's subsection: the table beside the authors' figures, and what fails."""
    lines = [
        f"### Estimators through the impact ({n:,} trials each)",
        "",
        f"The same first {n:,} trials (conditions and IMU seeds) with each estimator, all "
        "with the `impact` sensors: the noisy IMU, the authors' impact disturbance (extra "
        "noise of 14 m/s² and 0.1 rad/s decaying with 0.4 s after each contact onset) and a "
        "gyro bias walk; no magnetometer, no pose sensor. The controller and the detector's "
        "wall normal read the estimate. Attitude error: each trial's RMS in the phase, then "
        "the median / 90th percentile over the trials (crash: first contact to stage 4).",
        "",
        "| estimator | success [95 % CI] | time to recover (s) | time to hover (s), reached "
        "| height loss (m) | attitude error, crash (°) | after stage 4 (°) | whole run (°) "
        "| authors: crash / run (°) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name in ESTIMATORS:
        x = numbers[name]
        e = x.get("estimation") or {}
        authors = "–"
        if name in AUTHORS["crash_rms_deg"]:
            authors = f"{AUTHORS['crash_rms_deg'][name]} / {AUTHORS['run_rms_deg'][name]}"
        hover = e.get("time_to_hover_s") or {}
        lines.append(
            f"| {name} | {rate_text(x['success'])} | {_q(x['time_to_recover_s'], 3)} "
            f"| {_q(hover, 2)}, {100 * e.get('hover_share', 0.0):.0f} % "
            f"| {_q(x['height_loss_m'], 3)} | {_q(e.get('attitude_crash', {}))} "
            f"| {_q(e.get('attitude_post', {}))} | {_q(x['whole_run_rms_deg'])} | {authors} |"
        )
    real = AUTHORS["real_time_to_recover_s"]
    lines += [
        "",
        f"The authors' real vehicle recovered in {real['ekf']} s (mean, their EKF on board) "
        f"against {real['complementary']} s (the autopilot's complementary estimator), over "
        f"{AUTHORS['real_crashes']} crashes each; their simulated Monte Carlo gave the attitude "
        "errors in the last column.",
        "",
        f"![Attitude error around the impact]({FIGURE})",
        "",
        *_what_fails(numbers),
    ]
    return lines


def _what_fails(numbers: dict[str, Any]) -> list[str]:
    ideal = numbers["ideal"]
    lines = ["What fails, where and why:", ""]
    for name in ESTIMATORS[1:]:
        x = numbers[name]
        e = x.get("estimation") or {}
        diff = x["success"].k - ideal["success"].k
        lines.append(
            f"- `{name}`: {_fmt(100 * x['success'].value)} % recovered against "
            f"{_fmt(100 * ideal['success'].value)} % with the true state ({diff:+d} trials); "
            f"its attitude error is {_q(e.get('attitude_crash', {}))} ° in the "
            f"crash and {_q(e.get('attitude_post', {}))} ° after stage 4, its velocity error "
            f"{_q(e.get('velocity_post', {}), 2)} m/s after stage 4."
        )
    lines += [
        "- Where: the accelerometer measures gravity only when the vehicle does not "
        "accelerate, but a quadrotor's specific force always points along its thrust axis; "
        "so a tilted vehicle whose thrust is near its weight passes the `||f| - g|` gate and "
        "pulls the estimate toward level. During the impact the contact forces and the "
        "disturbance put the specific force far from g and the gate closes: the attitude "
        "rests on the gyro, whose disturbance noise integrates into a small error.",
        "- Why the velocity and position fail: without a pose sensor they come from "
        "integrating the accelerometer, which saturates (±16 g) and rings through the "
        "impact: their errors grow to metres per second and metres, and stage 5 holds a "
        "drifting position (the vehicle follows the drift). With a pose sensor (the "
        "`indoor` sensors) the EKF's velocity and position stay bounded.",
        "",
    ]
    return lines
