"""Table III in Markdown: the crashes at Table III's and at the authors' matched
conditions, in both variants, against the experiments and the flight logs.

Pure functions of the tables of :mod:`quadimpact.studies.table3.table3_study`
(``table3.csv``, ``table3_runs.csv``, ``table3_switches.csv``), used by
``quadimpact experiments`` (``table3.md``) and by the report of
``quadimpact reproduce``.
"""

from __future__ import annotations

import math
from typing import Any

import pandas as pd

from quadimpact.inputs.vehicle import load_vehicle
from quadimpact.rotations import wrap_angle_deg

__all__ = [
    "CHAINING_NOTE_MS",
    "MOTION_RMS_DEG",
    "TYPE_SHARE_PARTLY",
    "VERDICT_RULE",
    "crash_verdict",
    "table3_markdown",
]

#: A type hinging on a chaining margin smaller than this (ms) is noted in the report.
CHAINING_NOTE_MS = 5.0
#: A run matches the crash in motion when its attitude error against the log over
#: the first 0.3 s (RMS of the rotation angle) is at most this, deg.
MOTION_RMS_DEG = 20.0
#: A different type at the nominal conditions is ``partly`` when the experiment's
#: type occurs in at least this share of the runs over the stated uncertainty.
TYPE_SHARE_PARTLY = 0.2
#: The rule of :func:`crash_verdict`, as the report states it.
VERDICT_RULE = (
    f"agrees: ours (default) has the experiment's type and its attitude error against the "
    f"log over the first 0.3 s is at most {MOTION_RMS_DEG:g}° RMS (or there is no log); "
    f"partly: the same type with a larger attitude error (the type matches, the motion "
    f"does not), or another type at the nominal conditions while the experiment's occurs in "
    f"at least {TYPE_SHARE_PARTLY:.0%} of the runs over the stated uncertainty; disagrees: "
    "otherwise"
)


def crash_verdict(row: Any) -> tuple[str, str]:
    """Our nominal run against the experiment, for one row of Table III (:data:`VERDICT_RULE`).

    Parameters
    ----------
    row : mapping
        A row of the table (``type_ours``, ``type_paper_experiment``,
        ``attitude_rms_deg_0_3s``, ``share_<type>``).

    Returns
    -------
    (str, str)
        The verdict and its reason, with the measure and the threshold.
    """
    ours, exp = row["type_ours"], row["type_paper_experiment"]
    rms = float(row["attitude_rms_deg_0_3s"])
    if ours == exp:
        if math.isnan(rms):
            return "agrees", f"type {ours} (no log to compare the motion with)"
        if rms <= MOTION_RMS_DEG:
            return "agrees", f"type {ours}; attitude RMS {rms:.1f}° ≤ {MOTION_RMS_DEG:g}°"
        return "partly", (
            f"type {ours}, but not the motion: attitude RMS {rms:.1f}° > {MOTION_RMS_DEG:g}°"
        )
    share = float(row.get(f"share_{exp}", math.nan))
    if math.isnan(share):
        return "disagrees", f"type {ours}, not {exp} (no runs over the uncertainty)"
    seen = f"type {ours}, not {exp}; {exp} in {share:.0%} of the runs over the uncertainty"
    if share >= TYPE_SHARE_PARTLY:
        return "partly", f"{seen} (≥ {TYPE_SHARE_PARTLY:.0%})"
    return "disagrees", f"{seen} (< {TYPE_SHARE_PARTLY:.0%})"


def _percent(x: float) -> str:
    """A share as a whole percentage; never 0 % or 100 % unless exact."""
    if 0 < x < 0.005:
        return "<1%"
    if 0.995 <= x < 1:
        return ">99%"
    return f"{x:.0%}"


def _share_text(r: pd.Series, prefix: str) -> str:
    cols = [c for c in r.index if c.startswith(prefix)]
    return ", ".join(
        f"{c.removeprefix(prefix)} {_percent(r[c])}" for c in cols if r[c] == r[c] and r[c] > 0
    )


def _deg(x: float | None, fmt: str = ".1f") -> str:
    return "–" if x is None or x != x else format(x, fmt)


def _depth(x: float, rb_mm: float) -> str:
    return "–" if x != x else f"{x:.0f}" + (" †" if x > rb_mm else "")


def _front_first(heading_deg: float) -> float:
    """A rear-first heading (log frame, scenario files) as Table III gives it, in (-180, 180]."""
    return float(wrap_angle_deg(heading_deg + 180.0))


def _motion_note(r: pd.Series, threshold_deg: float) -> str:
    """Why a row of the same type as the experiment is not the same motion, from the data."""
    note = (
        f"- Crash {r['crash']}: the type is the experiment's ({r['type_ours']}), the motion is "
        f"not: the attitude differs from the log's by {r['attitude_rms_deg_0_3s']:.1f}° RMS over "
        f"the first 0.3 s after the impact (a match needs at most {threshold_deg:g}°)."
    )
    moved = []
    for angle in ("roll", "pitch", "yaw"):
        sim, log = r.get(f"sim_{angle}_change_deg_0_3s"), r.get(f"log_{angle}_change_deg_0_3s")
        if sim is None or log is None or sim != sim or log != log:
            continue
        moved.append((angle, float(sim), float(log)))
    if moved:
        note += (
            " In that time the log turns "
            + ", ".join(f"{a} {lg:+.0f}°" for a, _, lg in moved)
            + "; ours "
            + ", ".join(f"{a} {sm:+.0f}°" for a, sm, _ in moved)
            + "."
        )
        opposite = [a for a, sm, lg in moved if sm * lg < 0 and min(abs(sm), abs(lg)) > 5.0]
        if opposite:
            verb = "turns" if len(opposite) == 1 else "turn"
            note += f" Ours {verb} the other way in {' and '.join(opposite)}."
        if any(max(abs(sm), abs(lg)) > 180.0 for a, sm, lg in moved if a != "pitch"):
            note += (
                " Roll and yaw change by more than half a turn: the pitch nears 90°, where "
                "they are ill-defined (the Euler angles' singularity); the RMS above is of the "
                "rotation angle, which is not."
            )
    no_contact = isinstance(r.get("type_log"), str) and r.get("log_speed_m_s") != r.get(
        "log_speed_m_s"
    )
    if no_contact:
        note += (
            " The log does not show the wall contact (the motion capture misses it), so its "
            "impact time is the on-board estimate and the two may not be aligned on the same "
            "event; the log's own type is unknown."
        )
    return note


def table3_markdown(
    table: pd.DataFrame,
    runs: pd.DataFrame | None = None,
    switches: pd.DataFrame | None = None,
) -> str:
    """Table III, ours beside the paper's, and each differing row explained by the data.

    With ``runs`` (``table3_runs.csv``) the nominal and matched conditions come
    first, side by side per variant (:func:`conditions_markdown`); with
    ``switches`` (``table3_switches.csv``), what each change of the crash runs
    does (:func:`switches_markdown`). Then the nominal runs against the
    experiments (verdicts) and the runs at the logs' own estimates.
    """
    parts = []
    if runs is not None and not runs.empty:
        parts += [conditions_markdown(table, runs), ""]
    if switches is not None and not switches.empty:
        parts += [switches_markdown(switches), ""]
    if parts:
        parts += ["### At Table III's conditions: ours against the experiment", ""]
    return "\n".join([*parts, _nominal_markdown(table)])


def _nominal_markdown(table: pd.DataFrame) -> str:
    """The nominal runs against the experiments (verdicts) and the runs at the logs' estimates."""
    rb_mm = 1e3 * load_vehicle("spiri").bumper_radius_m
    has_log = "type_log_conditions" in table.columns
    head = (
        "| crash | ψ (°) | V_c (m/s) | ι (°) | experiment | paper's simulation | ours (default) "
        "| replica | over the uncertainty (default) | attitude RMS 0-0.3 s (°) |"
    )
    lines = [head, "|---" * 10 + "|"]
    if has_log:
        lines = [head + " deepest δ (mm) |", "|---" * 11 + "|"]
    lines = [lines[0] + " ours vs the experiment |", lines[1] + "---|"]
    notes, motion_notes = [], []
    for _, r in table.iterrows():
        verdict, reason = (
            (r["verdict"], r["verdict_reason"])
            if isinstance(r.get("verdict"), str)
            else crash_verdict(r)
        )
        dist = _share_text(r, "share_")
        rms = (
            "no log"
            if r["attitude_rms_deg_0_3s"] != r["attitude_rms_deg_0_3s"]
            else (f"{r['attitude_rms_deg_0_3s']:.1f}")
        )
        lines.append(
            f"| {r['crash']} | {r['heading_deg']:g} | {r['speed_m_s']:g} "
            f"| {r['inclination_deg']:g} "
            f"| {r['type_paper_experiment']} | {r['type_paper_simulation']} | {r['type_ours']} "
            f"| {r['type_replica']} | {dist or 'not run'} | {rms} |"
            + (f" {_depth(r['max_penetration_mm'], rb_mm)} |" if has_log else "")
            + f" **{verdict}**: {reason} |"
        )
        if r["type_ours"] == r["type_paper_experiment"] and verdict != "agrees":
            motion_notes.append(_motion_note(r, MOTION_RMS_DEG))
        if r["type_ours"] != r["type_paper_experiment"]:
            notes.append(_type_note(r, dist, has_log, rb_mm))
    lines += ["", f"Verdict of each row: {VERDICT_RULE}."]
    if motion_notes:
        lines += ["", "Rows where our type is the experiment's but the motion is not:", "",
                  *motion_notes]  # fmt: skip
    if notes:
        lines += ["", "Rows where our type differs from the experiment's:", "", *notes]
    if has_log:
        lines += _log_conditions_lines(table, rb_mm)
    return "\n".join(lines)


def _type_note(r: pd.Series, dist: str, has_log: bool, rb_mm: float) -> str:
    """Why a row's type at the nominal conditions differs from the experiment's, from the
    data: the replica's type, the share of the experiment's type over the stated
    uncertainty (``dist``: every type's share, as text), and with ``has_log`` the log's
    own conditions and our type there; a deflection beyond the bumper radius ``rb_mm``
    (mm) is said."""
    key = f"share_{r['type_paper_experiment']}"
    seen = r[key] if key in r and r[key] == r[key] else float("nan")
    deep = (
        f"; the bumpers deflect {r['max_penetration_mm']:.0f} mm, beyond their radius"
        if has_log and r["max_penetration_mm"] > rb_mm
        else ""
    )
    note = (
        f"- Crash {r['crash']}: the experiment was type {r['type_paper_experiment']}, ours "
        f"at the nominal conditions is {r['type_ours']} (the replica: "
        f"{r['type_replica']}{deep}). Over the stated uncertainty type "
        f"{r['type_paper_experiment']} occurs in {seen:.0%} of the runs ({dist})."
    )
    if has_log and isinstance(r["type_log_conditions"], str):
        note += (
            f" The log puts the impact at V_c {r['log_speed_m_s']:.2f} m/s, ι "
            f"{r['log_inclination_deg']:.1f}° (roll {r['log_roll_deg']:.1f}°, pitch "
            f"{r['log_pitch_deg']:.1f}°); there ours is "
            f"{r['type_log_conditions']} ({_share_text(r, 'log_share_')} over the "
            "log's uncertainty)"
        )
        depth = r["log_max_penetration_mm"]
        note += (
            f", but the bumpers deflect {depth:.0f} mm there, beyond their radius "
            "(the model's answer, not a prediction)."
            if depth > rb_mm
            else "."
        )
    return note


def _log_conditions_lines(table: pd.DataFrame, rb_mm: float) -> list[str]:
    """The runs at the logs' own pre-impact estimates: how far those are from Table III's
    conditions (m/s, deg), then one row per crash (its conditions, the log's type, ours
    and over the log's uncertainty, the attitude error in deg, the deepest deflection in
    mm, marked beyond the bumper radius ``rb_mm``), and what the mark means."""
    seen = table[table["type_log_conditions"].apply(lambda v: isinstance(v, str))]
    dv = seen["log_speed_m_s"] - seen["speed_m_s"]
    di = seen["log_inclination_deg"] - seen["inclination_deg"]
    spread = (
        f" Against Table III the logs' speeds differ by {dv.min():+.2f} to {dv.max():+.2f} "
        f"m/s (stated ±0.01) and their inclinations by {di.min():+.1f} to {di.max():+.1f}°."
        if len(seen)
        else ""
    )
    lines = [
        "",
        "At the logs' own pre-impact estimates (motion capture at the observed contact; "
        "docs/EXPERIMENTS.md explains why they differ from Table III). ψ is given as in "
        "Table III above: the heading of the equivalent front-first approach (the "
        "flights went into the wall rear first, at ψ − 180° in the log frame and in the "
        f"scenario files).{spread}",
        "",
        "| crash | ψ (°) | V_c (m/s) | ι (°) | roll / pitch (°) | log's own type "
        "| ours at the log's estimates | over their uncertainty (±2σ) "
        "| attitude RMS 0-0.3 s (°) | deepest δ (mm) |",
        "|---" * 10 + "|",
    ]
    for _, r in table.iterrows():
        if not isinstance(r["type_log_conditions"], str):
            why = "no log" if not isinstance(r["type_log"], str) else "contact not observed"
            lines.append(f"| {r['crash']} | {why} | | | | {r['type_log'] or '–'} | | | | |")
            continue
        lines.append(
            f"| {r['crash']} | {_deg(_front_first(r['log_heading_deg']))} "
            f"| {r['log_speed_m_s']:.2f} "
            f"| {_deg(r['log_inclination_deg'])} "
            f"| {_deg(r['log_roll_deg'])} / {_deg(r['log_pitch_deg'])} | {r['type_log']} "
            f"| {r['type_log_conditions']} | {_share_text(r, 'log_share_') or 'not run'} "
            f"| {_deg(r['attitude_rms_log_conditions_deg_0_3s'])} "
            f"| {_depth(r['log_max_penetration_mm'], rb_mm)} |"
        )
    lines += [
        "",
        f"† deeper than the bumper radius ({rb_mm:.0f} mm): the bumper model no longer "
        "holds (the body itself would reach the wall), so these runs' types are the "
        "model's, not a prediction (docs/MODEL_NOTES.md). The paper's bumper law is the "
        "same, with the same limit.",
    ]
    return lines


#: The report's names of the two variants of the crash runs.
_VARIANT_NAMES = {"default": "default", "paper-replica": "replica"}


def _cell_type(r: pd.Series) -> str:
    return f"{r['type']} ✓" if r["matches"] else f"{r['type']} ✗"


def _num(x: float, fmt: str = ".0f") -> str:
    return "–" if x is None or x != x else format(x, fmt)


def _bumpers(text: str) -> str:
    """A JSON list of bumpers (or of lists of them) as ``2+3`` / ``4+1, 3``; ``–`` if empty."""
    import json

    value = json.loads(text) if isinstance(text, str) else []
    if not value:
        return "–"
    if isinstance(value[0], list):
        return ", ".join("+".join(str(b) for b in group) for group in value)
    return "+".join(str(b) for b in value)


def conditions_markdown(table: pd.DataFrame, runs: pd.DataFrame) -> str:
    """Nominal and matched conditions side by side, per variant: conditions, types, runs, notes."""
    from quadimpact.experiments.crashes import AUTHORS_THRUST_COEFFICIENT_N_PER_RPM2, VARIANTS

    keys = [(c, m) for c in ("nominal", "matched") for m in VARIANTS]
    count = {k: int(runs[(runs.conditions == k[0]) & (runs.model == k[1])]["matches"].sum())
             for k in keys}  # fmt: skip
    n = len(table)
    lines = [
        "Each crash runs at two sets of pre-impact conditions: Table III's (*nominal*: "
        "heading, speed and inclination, the altitude set-point held from the start) and those "
        "the authors matched in their own simulations (*matched*, the crash set's description "
        "file: its roll, pitch and heading held from a start at a lower altitude, the "
        "controller climbing toward the set-point, the first contact 0.5 s later at the "
        "matched speed, so the vehicle reaches the wall climbing and drifting sideways). "
        "From the first contact the motors follow the measured schedules, a zero rate being "
        "the motor switched off. *default* is the physical model; *replica* the paper "
        "replica with the switches of the authors' crash runs (the crash at the first "
        "control tick with the CM at or below the ground, their thrust coefficient "
        f"{AUTHORS_THRUST_COEFFICIENT_N_PER_RPM2:g} N/rpm², motor 2 cut at the first tick "
        "after the contact as a one-tick command step; crash I-03's hand modification off). "
        "ψ is given as Table III gives it (front first: the flights went in rear first, at "
        "ψ − 180°).",
        "",
        "Experiment types matched: " + "; ".join(
            f"{c} conditions: default {count[(c, 'default')]} of {n}, replica "
            f"{count[(c, 'paper-replica')]} of {n}" for c in ("nominal", "matched")) + ".",
        "",
    ]  # fmt: skip
    by = runs.set_index(["crash", "conditions", "model"])
    lines += _matched_conditions_lines(table, by)
    lines += [
        "",
        "| crash | experiment | paper's simulation | "
        + " | ".join(f"{c}, {_VARIANT_NAMES[m]}" for c, m in keys)
        + " |",
        "|---" * (3 + len(keys)) + "|",
    ]
    for _, r in table.iterrows():
        cells = " | ".join(_cell_type(by.loc[(r["crash"], c, m)]) for c, m in keys)
        lines.append(f"| {r['crash']} | {r['type_paper_experiment']} "
                     f"| {r['type_paper_simulation']} | {cells} |")  # fmt: skip
    lines.append("| matched | | | " + " | ".join(f"{count[k]} of {n}" for k in keys) + " |")
    lines += _run_lines(runs)
    lines += [
        "",
        "The crash set holds no outputs of the authors' own simulations, so the distance "
        "of these runs to theirs cannot be measured here; the flight logs are the reference.",
    ]
    return "\n".join(lines)


def _matched_conditions_lines(table: pd.DataFrame, by: pd.DataFrame) -> list[str]:
    """Each crash's conditions, Table III's and the matched ones (heading, speed, roll and
    pitch in deg and m/s, the altitude's start and set-point in m), and where the matched
    default run meets the wall (altitude in m, climb and drift in m/s); ``by``: the runs
    indexed by crash, conditions and model."""
    lines = [
        "| crash | Table III: ψ (°) / V_c (m/s) / ι (°) | matched: ψ (°) / V_c (m/s) / roll, "
        "pitch (°) (ι) | matched: altitude start → set-point (m) | at the contact, matched, "
        "default: altitude (m), climb (m/s), drift (m/s) |",
        "|---|---|---|---|---|",
    ]
    for _, r in table.iterrows():
        m = by.loc[(r["crash"], "matched", "default")]
        lines.append(
            f"| {r['crash']} | {r['heading_deg']:g} / {r['speed_m_s']:g} / "
            f"{r['inclination_deg']:g} | {_front_first(r['matched_heading_deg']):g} / "
            f"{r['matched_speed_m_s']:g} / {r['matched_roll_deg']:g}, "
            f"{r['matched_pitch_deg']:g} ({r['matched_inclination_deg']:.1f}) "
            f"| {r['matched_start_altitude_m']:g} → {r['matched_altitude_setpoint_m']:g} "
            f"| {m['contact_altitude_m']:.2f}, {m['contact_climb_m_s']:+.2f}, "
            f"{m['contact_drift_m_s']:+.2f} |"
        )
    return lines


def _run_lines(runs: pd.DataFrame) -> list[str]:
    """One row per crash run (conditions, variant, type, the bumpers of each impact, the
    deflections in mm, the crash time in s, the errors against the log in deg and mm), then
    the types that hinge on a contact overlap or gap under :data:`CHAINING_NOTE_MS`."""
    lines = [
        "",
        "Each run: the bumpers of the initial impact and of each later one, δ_init (the "
        "initial impact's deepest deflection), the first episode's peak (bumper 2, the "
        "leading one), the crash time after the first contact, and the errors against the "
        "flight log over the first 0.3 s after the impact (attitude: RMS of the rotation "
        "angle between the two; position: RMS of the X, Y and altitude displacements since "
        "the impact).",
        "",
        "| crash | conditions | variant | type | initial impact | later impacts | δ_init (mm) "
        "| bumper 2 peak (mm) | crash after contact (s) | attitude RMS (°) "
        "| position RMS (mm) |",
        "|---" * 11 + "|",
    ]
    for _, r in runs.iterrows():
        lines.append(
            f"| {r['crash']} | {r['conditions']} | {_VARIANT_NAMES.get(r['model'], r['model'])} "
            f"| {_cell_type(r)} | {_bumpers(r['leading_bumpers'])} "
            f"| {_bumpers(r['subsequent_impacts'])} | {_num(r['delta_init_mm'])} "
            f"| {_num(r['first_peak_mm'])} | {_num(r['crash_after_contact_s'], '.3f')} "
            f"| {_num(r['attitude_rms_deg_0_3s'], '.1f')} "
            f"| {_num(r['position_rms_mm_0_3s'])} |"
        )
    notes = [_chaining_note(r) for _, r in runs.iterrows()
             if abs(r["chaining_margin_ms"]) < CHAINING_NOTE_MS
             and r["type_chaining_flipped"] != r["type"]]  # fmt: skip
    if notes:
        lines += ["", f"Types that hinge on a contact overlap (or gap) of less than "
                  f"{CHAINING_NOTE_MS:g} ms (docs/STUDIES.md 2: an episode starting before "
                  "the impact in progress has ended is part of it):", "", *notes]  # fmt: skip
    return lines


def _chaining_note(r: pd.Series) -> str:
    margin = float(r["chaining_margin_ms"])
    variant = _VARIANT_NAMES.get(r["model"], r["model"])
    where = (
        f"- Crash {r['crash']}, {r['conditions']} conditions, {variant}: "
        f"bumper {int(r['chaining_bumper'])}"
    )
    if margin <= 0.0:
        return (
            f"{where} touches {-margin:.1f} ms before the impact in progress ends, so it "
            f"joins it: type {r['type']}; {-margin:.1f} ms later it would start a later impact "
            f"of its own: type {r['type_chaining_flipped']}."
        )
    return (
        f"{where} touches {margin:.1f} ms after the impact before it has ended: a later "
        f"impact, type {r['type']}; {margin:.1f} ms earlier it would have joined it: type "
        f"{r['type_chaining_flipped']}."
    )


def switches_markdown(switches: pd.DataFrame) -> str:
    """The matched runs with one change each: what each switch of the crash runs does."""
    from quadimpact.experiments.crashes import SWITCH_CHANGES

    made = set(switches.change)
    lines = [
        "What each change does, at the matched conditions (each against the run as made, "
        "*as run*; the variants it is run in after the semicolon):",
        "",
        *(f"- *{name}*: {what}." for name, what in SWITCH_CHANGES.items() if name in made),
        "",
    ]
    summary = []
    for (model, change), g in switches[switches.change != "as run"].groupby(
        ["model", "change"], sort=False
    ):
        base = switches[(switches.model == model) & (switches.change == "as run")
                        & switches.crash.isin(g.crash)].set_index("crash")  # fmt: skip
        g = g.set_index("crash")
        dt = g["crash_after_contact_s"] - base["crash_after_contact_s"]
        dd = g["first_peak_mm"] / base["first_peak_mm"] - 1.0
        flips = [f"{c} ({base.loc[c, 'type']} → {g.loc[c, 'type']})" for c in g.index
                 if g.loc[c, "type"] != base.loc[c, "type"]]  # fmt: skip
        summary.append(
            f"- {_VARIANT_NAMES.get(model, model)}, {change}: crash time "
            f"{_range(dt, '+.3f')} s, bumper 2's peak {_range(100 * dd, '+.1f')} %, types "
            + ("changed in crash " + ", ".join(flips) if flips else "unchanged")
            + f"; matched {int(g['matches'].sum())} of {len(g)} (as run: "
            f"{int(base['matches'].sum())})."
        )
    lines += [*summary, "",
              "| crash | variant | change | type | δ_init (mm) | bumper 2 peak (mm) "
              "| crash after contact (s) | attitude RMS (°) | position RMS (mm) |",
              "|---" * 9 + "|"]  # fmt: skip
    for _, r in switches.iterrows():
        lines.append(
            f"| {r['crash']} | {_VARIANT_NAMES.get(r['model'], r['model'])} | {r['change']} "
            f"| {_cell_type(r)} | {_num(r['delta_init_mm'])} | {_num(r['first_peak_mm'])} "
            f"| {_num(r['crash_after_contact_s'], '.3f')} "
            f"| {_num(r['attitude_rms_deg_0_3s'], '.1f')} "
            f"| {_num(r['position_rms_mm_0_3s'])} |"
        )
    return "\n".join(lines)


def _range(values: pd.Series, fmt: str) -> str:
    v = values.dropna()
    if v.empty:
        return "–"
    lo, hi = float(v.min()), float(v.max())
    return format(lo, fmt) if lo == hi else f"{format(lo, fmt)} to {format(hi, fmt)}"
