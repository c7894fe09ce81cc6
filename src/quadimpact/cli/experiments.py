"""``quadimpact experiments``: the seven real crashes of the paper's Table III."""

from __future__ import annotations

from pathlib import Path

import click

from quadimpact.cli.options import (
    announce_compilation,
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
@data_option(
    "Folder of the crash set's data (spiri-crash-set-1/crash_N.mat); a folder given here "
    "must hold the logs. [default: $QUADIMPACT_DATA when set (then only it), else "
    "shared/data beside the checkout's folder, else /work/shared/data; without logs the "
    "comparisons with them are left out] The folder used is printed."
)
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

    Each crash runs at its Table III conditions with the motors powered off
    at impact at the measured rates, in both model variants; a sample over the
    stated uncertainty gives the share of each response type; where the flight
    log is available the simulation is compared with it (attitude error over
    the first 0.3 s after impact), and where the log shows the wall contact
    the crash is run again at the log's own pre-impact estimates (speed,
    heading, roll, pitch) and over their uncertainty.

    Ctrl-C (any number of times) or SIGTERM stops it at once and keeps every
    finished run (exit status 130, 143 for SIGTERM), saying how many; run the
    same command again to resume.
    """
    from quadimpact.experiments.table3 import check_data_dir, logs_source, run_experiments
    from quadimpact.results.files import check_out_dir

    check_out_dir(out, "experiments")
    if data is not None:
        check_data_dir(data)
    announce_compilation()
    with stoppable(out):
        table = run_experiments(
            out, data_dir=data, samples=samples, log_samples=log_samples, workers=workers,
            scheduler=scheduler, progress=not no_progress,
        )  # fmt: skip
    cols = ["crash", "type_paper_experiment", "type_paper_simulation", "type_ours", "type_replica",
            "attitude_rms_deg_0_3s", "type_log", "type_log_conditions", "verdict"]  # fmt: skip
    shown = table[cols].rename(
        columns={"type_paper_experiment": "experiment", "type_paper_simulation": "paper_sim",
                 "type_ours": "ours", "type_replica": "replica", "type_log": "log",
                 "attitude_rms_deg_0_3s": "att_rms_0.3s", "type_log_conditions": "ours_at_log"}
    )  # fmt: skip
    click.echo(shown.to_string(index=False, float_format="%.1f"))
    click.echo(f"table          {out / 'table3.csv'}")
    click.echo(f"logs           {logs_source(data)}")
