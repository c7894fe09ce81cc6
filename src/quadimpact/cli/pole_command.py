"""``quadimpact pole``: the pole study to a study folder (``quadimpact.studies.pole``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from quadimpact.cli.command_output import file_lines
from quadimpact.cli.options import (
    SENSORS_HELP,
    allow_large_option,
    out_option,
    parallel_options,
    plugin_option,
    policy_option,
    sensing_options,
    stoppable,
)
from quadimpact.errors import InputError

__all__ = ["pole"]


@click.command("pole")
@out_option(
    "results/pole",
    "Study folder: trials.parquet, report.md, the figures; the sweep itself in sweep/ (run "
    "the same command again to resume it).",
)
@click.option(
    "--vehicle", default="navi", show_default=True, metavar="navi|spiri|FILE",
    help="Bundled vehicle name or a vehicle TOML file.",
)  # fmt: skip
@click.option(
    "--pitch-max", "pitch_max_deg", type=float, default=45.0, show_default=True,
    metavar="DEG", help="Pitch from 0 down to -DEG (toward the pole).",
)  # fmt: skip
@click.option(
    "--pitch-step", "pitch_step_deg", type=float, default=1.0, show_default=True,
    metavar="DEG", help="Pitch step.",
)  # fmt: skip
@click.option(
    "--offset-max", "offset_max_m", type=float, default=0.35, show_default=True, metavar="M",
    help="Sideways offsets from -M to +M from the pole's centre line.",
)  # fmt: skip
@click.option(
    "--offset-step", "offset_step_m", type=float, default=0.01, show_default=True,
    metavar="M", help="Offset step.",
)  # fmt: skip
@click.option(
    "--baseline", type=click.Choice(("paper", "cascade-pid")), default="paper",
    show_default=True,
    help="The controller pair: this baseline without recovery, and the recovery controller "
    "flying it until the detection.",
)  # fmt: skip
@click.option(
    "--model", type=click.Choice(("default", "classic", "pole-replica")), default="default",
    show_default=True,
    help="Model variant of the recovery arm: default (docs/RECOVERY.md's staged law), classic "
    "(the default law before the benchmark, issue #45: earlier numbers) or pole-replica (the "
    "authors' retuned pole law, rotors held until the detection); with a variant the default "
    "law's recovery is flown beside it, a third arm, and the report puts the two laws side "
    "by side.",
)  # fmt: skip
@click.option(
    "--radius", "radius_m", type=float, default=0.1, show_default=True, metavar="M",
    help="Radius of the pole (vertical, infinite, through the origin).",
)  # fmt: skip
@click.option(
    "--obstacle", "obstacle_file", type=click.Path(dir_okay=False, path_type=Path),
    metavar="FILE.toml",
    help="A TOML file with [[obstacles]] (the first is the target) instead of the pole.",
)  # fmt: skip
@sensing_options(
    "State estimator both arms read (docs/ESTIMATION.md); a registered one is accepted too. "
    "[default: ideal]",
    SENSORS_HELP + " [default: the ideal IMU]",
)
@policy_option
@click.option(
    "--speed", "speed_m_s", type=float, default=2.0, show_default=True, metavar="M/S",
    help="Speed along +X.",
)  # fmt: skip
@allow_large_option
@parallel_options
@plugin_option
def pole(
    out: Path,
    vehicle: str,
    pitch_max_deg: float,
    pitch_step_deg: float,
    offset_max_m: float,
    offset_step_m: float,
    baseline: str,
    model: str,
    radius_m: float,
    obstacle_file: Path | None,
    estimator: str | None,
    sensors: str | None,
    policy: str | None,
    speed_m_s: float,
    allow_large: bool,
    workers: int | None,
    scheduler: str | None,
    no_progress: bool,
) -> None:
    """The authors' pole study: the Navi against a vertical pole, with and without recovery.

    A grid of pitches (0 to -45 deg, 1-deg steps) by sideways offsets from the
    pole's centre line (-0.35 to 0.35 m, 0.01-m steps): the vehicle starts at
    X = -0.4 m (0.3 m before a 0.1-m pole), 2 m up, at 2 m/s along +X, roll
    and yaw 0, friction 0.3, 3 s, no ground. Each point is flown by the
    baseline (the paper controller holding the attitude and altitude) and by
    the recovery controller flying that baseline until it detects the
    impact. Writes DIR/trials.parquet, the maps of height lost (crosses: 2 m
    or more, the authors' failure), success by pitch band with 95 % Wilson
    intervals, and DIR/report.md with the two side by side and where
    recovery fails. With --model pole-replica the recovery arm runs the
    authors' retuned pole law (docs/VARIANTS.md) and the default law's
    recovery is flown beside it: the report adds the two laws side by side,
    by pitch band, and one point where only the replica succeeds, drawn under
    each law. Resumable like every sweep (a study of another model needs
    another folder).

    \b
    Examples:
      quadimpact pole --out results/pole
      quadimpact pole --model pole-replica --out results/pole-replica
      quadimpact pole --pitch-step 5 --offset-step 0.05 --out results/pole-coarse
      quadimpact pole --estimator ekf --sensors impact --out results/pole-ekf
      quadimpact pole --sensors impact --estimator ekf --policy learned --out results/pole-learned
      quadimpact pole --obstacle box-corner.toml --out results/box
    """
    if scheduler is not None and workers is not None:
        raise InputError("--workers and --scheduler: give one or the other")
    from quadimpact.studies.pole.pole_study import FLAGS, PoleStudy, run_pole_study, study_folder
    from quadimpact.sweep.values import check_size

    try:
        study = PoleStudy(
            vehicle=vehicle,
            pitch_max_deg=pitch_max_deg,
            pitch_step_deg=pitch_step_deg,
            offset_max_m=offset_max_m,
            offset_step_m=offset_step_m,
            baseline=baseline,
            model=model,
            radius_m=radius_m,
            obstacle_file=None if obstacle_file is None else str(obstacle_file),
            estimator=estimator or "ideal",
            sensors=sensors,
            speed_m_s=speed_m_s,
            policy=policy,
        )
    except InputError as exc:  # "estimator: ..." -> "--estimator: ..." (the flag only)
        field, sep, rest = str(exc).partition(":")
        flag = FLAGS.get(field)
        raise InputError(f"{flag}{sep}{rest}" if flag else str(exc)) from None
    n_runs = 2 * len(study.pitches()) * len(study.offsets())
    check_size(n_runs, allow_large, f"--pitch-step {pitch_step_deg:g}, --offset-step "
               f"{offset_step_m:g}")  # fmt: skip
    folder = study_folder(study, out)
    folder.check()  # another study, or other options: refused at once
    from quadimpact.simulation.plugin_check import check_first_run

    check_first_run(study.sweep_spec())  # a plug-in estimator: its signature, one tick
    from quadimpact.sweep.runner import warm_pool

    if folder.finished_description() is None:  # a finished study has nothing left to run
        warm_pool(workers, scheduler)  # the pool's server warms up while the study loads
    with stoppable(out):
        result = run_pole_study(
            study, out, workers=workers, scheduler=scheduler, progress=not no_progress,
            allow_large=allow_large,
        )  # fmt: skip
    click.echo(_summary(result, model))


def _summary(result: Any, model: str) -> str:
    """The closing lines: the grid and its runs (time in s), each arm's share that loses
    less than 2 m (95 % Wilson), the table, the report and the study's time (s)."""
    from quadimpact.studies.statistics import rate_text

    arms = result.numbers["arms"]
    info = result.run_info
    rows = [
        f"grid      {result.numbers['n_points']} points x {len(arms)} controllers "
        f"({info['n_ran']} run now in {info['elapsed_s']:.1f} s, {info['backend']})",
        f"baseline  {rate_text(arms['baseline']['success'])} lose < 2 m",
        f"recovery  {rate_text(arms['recovery']['success'])} lose < 2 m"
        + ("" if model == "default" else f" ({model})"),
    ]
    if "recovery-default" in arms:
        rows.append(
            f"          {rate_text(arms['recovery-default']['success'])} lose < 2 m "
            "(the default law)"
        )
    rows += file_lines(result.out_dir / "trials.parquet", result.report, result.elapsed_s)
    return "\n".join(rows)
