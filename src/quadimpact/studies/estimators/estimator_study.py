"""``quadimpact estimators``: every named estimator on the same seeded trials of a scenario.

:class:`EstimatorStudy` names the scenario (``impact`` or ``authors-2016``),
the number of trials, the initial errors, whether the estimate is in the loop
and which parts of the replica are set back to quadimpact's trial
(:data:`~quadimpact.studies.estimators.estimator_scenarios.SWITCHES`).
:func:`run_estimator_study` runs trial x estimator through
:func:`quadimpact.sweep.run_sweep` into ``DIR/sweep/`` (resumable and
distributed like every study: the same command again resumes; a different
study in the same folder is refused) and writes into ``DIR``:

* ``trials.parquet``: one row per trial and estimator (the sweep's row with
  ``estimator_label`` and ``trial``);
* ``estimators.csv``: one row per estimator: the crash-phase RMS attitude
  error's mean, median, 90th percentile and standard deviation over the
  trials, the not-crash mean, the trials counted, and the success share
  with its 95 % Wilson interval when the estimate is in the loop;
* ``study.json``, the figures (the error over time around the first contact,
  mean over the first trials; the distribution per trial) and ``report.md``
  with the authors' figures beside the table.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from quadimpact import __version__
from quadimpact.errors import InputError
from quadimpact.results.files import atomic_write
from quadimpact.studies.estimators.estimator_scenarios import (
    CURVE_TRIALS,
    INITIAL_ERRORS,
    SCENARIOS,
    SWITCHES,
    Approach,
    estimator_rows,
    trial_scenario,
)
from quadimpact.studies.study_folder import SWEEP_DIR, TRIALS_PARQUET, StudyFolder, describe_run
from quadimpact.sweep import SweepSpec, read_runs, run_sweep
from quadimpact.sweep.values import check_size

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["EstimatorResult", "EstimatorStudy", "estimator_table", "run_estimator_study"]

ESTIMATORS_CSV = "estimators.csv"
LOOPS = ("default", "in", "out")


@dataclass(frozen=True)
class EstimatorStudy:
    """The study's options.

    Attributes
    ----------
    scenario : {"impact", "authors-2016"}
        quadimpact's impact trial with the ``impact`` sensors, or the authors' study.
    n : int
        Trials (each run with every estimator).
    initial_error : {"none", "authors"}
        The initial estimate exact, or the authors' errors (ZYX Euler N(0, (2, 2, 5)
        deg), the gyro bias estimate 0).
    loop : {"default", "in", "out"}
        The estimate in the loop or an observer; ``default``: in for ``impact``,
        out for ``authors-2016``. In the loop, the ``authors-2016`` flight has a
        position sensor (motion capture, position only: the waypoint flight is
        flown on the position estimate).
    seed : int
        Seed of the trials' conditions and sensor draws.
    back : tuple of str
        Parts of the replica set back to quadimpact's trial (``authors-2016``).
    approach : Approach
        The authors' flight before the wall (hover time, position loop).
    initial_bias : {"true", "zero"} or None
        The gyro bias estimate's start; None: 0 with the authors' initial errors,
        else the true bias.
    """

    scenario: str = "impact"
    n: int = 250
    initial_error: str = "none"
    loop: str = "default"
    seed: int = 0
    back: tuple[str, ...] = ()
    approach: Approach = field(default_factory=Approach)
    initial_bias: str | None = None

    def __post_init__(self) -> None:
        for name, value, known in (
            ("scenario", self.scenario, SCENARIOS),
            ("initial_error", self.initial_error, INITIAL_ERRORS),
            ("loop", self.loop, LOOPS),
            ("initial_bias", self.initial_bias, (None, "true", "zero")),
        ):
            if value not in known:
                choices = ", ".join(repr(k) for k in known)
                raise InputError(f"{name}: must be one of {choices} (got {value!r})")
        if not 1 <= self.n <= 100_000:
            raise InputError(f"n: must be in 1..100000 (got {self.n!r})")
        for b in self.back:
            if b not in SWITCHES:
                choices = ", ".join(SWITCHES)
                raise InputError(f"back: {b!r} is not one of {choices}")
        if self.back and self.scenario != "authors-2016":
            raise InputError("back: only with scenario 'authors-2016'")

    @property
    def in_loop(self) -> bool:
        """Whether the estimate is in the loop."""
        if self.loop != "default":
            return self.loop == "in"
        return self.scenario == "impact" or "in_loop" in self.back

    def rows(self) -> list[tuple[str, str, dict[str, Any]]]:
        """(label, estimator, parameters) of each estimator."""
        return estimator_rows(
            self.scenario, self.initial_error, frozenset(self.back), self.initial_bias
        )

    def scenario_dict(self, index: int) -> dict[str, Any]:
        """Trial ``index``'s scenario mapping (no estimator yet)."""
        d = trial_scenario(
            self.scenario, index, seed=self.seed, approach=self.approach,
            back=frozenset(self.back),
        )  # fmt: skip
        d["estimate_in_loop"] = self.in_loop
        if self.in_loop and d["kind"] == "flight":
            # the waypoint flight is flown on the estimate: it needs a position sensor
            # (motion capture, position only), or the integrated position drifts
            d["pose_sensor"] = {"attitude": False}
        return d

    def sweep_spec(self) -> SweepSpec:
        """Every trial with every estimator, trial by trial (run ``i``: trial ``i // m``)."""
        base = self.scenario_dict(0)
        runs = []
        for i in range(self.n):
            trial = self.scenario_dict(i)
            varying = {k: v for k, v in trial.items() if v != base.get(k)}
            for _, name, params in self.rows():
                runs.append({**varying, "estimator": name, "estimator_params": params})
        return SweepSpec(base=base, runs=runs, where="estimators")

    def options(self) -> dict[str, Any]:
        """The options as plain data (``study.json``)."""
        d = asdict(self)
        d["back"] = list(self.back)
        d["in_loop"] = self.in_loop
        return d


def estimator_table(runs: pd.DataFrame, study: EstimatorStudy) -> pd.DataFrame:
    """``trials.parquet``: the sweep's rows with ``estimator_label`` and ``trial``."""
    t = runs.sort_values("run_id").reset_index(drop=True)
    labels = [label for label, _, _ in study.rows()]
    m = len(labels)
    ids = t["run_id"].to_numpy()
    t["trial"] = ids // m
    t["estimator_label"] = [labels[i % m] for i in ids]
    return t


def _crash_counted(part: pd.DataFrame) -> np.ndarray:
    """Trials whose crash phase has samples and whose run did not fail."""
    crash = part["est_attitude_rms_crash_deg"].to_numpy(dtype=float)
    return np.isfinite(crash) & (part["status"].to_numpy() != "failed")


def summarise(table: pd.DataFrame, study: EstimatorStudy) -> list[dict[str, Any]]:
    """One row per estimator (``estimators.csv``; module docstring)."""
    from quadimpact.studies.statistics import rate

    out = []
    for label, name, _ in study.rows():
        part = table[table["estimator_label"] == label]
        ok = _crash_counted(part)
        crash = part["est_attitude_rms_crash_deg"].to_numpy(dtype=float)[ok]
        rest = part["est_attitude_rms_not_crash_deg"].to_numpy(dtype=float)[ok]
        rest = rest[np.isfinite(rest)]
        n = int(crash.size)
        sd = float(crash.std(ddof=1)) if n > 1 else math.nan
        row: dict[str, Any] = {
            "estimator": label,
            "crash_rms_mean_deg": float(crash.mean()) if n else math.nan,
            "crash_rms_median_deg": float(np.median(crash)) if n else math.nan,
            "crash_rms_p90_deg": float(np.quantile(crash, 0.9)) if n else math.nan,
            "crash_rms_sd_deg": sd,
            "not_crash_rms_mean_deg": float(rest.mean()) if rest.size else math.nan,
            "crash_rms_mean_ci95_deg": 1.96 * sd / math.sqrt(n) if n > 1 else math.nan,
            "registered_as": name,
            "trials": int(len(part)),
            "trials_counted": n,
            "no_contact": int(part["first_contact_s"].isna().sum()),
            "failed": int((part["status"] == "failed").sum()),
        }
        if study.in_loop:
            rec = part["recovered"].fillna(False).astype(bool)
            r = rate(int(rec.sum()), len(part))
            row.update(success_share=r.value, success_low=r.low, success_high=r.high)
        out.append(row)
    return out


def error_curves(
    study: EstimatorStudy, n_trials: int = CURVE_TRIALS
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Mean attitude error (deg) over time from the first contact (s), per estimator.

    The first ``n_trials`` trials are simulated again (their IMU records) and
    aligned at their first contact; the mean is over the trials still running
    at each time.
    """
    from quadimpact.inputs.scenarios import scenario_from_dict
    from quadimpact.simulation import simulate

    grid = np.round(np.arange(-1.0, 3.0 + 1e-9, 0.01), 6)
    curves: dict[str, np.ndarray] = {}
    for label, name, params in study.rows():
        total = np.zeros(grid.size)
        count = np.zeros(grid.size)
        for i in range(min(n_trials, study.n)):
            d = {**study.scenario_dict(i), "estimator": name, "estimator_params": params}
            result = simulate(scenario_from_dict(d))
            t_c = result.summary.get("first_contact_s")
            imu = result.imu
            if t_c is None or imu is None:
                continue
            t = imu["t_s"].to_numpy() - t_c
            e = imu["attitude_error_deg"].to_numpy()
            keep = np.isfinite(e)
            v = np.interp(grid, t[keep], e[keep], left=np.nan, right=np.nan)
            ok = np.isfinite(v)
            total[ok] += v[ok]
            count[ok] += 1
        with np.errstate(invalid="ignore", divide="ignore"):
            curves[label] = np.where(count > 0, total / np.maximum(count, 1), np.nan)
    return grid, curves


@dataclass
class EstimatorResult:
    """What :func:`run_estimator_study` produced."""

    out_dir: Path
    table: pd.DataFrame
    rows: list[dict[str, Any]]
    report: Path
    figures: list[Path]
    run_info: dict[str, Any]
    elapsed_s: float


#: The study's options as its command line names them (messages).
FLAGS = {"scenario": "--scenario", "n": "--n", "initial_error": "--initial-error", "loop": "--loop",
         "seed": "--seed", "back": "--back", "in_loop": "--loop", "approach.hover_s": "--hover",
         "initial_bias": "--initial-bias"}  # fmt: skip


def study_folder(study: EstimatorStudy, out_dir: str | os.PathLike[str]) -> StudyFolder:
    """The study's folder: its options decide its trials."""
    return StudyFolder(Path(out_dir), "estimators", study.options(), where="", flags=FLAGS)


def run_estimator_study(
    study: EstimatorStudy,
    out_dir: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    allow_large: bool = False,
) -> EstimatorResult:
    """Run the study into ``out_dir`` (see the module docstring) and report it.

    The folder is claimed (``study.json`` first, with the study's options)
    before any trial runs.

    Raises
    ------
    InputError
        A folder holding another study (or this study with other options), more
        runs than :data:`quadimpact.sweep.values.LARGE_RUNS` without
        ``allow_large``, bad workers or scheduler.
    """
    import pandas as pd

    from quadimpact.studies.estimators import estimator_report as report

    start = time.perf_counter()
    check_size(study.n * len(study.rows()), allow_large, f"--n {study.n}")
    spec = study.sweep_spec()
    folder = study_folder(study, out_dir)
    out = folder.claim()
    info = run_sweep(
        spec, out / SWEEP_DIR, workers=workers, scheduler=scheduler, progress=progress,
        load=False, allow_large=allow_large,
    )  # fmt: skip
    table = estimator_table(read_runs(out / SWEEP_DIR), study)
    atomic_write(out / TRIALS_PARQUET, lambda tmp: table.to_parquet(tmp, index=False))
    rows = summarise(table, study)
    frame = pd.DataFrame(rows)
    atomic_write(out / ESTIMATORS_CSV, lambda tmp: frame.to_csv(tmp, index=False))
    grid, curves = error_curves(study)
    paths = report.write_figures(table, study, grid, curves, out)
    elapsed = time.perf_counter() - start
    run = describe_run(info)
    description = {
        "quadimpact_version": __version__,
        "study": study.options(),
        "run": run,
        "sweeps": folder.sweep_history(run),
        "elapsed_s": elapsed,
        "estimators": rows,
    }
    md = report.render_report(study, rows, [p.relative_to(out) for p in paths], run)
    report_path = folder.finish(description, md)
    return EstimatorResult(out, table, rows, report_path, paths, info, elapsed)
