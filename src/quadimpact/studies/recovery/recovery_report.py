"""``report.md`` of the recovery study: a pure function of what ran and of the table's numbers.

:func:`render_report` takes the description of the run
(:func:`quadimpact.studies.recovery.recovery_study.describe`) and the numbers of
:func:`quadimpact.studies.recovery.recovery_analysis.summarise`; nothing in it is typed in.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from quadimpact.results.costs import cost_text
from quadimpact.studies.recovery.estimation_numbers import estimation_lines
from quadimpact.studies.recovery.recovery_analysis import FLIP_DEG, OUTCOME_CLASSES
from quadimpact.studies.slowest import slowest_lines
from quadimpact.studies.statistics import percent, rate_text

__all__ = [
    "bin_table",
    "excluded_text",
    "render_report",
    "spread_table",
]

_MEASURES = (
    ("time_to_recover_s", "time to recover (detection to stage 4)", "s", 3),
    ("height_loss_m", "height loss (detection to stage 4; > 0: lost)", "m", 3),
    ("horizontal_drift_m", "horizontal drift (detection to stage 4)", "m", 3),
    ("stage1_duration_s", "time in stage 1 (tilting away)", "s", 3),
    ("stage2_duration_s", "time in stage 2 (levelling)", "s", 3),
    ("stage3_duration_s", "time in stage 3 (arresting the descent)", "s", 3),
)


def excluded_text(numbers: dict[str, Any]) -> str:
    """How many trials the rates leave out, and why (``none`` when none)."""
    parts = [f"{k} {c}" for c, k in numbers["excluded"].items() if k]
    if not parts:
        return f"none (all {numbers['n']} trials valid)"
    total = numbers["n"] - numbers["n_valid"]
    return f"{total} of {numbers['n']} trials ({', '.join(parts)})"


def _num(x: float, digits: int = 3) -> str:
    return "–" if x is None or not math.isfinite(x) else f"{x:.{digits}f}"


def bin_table(rates: pd.DataFrame, what: str) -> str:
    """A :func:`~quadimpact.studies.recovery.recovery_analysis.rate_by` table as Markdown."""
    lines = [
        f"| {what} | valid trials | recovered | success rate | 95 % interval | not detected "
        "| false detections | excluded |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rates.itertuples():
        lines.append(
            f"| {r.bin} | {r.n} | {r.recovered} | {percent(r.rate)} "
            f"| [{percent(r.low)}, {percent(r.high)}] | {r.not_detected} | {r.false_detection} "
            f"| {getattr(r, 'excluded', 0)} |"
        )
    return "\n".join(lines)


def spread_table(numbers: dict[str, Any], rows: Sequence[tuple[str, str, str, int]]) -> str:
    """Median, 90th percentile, min and max of some measures as Markdown."""
    lines = ["| measure | trials | median | 90th percentile | min | max |",
             "|---|---|---|---|---|---|"]  # fmt: skip
    for key, label, unit, digits in rows:
        q = numbers[key]
        lines.append(
            f"| {label} ({unit}) | {q['n']} | {_num(q['median'], digits)} "
            f"| {_num(q['p90'], digits)} | {_num(q['min'], digits)} | {_num(q['max'], digits)} |"
        )
    return "\n".join(lines)


def _values(v: Sequence[Any]) -> str:
    if not v:
        return "–"

    def one(x: Any) -> str:
        if isinstance(x, (bool, np.bool_)):
            return f"`{str(bool(x)).lower()}`"
        return f"`{x}`" if isinstance(x, str) else f"{x:g}"

    return ", ".join(one(x) for x in v)


def _policy_lines(study: dict[str, Any] | None) -> list[str]:
    """The learned residual the law flew with, if any (docs/LEARNING.md 12)."""
    if not study or study.get("policy") is None:
        return []
    return [
        f"- **Learned policy**: `{study['policy']}` (weights' SHA-256 "
        f"`{study.get('policy_sha256', '')[:16]}`...): a residual on the staged law's thrust and "
        "roll and pitch rate references from the detection on (to the recovery, or the hover "
        "too: its file's `last_stage`), from on-board "
        "quantities only."
    ]


def _what_ran(d: dict[str, Any]) -> list[str]:
    study = d.get("study")
    imu = d["imu"]
    det = d["detection"]
    lines = ["## What ran", ""]
    if study is not None:
        dist = d["distribution"]
        ranges = ", ".join(
            f"{k.removesuffix('_deg').removesuffix('_m_s')} in [{lo:g}, {hi:g}] "
            f"{'deg' if k.endswith('_deg') else 'm/s'}"
            for k, (lo, hi) in dist.items()
        )
        lines += [
            f"- **Trials**: {d['n_trials']} impact trials (docs/RECOVERY.md 5.1) drawn from the "
            f"authors' distribution, each uniform: {ranges}; study seed {study['seed']}. Trial "
            "*i*'s inputs and its own IMU seed come from its own random stream, seeded with "
            "(seed, *i*): the IMU noise is independent from trial to trial and the table is the "
            "same on any number of cores.",
        ]
    else:
        lines += [
            f"- **Trials**: {d['n_trials']} runs of the sweep file `{d['sweep_file']}` (its base "
            f"an impact trial); swept: {', '.join(d['swept']) or 'nothing'}.",
        ]
    lines += [
        f"- **Vehicle**: {_values(d['vehicle'])}; rotor range "
        + (
            f"{d['rotor_speed_range_rpm'][0]:g}-{d['rotor_speed_range_rpm'][1]:g} RPM"
            if d["rotor_speed_range_rpm"]
            else "none"
        )
        + f"; rotor slew limit {d['slew_limit']}."
        + (
            " The vehicle file has no slew limit; without one the spin-down would stop the "
            "rotors within one control tick, so the study passes the Navi's."
            if "set by the study" in d["slew_limit"]
            else ""
        ),
        f"- **Model variant**: {_values(d['model'])}; controller {_values(d['controller'])}; "
        f"pre-impact behaviour {_values(d['pre_impact'])}.",
        *_policy_lines(study),
        "- **Model switches** (as run): "
        + "; ".join(f"`{k}` = {_values(v)}" for k, v in d["model_options"].items())
        + ".",
        f"- **IMU**: preset `{imu['preset']}`, {imu['rate_hz']:g} Hz, at "
        f"({', '.join(f'{c:g}' for c in imu['position_m'])}) m from the CM (body FRD); "
        f"noise {imu['accel_noise_m_s2']:g} m/s² and {imu['gyro_noise_rad_s']:g} rad/s, "
        f"bias std {imu['accel_bias_m_s2']:g} m/s² and {imu['gyro_bias_rad_s']:g} rad/s, "
        "ranges "
        + (f"±{imu['accel_range_m_s2']:g} m/s²" if imu["accel_range_m_s2"] else "none")
        + " and "
        + (f"±{imu['gyro_range_rad_s']:g} rad/s" if imu["gyro_range_rad_s"] else "none")
        + f", filter `{imu['filter']}`.",
        f"- **Detection**: {'on' if det['enabled'] else 'off'}, threshold "
        f"{det['threshold_g']:g} g = {_values(d['detection_threshold_m_s2'])} m/s², "
        f"{det['frame']}-horizontal specific force, persistence {det['persistence']}.",
        f"- **Trial set-up**: start {d['start_distance_m']:g} m from the wall at "
        f"{d['altitude_m']:g} m altitude, friction μ = {d['friction_coefficient']:g}, ground "
        f"`{d['ground']}`, {d['final_time_s']:g} s per trial.",
    ]
    run = d["run"]
    if run["n_ran"] == 0:
        ran = f"nothing to run now (all {run['n_runs']} trials done before)"
    else:
        before = f", {run['n_already_done']} done before (resumed)" if run["n_already_done"] else ""
        ran = f"{run['n_ran']} trials run now in {run['sweep_s']:.1f} s ({run['backend']}){before}"
    history = d.get("sweeps") or []
    if history and (run["n_ran"] == 0 or len(history) > 1):
        ran += "; the trials were run " + ", ".join(
            f"{h['n_ran']} in {h['sweep_s']:.1f} s ({h['backend']})" for h in history
        )
    included = "tables, figures and the example" if d.get("example") else "tables and figures"
    lines += [
        f"- **quadimpact** {d['quadimpact_version']}. **Wall time**: {ran}; the whole command "
        f"{d['elapsed_s']:.1f} s ({included} included).",
    ]
    if d.get("cost"):
        lines.append(f"- **Cost**: {cost_sentence(d['cost'])}")
    return [*lines, ""]


def cost_sentence(cost: dict[str, Any]) -> str:
    """What the trials cost, as a sentence (``results.costs.cost_ratio`` of the table)."""
    if not cost.get("runs"):
        return "no trial's cost measured."
    return (
        f"the trials took {cost_text(cost)} (CPU time of the thread that ran each trial: "
        "the compiled loop is the physics; the rest prepares each trial and computes its "
        "metrics and row)."
    )


def _outcomes(n: dict[str, Any]) -> list[str]:
    c = n["classes"]
    total = n["n"]
    lines = ["## Outcomes", "", "| class | trials | share |", "|---|---|---|"]
    for k in OUTCOME_CLASSES:
        lines.append(f"| {k} | {c[k]} | {percent(c[k] / total if total else math.nan)} |")
    s, sd = n["success"], n["success_detected"]
    lines += [
        "",
        "Classes: *recovered*: impact detected, stage 4 reached; *recovered below ground "
        "level*: the same, but the altitude went below 0 on the way (the start altitude is "
        "measured from a ground at 0 that the trial does not model: with it the vehicle would "
        "have hit the ground), not a success; *not recovered*: impact "
        "detected, stage 4 not reached (a failed recovery); *not detected*: a contact the "
        "detector never saw (a failure of the detector, not of the recovery); *false "
        "detection*: the detector fired before any contact; *no contact*: neither; "
        "*invalid: bumper model exceeded*: a bumper went deeper than its radius, beyond what "
        "the contact model covers; *invalid: started in contact*: the vehicle started "
        "touching the wall (the trial is not an impact); *failed*: the run failed "
        "numerically. The last three are excluded from the rates.",
        "",
        f"- **Success rate** = recovered / valid trials: **{rate_text(s)}** (95 % Wilson "
        "interval). A not-detected trial counts as not recovered here; so does a trial "
        f"recovered below ground level ({n['below_ground']}).",
        f"- **Excluded** from the rates: {excluded_text(n)}.",
        f"- **Recovery rate of the detected impacts** = recovered / detected: {rate_text(sd)}.",
        f"- Not detected: {c['not detected']}; false detections: {c['false detection']}"
        + (
            f" (of which {n['false_recovered']} reached stage 4 and count in the success rate)"
            if n["false_recovered"]
            else ""
        )
        + f"; failed runs: {c['failed']}.",
        "",
    ]
    why = {
        "not detected": "the initial impact's horizontal specific force stayed below the "
        "detection threshold",
        "false detection": "the detector fired before the first contact",
        "no contact": "the vehicle never touched the wall",
    }
    for name, text in why.items():
        q = n["conditions"].get(name)
        if q is None:
            continue
        force = q["peak_force_n"]
        seen = n["conditions"].get("recovered")
        lines.append(
            f"- *{name}* ({q['n']}; {text}): inclination {q['inclination_deg']['min']:.1f}° to "
            f"{q['inclination_deg']['max']:.1f}° (median {q['inclination_deg']['median']:.1f}°), "
            f"speed {q['speed_m_s']['min']:.2f} to {q['speed_m_s']['max']:.2f} m/s (median "
            f"{q['speed_m_s']['median']:.2f} m/s)"
            + (
                f"; initial-impact peak force median {force['median']:.2f} N (recovered "
                f"trials: {seen['peak_force_n']['median']:.2f} N)"
                if force and force["n"] and seen and seen["peak_force_n"]["n"]
                else ""
            )
            + "."
        )
    if any(name in n["conditions"] for name in why):
        lines.append("")
    return lines


def _failures(n: dict[str, Any]) -> list[str]:
    f = n["failures"]
    lines = ["## Where recovery fails, and why", ""]
    if f["n_failed"] == 0:
        return lines + ["No detected impact failed to recover.", ""]
    inc, sp = f["inclination"], f["speed"]
    stage_text = ", ".join(
        f"{v} stayed in stage {k}" if k else f"{v} never entered a stage"
        for k, v in f["stage_reached"].items()
    )
    lines.append(
        f"- **Conditions**: the {f['n_failed']} failed recoveries lie at inclinations toward "
        f"the wall from {inc['min']:.1f}° to {inc['max']:.1f}° (median {inc['median']:.1f}°), "
        f"speeds from {sp['min']:.2f} to {sp['max']:.2f} m/s (median {sp['median']:.2f} m/s), "
        f"|roll| median {f['roll']['median']:.1f}°, |yaw| median {f['yaw']['median']:.1f}°."
    )
    if f["threshold_bin"] is not None:
        lines.append(
            f"- From the inclination bin {f['threshold_bin']}° up, every bin recovers in "
            "fewer than half of its trials."
        )
    worst = "; ".join(
        f"inclination {w['inclination_bin']}°, speed {w['speed_bin']} m/s: "
        f"{w['recovered']}/{w['n']}"
        for w in f["worst_cells"]
    )
    lines += [
        f"- Lowest success in the map: {worst}.",
        f"- **Stage reached**: {stage_text}.",
        f"- **What happened** (failed vs recovered trials): turned over (tilt beyond "
        f"{FLIP_DEG:g}° after the detection) {percent(f['flipped']['failed'])} vs "
        f"{percent(f['flipped']['recovered'])}; hit the wall again after the detection "
        f"{percent(f['hit_again']['failed'])} vs {percent(f['hit_again']['recovered'])}, "
        f"median {f['impacts_after_detection']['failed']['median']:g} vs "
        f"{f['impacts_after_detection']['recovered']['median']:g} impacts after the "
        f"detection; median largest tilt {f['max_tilt_deg']['failed']['median']:.0f}° vs "
        f"{f['max_tilt_deg']['recovered']['median']:.0f}°; median fall below the start "
        f"altitude {f['fall_m']['failed']['median']:.2f} m vs "
        f"{f['fall_m']['recovered']['median']:.2f} m in the "
        f"{n.get('final_time_s', 'whole')} run; median final speed "
        f"{f['final_speed_m_s']['failed']['median']:.2f} vs "
        f"{f['final_speed_m_s']['recovered']['median']:.2f} m/s.",
        "",
    ]
    return lines


def render_report(
    description: dict[str, Any], numbers: dict[str, Any], figures: Sequence[Path | str]
) -> str:
    """The Markdown report of a recovery study.

    Parameters
    ----------
    description : dict
        What ran (``quadimpact.studies.recovery.recovery_study.describe`` plus ``run``,
        ``elapsed_s`` and, when written, ``example``).
    numbers : dict
        ``quadimpact.studies.recovery.recovery_analysis.summarise`` of the trials table.
    figures : sequence of path
        The figures and example files written, relative to the report.
    """
    names = {Path(p).as_posix() for p in figures}
    d = description
    numbers = {**numbers, "final_time_s": f"{d['final_time_s']:g}-s"}
    lines = [
        "# Recovery study: Monte Carlo of impact trials",
        "",
        "Generated by `quadimpact recovery`. Every number below is computed from "
        "`trials.parquet` (one row per trial: its inputs, every metric of docs/RESULTS.md, "
        "`inclination_deg` = -pitch, the bins and the outcome class).",
        "",
        *_what_ran(d),
        *_outcomes(numbers),
        "## Success by inclination and by speed",
        "",
        "Inclination toward the wall = -pitch, in 10° bins; speed toward the wall in "
        "0.25 m/s bins; success = recovered / valid trials of the bin, with its 95 % Wilson "
        "interval.",
        "",
    ]
    for name, alt in (("success_by_bin.png", "Success rate by bin"),
                      ("success_map.png", "Success map")):  # fmt: skip
        if name in names:
            lines += [f"![{alt}]({name})", ""]
    lines += [
        bin_table(numbers["by_inclination"], "inclination (deg)"),
        "",
        bin_table(numbers["by_speed"], "speed (m/s)"),
        "",
        "## Time to recover, height loss and drift (recovered trials)",
        "",
        spread_table(numbers, _MEASURES),
        "",
    ]
    if "distributions.png" in names:
        lines += ["![Distributions](distributions.png)", ""]
    lines += [
        "Detection (detected impacts):",
        "",
        spread_table(numbers, (
            ("detection_latency_s", "latency, detection minus first contact", "s", 3),
            ("normal_error_deg", "wall-normal estimate error", "deg", 1),
        )),
        "",
        *_failures(numbers),
        *estimation_lines(numbers),
    ]  # fmt: skip
    lines += slowest_lines(d.get("slowest_trials"))
    ex = d.get("example")
    if ex is not None:
        lines += _example_lines(ex, names)
    return "\n".join(lines) + "\n"


def _example_lines(ex: dict[str, Any], names: set[str]) -> list[str]:
    """The section "Example trial": the trial ``ex`` (its run id, roll, pitch, inclination
    and yaw in deg, speed in m/s, IMU seed), and of its figure, viewer and animation those
    among the files written, ``names`` (paths relative to the report)."""
    lines = [
        "## Example trial",
        "",
        f"Trial {ex['run_id']}, the one nearest the median conditions (roll, pitch, yaw and "
        f"speed, each scaled by its range): roll {ex['roll_deg']:.1f}°, pitch "
        f"{ex['pitch_deg']:.1f}° (inclination {ex['inclination_deg']:.1f}°), yaw "
        f"{ex['yaw_deg']:.1f}°, {ex['speed_m_s']:.2f} m/s, IMU seed {ex['seed']}. Its "
        "result folder is `example/` (summary, time series, IMU samples, Figures 5-6); "
        "the vertical lines mark the detection and the entry into each stage.",
        "",
    ]
    if "example/recovery.png" in names:
        lines += ["![Example trial](example/recovery.png)", ""]
    extras = [f"[{label}]({p})" for p, label in (
        ("example/viewer.html", "interactive viewer"),
        ("example/animation.mp4", "animation"),
    ) if p in names]  # fmt: skip
    if extras:
        lines += ["Also: " + ", ".join(extras) + ".", ""]
    return lines
