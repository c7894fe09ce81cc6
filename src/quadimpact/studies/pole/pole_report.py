"""``report.md`` of the pole study: the two controllers side by side, and where recovery fails."""

from __future__ import annotations

from pathlib import Path
from typing import Any

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


def render_report(description: dict[str, Any], numbers: dict[str, Any], figures: list[Path]) -> str:
    """The report's Markdown."""
    st = description["study"]
    grid = description["grid"]
    run = description["run"]
    arms = numbers["arms"]
    fl = numbers["failures"]
    obstacle = st["obstacles"][0]
    what = (
        f"a vertical pole of radius {obstacle['radius_m']:g} m through the origin"
        if st.get("obstacle_file") is None
        else f"obstacle {obstacle.get('name')!r} ({obstacle.get('kind')}) of {st['obstacle_file']}"
    )
    lines = [
        "# The pole study",
        "",
        f"The {st['vehicle']} flies at {st['speed_m_s']:g} m/s along +X toward {what}, "
        f"starting {st['start_distance_m']:g} m before its surface at {st['altitude_m']:g} m "
        f"altitude, roll and yaw 0, over a grid of {grid['pitch_deg']} pitches (0 to "
        f"-{st['pitch_max_deg']:g} deg, every {st['pitch_step_deg']:g} deg; negative pitch "
        f"leans the top toward the pole) by {grid['lateral_offset_m']} sideways offsets "
        f"(+-{st['offset_max_m']:g} m every {st['offset_step_m']:g} m), friction "
        f"{st['friction_coefficient']:g}, {st['final_time_s']:g} s, no ground. Each point is "
        f"flown twice: by the `{st['baseline']}` controller holding the initial attitude and "
        f"the altitude (the baseline, no recovery), and by the `recovery` controller flying "
        f"that same baseline until it detects the impact, then its staged law. Success: less "
        f"than 2 m of height lost over the run (altitude at the start minus at the end), the "
        f"authors' criterion.",
        "",
        f"{run['n_runs']} runs ({run['n_ran']} run now in {run['sweep_s']:.1f} s, "
        f"{run['backend']}; {run['n_already_done']} done before); the whole study "
        f"{description['elapsed_s']:.1f} s this time."
        + "".join(
            f" Earlier: {h['n_ran']} runs in {h['sweep_s']:.1f} s ({h['backend']})."
            for h in description.get("sweeps", [])[: -1 if run["n_ran"] else None]
        ),
        "",
        "## The two controllers",
        "",
        "| | without recovery | with recovery |",
        "|---|---|---|",
        f"| lose less than 2 m (95 % Wilson) | {rate_text(arms['baseline']['success'])} | "
        f"{rate_text(arms['recovery']['success'])} |",
        f"| touched the obstacle | {arms['baseline']['contact']} | {arms['recovery']['contact']} |",
        f"| impact detected | {arms['baseline']['detected']} | {arms['recovery']['detected']} |",
        f"| recovered (stage 4) | - | {arms['recovery']['recovered']} |",
        f"| median height lost | {arms['baseline']['height_lost_median_m']:.2f} m | "
        f"{arms['recovery']['height_lost_median_m']:.2f} m |",
        f"| failed runs | {arms['baseline']['failed_runs']} | {arms['recovery']['failed_runs']} |",
        "",
        "## Success by pitch band",
        "",
        "| abs(pitch) (deg) | without recovery | with recovery |",
        "|---|---|---|",
    ]
    for band in numbers["bands"]:
        lines.append(
            f"| {band['band']} | {rate_text(band['baseline'])} | {rate_text(band['recovery'])} |"
        )
    stage = fl["stage_reached"]
    lines += [
        "",
        "## Where recovery fails, and why",
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
        _explain(fl, arms),
        "",
        "## Figures",
        "",
    ]
    for path in figures:
        lines.append(f"![{path.stem}]({path.as_posix()})")
        lines.append("")
    return "\n".join(lines)


def _explain(fl: dict[str, Any], arms: dict[str, Any]) -> str:
    """A paragraph reading the failure numbers."""
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
            "so tilting 45 deg away from the first contact's normal (the detector's estimate) "
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
