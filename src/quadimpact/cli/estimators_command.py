"""``quadimpact estimators``: the estimator study (``quadimpact.studies.estimators``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from quadimpact.cli.command_output import file_lines
from quadimpact.cli.options import (
    Count,
    allow_large_option,
    out_option,
    parallel_options,
    plugin_option,
    stoppable,
)

__all__ = ["estimators"]

#: The most trials of one study (each runs every estimator: six runs a trial).
MAX_TRIALS = 100_000

_SWITCHES = ("flight", "gain", "rate", "impact_noise", "in_loop", "initial_error", "sensors")


@click.command("estimators")
@out_option(
    "results/estimators",
    "Study folder: estimators.csv, trials.parquet, report.md, the figures; the sweep itself "
    "in sweep/ (run the same command again to resume it).",
)
@click.option(
    "--scenario", type=click.Choice(("impact", "authors-2016")), default="impact",
    show_default=True,
    help="'impact': quadimpact's impact trial (the authors' distribution) with the 'impact' "
    "sensors, the estimate in the loop; 'authors-2016': the authors' estimator study (hover, "
    "waypoint flight into the wall, recovery, 5 s after stage 4; their sensors; observers).",
)  # fmt: skip
@click.option(
    "--n", "n", type=Count(1, MAX_TRIALS, "trials"), default=250, show_default=True, metavar="N",
    help=f"Trials (1 to {MAX_TRIALS:,}), each run with every estimator.",
)  # fmt: skip
@click.option(
    "--initial-error", type=click.Choice(("none", "authors")), default="none",
    show_default=True,
    help="'authors': ZYX Euler errors N(0, (2, 2, 5) deg) and the gyro bias estimate 0.",
)  # fmt: skip
@click.option(
    "--loop", type=click.Choice(("default", "in", "out")), default="default",
    show_default=True,
    help="The estimate in the loop, or observers (the controller and detector read the "
    "truth); default: in for 'impact', out for 'authors-2016'.",
)  # fmt: skip
@click.option(
    "--back", "back", multiple=True, type=click.Choice(_SWITCHES), metavar="PART",
    help="With 'authors-2016': set a part of the replica back to quadimpact's trial "
    f"(repeatable): {', '.join(_SWITCHES)}.",
)  # fmt: skip
@click.option(
    "--hover", "hover_s", type=click.FloatRange(0.0, 60.0), default=4.0, show_default=True,
    metavar="S", help="'authors-2016': hover before the waypoint flight, s.",
)  # fmt: skip
@click.option(
    "--initial-bias", type=click.Choice(("true", "zero")), default=None,
    help="The gyro bias estimate's start, whatever the initial error. [default: zero with "
    "--initial-error authors, else the true bias]",
)  # fmt: skip
@click.option(
    "--seed", type=click.IntRange(0, 2**31 - 1), default=0, show_default=True,
    help="Seed of the trials' conditions and sensor draws.",
)  # fmt: skip
@allow_large_option
@parallel_options
@plugin_option
def estimators(
    out: Path,
    scenario: str,
    n: int,
    initial_error: str,
    loop: str,
    back: tuple[str, ...],
    hover_s: float,
    initial_bias: str | None,
    seed: int,
    allow_large: bool,
    workers: int | None,
    scheduler: str | None,
    no_progress: bool,
) -> None:
    """Every named estimator on the same seeded trials, beside the authors' figures.

    Runs ideal, the authors' CF (raw vectors), their 7-state EKF (transition
    as written, and correct) and quadimpact's complementary filter and EKF on N
    seeded trials of the scenario. Writes DIR/estimators.csv (per estimator:
    crash-phase RMS attitude error, mean, median, p90, sd over the trials; the
    not-crash mean; the success share with its 95 % interval when the estimate
    is in the loop), DIR/trials.parquet, the error over time around the first
    contact, the distribution per trial and DIR/report.md. Resumable like
    every sweep.

    \b
    Examples:
      quadimpact estimators --out results/estimators
      quadimpact estimators --scenario authors-2016 --n 250 --out results/est-2016
      quadimpact estimators --scenario authors-2016 --initial-error authors
      quadimpact estimators --scenario authors-2016 --back flight --back gain
    """
    from dataclasses import replace

    from quadimpact.studies.estimators.estimator_scenarios import Approach
    from quadimpact.studies.estimators.estimator_study import (
        EstimatorStudy,
        run_estimator_study,
        study_folder,
    )
    from quadimpact.sweep.runner import warm_pool
    from quadimpact.sweep.values import check_size

    study = EstimatorStudy(
        scenario=scenario,
        n=n,
        initial_error=initial_error,
        loop=loop,
        seed=seed,
        back=tuple(dict.fromkeys(back)),
        approach=replace(Approach(), hover_s=hover_s),
        initial_bias=initial_bias,
    )
    check_size(n * len(study.rows()), allow_large, f"--n {n}")  # before any planning
    study_folder(study, out).check()  # another study, or other options: refused at once
    warm_pool(workers, scheduler)
    with stoppable(out):
        result = run_estimator_study(
            study, out, workers=workers, scheduler=scheduler, progress=not no_progress,
            allow_large=allow_large,
        )  # fmt: skip
    click.echo(_summary(result, n))


def _summary(result: Any, n: int) -> str:
    """The closing lines: the ``n`` trials by estimators and their runs (time in s), each
    estimator's mean crash-phase and not-crash RMS attitude error (deg) and its recovered
    share (%, where the estimate is in the loop), the table, the report and the time (s)."""
    info = result.run_info
    lines = [
        f"trials    {n} x {len(result.rows)} estimators ({info['n_ran']} run now in "
        f"{info['elapsed_s']:.1f} s, {info['backend']})"
    ]
    for r in result.rows:
        share = ""
        if "success_share" in r:
            share = f"  recovered {100 * r['success_share']:.1f} %"
        lines.append(
            f"{r['estimator']:<15} crash {r['crash_rms_mean_deg']:6.2f} deg (mean), "
            f"not-crash {r['not_crash_rms_mean_deg']:6.2f} deg{share}"
        )
    lines += file_lines(result.out_dir / "estimators.csv", result.report, result.elapsed_s)
    return "\n".join(lines)
