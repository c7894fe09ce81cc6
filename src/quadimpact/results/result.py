"""The result of one simulation run, how it is written to a folder and read back.

The simulation builds a :class:`SimulationResult` (``quadimpact.simulation``);
this module only holds and writes it, so that results never depend on the
simulator.
"""

from __future__ import annotations

import math
import numbers
import os
import sys
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import pandas as pd

from quadimpact.errors import InputError, one_line
from quadimpact.results import files

__all__ = ["FIG5_PNG", "FIG6_PNG", "IMU_PNG", "SimulationResult", "read_result"]

#: Time-series columns a folder must have to be read back (plotted and drawn).
READ_COLUMNS: tuple[str, ...] = (
    "t_s", "x_m", "y_m", "z_m", "q0", "q1", "q2", "q3", "altitude_m",
    "roll_deg", "pitch_deg", "yaw_deg",
)  # fmt: skip
"""And the deflection and force columns of at least one contact feature."""
FIG5_PNG = "fig5.png"
FIG6_PNG = "fig6.png"
IMU_PNG = "imu.png"
ESTIMATE_PNG = "estimate.png"


class SimulationResult:
    """Everything one run produced.

    The tables are built when first read (or when the folder is written), so
    that a run whose summary is all that is wanted (a sweep) never builds a
    DataFrame.

    Attributes
    ----------
    summary : dict
        Run summary, the content of ``summary.json`` (metrics, status, ...).
    episodes : pandas.DataFrame
        Contact episodes (columns in docs/RESULTS.md).
    timeseries : pandas.DataFrame
        Sampled states (columns in docs/RESULTS.md; inertial NED, body FRD, SI,
        Euler angles in degrees).
    references : dict
        Controller references: ``roll_rad``, ``pitch_rad``, ``yaw_rad`` (rad,
        ZYX Euler) and ``altitude_m`` (m).
    scenario : object
        The input scenario (``None`` when read back from a folder).
    stats : dict
        Integrator counters (steps, rejected steps, right-hand-side calls, ...).
    imu : pandas.DataFrame or None
        The IMU samples (columns in docs/RESULTS.md; body FRD, SI); ``None``
        when the run had no IMU record.
    world : dict
        The world that ran, the content of ``scenario.json`` (docs/RESULTS.md):
        ``scenario`` (every field of the validated scenario), ``resolved`` (what
        its settings resolved to), ``vehicle`` (every field, overrides applied)
        and ``surfaces`` (the contact surfaces as packed). Empty when read
        from a folder written before ``scenario.json`` existed.
    """

    def __init__(
        self,
        summary: dict[str, Any],
        episodes: pd.DataFrame | None = None,
        timeseries: pd.DataFrame | None = None,
        references: dict[str, Any] | None = None,
        scenario: object = None,
        stats: dict[str, Any] | None = None,
        imu: pd.DataFrame | None = None,
        world: dict[str, Any] | None = None,
        *,
        tables: Callable[[str], Any] | None = None,
    ) -> None:
        self.summary = summary
        self.references = dict(references or {})
        self.scenario = scenario
        self.stats = dict(stats or {})
        self._tables: dict[str, Any] = {
            "episodes": episodes,
            "timeseries": timeseries,
            "imu": imu,
            "world": world,
        }
        self._build = tables

    def _table(self, name: str) -> Any:
        if self._tables[name] is None and self._build is not None:
            self._tables[name] = self._build(name)
        return self._tables[name]

    def _columns(self, name: str) -> Any:
        """The table ``name`` as built, or its raw columns (no DataFrame) if not built yet."""
        if self._tables[name] is None and self._build is not None:
            return self._build(name + "_columns")
        return self._tables[name]

    @property
    def episodes(self) -> pd.DataFrame:
        """Contact episodes (built on first use)."""
        return self._table("episodes")

    @episodes.setter
    def episodes(self, value: pd.DataFrame) -> None:
        self._tables["episodes"] = value

    @property
    def timeseries(self) -> pd.DataFrame:
        """Sampled states (built on first use)."""
        return self._table("timeseries")

    @timeseries.setter
    def timeseries(self, value: pd.DataFrame) -> None:
        self._tables["timeseries"] = value

    @property
    def imu(self) -> pd.DataFrame | None:
        """IMU samples (built on first use)."""
        return self._table("imu")

    @imu.setter
    def imu(self, value: pd.DataFrame | None) -> None:
        self._tables["imu"] = value

    @property
    def world(self) -> dict[str, Any]:
        """The world that ran (built on first use; empty when unknown)."""
        return self._table("world") or {}

    @world.setter
    def world(self, value: dict[str, Any]) -> None:
        self._tables["world"] = value

    def __repr__(self) -> str:
        s = self.summary
        parts = [f"status={s.get('status')!r}"]
        if s.get("response_type") is not None:
            parts.append(f"type={s.get('response_type')!r}")
        if s.get("delta_init_m") is not None:
            parts.append(f"delta_init={s['delta_init_m'] * 1e3:.2f} mm")
        if s.get("recovered"):
            parts.append("recovered")
        return f"SimulationResult({', '.join(parts)})"

    # ------------------------------------------------------------------
    def _scenario_value(self, key: str) -> Any:
        """``key`` from the scenario object, else from the world record's scenario."""
        if self.scenario is not None and hasattr(self.scenario, key):
            return getattr(self.scenario, key)
        sc = self.world.get("scenario")
        if isinstance(sc, Mapping):
            return sc.get(key)
        return None

    def vehicle(self) -> Any:
        """The vehicle that ran (overrides applied), from the world record; ``None`` without one.

        Returns
        -------
        quadimpact.inputs.vehicle.Vehicle or None
        """
        data = self.world.get("vehicle")
        if not isinstance(data, Mapping):
            return None
        from quadimpact.inputs.vehicle import Vehicle

        return Vehicle.model_validate(dict(data))

    def wall_x_m(self) -> float | None:
        """Inertial X of the wall plane (m), if known (wall-approach runs)."""
        for value in (
            self.summary.get("wall_x_m"),
            self.summary.get("wall_distance_m"),
            self._scenario_value("wall_distance_m"),
        ):
            if isinstance(value, numbers.Real) and math.isfinite(float(value)):
                return float(value)
        return None

    def plot_title(self) -> str | None:
        """Short title naming the run: the approach (heading, speed, inclination) of a wall
        approach, the initial attitude and speed of an impact trial, the surfaces of a flight;
        None when the folder does not say."""
        kind = self._scenario_value("kind")
        if kind == "flight":
            surfaces = self._scenario_value("surfaces") or []
            names = [str(s.get("name", "?")) if isinstance(s, Mapping) else str(getattr(
                s, "name", "?")) for s in surfaces]  # fmt: skip
            ground = self._scenario_value("ground")
            what = ", ".join(names) if names else "no surface"
            return f"flight: {what}; ground {ground}" if ground else f"flight: {what}"
        if kind == "impact-trial":
            values = [self._scenario_value(k) for k in ("roll_deg", "pitch_deg", "speed_m_s")]
            if all(isinstance(v, numbers.Real) for v in values):
                roll, pitch, speed = values
                return f"impact trial: roll {roll:g}°, pitch {pitch:g}°, {speed:g} m/s"
            return "impact trial"
        heading = self._scenario_value("heading_deg")
        speed = self._scenario_value("speed_m_s")
        incl = self._scenario_value("inclination_deg")
        if any(not isinstance(v, numbers.Real) for v in (heading, speed, incl)):
            return None
        return f"ψ = {heading:g}°, V_c = {speed:g} m/s, inclination = {incl:g}°"

    # ------------------------------------------------------------------
    def write(self, out_dir: str | os.PathLike[str]) -> Path:
        """Write the result folder and return its path.

        Files, in this order so that a plotting failure loses no data:
        ``summary.json`` (the summary plus ``references``, and the integrator
        counters ``integrator`` unless it already has those keys),
        ``scenario.json`` (the world record, when there is one),
        ``episodes.csv``, ``timeseries.parquet``, ``imu.parquet`` (when there
        are IMU samples), ``fig5.png``, ``fig6.png``, ``imu.png``, and
        ``estimate.png`` with an estimator other than ``ideal``. A figure
        that fails is not written; the failure is printed as a one-line
        warning on stderr and listed under ``plot_errors`` in ``summary.json``
        (and in ``self.summary``).

        The folder is written beside its place and moved there when complete
        (:func:`~quadimpact.results.files.staged_folder`): a failure (a full
        disk) leaves no half folder, and an existing run folder as it was.
        Written into a run folder, the new run replaces the old one: its
        files, and the pictures drawn from it (snapshots, animation, viewer,
        a log comparison: :data:`~quadimpact.results.files.DERIVED_FILES`),
        which showed the old run, are removed; other files are left. A folder
        holding anything else (a sweep, a report, files that are not
        quadimpact's) is refused.

        Raises
        ------
        InputError
            ``out_dir`` cannot be a run folder (one line: what it holds).
        OSError
            Writing failed (the folder is left as it was).
        """
        d = Path(out_dir)
        files.check_out_dir(d, "run", where="")
        with files.staged_folder(d, replaces=files.RUN_FILES + files.DERIVED_FILES) as stage:
            self._write_files(stage)
        return d

    def _write_files(self, d: Path) -> None:
        """Every file of the folder into ``d`` (a new, empty folder)."""
        summary = dict(self.summary)
        summary.pop("plot_errors", None)
        summary.setdefault("references", dict(self.references))
        if self.stats:
            summary.setdefault("integrator", dict(self.stats))
        files.write_summary_json(summary, d / files.SUMMARY_JSON)
        world = self.world
        if world:
            files.write_summary_json(world, d / files.SCENARIO_JSON)
        timeseries = self._columns("timeseries")
        imu = self._columns("imu")
        files.write_episodes_csv(self._columns("episodes"), d / files.EPISODES_CSV)
        files.write_timeseries_parquet(timeseries, d / files.TIMESERIES_PARQUET)
        has_imu = imu is not None and len(imu["t_s"]) > 0
        if has_imu:
            files.write_imu_parquet(imu, d / files.IMU_PARQUET)

        from quadimpact.results import figures as plots  # matplotlib only when drawing

        title = self.plot_title()
        jobs: tuple[tuple[str, Callable[[Path], Path]], ...] = (
            (FIG5_PNG, lambda p: plots.plot_fig5(timeseries, p, title=title)),
            (
                FIG6_PNG,
                lambda p: plots.plot_fig6(
                    timeseries, self.references, p, wall_x_m=self.wall_x_m(), title=title
                ),
            ),
        )
        if has_imu:
            jobs += (
                (
                    IMU_PNG,
                    lambda p: plots.plot_imu(imu, timeseries, p, summary=self.summary, title=title),
                ),
            )
            if self.summary.get("estimator") not in (None, "ideal") and "q0_hat" in imu:
                from quadimpact.results.estimate_figures import plot_estimate

                jobs += (
                    (
                        ESTIMATE_PNG,
                        lambda p: plot_estimate(imu, timeseries, p, self.summary, title=title),
                    ),
                )
        errors: list[str] = []
        for name, job in jobs:
            try:
                job(d / name)
            except Exception as exc:  # keep the data; report the figure failure
                (d / name).unlink(missing_ok=True)
                msg = f"{name}: {type(exc).__name__}: {exc}".replace("\n", " ")
                errors.append(msg)
                print(f"quadimpact: warning: plot failed: {msg}", file=sys.stderr)
        if errors:
            summary["plot_errors"] = errors
            self.summary["plot_errors"] = list(errors)
            files.write_summary_json(summary, d / files.SUMMARY_JSON)
        else:
            self.summary.pop("plot_errors", None)


#: The parts of ``scenario.json`` and the JSON kind each must have (absent: allowed).
_WORLD_PARTS = {"scenario": (dict, type(None)), "resolved": (dict,), "vehicle": (dict,),
                "surfaces": (list,)}  # fmt: skip
#: The keys every surface record has, by kind (``packing.world_block.surface_records``).
_SURFACE_KEYS = ("name", "point_m", "normal", "is_ground", "kind")
_SHAPE_KEYS = {
    "plane": _SURFACE_KEYS,
    "cylinder": ("name", "kind", "point_m", "axis", "radius_m", "length_m", "is_ground"),
    "box": ("name", "kind", "centre_m", "half_extents_m", "axes", "is_ground"),
}


def _component_keys(kind: str) -> tuple[str, ...] | None:
    """The record keys of a shape component's surfaces (``core/geometry/shapes.py``)."""
    from quadimpact.core.geometry.shapes import by_name

    comp = by_name(kind)
    return comp.record_keys() if comp is not None else None


def _check_world(world: dict, path: Path) -> None:
    """Refuse a ``scenario.json`` whose parts are not what quadimpact writes (one line)."""
    for key, kinds in _WORLD_PARTS.items():
        if key in world and not isinstance(world[key], kinds):
            want = "a JSON object" if dict in kinds else "a JSON array"
            raise InputError(
                f"{path}: {key}: must be {want} (got a JSON {_json_kind(world[key])}): the file "
                "is damaged or was not written by quadimpact"
            )
    for i, surface in enumerate(world.get("surfaces") or []):
        kind = surface.get("kind", "plane") if isinstance(surface, dict) else "plane"
        keys = _SHAPE_KEYS.get(kind) or _component_keys(kind) or _SURFACE_KEYS
        missing = [k for k in keys if not isinstance(surface, dict) or k not in surface]
        if missing:
            raise InputError(
                f"{path}: surfaces.{i}: must be a surface record with {', '.join(keys)} "
                f"(missing {', '.join(missing)}): the file is damaged or was not written by "
                "quadimpact"
            )


def read_result(directory: str | os.PathLike[str]) -> SimulationResult:
    """Load a result folder written by :meth:`SimulationResult.write`.

    Returns a :class:`SimulationResult` with ``summary``,
    ``episodes``, ``timeseries``, ``imu``, ``references`` and ``stats`` taken
    from the summary (``stats`` from its ``integrator`` table, or from the
    ``stats`` copy that older folders hold; empty dicts if
    absent) and ``world`` from ``scenario.json``
    (empty for a folder written before that file existed); ``scenario`` is
    ``None``. Enough to re-plot and redraw the folder.

    Raises
    ------
    FileNotFoundError
        No such folder.
    InputError
        A file that is missing or cannot be parsed, a ``summary.json`` that is
        not a JSON object, a time series without the columns of
        :data:`READ_COLUMNS`: one line naming the file.
    """
    d = Path(directory)
    if not d.is_dir():
        raise FileNotFoundError(f"result folder not found: {d}")
    summary = _read(d / files.SUMMARY_JSON, files.read_summary_json)
    if not isinstance(summary, dict):
        raise InputError(
            f"{d / files.SUMMARY_JSON}: must be a JSON object of summary fields "
            f"(got a JSON {_json_kind(summary)})"
        )
    episodes = _read(d / files.EPISODES_CSV, files.read_episodes_csv)
    timeseries = _read(d / files.TIMESERIES_PARQUET, files.read_timeseries_parquet)
    missing = [c for c in READ_COLUMNS if c not in timeseries.columns]
    features = files.feature_columns(timeseries.columns)
    if not features:
        missing.append("delta1_m")
    missing += [c for _, d, f in features for c in (d, f) if c not in timeseries.columns]
    if missing:
        more = f" and {len(missing) - 4} more" if len(missing) > 4 else ""
        shown = ", ".join(missing[:4]) + more
        raise InputError(
            f"{d / files.TIMESERIES_PARQUET}: missing column(s) {shown}: not a time series "
            "written by 'quadimpact run'"
        )
    imu_path = d / files.IMU_PARQUET
    imu = _read(imu_path, files.read_timeseries_parquet) if imu_path.is_file() else None
    world_path = d / files.SCENARIO_JSON
    world = _read(world_path, files.read_summary_json) if world_path.is_file() else {}
    if not isinstance(world, dict):
        raise InputError(f"{world_path}: must be a JSON object (got a JSON {_json_kind(world)})")
    _check_world(world, world_path)
    references = dict(summary.get("references") or {})
    stats = dict(summary.get("integrator") or summary.pop("stats", None) or {})
    return SimulationResult(
        summary=summary,
        episodes=episodes,
        timeseries=timeseries,
        references=references,
        scenario=None,
        stats=stats,
        imu=imu,
        world=world,
    )


def _json_kind(value: Any) -> str:
    """``list``, ``number``... : what a JSON value is, in JSON's words."""
    if isinstance(value, list):
        return "array"
    if isinstance(value, bool):
        return "true/false"
    if isinstance(value, (int, float)):
        return "number"
    return "string" if isinstance(value, str) else "null"


def _read(path: Path, reader: Callable[[Path], Any]) -> Any:
    """``reader(path)``, a file that cannot be read or parsed as one line naming it."""
    try:
        return reader(path)
    except FileNotFoundError:
        raise InputError(f"{path}: missing (not a folder written by 'quadimpact run')") from None
    except (OSError, ValueError) as exc:  # JSON and Arrow errors are ValueErrors
        reason = one_line(str(exc)).split(". ")[0]
        raise InputError(f"{path}: cannot be read ({type(exc).__name__}: {reason})") from None
