"""Table III: the seven real crashes, simulated at two sets of conditions, with their logs.

``run_experiments(out_dir)`` simulates each crash of ``crashes.TABLE3`` at
Table III's nominal conditions and at the conditions the authors matched in
their own simulations (``crashes.CONDITIONS``: their approach, climbing and
drifting into the wall), in the default model and in the paper replica with
the switches of the authors' crash runs (``crashes.REPLICA_CRASH_SWITCHES``),
and compares each run with its flight log where the log is available
(attitude and position over the first 0.3 s after the impact). For the
matched conditions it also runs the replica with each of its crash-run
switches off in turn, crash I-03's hand modification on, and both variants
with a zero scheduled rate read the old way (the motor held, not switched
off): what each changes (the changes: :mod:`quadimpact.studies.table3.switch_runs`).
A sensitivity sweep over Table III's stated uncertainty (heading +- 6.4 deg,
speed +- 0.01 m/s, inclination +- its own, uniform, seeded) gives the share of
each response type at the nominal conditions.

Where the log shows the wall contact, the crash is also simulated at the
log's own pre-impact estimates (heading, speed at the contact, roll and pitch
from the motion capture, :meth:`FlightLog.pre_impact`): once at the estimates
and over their uncertainty (uniform within ``LOG_RANGE_SIGMAS`` standard
uncertainties; the logs' part: :mod:`quadimpact.studies.table3.crash_logs`). The
log's own response type (classified from its motion) is given too.

It writes ``table3.csv`` (one row per crash; the stable interface:
``TABLE3_COLUMNS``, then ``EXTRA_COLUMNS``), ``table3_runs.csv`` (one row per
crash, conditions and variant: ``RUN_COLUMNS``), ``table3_switches.csv`` (the
switch runs: ``SWITCH_COLUMNS``), each also as Parquet, ``table3.md`` (the
report: :func:`quadimpact.studies.table3.table3_report.table3_markdown`), one folder
per crash (``crash_N/<conditions>-<model>/``: each run's files and its
comparison with the log; ``crash_N/log-conditions/``) and the sensitivity
sweeps (resumable).
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from quadimpact.experiments.crashes import (
    CONDITIONS,
    HEADING_UNCERTAINTY_DEG,
    SPEED_UNCERTAINTY_M_S,
    TABLE3,
    VARIANTS,
    Crash,
    scenario_file,
    scenario_path,
)
from quadimpact.experiments.spiri_mat import SpiriMatLog
from quadimpact.linalg import norm
from quadimpact.simulation import simulate
from quadimpact.simulation.response_types import RESPONSE_TYPES, closest_chaining
from quadimpact.studies.study_folder import StudyFolder
from quadimpact.studies.table3.crash_logs import (
    LOG_SENSITIVITY_RUNS,
    check_data_dir,
    log_conditions,
    log_sensitivity_spec,
    read_log,
)
from quadimpact.studies.table3.switch_runs import switch_changes
from quadimpact.studies.table3.table3_report import (  # noqa: F401 (the verdict rule, here as before)
    CHAINING_NOTE_MS,
    MOTION_RMS_DEG,
    TYPE_SHARE_PARTLY,
    VERDICT_RULE,
    crash_verdict,
    table3_markdown,
)
from quadimpact.sweep import SweepSpec, run_sweep

SENSITIVITY_RUNS = 300  # per crash
TABLE3_COLUMNS = (
    "crash",
    "heading_deg",
    "speed_m_s",
    "inclination_deg",
    "type_paper_experiment",
    "type_paper_simulation",
    "type_ours",
    "type_replica",
    *(f"share_{t}" for t in RESPONSE_TYPES),
    "attitude_rms_deg_0_3s",
)
#: The log's own estimates (empty where the log does not show the contact), the
#: log's own type, ours at the log's estimates (default model), the shares over
#: their uncertainty, that run's attitude error against the log and its deepest
#: bumper deflection, mm.
LOG_COLUMNS = (
    "log_heading_deg",
    "log_speed_m_s",
    "log_inclination_deg",
    "log_roll_deg",
    "log_pitch_deg",
    "type_log",
    "type_log_conditions",
    *(f"log_share_{t}" for t in RESPONSE_TYPES),
    "attitude_rms_log_conditions_deg_0_3s",
    "log_max_penetration_mm",
)
#: How each Euler angle moved in the first 0.3 s after the impact (signed largest
#: departure from its value at the impact, deg; roll and yaw unwrapped), in our
#: nominal run (default model) and in the log: where the motions differ.
MOTION_COLUMNS = tuple(
    f"{side}_{angle}_change_deg_0_3s"
    for angle in ("roll", "pitch", "yaw")
    for side in ("sim", "log")
)
#: The row's verdict (``agrees``, ``partly``, ``disagrees``: :func:`crash_verdict`) and why.
VERDICT_COLUMNS = ("verdict", "verdict_reason")
#: The authors' matched conditions of the crash (``crashes.Matched``: heading as
#: flown, rear first), our types there (default; replica with the crash-run
#: switches) and the default run's attitude error against the log.
MATCHED_COLUMNS = (
    "matched_heading_deg",
    "matched_speed_m_s",
    "matched_roll_deg",
    "matched_pitch_deg",
    "matched_inclination_deg",
    "matched_start_altitude_m",
    "matched_altitude_setpoint_m",
    "type_matched_ours",
    "type_matched_replica",
    "attitude_rms_matched_deg_0_3s",
)
#: Columns of ``table3.csv`` after ``TABLE3_COLUMNS``: the deepest bumper
#: deflection of our nominal run (default model, mm; beyond the bumper radius,
#: 110 mm, the model no longer holds), then ``LOG_COLUMNS``, ``MOTION_COLUMNS``,
#: ``VERDICT_COLUMNS`` and ``MATCHED_COLUMNS``.
EXTRA_COLUMNS = (
    "max_penetration_mm",
    *LOG_COLUMNS,
    *MOTION_COLUMNS,
    *VERDICT_COLUMNS,
    *MATCHED_COLUMNS,
)
#: ``table3_runs.csv``: one row per crash, conditions and variant. The conditions
#: as run (heading as flown, rear first; roll and pitch only where explicit;
#: start altitude and set-point), the type and the experiment's, the bumpers of
#: the initial impact and of each later one (JSON), delta_init and the first
#: episode's peak deflection (its bumper: 2, the leading one), the crash time
#: (from the start and after the first contact), the deepest deflection, the
#: state at the first contact (altitude, climb rate, sideways drift = inertial
#: V_Y, roll, pitch, yaw, the inclination toward the wall, the time since the
#: start), the errors against the log over the first 0.3 s
#: (attitude: RMS rotation angle; position: RMS of the X, Y, altitude
#: displacements since the impact), and the chaining decision closest to going
#: the other way (:func:`~quadimpact.simulation.response_types.closest_chaining`: its
#: margin in ms, negative an overlap, its bumper, and the type had it gone the
#: other way).
RUN_COLUMNS = (
    "crash", "conditions", "model",
    "heading_deg", "speed_m_s", "inclination_deg", "roll_deg", "pitch_deg",
    "start_altitude_m", "altitude_setpoint_m",
    "type", "type_experiment", "matches",
    "leading_bumpers", "subsequent_impacts", "delta_init_mm", "first_bumper", "first_peak_mm",
    "crash_time_s", "crash_after_contact_s", "max_penetration_mm",
    "contact_altitude_m", "contact_climb_m_s", "contact_drift_m_s",
    "contact_roll_deg", "contact_pitch_deg", "contact_yaw_deg", "contact_inclination_deg",
    "contact_after_start_s",
    "attitude_rms_deg_0_3s", "position_rms_mm_0_3s",
    "chaining_margin_ms", "chaining_bumper", "type_chaining_flipped",
)  # fmt: skip
#: ``table3_switches.csv``: the matched conditions with one change each
#: (:data:`SWITCH_CHANGES`; ``"as run"``: the run of ``table3_runs.csv``), with
#: the state at the first contact as in ``table3_runs.csv``.
SWITCH_COLUMNS = (
    "crash", "model", "change", "type", "type_experiment", "matches", "delta_init_mm",
    "first_peak_mm", "crash_time_s", "crash_after_contact_s",
    "contact_altitude_m", "contact_climb_m_s", "contact_drift_m_s", "contact_inclination_deg",
    "contact_after_start_s", "attitude_rms_deg_0_3s", "position_rms_mm_0_3s",
)  # fmt: skip


def sensitivity_spec(crash: Crash, n: int = SENSITIVITY_RUNS) -> SweepSpec:
    """Uniform sample over the crash's stated uncertainty (seeded by the crash number)."""
    u = crash.inclination_uncertainty_deg
    psi = scenario_file(crash.number).heading_deg  # flown rear first: Table III's - 180
    return SweepSpec(
        base=scenario_path(crash.number),
        sample={
            "n": n,
            "seed": crash.number,
            "ranges": {
                "heading_deg": [psi - HEADING_UNCERTAINTY_DEG, psi + HEADING_UNCERTAINTY_DEG],
                "speed_m_s": [crash.speed_m_s - SPEED_UNCERTAINTY_M_S,
                              crash.speed_m_s + SPEED_UNCERTAINTY_M_S],
                "inclination_deg": [crash.inclination_deg - u, crash.inclination_deg + u],
            },
        },
    )  # fmt: skip


def _shares(sweep: pd.DataFrame, prefix: str) -> dict[str, float]:
    """Share of each response type among a sweep's runs, as ``{prefix + type: share}``."""
    counts = sweep["response_type"].value_counts()
    return {f"{prefix}{t}": float(counts.get(t, 0)) / len(sweep) for t in RESPONSE_TYPES}


def _log_row(
    crash: Crash,
    log: SpiriMatLog | None,
    folder: Path,
    out: Path,
    samples: int,
    sweep_options: dict[str, Any],
) -> dict[str, Any]:
    """The ``LOG_COLUMNS`` of one crash (nan / None where not observable)."""
    from quadimpact.experiments.compare import log_response
    from quadimpact.experiments.logs_compare import attitude_rms_for_crash
    from quadimpact.inputs.scenarios import WallApproach

    row: dict[str, Any] = {c: math.nan for c in LOG_COLUMNS}
    row["type_log"] = row["type_log_conditions"] = None
    if log is None:
        return row
    row["type_log"] = log_response(log).type
    pre = log.pre_impact()
    fields = log_conditions(crash, pre)
    if fields is None:
        return row
    row.update(
        log_heading_deg=fields["heading_deg"],
        log_speed_m_s=fields["speed_m_s"],
        log_inclination_deg=round(pre.inclination_deg, 2),
        log_roll_deg=fields["roll_deg"],
        log_pitch_deg=fields["pitch_deg"],
    )
    r = simulate(WallApproach.model_validate(fields))
    r.write(folder / "log-conditions")
    row["type_log_conditions"] = r.summary["response_type"]
    row["attitude_rms_log_conditions_deg_0_3s"] = attitude_rms_for_crash(
        crash, r, log, folder / "log-conditions"
    )
    row["log_max_penetration_mm"] = 1e3 * r.summary["max_penetration_m"]
    spec = log_sensitivity_spec(crash, pre, samples) if samples > 0 else None
    if spec is not None:
        sweep = run_sweep(spec, out / "sensitivity-log" / f"crash_{crash.number}", **sweep_options)
        row.update(_shares(sweep, "log_share_"))
    return row


def _contact_state(result: Any) -> dict[str, float]:
    """Altitude, climb rate, sideways drift, attitude, inclination toward the wall and the time
    since the start, at the run's first contact (interpolated in the time series)."""
    from quadimpact.rotations import inclination_deg, quat_to_matrix

    keys = ("contact_altitude_m", "contact_climb_m_s", "contact_drift_m_s",
            "contact_roll_deg", "contact_pitch_deg", "contact_yaw_deg",
            "contact_inclination_deg", "contact_after_start_s")  # fmt: skip
    t_c = result.summary.get("first_contact_s")
    if t_c is None:
        return dict.fromkeys(keys, math.nan)
    ts = result.timeseries
    t = ts["t_s"].to_numpy()
    cols = ("altitude_m", "vz_m_s", "vy_m_s", "roll_deg", "pitch_deg", "yaw_deg")
    values = [float(np.interp(t_c, t, ts[c].to_numpy())) for c in cols]
    values[1] = -values[1]  # climb: -V_Z (NED)
    q = np.array([np.interp(t_c, t, ts[c].to_numpy()) for c in ("q0", "q1", "q2", "q3")])
    values.append(float(inclination_deg(quat_to_matrix(q / norm(q)))))
    values.append(float(t_c - t[0]))
    return dict(zip(keys, values, strict=True))


def run_record(
    crash: Crash, conditions: str, model: str, result: Any, comparison: Any
) -> dict[str, Any]:
    """One row of ``table3_runs.csv`` (:data:`RUN_COLUMNS`) from a crash's run."""
    from quadimpact.experiments.logs_compare import attitude_rms, position_rms_mm

    s = result.summary
    scenario = result.scenario
    episodes = result.episodes
    crash_t = s["crash_time_s"]
    contact = s["first_contact_s"]
    first = episodes.sort_values(["t_start_s", "bumper"]).iloc[0] if len(episodes) else None
    chain = closest_chaining(episodes, crash_t is not None)
    return {
        "crash": crash.number,
        "conditions": conditions,
        "model": model,
        "heading_deg": scenario.heading_deg,
        "speed_m_s": scenario.speed_m_s,
        "inclination_deg": scenario.inclination_deg,
        "roll_deg": scenario.roll_deg,
        "pitch_deg": scenario.pitch_deg,
        "start_altitude_m": scenario.start_altitude_m
        if scenario.start_altitude_m is not None
        else scenario.altitude_m,
        "altitude_setpoint_m": scenario.altitude_m,
        "type": s["response_type"],
        "type_experiment": crash.type_experiment,
        "matches": s["response_type"] == crash.type_experiment,
        "leading_bumpers": json.dumps(s["leading_bumpers"]),
        "subsequent_impacts": json.dumps(s["subsequent_impacts"]),
        "delta_init_mm": _mm(s["delta_init_m"]),
        "first_bumper": None if first is None else int(first["bumper"]),
        "first_peak_mm": math.nan if first is None else 1e3 * float(first["peak_delta_m"]),
        "crash_time_s": math.nan if crash_t is None else crash_t,
        "crash_after_contact_s": math.nan if crash_t is None or contact is None
        else crash_t - contact,
        "max_penetration_mm": _mm(s["max_penetration_m"]),
        **_contact_state(result),
        "attitude_rms_deg_0_3s": attitude_rms(comparison),
        "position_rms_mm_0_3s": position_rms_mm(comparison),
        "chaining_margin_ms": math.nan if chain is None else 1e3 * chain["margin_s"],
        "chaining_bumper": None if chain is None else chain["bumper"],
        "type_chaining_flipped": None if chain is None else chain["type_flipped"],
    }  # fmt: skip


def _mm(x: float | None) -> float:
    return math.nan if x is None else 1e3 * x


def switch_records(
    crash: Crash, log: SpiriMatLog | None, runs: dict[tuple[str, str], Any]
) -> list[dict[str, Any]]:
    """The rows of ``table3_switches.csv`` (:data:`SWITCH_COLUMNS`) of one crash.

    ``runs``: the crash's runs by (conditions, model), with their comparisons:
    the matched ones are the ``"as run"`` rows.
    """
    from quadimpact.experiments.compare import compare

    rows = []
    for model in VARIANTS:
        result, comparison = runs[("matched", model)]
        todo: list[tuple[str, Any, Any]] = [("as run", result, comparison)]
        for change, scenario in switch_changes(crash, model):
            r = simulate(scenario)
            c = None if log is None else compare(r, log, classify_log=False)
            todo.append((change, r, c))
        for change, r, c in todo:
            record = {**run_record(crash, "matched", model, r, c), "change": change}
            rows.append({k: record[k] for k in SWITCH_COLUMNS})
    return rows


def crash_task(
    crash: Crash,
    log: SpiriMatLog | None,
    out: Path,
    samples: int = SENSITIVITY_RUNS,
    log_samples: int = LOG_SENSITIVITY_RUNS,
    sweep_options: dict[str, Any] | None = None,
) -> tuple[dict[str, Any], float]:
    """One crash's runs, files and sweeps in ``out``: its row of Table III and its wall time, s.

    The piece of work a study hands to a process
    (:func:`quadimpact.sweep.tasks.run_tasks`); ``sweep_options`` go to its
    sweeps (default: in this process, no progress). The row also carries the
    crash's rows of ``table3_runs.csv`` and ``table3_switches.csv`` (keys
    ``"runs"`` and ``"switches"``), which :func:`write_table3` takes out.
    """
    from quadimpact.experiments.logs_compare import attitude_rms

    sweep_options = sweep_options or {"workers": 1, "scheduler": None, "progress": False}
    start = time.perf_counter()
    folder = out / f"crash_{crash.number}"
    runs, records = _crash_runs(crash, log, folder)
    shares: dict[str, float] = {f"share_{t}": math.nan for t in RESPONSE_TYPES}
    if samples > 0:
        sweep = run_sweep(
            sensitivity_spec(crash, samples),
            out / "sensitivity" / f"crash_{crash.number}",
            **sweep_options,
        )
        shares = _shares(sweep, "share_")
    nominal, comparison = runs[("nominal", "default")]
    row = {
        "crash": crash.number,
        "heading_deg": crash.heading_deg,
        "speed_m_s": crash.speed_m_s,
        "inclination_deg": crash.inclination_deg,
        "type_paper_experiment": crash.type_experiment,
        "type_paper_simulation": crash.type_paper_simulation,
        "type_ours": nominal.summary["response_type"],
        "type_replica": runs[("nominal", "paper-replica")][0].summary["response_type"],
        **shares,
        "attitude_rms_deg_0_3s": attitude_rms(comparison),
        "max_penetration_mm": 1e3 * nominal.summary["max_penetration_m"],
        **_log_row(crash, log, folder, out, log_samples, sweep_options),
        **_motion_changes(comparison),
        **_matched_columns(crash, runs),
    }
    row["verdict"], row["verdict_reason"] = crash_verdict(row)
    row["runs"] = records
    row["switches"] = switch_records(crash, log, runs)
    return row, time.perf_counter() - start


def _crash_runs(
    crash: Crash, log: SpiriMatLog | None, folder: Path
) -> tuple[dict[tuple[str, str], Any], list[dict[str, Any]]]:
    """The crash's runs at each set of conditions in each variant, each written to
    ``folder/<conditions>-<model>`` with its comparison with the ``log`` (None without a
    log): the (run, comparison) pairs by (conditions, model), and their rows of
    ``table3_runs.csv`` (:func:`run_record`)."""
    from quadimpact.experiments.logs_compare import compare_crash

    runs: dict[tuple[str, str], Any] = {}
    records = []
    for conditions in CONDITIONS:
        for model in VARIANTS:
            r = simulate(crash.scenario(model, conditions))
            name = f"{conditions}-{model}"
            r.write(folder / name)
            c = compare_crash(
                crash,
                r,
                log,
                folder / name,
                title=f"{conditions} conditions, {model}",
                classify_log=False,
            )
            runs[(conditions, model)] = (r, c)
            records.append(run_record(crash, conditions, model, r, c))  # fmt: skip
    return runs, records


def _motion_changes(comparison: Any) -> dict[str, float]:
    """How much roll, pitch and yaw change (deg) over the first 0.3 s after the impact, in
    the run and in the log (:data:`MOTION_COLUMNS`; NaN without a ``comparison``)."""
    motion = {c: math.nan for c in MOTION_COLUMNS}
    if comparison is not None:
        for angle, (sim, logged) in comparison.departures(0.3).items():
            motion[f"sim_{angle}_change_deg_0_3s"] = sim
            motion[f"log_{angle}_change_deg_0_3s"] = logged
    return motion


def _matched_columns(crash: Crash, runs: dict[tuple[str, str], Any]) -> dict[str, Any]:
    """The crash's matched conditions (heading, speed, roll, pitch, inclination in deg and
    m/s; the altitude's start and set-point in m) and its matched runs' types in both
    variants and attitude error against the log (deg RMS over 0.3 s, default model)."""
    from quadimpact.experiments.logs_compare import attitude_rms

    m = crash.matched
    return {
        "matched_heading_deg": m.heading_deg,
        "matched_speed_m_s": m.speed_m_s,
        "matched_roll_deg": m.roll_deg,
        "matched_pitch_deg": m.pitch_deg,
        "matched_inclination_deg": m.inclination_deg,
        "matched_start_altitude_m": m.altitude_at_start_m,
        "matched_altitude_setpoint_m": m.altitude_setpoint_m,
        "type_matched_ours": runs[("matched", "default")][0].summary["response_type"],
        "type_matched_replica": runs[("matched", "paper-replica")][0].summary["response_type"],
        "attitude_rms_matched_deg_0_3s": attitude_rms(runs[("matched", "default")][1]),
    }


def run_experiments(
    out_dir: str | Path,
    *,
    data_dir: str | Path | None = None,
    samples: int = SENSITIVITY_RUNS,
    log_samples: int = LOG_SENSITIVITY_RUNS,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = False,
) -> pd.DataFrame:
    """Simulate the seven crashes and write Table III (see the module docstring).

    Parameters
    ----------
    out_dir : path
        Output folder (created).
    data_dir : path, optional
        The data folder holding ``spiri-crash-set-1/`` (default: found by
        :func:`quadimpact.experiments.logs.data_dir`); without it the log
        columns stay empty. A folder given here that holds none of the logs
        is an input error (:func:`check_data_dir`), raised before any run.
    samples, log_samples : int
        Runs per crash over Table III's uncertainty, and over the log
        estimates' uncertainty (0: none).
    workers : int, optional
        Local processes (default: the cores this process may use). With more
        than one, the crashes run one per process
        (:func:`quadimpact.sweep.tasks.run_tasks`), each with its sweeps in
        its own process; with 1, one after the other in this process. The
        table is the same either way.
    scheduler : str, optional
        A Dask scheduler's address: the crashes then run one after the other
        here and their sweeps on the cluster.
    progress : bool
        Say on stderr what runs (and show the sweeps' progress when the
        crashes run here).

    Returns
    -------
    pandas.DataFrame
        The table written to ``table3.csv``.
    """
    from quadimpact.sweep.runner import _resolve_workers
    from quadimpact.sweep.tasks import run_tasks

    folder, logs = prepare_experiments(out_dir, data_dir, samples, log_samples)
    out = folder.path
    n = len(TABLE3)
    processes = 1 if scheduler is not None else _resolve_workers(workers)
    if processes > 1:  # one crash per process, each with its sweeps in that process
        sweep_options = {"workers": 1, "scheduler": None, "progress": False}
        if progress:
            print(f"experiments: the {n} crashes on {min(processes, n)} processes (each: both "
                  "variants, then the runs over the uncertainty)",
                  file=sys.stderr, flush=True)  # fmt: skip

        def done(i: int, result: tuple[dict[str, Any], float]) -> None:
            if progress:
                print(f"experiments: crash {TABLE3[i].number} of {n} done in {result[1]:.1f} s",
                      file=sys.stderr, flush=True)  # fmt: skip

        tasks = [(c, logs[c.number], out, samples, log_samples, sweep_options) for c in TABLE3]
        rows = [row for row, _ in run_tasks(crash_task, tasks, processes, done)]
    else:
        sweep_options = {"workers": workers, "scheduler": scheduler, "progress": progress}
        rows = []
        for crash in TABLE3:
            if progress:
                print(f"experiments: crash {crash.number} of {n}: both variants, then "
                      "the runs over the uncertainty", file=sys.stderr, flush=True)  # fmt: skip
            row, _ = crash_task(crash, logs[crash.number], out, samples, log_samples,
                                sweep_options)  # fmt: skip
            rows.append(row)
    table = write_table3(rows, out)
    folder.finish({"crashes": len(rows)})
    return table


def study_folder(
    out_dir: str | Path,
    samples: int = SENSITIVITY_RUNS,
    log_samples: int = LOG_SENSITIVITY_RUNS,
    where: str = "",
) -> StudyFolder:
    """The experiments' folder: the runs over the uncertainties decide its sweeps."""
    identity = {"samples": samples, "log_samples": log_samples}
    flags = {"samples": "--samples", "log_samples": "--log-samples"}
    return StudyFolder(Path(out_dir), "experiments", identity, where=where, flags=flags)


def prepare_experiments(
    out_dir: str | Path,
    data_dir: str | Path | None,
    samples: int = SENSITIVITY_RUNS,
    log_samples: int = LOG_SENSITIVITY_RUNS,
) -> tuple[StudyFolder, dict[int, SpiriMatLog | None]]:
    """The experiments' folder (checked, claimed) and each crash's log (None where absent).

    A ``data_dir`` given that holds no logs, a folder of another kind (or of
    these experiments with other ``samples``), or a log that cannot be read is
    an error here, before any run. The folder is the experiments' own from
    its first file (``study.json``): an interrupted run resumes in it.
    """
    data_dir = check_data_dir(data_dir, "data_dir")
    folder = study_folder(out_dir, samples, log_samples)
    folder.claim()
    return folder, {crash.number: read_log(crash, data_dir) for crash in TABLE3}


def write_table3(rows: list[dict[str, Any]], out: Path) -> pd.DataFrame:
    """Table III from the crashes' rows (in crash order), written to ``out``.

    ``table3.csv`` and ``.parquet`` (one row per crash), the runs and switch
    runs the rows carry (``table3_runs``, ``table3_switches``, CSV and
    Parquet) and the report ``table3.md``. Returns the per-crash table, with
    the other two as ``table.attrs["runs"]`` and ``table.attrs["switches"]``.
    """
    runs = pd.DataFrame([r for row in rows for r in row.get("runs", [])], columns=RUN_COLUMNS)
    switches = pd.DataFrame([r for row in rows for r in row.get("switches", [])],
                            columns=SWITCH_COLUMNS)  # fmt: skip
    table = pd.DataFrame(rows, columns=[*TABLE3_COLUMNS, *EXTRA_COLUMNS])
    table.to_csv(out / "table3.csv", index=False)
    table.to_parquet(out / "table3.parquet")
    for name, frame in (("table3_runs", runs), ("table3_switches", switches)):
        frame.to_csv(out / f"{name}.csv", index=False)
        frame.to_parquet(out / f"{name}.parquet")
    table.attrs["runs"] = runs
    table.attrs["switches"] = switches
    (out / "table3.md").write_text("# Table III: the seven real crashes\n\n"
                                    + table3_markdown(table, runs, switches) + "\n")  # fmt: skip
    return table
