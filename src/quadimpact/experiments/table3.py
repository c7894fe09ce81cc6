"""Table III: the seven real crashes, simulated, with their uncertainty and their logs.

``run_experiments(out_dir)`` simulates each crash of ``crashes.TABLE3`` at its
nominal conditions in both model variants, runs a sensitivity sweep over the
stated uncertainty (heading +- 6.4 deg, speed +- 0.01 m/s, inclination +- its
own, uniform, seeded) giving the share of each response type, and compares
each run with its flight log where the log is available.

Where the log shows the wall contact, the crash is also simulated at the
log's own pre-impact estimates (heading, speed at the contact, roll and pitch
from the motion capture, :meth:`FlightLog.pre_impact`): once at the estimates
and over their uncertainty (uniform within ``LOG_RANGE_SIGMAS`` standard
uncertainties). Table III's conditions and the logs' disagree beyond the
stated uncertainty (docs/EXPERIMENTS.md), and these runs show what that
changes. The log's own response type (classified from its motion) is given
too.

It writes ``table3.csv`` (the stable interface: ``TABLE3_COLUMNS``, then
``EXTRA_COLUMNS``), ``table3.parquet``, one folder per crash (the nominal runs'
files and the comparison plots) and the sensitivity sweeps (resumable).
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path
from typing import Any

import pandas as pd

from quadimpact.experiments.crashes import (
    HEADING_UNCERTAINTY_DEG,
    SPEED_UNCERTAINTY_M_S,
    TABLE3,
    Crash,
    scenario_file,
    scenario_path,
)
from quadimpact.experiments.logs import PreImpact, data_dir
from quadimpact.experiments.spiri_mat import SpiriMatLog
from quadimpact.inputs.files import read_toml_file
from quadimpact.simulation import simulate
from quadimpact.simulation.metrics import RESPONSE_TYPES
from quadimpact.sweep import SweepSpec, run_sweep

SENSITIVITY_RUNS = 300  # per crash
#: Runs per crash over the log estimates' uncertainty.
LOG_SENSITIVITY_RUNS = 100
#: Half-width of the log-conditions sample, in standard uncertainties.
LOG_RANGE_SIGMAS = 2.0
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
#: Columns of ``table3.csv`` after ``TABLE3_COLUMNS``: the deepest bumper
#: deflection of our nominal run (default model, mm; beyond the bumper radius,
#: 110 mm, the model no longer holds), then ``LOG_COLUMNS``, ``MOTION_COLUMNS``
#: and ``VERDICT_COLUMNS``.
EXTRA_COLUMNS = ("max_penetration_mm", *LOG_COLUMNS, *MOTION_COLUMNS, *VERDICT_COLUMNS)
#: A run matches the crash in motion when its attitude error against the log over
#: the first 0.3 s (RMS of the rotation angle) is at most this, deg.
MOTION_RMS_DEG = 20.0
#: A different type at the nominal conditions is ``partly`` when the experiment's
#: type occurs in at least this share of the runs over the stated uncertainty.
TYPE_SHARE_PARTLY = 0.2
#: The rule of :func:`crash_verdict`, as the report states it.
VERDICT_RULE = (
    f"agrees: ours (default) has the experiment's type and its attitude error against the "
    f"log over the first 0.3 s is at most {MOTION_RMS_DEG:g}° RMS (or there is no log); "
    f"partly: the same type with a larger attitude error (the type matches, the motion "
    f"does not), or another type at the nominal conditions while the experiment's occurs in "
    f"at least {TYPE_SHARE_PARTLY:.0%} of the runs over the stated uncertainty; disagrees: "
    "otherwise"
)
_LOG_FIELDS = ("heading_deg", "speed_m_s", "roll_deg", "pitch_deg")


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


def crash_verdict(row: Any) -> tuple[str, str]:
    """Our nominal run against the experiment, for one row of Table III (:data:`VERDICT_RULE`).

    Parameters
    ----------
    row : mapping
        A row of the table (``type_ours``, ``type_paper_experiment``,
        ``attitude_rms_deg_0_3s``, ``share_<type>``).

    Returns
    -------
    (str, str)
        The verdict and its reason, with the measure and the threshold.
    """
    ours, exp = row["type_ours"], row["type_paper_experiment"]
    rms = float(row["attitude_rms_deg_0_3s"])
    if ours == exp:
        if math.isnan(rms):
            return "agrees", f"type {ours} (no log to compare the motion with)"
        if rms <= MOTION_RMS_DEG:
            return "agrees", f"type {ours}; attitude RMS {rms:.1f}° ≤ {MOTION_RMS_DEG:g}°"
        return "partly", (
            f"type {ours}, but not the motion: attitude RMS {rms:.1f}° > {MOTION_RMS_DEG:g}°"
        )
    share = float(row.get(f"share_{exp}", math.nan))
    if math.isnan(share):
        return "disagrees", f"type {ours}, not {exp} (no runs over the uncertainty)"
    seen = f"type {ours}, not {exp}; {exp} in {share:.0%} of the runs over the uncertainty"
    if share >= TYPE_SHARE_PARTLY:
        return "partly", f"{seen} (≥ {TYPE_SHARE_PARTLY:.0%})"
    return "disagrees", f"{seen} (< {TYPE_SHARE_PARTLY:.0%})"


def check_data_dir(data: str | Path | None, where: str = "--data") -> Path | None:
    """The data folder to read the logs from, checked before any work.

    Parameters
    ----------
    data : path or None
        A folder given explicitly (``--data``): it must hold at least one of
        the seven crashes' logs, else this is an input error. ``None``: the
        default folder (:func:`quadimpact.experiments.logs.data_dir`), if any;
        a ``$QUADIMPACT_DATA`` that holds no logs is said in a warning on
        stderr (the log columns then stay empty).
    where : str
        How the folder was given, for the message.

    Returns
    -------
    pathlib.Path or None
        The folder holding ``spiri-crash-set-1/`` (None: no logs).

    Raises
    ------
    InputError
        A given folder that is absent, is a file or holds none of the logs.
    """
    import os

    from quadimpact.errors import InputError
    from quadimpact.experiments.logs import DATA_ENV_VAR

    logs = [c.log_file for c in TABLE3]
    if data is None:
        found = data_dir()
        env = os.environ.get(DATA_ENV_VAR)
        if found is None and env:
            print(f"quadimpact: warning: ${DATA_ENV_VAR}={env} holds none of the crash logs "
                  f"({logs[0]}, ...): the comparisons with the logs are left out",
                  file=sys.stderr)  # fmt: skip
        return found
    root = Path(data)
    if not root.exists():
        raise InputError(f"{where} {root}: no such folder")
    if not root.is_dir():
        raise InputError(f"{where} {root}: is a file, not a folder")
    if any((root / name).is_file() for name in logs):
        return root
    if any((root / Path(name).name).is_file() for name in logs):
        raise InputError(
            f"{where} {root}: is the crash set's own folder; give the folder that holds it, "
            f"{root.resolve().parent}"
        )
    raise InputError(
        f"{where} {root}: holds none of the crash logs (expected {logs[0]} ... "
        f"{Path(logs[-1]).name})"
    )


def logs_source(data: str | Path | None) -> str:
    """One line saying which folder the flight logs are read from, and how it was found.

    ``data``: the folder given (``--data``), or None for the default search
    (:func:`quadimpact.experiments.logs.find_data_dir`).
    """
    from quadimpact.experiments.logs import find_data_dir

    if data is not None:
        return f"flight logs read from {Path(data).resolve()} (--data)"
    found, how = find_data_dir()
    if found is None:
        return f"no flight logs: {how}; the comparisons with the logs are left out"
    return f"flight logs read from {found} (found: {how})"


def read_log(crash: Crash, data: str | Path | None = None) -> SpiriMatLog | None:
    """The crash's flight log, None where the data folder or the file is absent."""
    root = Path(data) if data is not None else data_dir()
    if root is None or not (root / crash.log_file).is_file():
        return None
    return SpiriMatLog(root / crash.log_file)


def log_conditions(crash: Crash, pre: PreImpact) -> dict[str, Any] | None:
    """The crash's scenario fields at the log's estimates, None without an observed contact.

    Heading (the log frame, rear first like the scenario, taken within 180 deg
    of the scenario's), speed toward the wall at the contact, and the measured
    roll and pitch (explicit attitude: the body z axis need not lie in the
    X-Z plane). Altitude and motor schedule stay the scenario's.
    """
    if not pre.contact_observed:
        return None
    psi0 = scenario_file(crash.number).heading_deg
    psi = psi0 + ((pre.heading_deg - psi0 + 180.0) % 360.0 - 180.0)
    fields = read_toml_file(scenario_path(crash.number))
    fields.update(
        heading_deg=round(psi, 2),
        speed_m_s=round(pre.speed_m_s, 3),
        roll_deg=round(pre.roll_deg, 2),
        pitch_deg=round(pre.pitch_deg, 2),
    )
    return fields


def log_sensitivity_spec(
    crash: Crash, pre: PreImpact, n: int = LOG_SENSITIVITY_RUNS
) -> SweepSpec | None:
    """Uniform sample within ``LOG_RANGE_SIGMAS`` standard uncertainties of the log's estimates."""
    base = log_conditions(crash, pre)
    if base is None:
        return None
    ranges = {}
    for name in _LOG_FIELDS:
        half = LOG_RANGE_SIGMAS * pre.uncertainty[name]
        ranges[name] = [base[name] - half, base[name] + half]
    return SweepSpec(base=base, sample={"n": n, "seed": 100 + crash.number, "ranges": ranges})


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
    sweeps (default: in this process, no progress).
    """
    from quadimpact.experiments.logs_compare import attitude_rms, compare_crash

    sweep_options = sweep_options or {"workers": 1, "scheduler": None, "progress": False}
    start = time.perf_counter()
    folder = out / f"crash_{crash.number}"
    types: dict[str, str | None] = {}
    results = {}
    for model, key in (("default", "type_ours"), ("paper-replica", "type_replica")):
        r = simulate(crash.scenario(model))
        r.write(folder / model)
        results[model] = r
        types[key] = r.summary["response_type"]
    shares: dict[str, float] = {f"share_{t}": math.nan for t in RESPONSE_TYPES}
    if samples > 0:
        sweep = run_sweep(
            sensitivity_spec(crash, samples),
            out / "sensitivity" / f"crash_{crash.number}",
            **sweep_options,
        )
        shares = _shares(sweep, "share_")
    comparison = compare_crash(crash, results["default"], log, folder)
    motion = {c: math.nan for c in MOTION_COLUMNS}
    if comparison is not None:
        for angle, (sim, logged) in comparison.departures(0.3).items():
            motion[f"sim_{angle}_change_deg_0_3s"] = sim
            motion[f"log_{angle}_change_deg_0_3s"] = logged
    row = {
        "crash": crash.number,
        "heading_deg": crash.heading_deg,
        "speed_m_s": crash.speed_m_s,
        "inclination_deg": crash.inclination_deg,
        "type_paper_experiment": crash.type_experiment,
        "type_paper_simulation": crash.type_paper_simulation,
        **types,
        **shares,
        "attitude_rms_deg_0_3s": attitude_rms(comparison),
        "max_penetration_mm": 1e3 * results["default"].summary["max_penetration_m"],
        **_log_row(crash, log, folder, out, log_samples, sweep_options),
        **motion,
    }
    row["verdict"], row["verdict_reason"] = crash_verdict(row)
    return row, time.perf_counter() - start


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
    from quadimpact.sweep.run import _resolve_workers
    from quadimpact.sweep.tasks import run_tasks

    out, logs = prepare_experiments(out_dir, data_dir)
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
    return write_table3(rows, out)


def prepare_experiments(
    out_dir: str | Path, data_dir: str | Path | None
) -> tuple[Path, dict[int, SpiriMatLog | None]]:
    """The experiments' folder (checked, created) and each crash's log (None where absent).

    A ``data_dir`` given that holds no logs, a folder of another kind, or a
    log that cannot be read is an error here, before any run.
    """
    from quadimpact.results.files import check_out_dir

    data_dir = check_data_dir(data_dir, "data_dir")
    out = check_out_dir(Path(out_dir), "experiments", where="")
    out.mkdir(parents=True, exist_ok=True)
    return out, {crash.number: read_log(crash, data_dir) for crash in TABLE3}


def write_table3(rows: list[dict[str, Any]], out: Path) -> pd.DataFrame:
    """Table III from the crashes' rows (in crash order), written to ``out``
    (``table3.csv``, ``table3.parquet``)."""
    table = pd.DataFrame(rows, columns=[*TABLE3_COLUMNS, *EXTRA_COLUMNS])
    table.to_csv(out / "table3.csv", index=False)
    table.to_parquet(out / "table3.parquet")
    return table
