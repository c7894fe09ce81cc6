"""``quadimpact reproduce``: the paper's study to a report folder."""

from __future__ import annotations

from pathlib import Path

import click

from quadimpact.cli.options import (
    data_option,
    out_option,
    parallel_options,
    stoppable,
)


@click.command("reproduce")
@out_option(
    "results/paper", "Report folder (report.md, figures, tables; the sweeps it ran, resumable)."
)
@click.option(
    "--no-ablation",
    is_flag=True,
    help="Skip the replica reruns with one difference switched off at a time.",
)
@click.option("--no-experiments", is_flag=True, help="Skip the seven crashes of Table III.")
@click.option(
    "--no-recovery",
    is_flag=True,
    help="Skip 'Beyond the paper: recovery' (the recovery Monte Carlo, the Figure 4 grid and "
    "the crashes with the recovery controller).",
)
@data_option
@parallel_options
def reproduce(
    out: Path,
    workers: int | None,
    scheduler: str | None,
    no_ablation: bool,
    no_experiments: bool,
    no_recovery: bool,
    data: Path | None,
    no_progress: bool,
) -> None:
    """Reproduce the paper's study: Figure 4, Table II, Figures 5-6, findings.

    Both model variants (the physically consistent default and the paper
    replica) run the Figure 4 grid (heading 0 and 45 deg, inclination -20 to
    20 deg, impact speed 0.5, 0.75, 1 m/s) and the example run; the report sets
    each of the paper's findings beside what each variant measured, with a
    verdict computed from the data, and shows which of the replica's
    differences causes each disagreement. Beyond the paper, it runs the
    recovery controller: a Monte Carlo of impact trials of the Navi (2,000 per
    variant), the Figure 4 grid and the seven crashes without power-off,
    nominal against recovery (docs/RECOVERY.md). The pieces before the
    recovery part run side by side on the local cores (--workers 1: one
    after the other here). Each stage is named on stderr when it starts and
    timed when it ends; the report ends with the time per stage.

    Ctrl-C (any number of times) or SIGTERM stops it at once and keeps every
    finished run (exit status 130, 143 for SIGTERM), saying how many; run the
    same command again to resume.
    """
    from quadimpact.results.files import check_out_dir

    check_out_dir(out, "report")  # before the study's imports: a wrong folder is said at once
    from quadimpact.sweep.runner import warm_pool

    # the pool's fork server imports the simulator and loads the kernel on another core
    # while this process imports the study (Matplotlib, pandas): the study's first pieces
    # then start on a warm server (docs/PERFORMANCE.md, "reproduce, warm")
    warm_pool(workers, scheduler)
    from quadimpact.studies.paper.paper_study import reproduce as run_study
    from quadimpact.studies.paper.paper_study import study_folder
    from quadimpact.studies.table3.crash_logs import check_data_dir, logs_source

    parts = {"ablation": not no_ablation, "experiments": not no_experiments,
             "recovery": not no_recovery}  # fmt: skip
    study_folder(out, where="--out", **parts).check()  # other parts: refused at once
    if data is not None and not no_experiments:
        check_data_dir(data)

    with stoppable(out):
        result = run_study(
            out, workers=workers, scheduler=scheduler, progress=not no_progress,
            ablation=not no_ablation, experiments=not no_experiments, recovery=not no_recovery,
            data_dir=data,
        )  # fmt: skip
    f = result.findings
    click.echo(f"report         {result.report}")
    if not no_experiments:
        click.echo(f"logs           {logs_source(data)}")
    for variant, group in f.groupby("variant", sort=False):
        counts = group["verdict"].value_counts()
        click.echo(
            f"{variant:<15}" + ", ".join(f"{counts.get(k, 0)} {k}" for k in ("agrees", "partly",
                                                                            "disagrees"))
        )  # fmt: skip
    if result.recovery is not None:
        from quadimpact.studies.statistics import rate_text

        for variant, numbers in result.recovery.monte_carlo.items():
            click.echo(f"recovery       {variant}: {rate_text(numbers['success'])}")
        click.echo(f"time           {result.elapsed_s:.1f} s "
                   f"(recovery {result.recovery.elapsed_s:.1f} s)")  # fmt: skip
    else:
        click.echo(f"time           {result.elapsed_s:.1f} s")
