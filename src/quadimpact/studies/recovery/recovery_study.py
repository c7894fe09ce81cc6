"""The recovery Monte Carlo: its spec, its run and the trials table (docs/RECOVERY.md 8).

:class:`RecoveryStudy` is the authors' study: N impact trials (docs/RECOVERY.md
5.1) with roll uniform in +-15 deg, pitch in +-45 deg, yaw in +-45 deg and the
speed toward the wall in [0.5, 2.5] m/s. Trial ``i`` is a function of the
study's seed ``S`` and ``i`` alone: its inputs and its IMU seed are drawn from
its own PCG64 stream (``numpy.random.SeedSequence(S, spawn_key=(i,))``), so
the noise is independent from trial to trial, the first ``M`` trials of a
study of ``N > M`` trials are those of the study of ``M`` trials, and the
table is the same on one core, two or a Dask cluster.

:func:`run_study` runs a study (or a user's sweep whose base is an impact
trial) through :func:`quadimpact.sweep.run_sweep` into ``DIR/sweep/``
(resumable: the same command again resumes; a different one in the same
folder is refused), then writes into ``DIR``:

* ``trials.parquet``: one row per trial, the sweep's row (inputs, every
  summary metric; ``docs/RESULTS.md``) with the trial's ``roll_deg``,
  ``pitch_deg``, ``yaw_deg``, ``speed_m_s`` and ``seed`` whatever was swept,
  and the derived columns of :func:`quadimpact.studies.recovery.recovery_analysis.add_derived`
  (``inclination_deg = -pitch_deg``, ``inclination_bin``, ``speed_bin``,
  ``outcome_class``);
* ``study.json``: what ran;
* the figures (:mod:`quadimpact.studies.recovery.recovery_figures`) and ``report.md``;
* ``example/``: the example trial's result folder, with its viewer and
  animation.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from quadimpact import __version__
from quadimpact.errors import InputError
from quadimpact.inputs.scenarios import scenario_from_dict
from quadimpact.packing.constants import RPM
from quadimpact.results.costs import cost_ratio
from quadimpact.results.files import atomic_write
from quadimpact.studies.recovery.recovery_spec import (  # noqa: F401  (the spec, here too)
    DISTRIBUTION,
    SLEW_DONOR,
    TRIAL_FIELDS,
    RecoveryStudy,
    sample_trials,
)
from quadimpact.studies.slowest import slowest_trials
from quadimpact.studies.study_folder import (
    SWEEP_DIR,
    TRIALS_PARQUET,
    StudyFolder,
    describe_run,
)
from quadimpact.studies.trial_analysis import trial_inputs, trial_table  # shared, here too
from quadimpact.sweep import SweepSpec, read_runs, run_sweep
from quadimpact.sweep.values import check_size

if TYPE_CHECKING:
    import pandas as pd

    from quadimpact.studies.recovery.example_trial import EarlyExample
# pandas, the analysis and the example are imported where used: a script that imports this
# module has every worker of its sweeps import it again (multiprocessing runs the main
# script in each), which must not cost them pandas (0.4 s of CPU each)

__all__ = [
    "DISTRIBUTION",
    "RecoveryResult",
    "RecoveryStudy",
    "describe",
    "run_study",
    "run_trials",
    "sample_trials",
    "trial_inputs",
    "trial_table",
]


# ------------------------------------------------------------------- tables


def _first_runs(spec: SweepSpec, n: int) -> SweepSpec:
    """``spec`` itself, or, for a sweep of more than ``n`` trials, a sweep of its first ``n``."""
    if spec.trials is None or spec.n_runs <= n or spec.grid:
        return spec
    return SweepSpec(spec.base, trials={**spec.trials, "n": n}, where=spec.where)


def _check_trial_base(spec: SweepSpec, where: str) -> None:
    kind = spec.base.get("kind", "wall-approach")
    if kind != "impact-trial":
        raise InputError(
            f"{where}: base: kind: must be 'impact-trial' for the recovery study (got {kind!r})"
        )


# ----------------------------------------------------------------- describe
def describe(spec: SweepSpec, study: RecoveryStudy | None, table: pd.DataFrame) -> dict[str, Any]:
    """What ran, for ``study.json`` and the report: settings from the spec, facts from the table.

    The first run's validated scenario gives the settings common to the runs
    (friction, IMU, detection, slew limit, final time); the table's columns
    give the values actually in force in every run (model, switches, vehicle,
    controller, pre-impact behaviour, detection threshold).
    """
    import pandas as pd

    from quadimpact.inputs.resolve import control_rate_hz

    first = scenario_from_dict(spec.scenario_dict(0), where="recovery: run 0")
    vehicle = first.build_vehicle()
    imu = first.imu.resolved(vehicle.imu_position_m, control_rate_hz(first))

    def values(column: str) -> list[Any]:
        if column not in table:
            return []
        return [v for v in pd.unique(table[column]) if v is not None and v == v]

    switches = {
        c.removeprefix("model_options__"): values(c)
        for c in table.columns
        if c.startswith("model_options__")
    }
    slew = first.rotor_slew_limit_rad_s2
    if slew == "vehicle":
        rpm_s = vehicle.rotor_slew_limit_rpm_per_s
        slew_text = f"{rpm_s:,.0f} RPM/s (the vehicle's)" if rpm_s else "none"
    elif slew is None:
        slew_text = "none"
    else:
        slew_text = f"{slew / RPM:,.0f} RPM/s ({slew:.1f} rad/s², set by the study)"
    swept = sorted(set(spec.columns))
    return {
        "quadimpact_version": __version__,
        "source": "the authors' distribution" if study is not None else "a sweep file",
        "study": study.options() if study is not None else None,
        "sweep_file": spec.where if study is None else None,
        "n_trials": int(spec.n_runs),
        "swept": swept,
        "distribution": {k: list(v) for k, v in DISTRIBUTION.items()} if study else None,
        "vehicle": values("vehicle"),
        "model": values("model"),
        "model_options": switches,
        "controller": values("controller"),
        "pre_impact": values("pre_impact"),
        "detection_threshold_m_s2": values("detection_threshold_m_s2"),
        "detection": first.detection.model_dump(),
        "imu": {"preset": first.imu.preset, **imu.model_dump()},
        "estimator": first.estimator,
        "estimator_params": first.resolved_estimator_params().model_dump(mode="json"),
        "sensors": first.sensors,
        "magnetometer": first.magnetometer.model_dump() if first.magnetometer else None,
        "pose_sensor": first.pose_sensor.model_dump() if first.pose_sensor else None,
        "friction_coefficient": float(first.friction_coefficient),
        "slew_limit": slew_text,
        "rotor_speed_range_rpm": list(vehicle.rotor_speed_range_rpm)
        if vehicle.rotor_speed_range_rpm
        else None,
        "final_time_s": float(first.final_time_s),
        "start_distance_m": float(first.start_distance_m),
        "altitude_m": float(first.altitude_m),
        "ground": first.ground,
    }


# ---------------------------------------------------------------------- run
@dataclass
class RecoveryResult:
    """What :func:`run_study` produced."""

    out_dir: Path
    table: pd.DataFrame
    description: dict[str, Any]
    numbers: dict[str, Any]
    report: Path
    figures: list[Path]
    example_dir: Path | None
    run_info: dict[str, Any]
    elapsed_s: float
    warnings: list[str] = field(default_factory=list)


#: The recovery study's options as its command line names them (messages).
FLAGS = {
    "vehicle": "--vehicle", "n": "--n", "seed": "--seed", "model": "--model", "imu": "--imu",
    "pre_impact": "--pre-impact", "estimator": "--estimator", "sensors": "--sensors",
    "sweep": "--sweep", "policy": "--policy", "policy_sha256": "--policy",
}  # fmt: skip


def study_folder(study: RecoveryStudy | SweepSpec, out_dir: str | os.PathLike[str]) -> StudyFolder:
    """The study's folder: a study's options (a sweep's fingerprint) decide its trials.

    Raises
    ------
    InputError
        A sweep whose base is not an impact trial.
    """
    if isinstance(study, SweepSpec):
        _check_trial_base(study, study.where)
        identity: dict[str, Any] = {"sweep": study.fingerprint()}
    else:
        identity = study.options()
    return StudyFolder(Path(out_dir), "recovery", identity, where="", flags=FLAGS)


def run_trials(
    study: RecoveryStudy | SweepSpec,
    out_dir: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    allow_large: bool = False,
    on_placed: Callable[[], None] | None = None,
) -> tuple[SweepSpec, pd.DataFrame, dict[str, Any]]:
    """Run the trials into ``out_dir/sweep`` and write ``out_dir/trials.parquet``.

    The part of :func:`run_study` without figures, report and example; the
    folder is claimed (``study.json`` first) before any trial runs.
    ``allow_large``, ``on_placed``: as :func:`quadimpact.sweep.run_sweep`'s.

    Returns
    -------
    (spec, table, info)
        The sweep, the trials table (:func:`trial_table`) and
        :func:`quadimpact.sweep.run_sweep`'s run information.
    """
    spec = study if isinstance(study, SweepSpec) else study.sweep_spec()
    check_size(spec.n_runs, allow_large, spec.where)
    out = study_folder(study, out_dir).claim()
    info = run_sweep(
        spec, out / SWEEP_DIR, workers=workers, scheduler=scheduler, progress=progress,
        load=False, allow_large=allow_large, on_placed=on_placed,
    )  # fmt: skip
    table = _kept_table(out, info)
    if table is None:
        table = trial_table(read_runs(out / SWEEP_DIR), spec)
        atomic_write(out / TRIALS_PARQUET, lambda tmp: table.to_parquet(tmp, index=False))
    return spec, table, info


def _kept_table(out: Path, info: dict[str, Any]) -> pd.DataFrame | None:
    """``trials.parquet`` as it is, when nothing ran and it is newer than the sweep's table."""
    import pandas as pd

    trials, runs = out / TRIALS_PARQUET, out / SWEEP_DIR / "runs.parquet"
    if info["n_ran"] or not trials.is_file() or not runs.is_file():
        return None
    if trials.stat().st_mtime_ns < runs.stat().st_mtime_ns:
        return None
    try:
        return pd.read_parquet(trials)
    except (OSError, ValueError):
        return None


def run_study(
    study: RecoveryStudy | SweepSpec,
    out_dir: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    example: bool = True,
    animation: bool = True,
    allow_large: bool = False,
) -> RecoveryResult:
    """Run the recovery study into ``out_dir`` (see the module docstring) and report it.

    Parameters
    ----------
    study : RecoveryStudy or SweepSpec
        The authors' Monte Carlo with its options, or a user's sweep whose
        base is an impact trial.
    out_dir : path-like
        The study folder; its ``sweep/`` subfolder is the resumable sweep.
    workers, scheduler, progress, allow_large
        As :func:`quadimpact.sweep.run_sweep`.
    example : bool
        Run the example trial again with its files, figure and viewer.
    animation : bool
        Also write the example's animation (needs the ``viz`` extra).

    A rerun of a finished study with nothing left to run draws nothing again:
    it reads the table, and the figures, example and report are those already
    there.

    Raises
    ------
    InputError
        A sweep whose base is not an impact trial, a folder holding another
        study (or this study with other options), too many trials without
        ``allow_large``, bad workers or scheduler.
    """
    from quadimpact.studies.recovery import recovery_analysis as analysis
    from quadimpact.studies.recovery.example_trial import EarlyExample, beside

    start = time.perf_counter()
    spec = study if isinstance(study, SweepSpec) else study.sweep_spec()
    check_size(spec.n_runs, allow_large, spec.where)
    folder = study_folder(study, out_dir)
    out = folder.path
    # the example trial depends on the trials' inputs only: it runs beside the trials
    # when they run on other processes (a pool or Dask), else after them, here. It
    # starts once the sweep has placed its runs (the default sweep measures the idle
    # cores first, which the example would take)
    early: EarlyExample | None = None

    def start_example() -> None:
        nonlocal early
        first = trial_inputs(_first_runs(spec, analysis.EXAMPLE_AMONG))
        run_id = analysis.example_trial(first.reset_index())
        early = EarlyExample.start(spec.scenario_dict(run_id), run_id, out, animation)

    folder.claim()  # a folder or base it cannot use: refused before any run
    unchanged = folder.finished_description()
    early_example = example and beside(workers, scheduler) and unchanged is None
    try:
        spec, table, info = run_trials(
            spec if isinstance(study, SweepSpec) else study, out, workers=workers,
            scheduler=scheduler, progress=progress, allow_large=allow_large,
            on_placed=start_example if early_example else None,
        )  # fmt: skip
        numbers = analysis.summarise(table)
        if info["n_ran"] == 0 and unchanged is not None and _drawn(unchanged, out, example):
            return _as_before(unchanged, table, numbers, folder, info, start)
        description = _run_description(spec, study, table, info, folder)
        paths, example_dir, warnings = _draw(spec, table, numbers, description, out,
                                             early, example, animation)  # fmt: skip
    except BaseException:
        if early is not None:
            early.cancel()
        raise
    return _finish(folder, description, table, numbers, paths, example_dir, info, start, warnings)


def _run_description(
    spec: SweepSpec,
    study: RecoveryStudy | SweepSpec,
    table: pd.DataFrame,
    info: dict[str, Any],
    folder: StudyFolder,
) -> dict[str, Any]:
    """What ran (:func:`describe`) with how it ran (the sweep's run information ``info``),
    the folder's sweeps so far and the trials' CPU cost (``results.costs.cost_ratio``)."""
    description = describe(spec, study if isinstance(study, RecoveryStudy) else None, table)
    description["run"] = describe_run(info)
    description["sweeps"] = folder.sweep_history(description["run"])
    description["cost"] = cost_ratio(table)
    return description


def _draw(
    spec: SweepSpec,
    table: pd.DataFrame,
    numbers: dict[str, Any],
    description: dict[str, Any],
    out: Path,
    early: EarlyExample | None,
    example: bool,
    animation: bool,
) -> tuple[list[Path], Path | None, list[str]]:
    """The figures and the example trial (its folder, figure, viewer, animation)."""
    from quadimpact.studies.recovery import recovery_analysis as analysis
    from quadimpact.studies.recovery import recovery_figures as figures
    from quadimpact.studies.recovery.example_trial import check_example, write_example

    submit = early.submit if early is not None else None  # its idle process helps
    paths = figures.write_figures(table, out, numbers, submit=submit)
    example_dir, warnings = None, []
    if example:
        run_id = analysis.example_trial(table)
        if early is not None and early.run_id == run_id:
            example_dir, more, recovered = early.result()
            check_example(run_id, recovered, table)
        else:
            if early is not None:  # pragma: no cover (the same inputs, the same trial)
                early.cancel()
            example_dir, more = write_example(spec, run_id, table, out, animation)
        paths += more[0]
        warnings += more[1]
        description["example"] = {"run_id": run_id, **_row_inputs(table, run_id)}
    return paths, example_dir, warnings


def _finish(
    folder: StudyFolder,
    description: dict[str, Any],
    table: pd.DataFrame,
    numbers: dict[str, Any],
    paths: list[Path],
    example_dir: Path | None,
    info: dict[str, Any],
    start: float,
    warnings: list[str],
) -> RecoveryResult:
    """Write ``study.json`` and ``report.md``; say the warnings; the result."""
    from quadimpact.studies.recovery import recovery_report as report

    out = folder.path
    elapsed = time.perf_counter() - start
    description["elapsed_s"] = elapsed
    description["figures"] = [str(p.relative_to(out)) for p in paths]
    description["example_dir"] = None if example_dir is None else str(example_dir.relative_to(out))
    description["slowest_trials"] = slowest_trials(table, ("run_id", "arm", "seed"))
    md = report.render_report(description, numbers, [p.relative_to(out) for p in paths])
    report_path = folder.finish(description, md)
    for w in warnings:
        print(f"quadimpact: warning: {w}", file=sys.stderr)
    return RecoveryResult(
        out, table, description, numbers, report_path, paths, example_dir, info, elapsed, warnings
    )


def _drawn(held: dict[str, Any], out: Path, example: bool) -> bool:
    """Whether a finished study's figures (and example, if asked for) are all there."""
    names = list(held.get("figures") or [])
    if not names or (example and not held.get("example_dir")):
        return False
    return all((out / name).exists() for name in names)


def _as_before(
    held: dict[str, Any],
    table: pd.DataFrame,
    numbers: dict[str, Any],
    folder: StudyFolder,
    info: dict[str, Any],
    start: float,
) -> RecoveryResult:
    """The result of a finished study that had nothing left to run: its files as they are."""
    out = folder.path
    paths = [out / name for name in held["figures"]]
    example_dir = out / held["example_dir"] if held.get("example_dir") else None
    elapsed = time.perf_counter() - start
    return RecoveryResult(
        out, table, held, numbers, folder.report_path(), paths, example_dir, info, elapsed
    )


def _row_inputs(table: pd.DataFrame, run_id: int) -> dict[str, Any]:
    row = table.loc[table["run_id"] == run_id].iloc[0]
    return {name: row[name].item() for name in (*TRIAL_FIELDS, "inclination_deg")}
