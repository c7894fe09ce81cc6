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
from quadimpact.inputs.scenarios import ImpactTrial, scenario_from_dict
from quadimpact.results.costs import cost_ratio
from quadimpact.results.files import atomic_write, check_out_dir
from quadimpact.results.study_files import sweep_history, write_report, write_study_json
from quadimpact.simulation.packing import CONTROL_RATE_HZ, RPM
from quadimpact.studies.recovery.recovery_spec import (  # noqa: F401  (the spec, here too)
    DISTRIBUTION,
    SEED_LIMIT,
    SLEW_DONOR,
    TRIAL_FIELDS,
    RecoveryStudy,
    sample_trials,
    trial_rng,
)
from quadimpact.sweep import SweepSpec, read_runs, run_sweep

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

SWEEP_DIR = "sweep"
TRIALS_PARQUET = "trials.parquet"


# ------------------------------------------------------------------- tables
_TRIAL_DEFAULTS = {name: ImpactTrial.model_fields[name].default for name in TRIAL_FIELDS}


def trial_inputs(spec: SweepSpec) -> pd.DataFrame:
    """Roll, pitch, yaw (deg), speed (m/s) and IMU seed of every run of a sweep.

    From each run's scenario (base and swept values), the impact trial's
    defaults where neither sets a field. Indexed by ``run_id``.
    """
    import pandas as pd

    rows = []
    for run_id in range(spec.n_runs):
        scenario = spec.scenario_dict(run_id)
        rows.append({name: scenario.get(name, _TRIAL_DEFAULTS[name]) for name in TRIAL_FIELDS})
    frame = pd.DataFrame(rows, index=pd.RangeIndex(spec.n_runs, name="run_id"))
    for name in TRIAL_FIELDS[:-1]:
        frame[name] = frame[name].astype("float64")
    frame["seed"] = frame["seed"].astype("int64")
    return frame


def trial_table(runs: pd.DataFrame, spec: SweepSpec) -> pd.DataFrame:
    """``trials.parquet``: the sweep's rows, the trial inputs and the derived columns."""
    from quadimpact.studies.recovery import recovery_analysis as analysis

    table = runs.sort_values("run_id").reset_index(drop=True)
    inputs = trial_inputs(spec).reindex(table["run_id"].to_numpy())
    for name in TRIAL_FIELDS:
        table[name] = inputs[name].to_numpy()
    return analysis.add_derived(table)


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

    first = scenario_from_dict(spec.scenario_dict(0), where="recovery: run 0")
    vehicle = first.build_vehicle()
    imu = first.imu.resolved(vehicle.imu_position_m, CONTROL_RATE_HZ)

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


def _refuse_another_study(study: RecoveryStudy, spec: SweepSpec, out: Path) -> None:
    """Refuse a folder holding the recovery study with another ``n``, ``seed`` or options,
    saying which in the study's own terms (the sweep's check would only say "a different
    sweep"). Nothing is said of a folder without a readable ``sweep/sweep.json``: the
    sweep's own checks judge it."""
    import json

    from quadimpact.sweep.values import canonical

    path = out / SWEEP_DIR / "sweep.json"
    try:
        old = json.loads(path.read_text(encoding="utf-8"))["spec"]
        old_runs = list(old.get("runs") or [])
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return
    new = json.loads(canonical(spec.to_dict()))
    if old == new:
        return
    advice = "use another output folder, or delete this one to start over"
    if old.get("base") != new["base"] or not old_runs:
        raise InputError(
            f"{out}: holds a recovery study with other settings (vehicle, model, IMU, "
            f"estimator, sensors or pre-impact behaviour; see {path}); {advice}"
        )
    k = min(len(old_runs), len(new["runs"]))
    if old_runs[:k] == new["runs"][:k]:  # the first trials of a seed are the same for any n
        raise InputError(
            f"{out}: holds the recovery study of n = {len(old_runs)} trials (--n "
            f"{len(old_runs)}), not {study.n}: give --n {len(old_runs)} to resume or finish "
            f"it, or {advice}"
        )
    raise InputError(f"{out}: holds a recovery study of other trials (another --seed); {advice}")


def _claim_folder(spec: SweepSpec, out: Path) -> None:
    """Refuse a folder or sweep base the study cannot use; mark the folder as a study's."""
    check_out_dir(out, "recovery", where="")
    _check_trial_base(spec, spec.where)
    (out / SWEEP_DIR).mkdir(parents=True, exist_ok=True)  # a study's folder from now on


def run_trials(
    study: RecoveryStudy | SweepSpec,
    out_dir: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    on_placed: Callable[[], None] | None = None,
) -> tuple[SweepSpec, pd.DataFrame, dict[str, Any]]:
    """Run the trials into ``out_dir/sweep`` and write ``out_dir/trials.parquet``.

    The part of :func:`run_study` without figures, report and example.
    ``on_placed``: as :func:`quadimpact.sweep.run_sweep`'s.

    Returns
    -------
    (spec, table, info)
        The sweep, the trials table (:func:`trial_table`) and
        :func:`quadimpact.sweep.run_sweep`'s run information.
    """
    out = check_out_dir(Path(out_dir), "recovery", where="")
    if isinstance(study, SweepSpec):
        spec = study
        _check_trial_base(spec, spec.where)
    else:
        spec = study.sweep_spec()
        _refuse_another_study(study, spec, out)
    info = run_sweep(
        spec, out / SWEEP_DIR, workers=workers, scheduler=scheduler, progress=progress,
        load=False, on_placed=on_placed,
    )  # fmt: skip
    table = trial_table(read_runs(out / SWEEP_DIR), spec)
    atomic_write(out / TRIALS_PARQUET, lambda tmp: table.to_parquet(tmp, index=False))
    return spec, table, info


def run_study(
    study: RecoveryStudy | SweepSpec,
    out_dir: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    example: bool = True,
    animation: bool = True,
) -> RecoveryResult:
    """Run the recovery study into ``out_dir`` (see the module docstring) and report it.

    Parameters
    ----------
    study : RecoveryStudy or SweepSpec
        The authors' Monte Carlo with its options, or a user's sweep whose
        base is an impact trial.
    out_dir : path-like
        The study folder; its ``sweep/`` subfolder is the resumable sweep.
    workers, scheduler, progress
        As :func:`quadimpact.sweep.run_sweep`.
    example : bool
        Run the example trial again with its files, figure and viewer.
    animation : bool
        Also write the example's animation (needs the ``viz`` extra).

    Raises
    ------
    InputError
        A sweep whose base is not an impact trial, a folder holding a
        different study, bad workers or scheduler.
    """
    from quadimpact.studies.recovery import recovery_analysis as analysis
    from quadimpact.studies.recovery import recovery_figures as figures
    from quadimpact.studies.recovery import recovery_report as report
    from quadimpact.studies.recovery.example_trial import (
        EarlyExample,
        beside,
        check_example,
        write_example,
    )

    start = time.perf_counter()
    out = Path(out_dir)
    spec = study if isinstance(study, SweepSpec) else study.sweep_spec()
    if isinstance(study, RecoveryStudy):
        _refuse_another_study(study, spec, out)
    # the example trial depends on the trials' inputs only: it runs beside the trials
    # when they run on other processes (a pool or Dask), else after them, here. It
    # starts once the sweep has placed its runs (the default sweep measures the idle
    # cores first, which the example would take)
    early: EarlyExample | None = None

    def start_example() -> None:
        nonlocal early
        run_id = analysis.example_trial(trial_inputs(spec).reset_index())
        early = EarlyExample.start(spec.scenario_dict(run_id), run_id, out, animation)

    early_example = example and beside(workers, scheduler)
    if early_example:
        _claim_folder(spec, out)  # a folder or base it cannot use: refused before any run
    try:
        spec, table, info = run_trials(
            spec, out, workers=workers, scheduler=scheduler, progress=progress,
            on_placed=start_example if early_example else None,
        )  # fmt: skip
        options = study if isinstance(study, RecoveryStudy) else None
        description = describe(spec, options, table)
        run = {k: info[k] for k in ("n_runs", "n_already_done", "n_ran", "backend")}
        description["run"] = {**run, "sweep_s": float(info["elapsed_s"])}
        description["sweeps"] = sweep_history(out, description["run"])
        description["cost"] = cost_ratio(table)
        numbers = analysis.summarise(table)
        warnings: list[str] = []

        submit = early.submit if early is not None else None  # its idle process helps
        paths = figures.write_figures(table, out, numbers, submit=submit)
        example_dir = None
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
    except BaseException:
        if early is not None:
            early.cancel()
        raise
    elapsed = time.perf_counter() - start
    description["elapsed_s"] = elapsed
    write_study_json(out, description)
    md = report.render_report(description, numbers, [p.relative_to(out) for p in paths])
    report_path = write_report(out, md)
    for w in warnings:
        print(f"quadimpact: warning: {w}", file=sys.stderr)
    return RecoveryResult(
        out, table, description, numbers, report_path, paths, example_dir, info, elapsed, warnings
    )


def _row_inputs(table: pd.DataFrame, run_id: int) -> dict[str, Any]:
    row = table.loc[table["run_id"] == run_id].iloc[0]
    return {name: row[name].item() for name in (*TRIAL_FIELDS, "inclination_deg")}
