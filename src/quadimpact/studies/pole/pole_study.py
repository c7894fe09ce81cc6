"""The pole study's spec, its run on the sweep machinery and its trials table.

:class:`PoleStudy` is the authors' grid (docs/OBSTACLES.md 3) with options:
the pitch and offset grids, the baseline controller (the recovery
controller flies it until the detection), the pole (or any obstacle from a
file), the vehicle. :func:`run_pole_study` runs every trial through
:func:`quadimpact.sweep.run_sweep` into ``DIR/sweep/`` (resumable: the same
command again resumes; a different study in the same folder is refused) and
writes into ``DIR``:

* ``trials.parquet``: one row per trial and controller: the sweep's row
  (inputs, outcome, the recovery metrics, the first contact's bumper and
  normal, ``final_altitude_m``) with ``arm`` (``"baseline"``, ``"recovery"``
  and, when the study's model is a variant of the staged law such as
  ``pole-replica``, ``"recovery-default"``: the default law beside it),
  ``pitch_deg``, ``abs_pitch_deg``, ``lateral_offset_m``,
  ``height_lost_m`` (altitude at the start minus at the end), ``success``
  (``height_lost_m`` below :data:`SUCCESS_LOSS_M`) and ``pitch_band``;
* ``study.json``: what ran and the headline numbers;
* the figures (:mod:`quadimpact.studies.pole.pole_figures`), with a variant
  the example point's runs under both laws
  (:mod:`quadimpact.studies.pole.pole_laws`), and ``report.md``.
"""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from quadimpact import __version__
from quadimpact.errors import InputError, format_value
from quadimpact.inputs.policy_file import checked_policy, record_policy
from quadimpact.inputs.toml_files import read_toml_file
from quadimpact.inputs.vehicle import bundled_vehicles, load_vehicle
from quadimpact.inputs.world import obstacle_from
from quadimpact.results.files import atomic_write
from quadimpact.studies.slowest import slowest_trials
from quadimpact.studies.study_folder import SWEEP_DIR, TRIALS_PARQUET, StudyFolder, describe_run
from quadimpact.studies.trial_analysis import (  # the analysis the studies share, here too
    SUCCESS_LOSS_M,
    height_lost,
    pitch_bands,
    recovery_arm,
)
from quadimpact.sweep import SweepSpec, read_runs, run_sweep
from quadimpact.sweep.values import check_size

if TYPE_CHECKING:
    import pandas as pd
# pandas and the recovery analysis are imported where used: a script that imports this
# module has every worker of its sweeps import it again (multiprocessing runs the main
# script in each), which must not cost them pandas (0.4 s of CPU each)

__all__ = [
    "BASELINES",
    "MODELS",
    "SUCCESS_LOSS_M",
    "PoleResult",
    "PoleStudy",
    "pole_table",
    "run_pole_study",
    "summarise",
]

#: Baseline controllers (the recovery controller flies the same until it detects).
BASELINES = ("paper", "cascade-pid")
ARMS = ("baseline", "recovery")
#: The default law's recovery arm, run beside the recovery arm of a variant.
DEFAULT_LAW_ARM = "recovery-default"
#: Model variants of the recovery arm (docs/VARIANTS.md): the default, or the authors'
#: retuned pole law (docs/OBSTACLES.md 6.1).
MODELS = ("default", "classic", "pole-replica")


def _grid(start: float, stop: float, step: float, name: str) -> list[float]:
    """``start``, ``start + step``, ... to ``stop`` inclusive, rounded to 1e-9."""
    if not step > 0:
        raise InputError(f"{name}: the step must be > 0 (got {format_value(step)})")
    n = int(math.floor((stop - start) / step + 1e-9)) + 1
    if n < 1:
        raise InputError(f"{name}: empty range {start:g} to {stop:g}")
    return [round(start + k * step, 9) + 0.0 for k in range(n)]


def checked_obstacles(items: Any, where: str) -> list[dict[str, Any]]:
    """``[[obstacles]]`` tables, each checked (:func:`quadimpact.inputs.world.obstacle_from`).

    Raises
    ------
    InputError
        No table, or a bad one (``<where>: obstacle 1 ('pole'): radius_m: ...``).
    """
    if isinstance(items, (str, Mapping)) or not isinstance(items, (list, tuple)) or not items:
        raise InputError(f"{where}: must list at least one [[obstacles]] table")
    out = []
    for i, item in enumerate(items):
        name = item.get("name") if isinstance(item, Mapping) else None
        label = f"obstacle {i + 1}" + (f" ({name!r})" if isinstance(name, str) else "")
        try:
            obstacle_from(item, label)
        except ValueError as exc:
            raise InputError(f"{where}: {exc}") from None
        out.append(dict(item))
    return out


def check_sensing(estimator: str, sensors: str | None) -> None:
    """Refuse an unknown estimator or preset of sensors (one line naming the field).

    Raises
    ------
    InputError
        ``estimator: ...`` (an unregistered name) or ``sensors: must be one of ...``.
    """
    from quadimpact.inputs.estimators import estimator_entry
    from quadimpact.inputs.sensors import SENSOR_PRESETS

    estimator_entry(estimator)
    if sensors is not None and sensors not in SENSOR_PRESETS:
        known = ", ".join(repr(k) for k in SENSOR_PRESETS)
        raise InputError(f"sensors: must be one of {known} (got {format_value(sensors)})")


@dataclass(frozen=True)
class PoleStudy:
    """The pole grid and its options (defaults: the authors', docs/OBSTACLES.md 3).

    Attributes
    ----------
    vehicle : str
        Bundled vehicle name or a vehicle TOML file (default the Navi).
    pitch_max_deg, pitch_step_deg : float
        Pitch from 0 down to ``-pitch_max_deg`` in steps of ``pitch_step_deg``
        (negative pitch leans the top toward the pole): 45 and 1.
    offset_max_m, offset_step_m : float
        Sideways offset from ``-offset_max_m`` to ``+offset_max_m`` in steps of
        ``offset_step_m``: 0.35 and 0.01 m.
    baseline : {"paper", "cascade-pid"}
        The controller without recovery, holding the initial attitude and the
        altitude; the recovery controller flies it until the detection.
    model : {"default", "classic", "pole-replica"}
        The model variant of the recovery arm. ``"classic"``: the default law
        before the benchmark (issue #45). ``"pole-replica"``: the
        authors' retuned law (its pre-impact ``hold`` included), with a third
        arm, the default law's recovery (``"recovery-default"``), beside it;
        the baseline arm is the same in both.
    radius_m : float
        The pole's radius (a vertical infinite cylinder through the origin), m.
    obstacle_file : str or None
        A TOML file with ``[[obstacles]]`` (the first is the target) instead of
        the pole.
    obstacles : tuple of mappings or None
        ``[[obstacles]]`` tables given directly (the first is the target)
        instead of the pole; not with ``obstacle_file``.
    estimator : str
        The state estimator both arms read (docs/ESTIMATION.md): ``"ideal"``
        (the default, the true state), ``"complementary"``, ``"ekf"`` or a
        registered one.
    sensors : str or None
        A preset of sensors (docs/ESTIMATION.md: ``"ideal"``, ``"noisy"``,
        ``"impact"``, ``"indoor"``, ``"onboard"``, ``"authors-2016"``); ``None``: the ideal IMU.
        With a preset, each grid point draws its sensors' noise from a seed of
        its own (:meth:`point_seeds`), the same for every arm of the point.
    seed : int
        The seed of the points' own seeds (with ``sensors`` only), >= 0.
    speed_m_s, altitude_m, start_distance_m : float
        Speed along +X, initial altitude, CM distance from the obstacle's
        surface along +X at the start (0.3 m: X = -0.4 m for the pole).
    friction_coefficient : float
        Coulomb friction at the bumpers (0.3).
    final_time_s : float
        Length of a run, s.
    policy : str or None
        A learned residual on the recovery arm's law (docs/LEARNING.md 12):
        ``"learned"`` (the policy shipped with quadimpact) or a ``.npz`` policy
        file; ``None`` (the default): the law alone. The baseline arm (and a
        variant's default-law arm) fly without it.
    """

    vehicle: str = "navi"
    pitch_max_deg: float = 45.0
    pitch_step_deg: float = 1.0
    offset_max_m: float = 0.35
    offset_step_m: float = 0.01
    baseline: str = "paper"
    model: str = "default"
    radius_m: float = 0.1
    obstacle_file: str | None = None
    obstacles: tuple[Mapping[str, Any], ...] | None = None
    estimator: str = "ideal"
    sensors: str | None = None
    seed: int = 0
    speed_m_s: float = 2.0
    altitude_m: float = 2.0
    start_distance_m: float = 0.3
    friction_coefficient: float = 0.3
    final_time_s: float = 3.0
    policy: str | None = None
    _vehicle_ref: str = field(init=False, repr=False, compare=False)
    _obstacles: tuple = field(init=False, repr=False, compare=False)
    _policy_sha256: str = field(init=False, repr=False, compare=False, default="")

    def __post_init__(self) -> None:
        if self.baseline not in BASELINES:
            known = ", ".join(repr(b) for b in BASELINES)
            raise InputError(f"baseline: must be one of {known} (got {self.baseline!r})")
        if self.model not in MODELS:
            known = ", ".join(repr(m) for m in MODELS)
            raise InputError(f"model: must be one of {known} (got {format_value(self.model)})")
        for name in ("pitch_max_deg", "offset_max_m"):
            if not getattr(self, name) >= 0:
                raise InputError(f"{name}: must be >= 0 (got {getattr(self, name)!r})")
        if not self.radius_m > 0:
            raise InputError(f"radius_m: must be > 0 (got {self.radius_m!r})")
        check_sensing(self.estimator, self.sensors)
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise InputError(f"seed: must be an integer >= 0 (got {format_value(self.seed)})")
        self.pitches()
        self.offsets()
        load_vehicle(self.vehicle)
        ref = self.vehicle
        if ref not in bundled_vehicles():
            ref = str(Path(ref).resolve())
        object.__setattr__(self, "_vehicle_ref", ref)
        object.__setattr__(self, "_obstacles", tuple(self._read_obstacles()))
        if self.policy is not None:
            ref, sha = checked_policy(str(self.policy))
            object.__setattr__(self, "policy", ref)
            object.__setattr__(self, "_policy_sha256", sha)

    def _read_obstacles(self) -> list[dict[str, Any]]:
        if self.obstacles is not None:
            if self.obstacle_file is not None:
                raise InputError("obstacles: give obstacle_file or obstacles, not both")
            return checked_obstacles(self.obstacles, "obstacles")
        if self.obstacle_file is None:
            return [
                {
                    "kind": "cylinder",
                    "name": "pole",
                    "point_m": [0.0, 0.0, 0.0],
                    "axis": [0.0, 0.0, 1.0],
                    "radius_m": float(self.radius_m),
                }
            ]
        where = str(self.obstacle_file)
        data = read_toml_file(Path(self.obstacle_file), where)
        return checked_obstacles(data.get("obstacles"), f"{where}: obstacles")

    def pitches(self) -> list[float]:
        """Pitch values, deg: 0, -step, ... down to ``-pitch_max_deg``."""
        values = _grid(0.0, self.pitch_max_deg, self.pitch_step_deg, "pitch_step_deg")
        return [-v + 0.0 for v in values]

    def offsets(self) -> list[float]:
        """Offsets, m: ``-offset_max_m`` to ``+offset_max_m``."""
        m = self.offset_max_m
        return _grid(-m, m, self.offset_step_m, "offset_step_m")

    def base(self) -> dict[str, Any]:
        """The impact trial every run starts from (a scenario-file mapping)."""
        sensing: dict[str, Any] = {}
        if self.estimator != "ideal":
            sensing["estimator"] = self.estimator
        if self.sensors is not None:
            sensing["sensors"] = self.sensors
        return {
            **sensing,
            "kind": "impact-trial",
            "vehicle": self._vehicle_ref,
            "obstacles": [dict(o) for o in self._obstacles],
            "speed_m_s": float(self.speed_m_s),
            "altitude_m": float(self.altitude_m),
            "start_distance_m": float(self.start_distance_m),
            "friction_coefficient": float(self.friction_coefficient),
            "final_time_s": float(self.final_time_s),
            "roll_deg": 0.0,
            "yaw_deg": 0.0,
        }

    def arm_names(self) -> tuple[str, ...]:
        """The arms of each grid point, in run order (``trials.parquet``'s ``arm``)."""
        return ARMS if self.model == "default" else (*ARMS, DEFAULT_LAW_ARM)

    def arms(self) -> list[dict[str, Any]]:
        """The controllers as sweep runs: the baseline, then recovery flying it (in the
        study's model), then, for a variant, the default law's recovery."""
        arm = recovery_arm(None if self.model == "default" else self.model, self.baseline)
        if self.policy is not None:
            arm["controller_params"] = {"policy": self.policy}
        if self.model == "default":
            return [{"controller": self.baseline}, arm]
        return [
            {"controller": self.baseline, "model": "default"},
            arm,
            recovery_arm("default", self.baseline),
        ]

    def point_seeds(self) -> list[int]:
        """Each grid point's seed (pitch-major, as the sweep's runs), from :attr:`seed` and
        the point's index alone (:func:`quadimpact.sweep.trials.trial_draws`)."""
        from quadimpact.sweep.trials import trial_draws

        n = len(self.pitches()) * len(self.offsets())
        return [int(trial_draws(self.seed, i, {}, "seed")["seed"]) for i in range(n)]

    def sweep_spec(self, arms: list[dict[str, Any]] | None = None) -> SweepSpec:
        """The study as a sweep: pitch x offset grid, each point with every arm.

        ``arms`` (default :meth:`arms`): the runs of each point. With ``sensors``
        the points are listed as runs, each with its own seed (:meth:`point_seeds`);
        without, they are the sweep's grid (the same runs as before sensors existed).
        """
        arms = self.arms() if arms is None else arms
        grid = {"pitch_deg": self.pitches(), "lateral_offset_m": self.offsets()}
        if self.sensors is None:
            return SweepSpec(base=self.base(), grid=grid, runs=arms, where="pole")
        points = [(p, o) for p in grid["pitch_deg"] for o in grid["lateral_offset_m"]]
        runs = [
            {"pitch_deg": p, "lateral_offset_m": o, "seed": seed, **arm}
            for (p, o), seed in zip(points, self.point_seeds(), strict=True)
            for arm in arms
        ]
        return SweepSpec(base=self.base(), runs=runs, where="pole")

    def options(self) -> dict[str, Any]:
        """The options as plain data (``study.json``)."""
        d = asdict(self)
        d.pop("_vehicle_ref", None)
        d.pop("_obstacles", None)
        record_policy(d, self._policy_sha256)
        d["obstacles"] = [dict(o) for o in self._obstacles]
        # the sensing options only when set: a study of the ideal sensors keeps the identity
        # it had before they existed (its folder resumes)
        for name, unset in (("estimator", "ideal"), ("sensors", None)):
            if d[name] == unset:
                del d[name]
        if self.sensors is None:
            del d["seed"]  # the points' seeds draw nothing without sensors
        return d


# ------------------------------------------------------------------- tables


def pole_table(runs: pd.DataFrame, study: PoleStudy) -> pd.DataFrame:
    """``trials.parquet``: the sweep's rows and the study's columns (module docstring)."""

    t = runs.sort_values("run_id").reset_index(drop=True)
    names = np.array(study.arm_names(), dtype=object)
    t["arm"] = names[t["run_id"].to_numpy() % names.size]
    t["pitch_deg"] = t["pitch_deg"].astype(float)
    t["abs_pitch_deg"] = t["pitch_deg"].abs()
    t["lateral_offset_m"] = t["lateral_offset_m"].astype(float)
    t["height_lost_m"], t["success"] = height_lost(t, study.altitude_m)
    t["pitch_band"] = pitch_bands(t["abs_pitch_deg"].to_numpy())
    return t


def table_arms(table: pd.DataFrame) -> tuple[str, ...]:
    """The arms a trials table holds, in run order."""
    present = set(table["arm"])
    return tuple(a for a in (*ARMS, DEFAULT_LAW_ARM) if a in present)


def summarise(table: pd.DataFrame) -> dict[str, Any]:
    """The headline numbers: success per arm, per pitch band, how recovery fails and, with
    the default law's arm beside a variant's, where the two laws differ."""
    from quadimpact.studies.statistics import rate

    arms = table_arms(table)
    n_points = int((table["arm"] == ARMS[0]).sum())
    out: dict[str, Any] = {"n_points": n_points, "arms": {}, "bands": []}
    for arm in arms:
        part = table[table["arm"] == arm]
        r = rate(int(part["success"].sum()), len(part))
        contact = part["first_contact_s"].notna()
        out["arms"][arm] = {
            "success": asdict(r),
            "failed_runs": int((part["status"] == "failed").sum()),
            "contact": int(contact.sum()),
            "detected": int(part["detected"].fillna(False).astype(bool).sum()),
            "recovered": int(part["recovered"].fillna(False).astype(bool).sum()),
            "height_lost_median_m": float(np.nanmedian(part["height_lost_m"])),
        }
    bands = sorted(set(table["pitch_band"]), key=lambda b: float(b.split("-")[0]))
    for band in bands:
        row: dict[str, Any] = {"band": band}
        for arm in arms:
            part = table[(table["arm"] == arm) & (table["pitch_band"] == band)]
            row[arm] = asdict(rate(int(part["success"].sum()), len(part)))
        out["bands"].append(row)
    out["failures"] = failure_analysis(table)
    if DEFAULT_LAW_ARM in arms:
        from quadimpact.studies.pole.pole_laws import compare_laws

        out["laws"] = compare_laws(table)
    return out


def failure_analysis(table: pd.DataFrame) -> dict[str, Any]:
    """Where recovery fails and why: its failures against the baseline at the same point."""
    import pandas as pd

    from quadimpact.studies.pole.pole_laws import spread

    base = table[table["arm"] == "baseline"].set_index(["pitch_deg", "lateral_offset_m"])
    rec = table[table["arm"] == "recovery"].set_index(["pitch_deg", "lateral_offset_m"])
    rec = rec.reindex(base.index)
    b_ok = base["success"].to_numpy(dtype=bool)
    r_ok = rec["success"].to_numpy(dtype=bool)
    fail = rec[~r_ok]
    stage = np.zeros(len(fail), dtype=int)
    for k in (1, 2, 3, 4):
        stage = np.where(fail[f"t_stage{k}_s"].notna().to_numpy(), k, stage)

    abs_pitch = np.abs(np.asarray(fail.index.get_level_values(0), dtype=float))
    offsets = np.asarray(fail.index.get_level_values(1), dtype=float)
    tilt = pd.to_numeric(fail["max_tilt_deg"], errors="coerce").to_numpy(dtype=float)
    normals = [n for n in fail["first_contact_normal"] if isinstance(n, str)]
    lateral = [abs(json.loads(n)[1]) for n in normals]
    ok_normals = [n for n in rec[r_ok]["first_contact_normal"] if isinstance(n, str)]
    ok_lateral = [abs(json.loads(n)[1]) for n in ok_normals]
    return {
        "n_points": int(len(base)),
        "recovery_fails": int((~r_ok).sum()),
        "both_fail": int((~r_ok & ~b_ok).sum()),
        "recovery_saves": int((r_ok & ~b_ok).sum()),
        "recovery_loses": int((~r_ok & b_ok).sum()),
        "no_contact": int(fail["first_contact_s"].isna().sum()),
        "not_detected": int(fail["not_detected"].fillna(False).astype(bool).sum()),
        "stage_reached": {str(k): int((stage == k).sum()) for k in range(5)},
        "flipped": int(np.sum(tilt > 90.0)),
        "impacts_after_detection": int(
            (pd.to_numeric(fail["impacts_after_detection"], errors="coerce") > 0).sum()
        ),
        "impacts_after_detection_failures": spread(
            pd.to_numeric(fail["impacts_after_detection"], errors="coerce")
        ),
        "impacts_after_detection_successes": spread(
            pd.to_numeric(rec[r_ok]["impacts_after_detection"], errors="coerce")
        ),
        "max_tilt_deg_successes": spread(
            pd.to_numeric(rec[r_ok]["max_tilt_deg"], errors="coerce").to_numpy(dtype=float)
        ),
        "t_stage4_failures_s": spread(pd.to_numeric(fail["t_stage4_s"], errors="coerce")),
        "abs_pitch_deg": spread(abs_pitch),
        "abs_offset_m": spread(np.abs(offsets)),
        "max_tilt_deg": spread(tilt),
        "lateral_normal_failures": spread(lateral),
        "lateral_normal_successes": spread(ok_lateral),
        "normal_error_deg_failures": spread(pd.to_numeric(fail["normal_error_deg"])),
        "normal_error_deg_successes": spread(pd.to_numeric(rec[r_ok]["normal_error_deg"])),
    }


# ---------------------------------------------------------------------- run
@dataclass
class PoleResult:
    """What :func:`run_pole_study` produced."""

    out_dir: Path
    table: pd.DataFrame
    numbers: dict[str, Any]
    report: Path
    figures: list[Path]
    run_info: dict[str, Any]
    elapsed_s: float


#: The pole study's options as its command line names them (messages).
FLAGS = {
    "vehicle": "--vehicle", "pitch_max_deg": "--pitch-max", "pitch_step_deg": "--pitch-step",
    "offset_max_m": "--offset-max", "offset_step_m": "--offset-step", "baseline": "--baseline",
    "radius_m": "--radius", "obstacles": "--obstacle", "speed_m_s": "--speed",
    "model": "--model", "estimator": "--estimator", "sensors": "--sensors",
    "policy": "--policy", "policy_sha256": "--policy",
}  # fmt: skip


def study_folder(study: PoleStudy, out_dir: str | os.PathLike[str]) -> StudyFolder:
    """The study's folder: its options decide its runs."""
    return StudyFolder(Path(out_dir), "pole", study.options(), where="", flags=FLAGS)


def run_pole_study(
    study: PoleStudy,
    out_dir: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    allow_large: bool = False,
) -> PoleResult:
    """Run the pole study into ``out_dir`` (see the module docstring) and report it.

    The folder is claimed (``study.json`` first) before any run; a rerun of a
    finished study with nothing left to run draws nothing again.

    Raises
    ------
    InputError
        A folder holding another study (or this study with other options),
        more than :data:`quadimpact.sweep.values.LARGE_RUNS` runs without
        ``allow_large``, bad workers or scheduler.
    """
    from quadimpact.studies.pole import pole_figures as figures
    from quadimpact.studies.pole import pole_report as report

    start = time.perf_counter()
    spec = study.sweep_spec()
    check_size(spec.n_runs, allow_large, "pole")
    folder = study_folder(study, out_dir)
    out = folder.claim()
    unchanged = folder.finished_description(*figures.FIGURES)
    info = run_sweep(
        spec, out / SWEEP_DIR, workers=workers, scheduler=scheduler, progress=progress,
        load=False, allow_large=allow_large,
    )  # fmt: skip
    if info["n_ran"] == 0 and unchanged is not None and (out / TRIALS_PARQUET).is_file():
        import pandas as pd

        table = pd.read_parquet(out / TRIALS_PARQUET)
        paths = [out / name for name in unchanged.get("figures") or figures.FIGURES]
        elapsed = time.perf_counter() - start
        return PoleResult(out, table, unchanged["numbers"], folder.report_path(), paths, info,
                          elapsed)  # fmt: skip
    table = pole_table(read_runs(out / SWEEP_DIR), study)
    atomic_write(out / TRIALS_PARQUET, lambda tmp: table.to_parquet(tmp, index=False))
    numbers = summarise(table)
    paths = figures.write_figures(table, out, model=study.model)
    example = numbers.get("laws", {}).get("example")
    if example is not None:
        from quadimpact.studies.pole.pole_laws import write_law_examples

        paths += write_law_examples(
            spec, example, out, altitude_m=study.altitude_m, model=study.model
        )
    elapsed = time.perf_counter() - start
    run = describe_run(info)
    description = {
        "quadimpact_version": __version__,
        "study": study.options(),
        "grid": {"pitch_deg": len(study.pitches()), "lateral_offset_m": len(study.offsets())},
        "run": run,
        "sweeps": folder.sweep_history(run),
        "elapsed_s": elapsed,
        "numbers": numbers,
        "figures": [str(p.relative_to(out)) for p in paths],
        "slowest_trials": slowest_trials(table, ("run_id", "arm", "pitch_deg", "lateral_offset_m")),
    }
    md = report.render_report(description, numbers, [p.relative_to(out) for p in paths])
    report_path = folder.finish(description, md)
    return PoleResult(out, table, numbers, report_path, paths, info, elapsed)
