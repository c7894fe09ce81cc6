"""The benchmark's report (``report.md``) and its figure (``leaderboard.png``).

``study`` below is the :class:`~quadimpact.studies.benchmark.benchmark_study.BenchmarkStudy`
(its ``subject``, ``tasks``, ``quick``, ``references``, ``limit``).

Both are drawn from ``benchmark.csv``'s table and the cells' trials tables
(``cells/<row>/<task>-<sensors>.parquet``), never from numbers typed in:

* the **leaderboard**, one table per task: every row with each sensor set of
  the suite, ranked by its success with the first (``ideal``), with its 95 %
  Wilson interval; in suites 2 and 3 its paired difference to the default row, the
  published criterion, the time and distance to the hover; in suite 1 what
  the ``impact`` sensors cost it, the times to recover and to hover, the drift;
  in both the height lost, the missed and false detections, the CPU time and
  where the line comes from (run now, the cache, or the authors' publication);
* in suites 2 and 3, **what the suite resolves**: the half-widths of the rows'
  paired intervals, per task and sensor set;
* the subject **against each reference**, trial by trial (the same trials):
  the trials only one of the two succeeds on;
* **where the subject fails**: success by inclination bin (the wall) or pitch
  band (the grids), bins in order;
* its **slowest trials** and **what ran**: each cell's source and time.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from quadimpact.studies.benchmark.suite import TASKS, sensor_set
from quadimpact.studies.statistics import percent, rate, rate_text

__all__ = ["FIGURES", "leaderboard_figure", "render_report", "write_figures"]

FIGURES = ("leaderboard.png",)
MARKERS = ("o", "s", "D", "^")  # by the sensor set's place in the suite's order


def _ranked_rows(part: pd.DataFrame, first: str = "ideal") -> list[str]:
    """A task's rows, best first by the success with the sensor set ``first`` (a row
    without it last)."""
    lines = part[(part["sensors"] == first) & (part["source"] != "published")]
    best = lines.set_index("row")["success"].fillna(-1.0)
    rows = list(dict.fromkeys(part["row"]))
    return sorted(rows, key=lambda r: -float(best.get(r, -1.0)))


def _shown_success(line: pd.Series) -> bool:
    """Whether a line's success means something: a row that never declares recovery has
    none on the wall in suite 1 (its criterion is the declared stage 4)."""
    return not (
        str(line.get("suite_version")) == "1"
        and line.get("task") == "wall"
        and line.get("source") != "published"
        and line.get("declares_recovery") is False
    )


def leaderboard_figure(table: pd.DataFrame, study: Any) -> Any:
    """Success with 95 % intervals, row by row, one panel per task.

    The benchmarked row is shaded and named in bold; a row with no success says
    why beside its axis; the legend sits below the panels, off the markers.
    """
    from quadimpact.results.figures import new_figure

    tasks, sets = study.tasks, study.sensor_sets()
    held = study.definition.held_hover
    n_rows = max(len(set(table[table["task"] == t]["row"])) for t in tasks)
    fig = new_figure(4.4 * len(tasks), 1.6 + 0.42 * n_rows)
    axes = fig.subplots(1, len(tasks), squeeze=False)[0]
    handles: dict[str, Any] = {}
    for ax, name in zip(axes, tasks, strict=True):
        part = table[table["task"] == name]
        rows = _ranked_rows(part, sets[0])
        for y, row in enumerate(rows):
            if row == study.subject.name:
                ax.axhspan(y - 0.45, y + 0.45, color="C1", alpha=0.12, lw=0)
            empty = True
            for k, sensors in enumerate((*sets, "published")):
                line = part[
                    (part["row"] == row) & (part["sensors"] == sensors)
                    & (part["source"] != "published")
                ]  # fmt: skip
                if sensors == "published":
                    line = part[(part["row"] == row) & (part["source"] == "published")]
                if line.empty or not _shown_success(line.iloc[0]):
                    continue
                s = line.iloc[0]
                published = s["source"] == "published"
                key = "published_success" if published and held else "success"
                x = 100 * s[key]
                if not np.isfinite(x):
                    continue
                empty = empty and x == 0.0
                err = [[x - 100 * s[f"{key}_low"]], [100 * s[f"{key}_high"] - x]]
                dy = 0.0 if published else 0.3 * (k - (len(sets) - 1) / 2)
                label = (
                    ("published (their criterion)" if held else "published") if published
                    else sensors
                )  # fmt: skip
                h = ax.errorbar(
                    x, y + dy, xerr=err, capsize=2,
                    fmt="*" if published else MARKERS[k % len(MARKERS)],
                    color="0.4" if published else f"C{k}", mfc="white" if k else None,
                )  # fmt: skip
                handles.setdefault(label, h)
            if empty and held:
                ax.annotate("no held hover", (0.98, y), xycoords=("axes fraction", "data"),
                            ha="right", va="center", fontsize="small", color="0.3")  # fmt: skip
        ax.set_yticks(range(len(rows)), rows)
        for tick in ax.get_yticklabels():
            if tick.get_text() == study.subject.name:
                tick.set_fontweight("bold")
        ax.invert_yaxis()
        ax.set_xlim(-2, 102)
        ax.set_xlabel("success, % (95 % interval)")
        ax.set_title(name)
        ax.grid(axis="x", alpha=0.3)
    fig.legend(handles.values(), handles.keys(), loc="outside lower center", ncol=len(handles),
               fontsize="small", frameon=False)  # fmt: skip
    what = "a held hover" if held else "the published criteria"
    fig.suptitle(f"quadimpact benchmark, suite {study.suite}: success is {what}")
    return fig


def write_figures(table: pd.DataFrame, out: Path, study: Any) -> list[Path]:
    """``leaderboard.png`` into ``out``."""
    from quadimpact.results.figures import save_figure

    return [save_figure(leaderboard_figure(table, study), out / FIGURES[0])]


# ------------------------------------------------------------------- text
def _pair(line: pd.Series, name: str, unit: str, digits: int) -> str:
    a, b = line.get(f"{name}_p50_{unit}"), line.get(f"{name}_p90_{unit}")
    if a is None or b is None or not (math.isfinite(a) and math.isfinite(b)):
        return "–"
    return f"{a:.{digits}f} / {b:.{digits}f}"


def _success_text(line: pd.Series) -> str:
    if not _shown_success(line):
        return "– (declares no recovery)"
    k, n = int(line["success_k"]), int(line["valid"])
    return rate_text({"k": k, "n": n, "value": line["success"], "low": line["success_low"],
                      "high": line["success_high"]})  # fmt: skip


def _leaderboard(table: pd.DataFrame, name: str, subject: str, study: Any) -> list[str]:
    if study.definition.held_hover:
        return _held_leaderboard(table, name, subject, study)
    part = table[table["task"] == name]
    lines = [
        "| row | sensors | success [95 %] | impact − ideal (points) | time to recover p50 / p90 "
        "(s) | hover reached; p50 / p90 (s) | height lost p50 / p90 (m) | drift p50 / p90 (m) "
        "| missed / false detections | CPU per trial (ms) | source |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row in _ranked_rows(part):
        mine = part[part["row"] == row]
        ideal = mine[mine["sensors"] == "ideal"]
        for _, line in mine.iterrows():
            label = f"**{row}**" if row == subject else row
            if line["source"] == "published":
                lines.append(f"| {label} | {line['sensors']} | {_success_text(line)} | | | | | "
                             f"| | | published: {line['note']} |")  # fmt: skip
                continue
            gap = "–"
            if line["sensors"] == "impact" and not ideal.empty and _shown_success(line):
                gap = f"{100 * (line['success'] - ideal.iloc[0]['success']):+.1f}"
            hover = percent(line["hover"])
            lines.append(
                f"| {label} | {line['sensors']} ({line['estimator']}) | {_success_text(line)} "
                f"| {gap} | {_pair(line, 'recover', 's', 3)} | {hover}; "
                f"{_pair(line, 'hover', 's', 2)} | {_pair(line, 'height_lost', 'm', 2)} | "
                f"{_pair(line, 'drift', 'm', 2)} | {int(line['missed_detections'])} / "
                f"{int(line['false_detections'])} | {line['cpu_ms_per_trial']:.1f} | "
                f"{line['source']} |"
            )
    return lines


def _share_text(line: pd.Series, key: str) -> str:
    value = line.get(key)
    if value is None or not math.isfinite(float(value)):
        return "–"
    return f"{percent(value)} [{percent(line[f'{key}_low'])}, {percent(line[f'{key}_high'])}]"


def _versus_default(line: pd.Series) -> str:
    """The row minus the default, points, with its 95 % interval (and whether resolved)."""
    d = line.get("vs_default")
    if d is None or not math.isfinite(float(d)):
        return "–"
    mark = "" if bool(line.get("vs_default_resolved")) else " (not resolved)"
    return f"{d:+.1f} [{line['vs_default_low']:+.1f}, {line['vs_default_high']:+.1f}]{mark}"


def _held_leaderboard(table: pd.DataFrame, name: str, subject: str, study: Any) -> list[str]:
    """Suite 2's table of a task: ranked by the success with the first sensor set."""
    part = table[table["task"] == name]
    lines = [
        "| row | sensors | success [95 %] | − default, points [95 %] | published criterion "
        "[95 %] | time to hover p50 / p90 (s) | distance to hover p50 / p90 (m) | height lost "
        "p50 / p90 (m) | missed / false detections | excluded | CPU per trial (ms) | source |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row in _ranked_rows(part, study.sensor_sets()[0]):
        label = f"**{row}**" if row == subject else row
        for _, line in part[part["row"] == row].iterrows():
            if line["source"] == "published":
                lines.append(f"| {label} | – | – | – | {_share_text(line, 'published_success')} "
                             f"| | | | | | | published: {line['note']} |")  # fmt: skip
                continue
            success = _share_text(line, "success")
            if int(line["success_k"]) == 0:
                success += " (no held hover)"
            lines.append(
                f"| {label} | {line['sensors']} ({line['estimator']}) | {success} | "
                f"{_versus_default(line)} | {_share_text(line, 'published_success')} | "
                f"{_pair(line, 'hover', 's', 2)} | {_pair(line, 'hover_distance', 'm', 2)} | "
                f"{_pair(line, 'height_lost', 'm', 2)} | {int(line['missed_detections'])} / "
                f"{int(line['false_detections'])} | {int(line['excluded'])} | "
                f"{line['cpu_ms_per_trial']:.1f} | {line['source']} |"
            )
    return lines


def _resolution(table: pd.DataFrame) -> list[str]:
    """What the suite resolves: per task and sensor set, the half-widths of the rows'
    paired intervals to the default (the smallest difference it tells apart)."""
    if "vs_default" not in table:
        return []
    part = table[table["vs_default"].notna()]
    if part.empty:
        return []
    lines = [
        "| task | sensors | trials | paired interval half-width, points: min / median / max "
        "| differences resolved |",
        "|---|---|---|---|---|",
    ]
    for (task, sensors), g in part.groupby(["task", "sensors"], sort=False):
        half = (g["vs_default_high"] - g["vs_default_low"]).to_numpy(dtype=float) / 2
        resolved = int(g["vs_default_resolved"].astype(bool).sum())
        spread = f"{half.min():.1f} / {np.median(half):.1f} / {half.max():.1f}"
        lines.append(f"| {task} | {sensors} | {int(g['valid'].max())} | {spread} | "
                     f"{resolved} of {len(g)} |")  # fmt: skip
    return lines


def _cell(out: Path, row: str, task: str, sensors: str) -> pd.DataFrame | None:
    path = out / "cells" / row / f"{task}-{sensors}.parquet"
    return pd.read_parquet(path) if path.is_file() else None


def _versus(out: Path, study: Any, table: pd.DataFrame) -> list[str]:
    """The subject against each reference row, trial by trial."""
    subject = study.subject.name
    lines = [
        "| task | sensors | reference | subject | reference's | only the subject | "
        "only the reference | neither |",
        "|---|---|---|---|---|---|---|---|",
    ]
    rows = [r for r in dict.fromkeys(table["row"]) if r != subject]
    for name in study.tasks:
        for sensors in study.sensor_sets():
            mine = _cell(out, subject, name, sensors)
            for ref in rows:
                theirs = _cell(out, ref, name, sensors)
                if mine is None or theirs is None or len(mine) != len(theirs):
                    continue
                a = (mine["success"] & mine["valid"]).to_numpy(dtype=bool)
                b = (theirs["success"] & theirs["valid"]).to_numpy(dtype=bool)
                lines.append(
                    f"| {name} | {sensors} | {ref} | {percent(a.mean())} | {percent(b.mean())} "
                    f"| {int((a & ~b).sum())} | {int((~a & b).sum())} | {int((~a & ~b).sum())} |"
                )
    return lines


def _bin_start(label: str) -> float:
    """Where a bin starts, for sorting: ``"[-15, -5)"`` -> -15, ``"40-45"`` -> 40."""
    match = re.match(r"[\[(]?\s*(-?\d+(?:\.\d+)?)", label)
    return float(match.group(1)) if match else math.inf


def _where_fails(out: Path, study: Any) -> list[str]:
    """The subject's success by inclination bin (wall) or pitch band (grids), ideal sensors."""
    from quadimpact.studies.trial_analysis import INCLINATION_BIN, binned, pitch_bands

    lines: list[str] = []
    for name in study.tasks:
        cols: dict[str, pd.DataFrame] = {}
        for sensors in study.sensor_sets():
            t = _cell(out, study.subject.name, name, sensors)
            if t is None:
                continue
            t = t[t["valid"].astype(bool)]
            if name == "wall":
                key = binned(t["inclination_deg"].astype(float), *INCLINATION_BIN).astype(str)
            else:
                key = pd.Series(pitch_bands(np.abs(t["pitch_deg"].to_numpy(dtype=float))),
                                index=t.index)  # fmt: skip
            cols[sensors] = t.assign(key=key.to_numpy())
        if not cols:
            continue
        first = next(iter(cols.values()))
        keys = sorted(dict.fromkeys(first["key"]), key=_bin_start)
        what = "inclination toward the wall (deg)" if name == "wall" else "abs(pitch) (deg)"
        lines += [f"**{name}**, by {what}:", "", "| bin | " + " | ".join(cols) + " |",
                  "|---|" + "---|" * len(cols)]  # fmt: skip
        for k in keys:
            cells = []
            for t in cols.values():
                part = t[t["key"] == k]
                cells.append(rate_text(rate(int(part["success"].sum()), len(part))))
            lines.append(f"| {k} | " + " | ".join(cells) + " |")
        lines.append("")
    return lines


def _slowest_trials(out: Path, study: Any) -> list[str]:
    """The subject's slowest trial of each task and sensor set: its CPU and why (issue 59)."""
    from quadimpact.studies.slowest import slowest_trials

    lines = [
        "## Slowest trials",
        "",
        f"The slowest trial of each of {study.subject.name}'s cells: its CPU in the "
        "compiled loop, against the cell's median, and what the integrator did (accepted "
        "and rejected steps, contact onsets). Each process loads the compiled code "
        "before its first trial, apart from the trials. A trial that would exceed the "
        "step budget fails (docs/NUMERICS.md).",
        "",
        "| task | sensors | run | CPU (ms) | x median | steps | rejected | onsets | status |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name in study.tasks:
        for sensors in study.sensor_sets():
            t = _cell(out, study.subject.name, name, sensors)
            found = None if t is None else slowest_trials(t, n=1)
            if found is None:
                continue
            w = found["trials"][0]
            status = w["status"] + (f" ({w['reason']})" if w["reason"] else "")
            counts = [("–" if w[k] is None else str(w[k]))
                      for k in ("steps", "rejected_steps", "contact_onsets")]  # fmt: skip
            cost = f"{w['cpu_ms']:.1f} | {w['times_median']:.1f}"
            run = w.get("run_id", "–")
            lines.append(
                f"| {name} | {sensors} | {run} | {cost} | {' | '.join(counts)} | {status} |"
            )
    lines.append("")
    return lines


def render_report(
    table: pd.DataFrame,
    study: Any,
    description: dict[str, Any],
    out: Path,
    figures: list[Path],
) -> str:
    """The report's Markdown (module docstring)."""
    s = study.subject
    d = s.describe()
    params = json.loads(d["params"])
    what = {
        "controller": f"the controller `{s.controller}`"
        + (f" in the model `{s.model}`" if s.controller == "recovery" else "")
        + (f" with {params}" if params else ""),
        "estimator": f"the estimator `{s.estimator}` (with the default law)",
        "policy": f"the policy `{s.policy}`",
    }[s.kind]
    sizes = ", ".join(
        f"{t} ({TASKS[t].size(study.quick):,} {'trials' if TASKS[t].kind == 'wall' else 'points'})"
        for t in study.tasks
    )
    suite = study.definition
    sets = study.sensor_sets()
    set_words = "; ".join(f"`{n}`: {sensor_set(n).title}" for n in sets)
    lines = [
        f"# quadimpact benchmark: {s.name}",
        "",
        f"Suite {suite.version}{' (quick)' if study.quick else ''}, quadimpact "
        f"{description['quadimpact_version']}. Benchmarked: **{s.name}**, {what}. Tasks: "
        f"{sizes}. Sensor sets: {set_words}; the sets of real sensors read the "
        f"`{s.estimator}` estimator (docs/BENCHMARK.md).",
        "",
        *_criterion_words(study),
        "",
        *(
            [
                f"**A smoke test, not a benchmark**: only the first {study.limit} trials or points "
                "of each task flew.",
                "",
            ]
            if study.limit is not None
            else []
        ),
        "## Leaderboard",
        "",
        *[f"![leaderboard]({p})" for p in figures],
        "",
    ]
    for name in study.tasks:
        lines += [f"### {name}: {TASKS[name].title}", "",
                  *_leaderboard(table, name, s.name, study), ""]  # fmt: skip
    resolution = _resolution(table)
    if resolution:
        lines += [
            "## What the suite resolves",
            "",
            "Each row's difference to the `default` row is paired: the same trials, flown by "
            "both. Its 95 % interval is Newcombe's for paired shares. A difference whose "
            "interval contains 0 is not resolved: the suite cannot tell the two rows apart. "
            "The half-width of the intervals is the smallest difference this suite resolves.",
            "",
            *resolution,
            "",
        ]
    if study.references:
        lines += [
            f"## {s.name} against each reference, trial by trial",
            "",
            "The same trials flown by both: the trials only one of the two succeeds on.",
            "",
            *_versus(out, study, table),
            "",
        ]
    lines += [f"## Where {s.name} fails", "", *_where_fails(out, study)]
    lines += _slowest_trials(out, study)
    lines += ["## What ran", "", "| row | task | sensors | source | sweep (s) | CPU (s) |",
              "|---|---|---|---|---|---|"]  # fmt: skip
    for c in description["cells"]:
        sweep = "–" if c["sweep_s"] is None else f"{c['sweep_s']:.1f}"
        lines.append(f"| {c['row']} | {c['task']} | {c['sensors']} | {c['source']} | {sweep} "
                     f"| {c['cpu_s']:.1f} |")  # fmt: skip
    lines += ["", f"The benchmark took {description['elapsed_s']:.1f} s of wall time this time "
              "(cells read from the cache took none; their sweep times are those of the run "
              "that computed them).", ""]  # fmt: skip
    return "\n".join(lines)


def _criterion_words(study: Any) -> list[str]:
    """The report's paragraph on what success means in the suite flown."""
    suite = study.definition
    if not suite.held_hover:
        return [
            "Success: " + "; ".join(f"{t}: {TASKS[t].success}" for t in study.tasks) + ". "
            "Time to recover: the detection to the declared recovery (stage 4), of the "
            "successes. Hover: the true CM speed below 0.2 m/s and the tilt below 5 deg for "
            "0.5 s (the share of the valid trials that get there, and when). Height lost: "
            "the altitude at the start minus at the end of the run, of the valid trials. "
            "Drift: the detection to the declared recovery, horizontal, of the successes."
        ]
    from quadimpact.studies.benchmark.suite import HELD_HOVER_SUCCESS

    words = [
        f"Success, the same for every task: {HELD_HOVER_SUCCESS}. Each trial runs "
        f"{suite.final_time_s:g} s, over a ground that ends it when touched. The published "
        "criterion of each task is kept beside it, to set rows against the authors' figures. "
        "Time to hover: from the first contact to the start of the held hover, of the "
        "successes. Distance to hover: horizontal, from the CM at the first contact to the "
        "hover point, of the successes. Height lost: the altitude at the start minus the "
        "lowest, of the valid trials."
    ]
    unflown = [n for n in suite.extra_sensor_sets if n not in study.sensor_sets()]
    if unflown:
        words += ["", f"Not on this leaderboard: {suite.extra_note}."]
    return words
