"""The estimator study's figures and ``report.md`` (``quadimpact estimators``).

``study`` is an :class:`~quadimpact.studies.estimators.estimator_study.EstimatorStudy`
(not imported here: the study imports this module).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from quadimpact.results.figures import new_figure, save_figure
from quadimpact.studies.estimators.estimator_scenarios import (
    AUTHORS_2016,
    AUTHORS_ROWS,
    CURVE_TRIALS,
)

__all__ = ["render_report", "write_figures"]

CURVES_PNG = "error_around_contact.png"
DISTRIBUTION_PNG = "crash_error_per_trial.png"


def write_figures(
    table: pd.DataFrame,
    study: Any,
    grid: np.ndarray,
    curves: dict[str, np.ndarray],
    out_dir: str | os.PathLike[str],
) -> list[Path]:
    """The error over time around the first contact and the distribution per trial."""
    out = Path(out_dir)
    fig = new_figure(8.0, 4.5)
    ax = fig.add_subplot(1, 1, 1)
    for label, curve in curves.items():
        if label == "ideal":
            continue
        ax.plot(grid, curve, linewidth=1.2, label=label)
    ax.axvline(0.0, color="grey", linewidth=0.8, linestyle=":")
    ax.set_xlabel("time from the first contact (s)")
    ax.set_ylabel("attitude error (deg)")
    ax.set_title(
        f"{study.scenario}: mean attitude error over the first {min(study.n, CURVE_TRIALS)} trials"
    )
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    paths = [save_figure(fig, out / CURVES_PNG)]
    fig = new_figure(8.0, 4.5)
    ax = fig.add_subplot(1, 1, 1)
    labels = [label for label, _, _ in study.rows() if label != "ideal"]
    data = []
    for label in labels:
        v = table.loc[table["estimator_label"] == label, "est_attitude_rms_crash_deg"]
        v = pd.to_numeric(v, errors="coerce").to_numpy(dtype=float)
        data.append(v[np.isfinite(v)])
    ax.boxplot(data, tick_labels=labels, showmeans=True)
    ax.set_yscale("log")
    ax.set_ylabel("crash-phase RMS attitude error per trial (deg)")
    ax.set_title(f"{study.scenario}: per trial ({study.n} trials; triangles: means)")
    ax.grid(True, axis="y", alpha=0.3)
    paths.append(save_figure(fig, out / DISTRIBUTION_PNG))
    return paths


def _f(x: Any, digits: int = 2) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    return f"{x:.{digits}f}"


def render_report(
    study: Any, rows: list[dict[str, Any]], figures: list[Path], run: dict[str, Any]
) -> str:
    """``report.md``: the table with the authors' figures beside it, the figures."""
    authors = AUTHORS_2016[study.initial_error] if study.scenario == "authors-2016" else {}
    loop = "in the loop" if study.in_loop else "out of the loop (observers)"
    lines = [
        f"# Estimators on the `{study.scenario}` scenario",
        "",
        f"{study.n} seeded trials (seed {study.seed}), every estimator on the same trials; "
        f"initial errors: `{study.initial_error}`; the estimates {loop}"
        + (f"; set back to quadimpact's trial: {', '.join(study.back)}" if study.back else "")
        + ". Attitude error: the angle of q ⊗ q̂⁻¹; per trial its RMS over the IMU "
        "samples of the crash phase (first contact to stage 4, judged on the truth) and "
        "of the rest of the run (not-crash); then over the trials.",
        "",
        "| estimator | crash mean ± 95 % (°) | median | p90 | sd | not-crash mean (°) "
        "| trials counted | success [95 %] | authors: crash / not-crash (°) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        success = "–"
        if "success_share" in r:
            success = (
                f"{100 * r['success_share']:.1f} % [{100 * r['success_low']:.1f}, "
                f"{100 * r['success_high']:.1f}]"
            )
        theirs = "–"
        key = AUTHORS_ROWS.get(r["estimator"])
        if key in authors:  # both numbers, "–" where their results give none
            a = authors[key]
            theirs = f"{_f(a.get('crash'))} / {_f(a.get('not_crash'))}"
        lines.append(
            f"| {r['estimator']} | {_f(r['crash_rms_mean_deg'])} ± "
            f"{_f(r['crash_rms_mean_ci95_deg'])} | {_f(r['crash_rms_median_deg'])} "
            f"| {_f(r['crash_rms_p90_deg'])} | {_f(r['crash_rms_sd_deg'])} "
            f"| {_f(r['not_crash_rms_mean_deg'])} | {r['trials_counted']} of {r['trials']} "
            f"| {success} | {theirs} |"
        )
    excluded = [r for r in rows if r["trials_counted"] < r["trials"]]
    lines.append("")
    if any("not_crash" not in a for a in authors.values()):
        lines.append(
            "- The authors' column: their crash / not-crash means; their saved results give "
            f"no not-crash figure with initial errors `{study.initial_error}` (–)."
        )
    for r in excluded:
        lines.append(
            f"- `{r['estimator']}`: {r['trials'] - r['trials_counted']} trials not counted "
            f"({r['no_contact']} without contact, {r['failed']} failed runs)."
        )
    lines += [
        "",
        "`cf`: the authors' explicit complementary filter on raw vectors; `ekf-as-written`: "
        "their 7-state additive-quaternion EKF with its transition matrix as written; "
        "`ekf-additive`: the same filter with the correct transition; `complementary` and "
        "`ekf`: quadimpact's own filters with their defaults (docs/ESTIMATION.md).",
        "",
        f"![Mean attitude error around the first contact]({figures[0].as_posix()})",
        "",
        f"![Crash-phase error per trial]({figures[1].as_posix()})",
        "",
        f"Runs: {run['n_runs']} ({run['n_ran']} run now in {run['sweep_s']:.1f} s, "
        f"{run['backend']}).",
        "",
    ]
    return "\n".join(lines)
