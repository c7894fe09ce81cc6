"""``quadimpact experiments``: the seven real crashes of the paper's Table III."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from quadimpact.cli.options import (
    data_option,
    defaulted_option,
    out_option,
    parallel_options,
    stoppable,
)


@click.command("experiments")
@out_option(
    "results/experiments",
    "Output folder: table3.csv, one folder per crash, the sensitivity sweeps.",
)
@data_option
@defaulted_option(
    "--samples",
    click.IntRange(min=0),
    300,
    "Runs per crash over the stated uncertainty (0: none).",
)
@defaulted_option(
    "--log-samples",
    click.IntRange(min=0),
    100,
    "Runs per crash over the uncertainty of the log's own pre-impact estimates (0: none).",
)
@parallel_options
def experiments(
    out: Path,
    data: Path | None,
    samples: int,
    log_samples: int,
    workers: int | None,
    scheduler: str | None,
    no_progress: bool,
) -> None:
    """Simulate the seven crashes of the paper's Table III and compare with the logs.

    Each crash runs at Table III's conditions and at the conditions the
    authors matched in their own simulations (their approach: climbing and
    drifting into the wall), in the default model and in the paper replica
    with the switches of the authors' crash runs, the motors following the
    measured schedules from the first contact (a zero rate: the motor switched
    off). Each run is compared with its flight log (attitude and position over
    the first 0.3 s after impact); the replica's crash-run switches are turned
    off in turn (and crash I-03's hand modification on) to show what each
    does; a sample over Table III's stated uncertainty gives the share of each
    response type; where the log shows the wall contact the crash is run again
    at the log's own pre-impact estimates (speed, heading, roll, pitch) and
    over their uncertainty. The report is table3.md (docs/EXPERIMENTS.md).

    Ctrl-C (any number of times) or SIGTERM stops it at once and keeps every
    finished run (exit status 130, 143 for SIGTERM), saying how many; run the
    same command again to resume.
    """
    from quadimpact.results.files import check_out_dir

    check_out_dir(out, "experiments")  # before the study's imports: a wrong folder is said at once
    from quadimpact.studies.table3.crash_logs import check_data_dir, logs_source
    from quadimpact.studies.table3.table3_study import run_experiments, study_folder

    study_folder(out, samples, log_samples, where="--out").check()  # other options: refused
    if data is not None:
        check_data_dir(data)
    with stoppable(out):
        table = run_experiments(
            out, data_dir=data, samples=samples, log_samples=log_samples, workers=workers,
            scheduler=scheduler, progress=not no_progress,
        )  # fmt: skip
    click.echo(format_table3(table, out))
    click.echo(f"logs           {logs_source(data)}")


def format_table3(table: Any, out: Path) -> str:
    """The command's summary: per crash the types at both conditions in both variants,
    with delta_init (mm), the crash time after the first contact (s) and the attitude error
    against the log (deg RMS, 0-0.3 s)."""
    import pandas as pd

    runs = pd.read_csv(out / "table3_runs.csv")
    names = {"default": "default", "paper-replica": "replica"}
    rows = []
    for _, r in table.iterrows():
        row = {"crash": r["crash"], "experiment": r["type_paper_experiment"],
               "paper_sim": r["type_paper_simulation"]}  # fmt: skip
        for _, x in runs[runs.crash == r["crash"]].iterrows():
            att = (
                ""
                if x["attitude_rms_deg_0_3s"] != x["attitude_rms_deg_0_3s"]
                else (f" {x['attitude_rms_deg_0_3s']:.0f}°")
            )
            row[f"{x['conditions']} {names[x['model']]}"] = (
                f"{x['type']} {x['delta_init_mm']:.0f}mm {x['crash_after_contact_s']:.3f}s{att}"
            )
        row["log"] = r["type_log"] if isinstance(r["type_log"], str) else "-"
        row["ours_at_log"] = (
            r["type_log_conditions"] if isinstance(r["type_log_conditions"], str) else "-"
        )
        rows.append(row)
    shown = pd.DataFrame(rows)
    matched = {c: int((runs[(runs.conditions == c.split()[0])
                            & (runs.model.map(names) == c.split()[1])]["matches"]).sum())
               for c in shown.columns[3:-2]}  # fmt: skip
    lines = [
        "types, delta_init, crash time after the first contact, attitude RMS vs the log; the "
        "log's own type and ours at the log's estimates:",
        shown.to_string(index=False),
        "experiment types matched: "
        + ", ".join(f"{c} {k} of {len(table)}" for c, k in matched.items()),
        f"table          {out / 'table3.csv'}",
        f"report         {out / 'table3.md'}",
    ]
    return "\n".join(lines)
