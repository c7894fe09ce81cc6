"""``quadimpact recovery``: the recovery Monte Carlo to a study folder.

The study itself is :mod:`quadimpact.studies.recovery`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from quadimpact.cli.command_output import ran_text
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
from quadimpact.studies.recovery import DEFAULT_N, IMUS, MODELS, PRE_IMPACTS

__all__ = ["recovery"]

_STUDY_OPTIONS = (
    "vehicle", "n", "seed", "model", "imu", "pre_impact", "estimator", "sensors", "policy",
)  # fmt: skip


@click.command("recovery")
@out_option(
    "results/recovery",
    "Study folder: trials.parquet, report.md, the figures, example/; the sweep itself in "
    "sweep/ (run the same command again to resume it).",
)
@click.option(
    "--vehicle",
    metavar="navi|spiri|FILE",
    help="Bundled vehicle name or a vehicle TOML file. A vehicle without a rotor slew limit "
    "gets the Navi's (70,000 RPM/s). [default: navi]",
)
@click.option(
    "--n", "n", type=click.IntRange(min=1), metavar="N",
    help=f"Number of trials. [default: {DEFAULT_N}]",
)  # fmt: skip
@click.option(
    "--seed", type=click.IntRange(min=0), metavar="S",
    help="Seed of the trials' conditions and of their IMU seeds. [default: 0]",
)  # fmt: skip
@click.option(
    "--model", type=click.Choice(MODELS),
    help="Model variant (docs/VARIANTS.md): the default model, the authors' recovery "
    "simulator, or the default model with the authors' retuned pole law (rotors held until "
    "the detection). [default: default]",
)  # fmt: skip
@click.option("--imu", type=click.Choice(IMUS), help="IMU preset. [default: ideal]")
@click.option(
    "--pre-impact", "pre_impact", type=click.Choice(PRE_IMPACTS),
    help="Rotors before the detection: spin down at the slew limit, or hold. "
    "[default: spin-down; hold with --model pole-replica, the variant's own]",
)  # fmt: skip
@sensing_options(
    "State estimator the controller and the detector read (docs/ESTIMATION.md); a "
    "registered one is accepted too. [default: ideal]",
    SENSORS_HELP.replace("sensors:", "sensors (replaces --imu):"),
)
@policy_option
@click.option(
    "--sweep", "sweep_file", type=click.Path(dir_okay=False, path_type=Path),
    metavar="SWEEP.toml",
    help="Run this sweep file (its base an impact trial) instead of the authors' distribution.",
)  # fmt: skip
@click.option("--no-animation", is_flag=True, help="Do not write the example's animation.")
@click.option(
    "--no-example", is_flag=True,
    help="Do not write the example trial (example/: its files, figure, viewer and animation): "
    "the study is its trials, table, figures and report. A small study's largest fixed cost.",
)  # fmt: skip
@allow_large_option
@parallel_options
@plugin_option
def recovery(
    out: Path,
    vehicle: str | None,
    n: int | None,
    seed: int | None,
    model: str | None,
    imu: str | None,
    pre_impact: str | None,
    estimator: str | None,
    sensors: str | None,
    policy: str | None,
    sweep_file: Path | None,
    no_animation: bool,
    no_example: bool,
    allow_large: bool,
    workers: int | None,
    scheduler: str | None,
    no_progress: bool,
) -> None:
    """Monte Carlo of impact trials with the recovery controller.

    N impact trials (docs/RECOVERY.md) drawn from the authors' distribution:
    roll uniform in +-15 deg, pitch in +-45 deg, yaw in +-45 deg, speed toward
    the wall in [0.5, 2.5] m/s, each with its own IMU seed from (S, trial
    index). Writes DIR/trials.parquet (one row per trial: inputs, every
    metric, inclination_deg = -pitch, bins, outcome class), the success map,
    success by inclination and speed bin with 95 % Wilson intervals, the
    distributions of time to recover, height loss and drift, the example
    trial (figure, viewer, animation) and DIR/report.md. The table is the
    same on any number of cores or a Dask cluster.

    Ctrl-C (any number of times) or SIGTERM stops it at once and keeps every
    finished run (exit status 130, 143 for SIGTERM), saying how many; run the
    same command again to resume.

    \b
    Examples:
      quadimpact recovery --out results/recovery
      quadimpact recovery --vehicle spiri --n 2000 --imu noisy --out results/spiri-noisy
      quadimpact recovery --estimator ekf --sensors impact --out results/ekf-impact
      quadimpact recovery --sensors impact --estimator ekf --policy learned --out results/learned
      quadimpact recovery --sweep my-trials.toml --out results/mine
    """
    from quadimpact.results.files import check_out_dir
    from quadimpact.sweep.values import check_size

    if n is not None:  # refused at once, before anything is planned or loaded
        check_size(n, allow_large, f"--n {n}")
    check_out_dir(out, "recovery")
    values = (vehicle, n, seed, model, imu, pre_impact, estimator, sensors, policy)
    given = {k: v for k, v in zip(_STUDY_OPTIONS, values, strict=True) if v is not None}
    study = _options_study(given, sweep_file)
    _warm_unless_finished(study, out, workers, scheduler)
    from quadimpact.studies.recovery.recovery_study import run_study

    if sweep_file is not None:
        from quadimpact.sweep import load_sweep_file

        study = load_sweep_file(sweep_file)
        check_size(study.n_runs, allow_large, str(sweep_file))
    from quadimpact.studies.recovery.recovery_study import study_folder

    study_folder(study, out).check()  # another study, or other options: refused at once
    from quadimpact.simulation.plugin_check import check_first_run
    from quadimpact.sweep import SweepSpec

    check_first_run(study if isinstance(study, SweepSpec) else study.sweep_spec())  # plug-ins
    with stoppable(out):
        result = run_study(
            study, out, workers=workers, scheduler=scheduler, progress=not no_progress,
            example=not no_example, animation=not no_animation, allow_large=allow_large,
        )  # fmt: skip
    click.echo(_summary(result))


def _options_study(given: dict[str, Any], sweep_file: Path | None) -> Any:
    """The study of the options ``given`` (option -> value, those given), checked before
    anything heavy loads; None with a sweep file, which sets the trials itself. Refused, in
    one line naming the flag: --imu with --sensors, an option with --sweep, a bad value."""
    if "imu" in given and "sensors" in given:
        raise InputError("--imu and --sensors: give one or the other (a preset sets the IMU)")
    if sweep_file is not None:
        if given:
            flag = "--" + next(iter(given)).replace("_", "-")
            raise InputError(
                f"--sweep: the sweep file sets the trials; {flag} cannot be given with it"
            )
        return None
    from quadimpact.studies.recovery.recovery_spec import RecoveryStudy

    try:
        return RecoveryStudy(**given)
    except InputError as exc:  # "pre_impact: ..." -> "--pre-impact: ..." (the flag only)
        field, sep, rest = str(exc).partition(":")
        raise InputError(f"--{field.replace('_', '-')}{sep}{rest}") from None


def _warm_unless_finished(
    study: Any, out: Path, workers: int | None, scheduler: str | None
) -> None:
    """Start the pool's fork server (``sweep.runner.warm_pool``) unless ``out`` holds this
    very study (``study``, None for a sweep file) finished: it has nothing left to run."""
    from quadimpact.studies.study_folder import StudyFolder
    from quadimpact.sweep.runner import warm_pool

    # the pool's fork server imports the simulator and loads the kernel on another core
    # while this process imports the study: the trials' pool and the example trial's
    # process (docs/RECOVERY.md 8) then start from a warm server instead of waiting for it
    finished = study is not None and (
        StudyFolder(out, "recovery", study.options()).finished_description() is not None
    )
    if not finished:
        warm_pool(workers, scheduler)


def _summary(result) -> str:
    from quadimpact.results.costs import cost_text
    from quadimpact.studies.recovery.recovery_report import excluded_text
    from quadimpact.studies.statistics import rate_text

    info, numbers = result.run_info, result.numbers
    c = numbers["classes"]
    rows = [
        ("trials", f"{numbers['n']} ({ran_text(info)})"),
        ("success", f"{rate_text(numbers['success'])} (recovered / valid trials, 95 % Wilson)"),
        ("excluded", excluded_text(numbers)),
        ("if detected", f"{rate_text(numbers['success_detected'])} (recovered / detected impacts)"),
        (
            "other",
            f"recovered below ground level {c['recovered below ground level']} (not "
            f"successes), not detected {c['not detected']}, false detections "
            f"{c['false detection']}",
        ),
        ("cost", cost_text(result.description["cost"])),
        ("table", str(result.out_dir / "trials.parquet")),
        ("report", str(result.report)),
        ("time", f"{result.elapsed_s:.1f} s"),
    ]
    return "\n".join(f"{label:<12}{text}" for label, text in rows)
