"""The paper's study in one call: Figure 4, Table II, Figures 5-6 and a report.

``reproduce(out_dir)`` runs, for both model variants (MODEL.md section 8),
the Figure 4 sweep (heading 0 and 45 deg, inclination -20..20 deg in 1-deg
steps, impact speed 0.5, 0.75, 1 m/s: 246 runs each) and the example run
(45 deg, 15 deg, 0.75 m/s), evaluates the paper's findings on each
(``findings.py``), and, to explain where the variants disagree, repeats the
replica with each of its six differences switched off in turn. It writes:

* ``report.md``: the findings with the paper's claim, what each variant
  measured and the computed verdict; the ablation; the figures and Table II;
* ``fig4_<variant>.png``, ``table2_<variant>.png``, ``example-<variant>/``
  (the run's files, Figures 5 and 6);
* ``fig4.parquet`` (every run of every sweep), ``table2.parquet``,
  ``findings.parquet``, ``ablation.parquet``;
* ``sweeps/<name>/``: the resumable sweep folders.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
from matplotlib.figure import Figure

from . import __version__
from .findings import Finding, evaluate, fig4_curves, findings_frame
from .inputs.model import MODEL_VARIANTS
from .inputs.scenarios import WallApproach
from .results import figures
from .simulation import simulate
from .simulation.metrics import RESPONSE_TYPES
from .sweep import SweepSpec, run_sweep
from .viz.scene import Scene
from .viz.snapshots import write_snapshots

FIG4_GRID: dict[str, list[float]] = {
    "heading_deg": [0.0, 45.0],
    "inclination_deg": [float(i) for i in range(-20, 21)],
    "speed_m_s": [0.5, 0.75, 1.0],
}
EXAMPLE = {"heading_deg": 45.0, "inclination_deg": 15.0, "speed_m_s": 0.75}
VARIANTS = ("paper-replica", "default")
SWITCHES = tuple(MODEL_VARIANTS["default"])  # the replica's six differences


@dataclass
class StudyResult:
    """What ``reproduce`` produced (paths and tables)."""

    out_dir: Path
    report: Path
    tables: dict[str, pd.DataFrame]
    findings: pd.DataFrame
    ablation: pd.DataFrame
    elapsed_s: float


def _ablation_name(switch: str) -> str:
    return f"replica-without-{switch}"


def _run_variant(
    name: str, base: dict, out: Path, workers: int | None, scheduler: str | None, progress: bool
) -> tuple[pd.DataFrame, tuple[dict, pd.DataFrame, pd.DataFrame]]:
    table = run_sweep(
        SweepSpec(base=base, grid=FIG4_GRID),
        out / "sweeps" / name,
        workers=workers,
        scheduler=scheduler,
        progress=progress,
    )
    example = simulate(WallApproach(**EXAMPLE, **base))
    return table, example


def reproduce(
    out_dir: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = False,
    ablation: bool = True,
    experiments: bool = True,
    data_dir: str | Path | None = None,
) -> StudyResult:
    """Run the paper's study and write the report folder (see the module docstring).

    With ``experiments`` the seven crashes of Table III are simulated too
    (``experiments/table3.py``, into ``out_dir/experiments``), compared with
    their logs when ``data_dir`` (or the default data folder) holds them.
    """
    start = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    tables: dict[str, pd.DataFrame] = {}
    found: dict[str, list[Finding]] = {}
    for variant in VARIANTS:
        table, ex = _run_variant(variant, {"model": variant}, out, workers, scheduler, progress)
        ex.write(out / f"example-{variant}")
        write_snapshots(out / f"example-{variant}", scene=Scene.from_result(ex))
        tables[variant] = table
        found[variant] = evaluate(table, (ex.summary, ex.episodes, ex.timeseries))
    ablation_rows = []
    if ablation:
        for switch in SWITCHES:
            name = _ablation_name(switch)
            base = {
                "model": "paper-replica",
                "model_options": {switch: MODEL_VARIANTS["default"][switch]},
            }
            table, ex = _run_variant(name, base, out, workers, scheduler, progress)
            tables[name] = table
            fs = evaluate(table, (ex.summary, ex.episodes, ex.timeseries))
            ablation_rows += [{"switch": switch, **f.__dict__} for f in fs]
    ablation_df = pd.DataFrame(ablation_rows)
    findings = findings_frame(found)
    table3 = None
    if experiments:
        from .experiments.table3 import run_experiments

        table3 = run_experiments(
            out / "experiments", data_dir=data_dir, workers=workers, scheduler=scheduler,
            progress=progress,
        )  # fmt: skip

    # tables behind the report
    pd.concat([t.assign(variant=v) for v, t in tables.items()]).to_parquet(out / "fig4.parquet")
    table2(tables).to_parquet(out / "table2.parquet")
    findings.to_parquet(out / "findings.parquet")
    ablation_df.to_parquet(out / "ablation.parquet")
    for variant in VARIANTS:
        fig4_figure(tables[variant], variant).savefig(out / f"fig4_{variant}.png", dpi=120)
        type_map_figure(tables[variant], variant).savefig(out / f"table2_{variant}.png", dpi=120)
    elapsed = time.perf_counter() - start
    report = out / "report.md"
    report.write_text(render_report(tables, findings, ablation_df, elapsed, table3))
    return StudyResult(out, report, tables, findings, ablation_df, elapsed)


# ------------------------------------------------------------------ tables
def type_label(row: pd.Series) -> str:
    """Table II cell: the type, with the count of subsequent impacts for C and D."""
    t = row["response_type"]
    if not isinstance(t, str):
        return "fail"
    return f"{t}{int(row['n_subsequent_impacts'])}" if t in ("C", "D") else t


def table2(tables: dict[str, pd.DataFrame]) -> pd.DataFrame:
    """Response type and subsequent-impact count of every Figure 4 run, all sweeps."""
    cols = ["heading_deg", "speed_m_s", "inclination_deg", "response_type", "n_subsequent_impacts"]
    parts = []
    for v, t in tables.items():
        p = t[cols].copy()
        p["label"] = t.apply(type_label, axis=1)
        p["variant"] = v
        parts.append(p)
    return pd.concat(parts, ignore_index=True)


def table2_markdown(table: pd.DataFrame) -> str:
    """Table II as Markdown: rows inclination, columns (heading, speed)."""
    t = table.assign(label=table.apply(type_label, axis=1))
    grid = t.pivot_table(
        index="inclination_deg", columns=["heading_deg", "speed_m_s"], values="label",
        aggfunc="first",
    )  # fmt: skip
    head = "| ι (°) | " + " | ".join(f"ψ {h:g}°, {v:g} m/s" for h, v in grid.columns) + " |"
    sep = "|---" * (len(grid.columns) + 1) + "|"
    rows = [f"| {i:+g} | " + " | ".join(str(x) for x in r) + " |" for i, r in grid.iterrows()]
    return "\n".join([head, sep, *rows])


# ------------------------------------------------------------------ figures
def fig4_figure(table: pd.DataFrame, variant: str) -> Figure:
    """Figure 4: delta_init against inclination, one panel per heading, one curve per speed."""
    curves = fig4_curves(table)
    headings = sorted({h for h, _ in curves.columns})
    fig = figures.new_figure(10, 4)
    axes = fig.subplots(1, len(headings), sharey=True, squeeze=False)[0]
    for ax, h in zip(axes, headings, strict=True):
        for v in sorted(curves[h].columns):
            ax.plot(curves.index, curves[h][v] * 1e3, marker=".", label=f"{v:g} m/s")
        ax.axvline(10.0, color="0.6", lw=0.8, ls="--")
        ax.set_title(f"ψ = {h:g}°")
        ax.set_xlabel("inclination (deg)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("δ_init (mm)")
    axes[-1].legend(title="V_c")
    fig.suptitle(f"Figure 4, {variant}: maximum deflection at the initial impact")
    return fig


def type_map_figure(table: pd.DataFrame, variant: str) -> Figure:
    """Table II as a picture: response type over inclination and speed, one panel per heading."""
    return figures.type_map_figure(
        table, "inclination_deg", "speed_m_s", facet="heading_deg", label=type_label,
        title=f"Table II, {variant}: response type (C/D with the number of subsequent impacts)",
    )  # fmt: skip


# ------------------------------------------------------------------ report
def _cell(f: pd.Series) -> str:
    return f"**{f['verdict']}**: {f['measured']}"


def render_report(
    tables: dict[str, pd.DataFrame],
    findings: pd.DataFrame,
    ablation: pd.DataFrame,
    elapsed_s: float,
    table3: pd.DataFrame | None = None,
) -> str:
    """The Markdown report: findings, ablation, figures, Table II, Table III."""
    lines = [
        "# The paper's study, reproduced",
        "",
        f"Generated by `quadimpact reproduce` (quadimpact {__version__}) in {elapsed_s:.1f} s. "
        "Every verdict below is computed from the runs (thresholds in `quadimpact/findings.py`).",
        "Variants (MODEL.md section 8): `paper-replica` reproduces the authors' simulator, errors "
        "included; `default` is the physically consistent model.",
        "",
        "## Findings",
        "",
        "| finding | paper | paper-replica | default |",
        "|---|---|---|---|",
    ]
    rep = findings[findings["variant"] == "paper-replica"].set_index("key")
    dft = findings[findings["variant"] == "default"].set_index("key")
    for key in rep.index:
        lines.append(f"| {key} | {rep.loc[key, 'claim']} | {_cell(rep.loc[key])} | "
                     f"{_cell(dft.loc[key])} |")  # fmt: skip
    lines += ["", "## Where the variants disagree", ""]
    differ = [k for k in rep.index if rep.loc[k, "verdict"] != dft.loc[k, "verdict"]]
    if not differ:
        lines.append("The two variants reach the same verdict on every finding.")
    elif ablation.empty:
        lines.append("Differing findings: " + ", ".join(differ) + " (ablation not run).")
    else:
        lines += [
            "The replica was rerun with one of its differences switched to the default's at a "
            "time. A switch *explains* a finding when removing it alone turns the replica's "
            "verdict into the default's.",
            "",
            "| finding | replica | default | "
            + " | ".join(f"without `{s}`" for s in SWITCHES)
            + " | explained by |",
            "|---" * (len(SWITCHES) + 4) + "|",
        ]
        for key in differ:
            row = ablation[ablation["key"] == key].set_index("switch")
            target = dft.loc[key, "verdict"]
            causes = [s for s in SWITCHES if row.loc[s, "verdict"] == target]
            cells = " | ".join(
                f"{row.loc[s, 'verdict']} ({row.loc[s, 'value']:.2f})" for s in SWITCHES
            )
            lines.append(
                f"| {key} | {rep.loc[key, 'verdict']} ({rep.loc[key, 'value']:.2f}) | {target} "
                f"({dft.loc[key, 'value']:.2f}) | {cells} | "
                + (", ".join(f"`{c}`" for c in causes) or "no single switch (a combination)")
                + " |"
            )
    lines += ["", "## Figure 4", ""]
    for v in VARIANTS:
        lines.append(f"![Figure 4, {v}](fig4_{v}.png)")
    lines += ["", "## Table II", ""]
    for v in VARIANTS:
        counts = tables[v]["response_type"].value_counts().reindex(RESPONSE_TYPES, fill_value=0)
        lines += [f"### {v}", "", f"![Table II, {v}](table2_{v}.png)", "",
                  "Counts: " + ", ".join(f"{k} {n}" for k, n in counts.items()), "",
                  table2_markdown(tables[v]), ""]  # fmt: skip
    lines += ["## Figures 5 and 6: the example (ψ 45°, V_c 0.75 m/s, ι 15°)", ""]
    for v in VARIANTS:
        lines += [f"### {v}", "", f"![Figure 5, {v}](example-{v}/fig5.png)",
                  f"![Figure 6, {v}](example-{v}/fig6.png)",
                  f"![Snapshots after impact (the paper's Figure 8 times), {v}]"
                  f"(example-{v}/snapshots.png)", ""]  # fmt: skip
    if table3 is not None:
        lines += ["## Table III: the seven real crashes", "", table3_markdown(table3), ""]
    return "\n".join(lines) + "\n"


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


def table3_markdown(table: pd.DataFrame) -> str:
    """Table III, ours beside the paper's, and each differing row explained by the data."""
    from quadimpact.inputs.vehicle import load_vehicle

    rb_mm = 1e3 * load_vehicle("spiri").bumper_radius_m
    has_log = "type_log_conditions" in table.columns
    head = (
        "| crash | ψ (°) | V_c (m/s) | ι (°) | experiment | paper's simulation | ours (default) "
        "| replica | over the uncertainty (default) | attitude RMS 0-0.3 s (°) |"
    )
    lines = [head, "|---" * 10 + "|"]
    if has_log:
        lines = [head + " deepest δ (mm) |", "|---" * 11 + "|"]
    notes = []
    for _, r in table.iterrows():
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
        )
        if r["type_ours"] != r["type_paper_experiment"]:
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
            notes.append(note)
    if notes:
        lines += ["", "Rows where our type differs from the experiment's:", "", *notes]
    if has_log:
        seen = table[table["type_log_conditions"].apply(lambda v: isinstance(v, str))]
        dv = seen["log_speed_m_s"] - seen["speed_m_s"]
        di = seen["log_inclination_deg"] - seen["inclination_deg"]
        spread = (
            f" Against Table III the logs' speeds differ by {dv.min():+.2f} to {dv.max():+.2f} "
            f"m/s (stated ±0.01) and their inclinations by {di.min():+.1f} to {di.max():+.1f}°."
            if len(seen)
            else ""
        )
        lines += [
            "",
            "At the logs' own pre-impact estimates (motion capture at the observed contact; "
            "heading in the log frame, flown rear first; docs/EXPERIMENTS.md explains why "
            f"they differ from Table III).{spread}",
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
                f"| {r['crash']} | {_deg(r['log_heading_deg'])} | {r['log_speed_m_s']:.2f} "
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
    return "\n".join(lines)
