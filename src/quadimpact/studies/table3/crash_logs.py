"""Table III's flight logs: where they are read from, each crash's log, and the scenario
at a log's own pre-impact estimates.

:func:`check_data_dir` checks a given data folder before any run (an input
error names the flag and the rule), :func:`logs_source` says in one line which
folder is read and how it was found, :func:`read_log` opens a crash's log
(None where it is absent), :func:`log_conditions` puts a log's estimates
(heading, speed at the contact, roll, pitch) into the crash's scenario, and
:func:`log_sensitivity_spec` samples uniformly within ``LOG_RANGE_SIGMAS``
standard uncertainties of them. The Table III driver is
:mod:`quadimpact.studies.table3.table3_study`.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from quadimpact.experiments.crashes import TABLE3, Crash, scenario_file, scenario_path
from quadimpact.experiments.logs import PreImpact, data_dir
from quadimpact.experiments.spiri_mat import SpiriMatLog
from quadimpact.inputs.toml_files import read_toml_file
from quadimpact.sweep import SweepSpec

__all__ = [
    "LOG_RANGE_SIGMAS",
    "LOG_SENSITIVITY_RUNS",
    "check_data_dir",
    "log_conditions",
    "log_sensitivity_spec",
    "logs_source",
    "read_log",
]

#: Runs per crash over the log estimates' uncertainty.
LOG_SENSITIVITY_RUNS = 100
#: Half-width of the log-conditions sample, in standard uncertainties.
LOG_RANGE_SIGMAS = 2.0
#: The scenario fields set from the log's estimates.
_LOG_FIELDS = ("heading_deg", "speed_m_s", "roll_deg", "pitch_deg")


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
