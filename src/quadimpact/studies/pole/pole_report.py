"""``report.md`` of the pole study: the two controllers side by side, and where recovery fails."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from quadimpact.studies.slowest import slowest_lines
from quadimpact.studies.statistics import rate_text

__all__ = ["render_report"]


def _spread(s: dict[str, Any], unit: str, scale: float = 1.0, digits: int = 2) -> str:
    if not s.get("n"):
        return "none"
    f = f"{{:.{digits}f}}"
    return (
        f"{f.format(s['min'] * scale)} to {f.format(s['max'] * scale)} {unit} "
        f"(median {f.format(s['median'] * scale)})"
    )


#: Column heads of the arms.
HEADS = {
    "baseline": "without recovery",
    "recovery": "with recovery",
    "recovery-default": "with recovery, default law",
}


def _sensing_text(st: dict[str, Any]) -> str:
    """What both arms sense: the preset of sensors and the estimator they read."""
    sensors = st.get("sensors")
    estimator = st.get("estimator", "ideal")
    imu = "the ideal IMU" if sensors is None else f"the `{sensors}` sensors"
    state = (
        "the true state (the `ideal` estimator)"
        if estimator == "ideal"
        else f"the `{estimator}` estimator's estimate"
    )
    return f"Both arms sense with {imu} and fly on {state}."


def _model_text(st: dict[str, Any]) -> str:
    """Which law the recovery arm ran (the study's model variant)."""
    model = st.get("model", "default")
    if model == "default":
        return (
            "The recovery arm runs the `default` model: the staged law of docs/RECOVERY.md "
            "with its default parameters."
        )
    if model == "classic":
        return (
            "The recovery arm runs the `classic` model variant: the staged law with the "
            "values that were its defaults before the benchmark (issue #45: a_mag = g, a 45 "
            "deg tilt away from the contact, stage 1 test |p|, |q| < 0.5 rad/s, no "
            "vertical-velocity damping in stages 1-2, no lean cut; docs/VARIANTS.md 9). "
            "Beside it every point is flown by the default law too (`with recovery, default "
            "law`: the recovery arm of `quadimpact pole` without `--model`), so that the two "
            "laws compare point by point; the baseline arm is the same in both studies."
        )
    return (
        f"The recovery arm runs the `{model}` model variant: the authors' retuned pole law "
        "(stage 1 reference a_mag = 4.8 m/s², stage 1 test |q_e,x|, |q_e,y| < 0.15 and "
        "|p|, |q| < 2 rad/s, stage 2 test on the ZYX Euler |roll|, |pitch| < 0.2 rad and "
        "|p|, |q| < 2 rad/s, stage 3 ends at w < 0.2 m/s) and its pre-impact `hold`: the "
        "rotor speeds stay at their trimmed values until the detection instead of flying the "
        "baseline (docs/VARIANTS.md, docs/OBSTACLES.md). Beside it every point is flown by the "
        "default law too (`with recovery, default law`: the recovery arm of `quadimpact pole` "
        "without `--model`), so that the two laws compare point by point; the baseline arm is "
        "the same in both studies."
    )


def _policy_text(st: dict[str, Any]) -> str:
    """The learned residual the recovery arm flew with, if any (docs/LEARNING.md 12)."""
    if st.get("policy") is None:
        return ""
    return (
        f" The recovery arm's law flies with the learned policy `{st['policy']}` (weights' "
        f"SHA-256 `{st.get('policy_sha256', '')[:16]}`...): a residual on its thrust and roll "
        "and pitch rate references from the detection on (to the recovery, or the hover too: "
        "its file's `last_stage`), from on-board "
        "quantities only."
    )


def render_report(description: dict[str, Any], numbers: dict[str, Any], figures: list[Path]) -> str:
    """The report's Markdown."""
    st = description["study"]
    arms = numbers["arms"]
    names = list(arms)
    heads = [HEADS[a] for a in names]
    if st.get("model", "default") != "default":
        heads[names.index("recovery")] = f"with recovery, {st['model']}"
    lines = [*_setup_lines(description, len(names)), *_arms_lines(numbers, names, heads)]
    examples = [p for p in figures if p.name.startswith("example_")]
    if "laws" in numbers:
        lines += ["", *_laws_section(numbers, st["model"], examples)]
    lines += _failures_lines(numbers["failures"], arms, st)
    lines += ["", *slowest_lines(description.get("slowest_trials"))]
    for path in figures:
        if path in examples:
            continue
        lines.append(f"![{path.stem}]({path.as_posix()})")
        lines.append("")
    return "\n".join(lines)


def _row(label: str, cells: list[str]) -> str:
    """A Markdown table row: ``label`` then the ``cells``."""
    return f"| {label} | " + " | ".join(cells) + " |"


def _setup_lines(description: dict[str, Any], n_arms: int) -> list[str]:
    """The report's title and what was flown: the vehicle, its speed (m/s), the obstacle,
    the grid of pitches (deg) by sideways offsets (m), the ``n_arms`` arms, the success
    criterion, the recovery arm's law, and the runs with their times (s)."""
    st = description["study"]
    grid = description["grid"]
    run = description["run"]
    obstacle = st["obstacles"][0]
    what = (
        f"a vertical pole of radius {obstacle['radius_m']:g} m through the origin"
        if st.get("obstacle_file") is None
        else f"obstacle {obstacle.get('name')!r} ({obstacle.get('kind')}) of {st['obstacle_file']}"
    )
    flown = "twice" if n_arms == 2 else "three times"
    return [
        "# The pole study",
        "",
        f"The {st['vehicle']} flies at {st['speed_m_s']:g} m/s along +X toward {what}, "
        f"starting {st['start_distance_m']:g} m before its surface at {st['altitude_m']:g} m "
        f"altitude, roll and yaw 0, over a grid of {grid['pitch_deg']} pitches (0 to "
        f"-{st['pitch_max_deg']:g} deg, every {st['pitch_step_deg']:g} deg; negative pitch "
        f"leans the top toward the pole) by {grid['lateral_offset_m']} sideways offsets "
        f"(+-{st['offset_max_m']:g} m every {st['offset_step_m']:g} m), friction "
        f"{st['friction_coefficient']:g}, {st['final_time_s']:g} s, no ground. Each point is "
        f"flown {flown}: by the `{st['baseline']}` controller holding the initial attitude and "
        f"the altitude (the baseline, no recovery), and by the `recovery` controller flying "
        f"that same baseline until it detects the impact, then its staged law. Success: less "
        f"than 2 m of height lost over the run (altitude at the start minus at the end), the "
        f"authors' criterion. {_sensing_text(st)}",
        "",
        _model_text(st) + _policy_text(st),
        "",
        f"{run['n_runs']} runs ({run['n_ran']} run now in {run['sweep_s']:.1f} s, "
        f"{run['backend']}; {run['n_already_done']} done before); the whole study "
        f"{description['elapsed_s']:.1f} s this time."
        + "".join(
            f" Earlier: {h['n_ran']} runs in {h['sweep_s']:.1f} s ({h['backend']})."
            for h in description.get("sweeps", [])[: -1 if run["n_ran"] else None]
        ),
        "",
    ]


def _arms_lines(numbers: dict[str, Any], names: list[str], heads: list[str]) -> list[str]:
    """The arms side by side (columns ``heads`` of the arms ``names``): success (95 % Wilson),
    contact, detection, recovery, median height lost (m) and failed runs; then success by
    pitch band."""
    arms = numbers["arms"]
    lines = [
        "## The two controllers" if len(names) == 2 else "## The controllers",
        "",
        _row("", heads),
        "|---|" + "---|" * len(names),
        _row("lose less than 2 m (95 % Wilson)", [rate_text(arms[a]["success"]) for a in names]),
        _row("touched the obstacle", [str(arms[a]["contact"]) for a in names]),
        _row("impact detected", [str(arms[a]["detected"]) for a in names]),
        _row(
            "recovered (stage 4)",
            ["-" if a == "baseline" else str(arms[a]["recovered"]) for a in names],
        ),
        _row("median height lost", [f"{arms[a]['height_lost_median_m']:.2f} m" for a in names]),
        _row("failed runs", [str(arms[a]["failed_runs"]) for a in names]),
        "",
        "## Success by pitch band",
        "",
        _row("abs(pitch) (deg)", heads),
        "|---|" + "---|" * len(names),
    ]
    for band in numbers["bands"]:
        lines.append(_row(band["band"], [rate_text(band[a]) for a in names]))
    return lines


def _failures_lines(fl: dict[str, Any], arms: dict[str, Any], st: dict[str, Any]) -> list[str]:
    """The section "Where recovery fails, and why" from the failure numbers ``fl``: where
    (|pitch| in deg, |offset| in m), contact and detection, the stage reached, the largest
    tilt (deg), the impacts after the detection, stage 4's time (s), the first contact's
    normal and its estimate's error (deg), and a paragraph reading them; then the heading
    of the figures."""
    stage = fl["stage_reached"]
    return [
        "",
        "## Where recovery fails, and why"
        + ("" if st.get("model", "default") == "default" else f" (`{st['model']}`)"),
        "",
        f"Of the {fl['n_points']} grid points, recovery loses 2 m or more at "
        f"{fl['recovery_fails']}: at {fl['both_fail']} of them the baseline fails too, at "
        f"{fl['recovery_loses']} only recovery fails; recovery saves {fl['recovery_saves']} "
        f"points where the baseline falls.",
        "",
        f"- Where: |pitch| {_spread(fl['abs_pitch_deg'], 'deg', digits=0)}, |offset| "
        f"{_spread(fl['abs_offset_m'], 'm')}.",
        f"- Contact and detection: {fl['no_contact']} never touched the obstacle, "
        f"{fl['not_detected']} touched it without the detector firing.",
        f"- Stage reached: none {stage['0']}, stage 1 (tilting away) {stage['1']}, stage 2 "
        f"{stage['2']}, stage 3 (level, braking the descent) {stage['3']}, stage 4 "
        f"(levelled and braked, but too late: 2 m or more already lost) {stage['4']}.",
        f"- Largest tilt after the detection: {_spread(fl['max_tilt_deg'], 'deg', digits=0)};"
        f" {fl['flipped']} turned past 90 deg (upside down); in the successes "
        f"{_spread(fl['max_tilt_deg_successes'], 'deg', digits=0)}.",
        f"- {fl['impacts_after_detection']} hit the obstacle again after the detection: "
        f"{_spread(fl['impacts_after_detection_failures'], 'impacts', digits=0)} against "
        f"{_spread(fl['impacts_after_detection_successes'], 'impacts', digits=0)} in the "
        "successes.",
        f"- Stage 4 entered, when it was: {_spread(fl['t_stage4_failures_s'], 's')}.",
        f"- The first contact's normal: its sideways part |n_Y| is "
        f"{_spread(fl['lateral_normal_failures'], '')} in the failures against "
        f"{_spread(fl['lateral_normal_successes'], '')} in the successes; the detector's "
        f"normal estimate is off by {_spread(fl['normal_error_deg_failures'], 'deg', digits=0)}"
        f" in the failures against "
        f"{_spread(fl['normal_error_deg_successes'], 'deg', digits=0)} in the successes.",
        "",
        _explain(fl, arms, tilt="45 deg" if st.get("model") == "classic" else "about 26 deg"),
        "",
        "## Figures",
        "",
    ]


def _explain(fl: dict[str, Any], arms: dict[str, Any], tilt: str = "45 deg") -> str:
    """A paragraph reading the failure numbers (``tilt``: stage 1's tilt away, in words)."""
    parts = []
    stage = fl["stage_reached"]
    n = max(fl["recovery_fails"], 1)
    if stage["1"] + stage["2"] >= 0.5 * n:
        parts.append(
            "Most failures never level out: the staged law is still tilting away or "
            "converging (stages 1-2) while the vehicle falls."
        )
    if fl["flipped"] >= 0.3 * n:
        parts.append(
            "Many turn past 90 deg: a steep pitch toward the pole plus the impact's moment "
            "leave more rotation than the attitude loop can take back before the rotors, "
            "already tilted away, stop holding the weight."
        )
    if fl["impacts_after_detection"] >= 0.3 * n:
        parts.append(
            "Many hit the obstacle again and again after the detection: a pole is not a wall, "
            f"so tilting {tilt} away from the first contact's normal (the detector's estimate) "
            "does not take the vehicle clear of it: the rotor arms swing around the pole and "
            "the body tumbles against it while it falls, and the staged law levels the vehicle "
            "(stage 4) only once it has slid off, metres lower."
        )
    if fl["not_detected"] >= 0.3 * n:
        parts.append(
            "Many are never detected: a glancing contact at a large offset gives a "
            "horizontal specific force below the threshold, so the baseline keeps flying "
            "the lean it had."
        )
    if not parts:
        parts.append(
            "The failures have no single cause among those counted above (stage, flip, "
            "second impact, detection); see the maps for where they lie."
        )
    return " ".join(parts)


def _where(w: dict[str, Any], who: str) -> str:
    if not w["abs_pitch_deg"].get("n"):
        return f"- Only {who} succeeds: nowhere."
    return (
        f"- Only {who} succeeds: {w['abs_pitch_deg']['n']} points, |pitch| "
        f"{_spread(w['abs_pitch_deg'], 'deg', digits=0)}, |offset| "
        f"{_spread(w['abs_offset_m'], 'm')}."
    )


def _laws_section(numbers: dict[str, Any], model: str, examples: list[Path]) -> list[str]:
    """The two laws side by side: counts, by pitch band, where they differ, the example."""
    laws = numbers["laws"]
    arms = numbers["arms"]
    var, dflt = arms["recovery"]["success"], arms["recovery-default"]["success"]
    lines = [
        "## The two laws side by side",
        "",
        f"Recovery loses less than 2 m at {rate_text(var)} of the points with `{model}` and "
        f"at {rate_text(dflt)} with the default law. Point by point: both succeed at "
        f"{laws['both']}, only `{model}` at {laws['variant_only']}, only the default law at "
        f"{laws['default_only']}, neither at {laws['neither']}.",
        "",
        f"| abs(pitch) (deg) | default law | {model} | only {model} | only the default law |",
        "|---|---|---|---|---|",
    ]
    by_band = {b["band"]: b for b in numbers["bands"]}
    for band in laws["bands"]:
        b = by_band[band["band"]]
        lines.append(
            f"| {band['band']} | {rate_text(b['recovery-default'])} | "
            f"{rate_text(b['recovery'])} | {band['variant_only']} | {band['default_only']} |"
        )
    lines += [
        "",
        _where(laws["variant_only_where"], f"`{model}`"),
        _where(laws["default_only_where"], "the default law"),
    ]
    ex = laws.get("example")
    if ex is not None:
        lost = ex["height_lost_m"]
        lines += [
            "",
            f"An example where the default law fails and `{model}` does not (of those points, "
            f"the one nearest their median |pitch| and offset): pitch {ex['pitch_deg']:g} deg, "
            f"offset {ex['lateral_offset_m']:+.2f} m; the default law loses "
            f"{lost['recovery-default']:.2f} m, `{model}` {lost['recovery']:.2f} m. Each run's "
            "attitude, tilt, altitude and X, with the detection and each stage's entry marked:",
            "",
        ]
        for path in examples:
            lines += [f"![{path.stem}]({path.as_posix()})", ""]
    return lines
