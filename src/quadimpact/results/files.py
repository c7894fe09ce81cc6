"""Writers and readers of a result folder.

A result folder holds:

- ``summary.json``: the run summary (NaN and infinities written as ``null``),
  with the attitude/altitude ``references`` and the ``integrator`` counters,
  so the folder can be re-plotted;
- ``scenario.json``: the world that ran (the validated scenario, what its
  settings resolved to, the vehicle with its overrides applied, the contact
  surfaces as packed), so the folder can be drawn as it ran;
- ``episodes.csv``: one row per contact episode (see docs/RESULTS.md);
- ``timeseries.parquet``: the sampled states, with the unit of every column
  as JSON in the schema metadata key ``quadimpact.units``;
- ``fig5.png``, ``fig6.png``: the plots.

Every file quadimpact writes (these, the figures, the pictures, a sweep's
parts and table) is written by :func:`atomic_write`: a temporary file next to
the target, renamed into place (``os.replace``), so a reader never sees a
half-written file. A whole result folder is written by :func:`staged_folder`:
into a hidden folder beside it, moved into place only when every file is
there. :func:`check_out_dir` refuses, before any work, an output folder that
cannot be made or that holds something of another kind (:func:`folder_kind`).
Files and folders are created with the process's umask (never a private
mode), so a group can share them. :func:`to_jsonable` is the one conversion of values to
plain JSON types (the summary here; a sweep's inputs and table rows).

pandas and pyarrow are imported by the functions that need them, so that
importing this module stays light (sweep workers, the command line).
"""

from __future__ import annotations

import contextlib
import dataclasses
import errno
import json
import math
import os
import re
import secrets
import shutil
import sys
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import pandas as pd

from quadimpact.errors import InputError
from quadimpact.errors import short_path as _short
from quadimpact.results.schema import (
    BUMPERS,
    EPISODE_COLUMNS,
    IMU_COLUMNS,
    TIMESERIES_COLUMNS,
    feature_columns,
)

__all__ = [
    "BUMPERS",
    "EPISODE_COLUMNS",
    "EPISODES_CSV",
    "EPISODES_LEADING_COLUMNS",
    "SCENARIO_JSON",
    "SUMMARY_JSON",
    "TIMESERIES_COLUMNS",
    "feature_columns",
    "TIMESERIES_PARQUET",
    "UNITS_METADATA_KEY",
    "DERIVED_FILES",
    "FOLDER_MARKERS",
    "RUN_FILES",
    "STUDY_JSON",
    "atomic_write",
    "check_out_dir",
    "check_writable",
    "column_unit",
    "folder_kind",
    "kind_words",
    "staged_folder",
    "read_episodes_csv",
    "read_summary_json",
    "read_timeseries_parquet",
    "read_timeseries_units",
    "remove_stale_temporaries",
    "split_unit",
    "to_jsonable",
    "write_episodes_csv",
    "write_imu_parquet",
    "write_summary_json",
    "write_timeseries_parquet",
    "IMU_COLUMNS",
    "IMU_PARQUET",
]

SUMMARY_JSON = "summary.json"
SCENARIO_JSON = "scenario.json"
EPISODES_CSV = "episodes.csv"
TIMESERIES_PARQUET = "timeseries.parquet"
IMU_PARQUET = "imu.parquet"

#: Every file of a run folder that :meth:`SimulationResult.write` writes (data, then figures).
RUN_FILES: tuple[str, ...] = (
    SUMMARY_JSON, SCENARIO_JSON, EPISODES_CSV, TIMESERIES_PARQUET, IMU_PARQUET,
    "fig5.png", "fig6.png", "imu.png", "estimate.png",
)  # fmt: skip
#: Files drawn from a run folder afterwards (``quadimpact snapshots``, ``animate``,
#: ``view``, the crash experiments' comparison with the log): a new run written into
#: the folder removes them, since they show the old run.
DERIVED_FILES: tuple[str, ...] = (
    "snapshots.png", "snapshots.pdf", "animation.mp4", "animation.gif", "viewer.html",
    "compare.csv", "compare.png",
)  # fmt: skip
#: What each kind of output folder holds (any one of these names marks it), in the
#: order they are recognised.
#: A study stopped early holds only the folders it had begun (``sweep/`` of a recovery
#: study, ``sweeps/`` of a report, ``sensitivity/`` of the experiments): they mark it too.
#: The file a study writes first into its folder (``studies/study_folder.py``): its
#: ``kind`` says which study the folder is.
STUDY_JSON = "study.json"
FOLDER_MARKERS: dict[str, tuple[str, ...]] = {
    "sweep": ("sweep.json", "runs.parquet", "parts"),
    "recovery": (STUDY_JSON, "trials.parquet", "sweep"),
    "report": ("report.md", "findings.parquet", "sweeps", "experiments", "recovery"),
    "experiments": ("table3.csv", "table3.parquet", "sensitivity", "sensitivity-log"),
    "run": (SUMMARY_JSON, TIMESERIES_PARQUET),
}
_KIND_WORDS = {
    "sweep": "a sweep",
    "recovery": "a recovery study",
    "pole": "a pole study",
    "benchmark": "a benchmark",
    "estimators": "an estimator study",
    "report": "a study report",
    "experiments": "the crash experiments",
    "run": "a run",
    "other": "files that are not quadimpact's",
}


def kind_words(kind: str) -> str:
    """What a folder of ``kind`` holds, in words (``"a recovery study"``)."""
    return _KIND_WORDS.get(kind, f"a {kind} study")


def _study_kind(folder: Path) -> str | None:
    """The ``kind`` a folder's ``study.json`` names (None: no such file or no kind in it)."""
    try:
        data = json.loads((folder / STUDY_JSON).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    kind = data.get("kind") if isinstance(data, dict) else None
    return kind if isinstance(kind, str) and kind in _KIND_WORDS else None


#: Schema metadata key holding ``{column: unit}`` as a JSON string.
UNITS_METADATA_KEY = "quadimpact.units"

#: Columns written first in episodes.csv, in this order; the rest follow.
EPISODES_LEADING_COLUMNS: tuple[str, ...] = EPISODE_COLUMNS[:8]

# Unit suffixes of column names, longest first.
_UNIT_SUFFIXES: tuple[tuple[str, str], ...] = (
    ("_rad_s2", "rad/s^2"),
    ("_m_s2", "m/s^2"),
    ("_rad_s", "rad/s"),
    ("_m_s", "m/s"),
    ("_rpm", "rpm"),
    ("_kg_m2", "kg m^2"),
    ("_kg", "kg"),
    ("_hz", "Hz"),
    ("_deg", "deg"),
    ("_rad", "rad"),
    ("_mm", "mm"),
    ("_nm", "N m"),
    ("_n", "N"),
    ("_m", "m"),
    ("_s", "s"),
)


def split_unit(name: str) -> tuple[str, str]:
    """A column name as (stem, unit): ``speed_m_s`` -> ``("speed", "m/s")``.

    The unit is that of :func:`column_unit` (``"1"`` when dimensionless, and
    the stem is then the whole name).
    """
    for suffix, unit in _UNIT_SUFFIXES:
        if name.endswith(suffix) and len(name) > len(suffix):
            return name[: -len(suffix)], unit
    return name, "1"


def column_unit(name: str) -> str:
    """Unit of a column from its name's suffix (``"1"`` when dimensionless).

    ``t_s`` -> ``s``, ``vx_m_s`` -> ``m/s``, ``p_rad_s`` -> ``rad/s``,
    ``force1_n`` -> ``N``, ``roll_deg`` -> ``deg``, ``q0`` -> ``1``.
    """
    return split_unit(name)[1]


def to_jsonable(obj: Any, *, finite: bool = True, strict: bool = True) -> Any:
    """Convert ``obj`` into plain JSON types (the one converter).

    NumPy scalars and arrays (anything with ``tolist``), tuples, sets (sorted),
    paths, dataclasses and pydantic models become their plain equivalents;
    mapping keys become strings.

    Parameters
    ----------
    obj : object
        The value.
    finite : bool, keyword
        NaN and infinities become ``None`` (JSON has neither; the summary).
        ``False`` keeps them (a sweep's inputs, which are checked afterwards).
    strict : bool, keyword
        Anything else raises ``TypeError`` (nothing is silently turned into a
        string); ``False`` returns it unchanged.
    """

    def convert(value: Any) -> Any:
        return to_jsonable(value, finite=finite, strict=strict)

    if obj is None or isinstance(obj, bool | str):
        return obj
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, float):  # NumPy float64 too
        f = float(obj)
        return None if finite and not math.isfinite(f) else f
    if isinstance(obj, Mapping):
        return {str(k): convert(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple | set | frozenset):
        items = sorted(obj) if isinstance(obj, set | frozenset) else obj
        return [convert(v) for v in items]
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return convert(dataclasses.asdict(obj))
    model_dump = getattr(obj, "model_dump", None)
    if callable(model_dump):
        return convert(model_dump(mode="json"))
    tolist = getattr(obj, "tolist", None)
    if callable(tolist) and not isinstance(obj, bytes):  # NumPy scalars and arrays
        return convert(tolist())
    pd = sys.modules.get("pandas")  # pd.NA and pd.NaT only exist once pandas is loaded
    if pd is not None and (obj is pd.NA or obj is pd.NaT):
        return None
    if not strict:
        return obj
    raise TypeError(f"summary: cannot write a value of type {type(obj).__name__} to JSON")


def _fsync(path: Path) -> None:
    with contextlib.suppress(OSError):  # folders cannot be opened everywhere
        fd = os.open(path, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def atomic_write(
    path: str | os.PathLike[str],
    write: Callable[[Path], None],
    *,
    durable: bool = False,
    suffix: str = ".tmp",
) -> Path:
    """Write a file so that it is either complete or absent (the one atomic writer).

    ``write(tmp)`` writes a temporary file beside ``path`` (in the same
    folder: ``.<name>.<pid>.<random><suffix>``), which is then renamed to
    ``path``; if ``write`` fails the temporary file is removed and the error
    raised, and ``path`` keeps its old content (or stays absent).

    Parameters
    ----------
    path : path-like
        The target file.
    write : callable
        Writes the content to the path it is given (which does not exist yet).
    durable : bool, keyword
        Also flush the file and the folder to disk (``fsync``) around the
        rename, so that the file survives a power cut once this returns
        (a sweep's parts and table).
    suffix : str, keyword
        End of the temporary name (a writer that picks its format from the
        name, like ffmpeg, needs the real extension).

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    target = Path(path)
    tmp = target.parent / f".{target.name}.{os.getpid()}.{secrets.token_hex(4)}{suffix}"
    try:
        write(tmp)
        if durable:
            _fsync(tmp)
        os.replace(tmp, target)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    if durable:
        _fsync(target.parent)
    return target


#: A temporary file of :func:`atomic_write` (``.<name>.<pid>.<8 hex digits><suffix>``) or a
#: folder of :func:`staged_folder` (``.<name>.partial-<pid>-<random>``).
_TEMPORARY = re.compile(
    r"^\..+?(?:\.(?P<pid>\d+)\.[0-9a-f]{8}(?:\.[^/]*)?|\.partial-(?P<pid2>\d+)-\w+)$"
)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # another user's process: alive
        return True
    return True


def remove_stale_temporaries(folder: str | os.PathLike[str]) -> list[Path]:
    """Remove, under ``folder``, the temporary files and folders of writers no longer running.

    :func:`atomic_write` and :func:`staged_folder` name their temporaries
    after their process; a process killed while writing (a study's worker
    stopped by Ctrl-C, ``kill -9``) leaves them behind. Those of a process that
    no longer exists are removed; those of running processes are kept.
    Returns what was removed.
    """
    removed: list[Path] = []
    root = Path(folder)
    if not root.is_dir():
        return removed
    for path in sorted(root.rglob(".*")):
        m = _TEMPORARY.match(path.name)
        if m is None:
            continue
        pid = int(m.group("pid") or m.group("pid2"))
        if pid == os.getpid() or _alive(pid):
            continue
        try:
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path)
            else:
                path.unlink()
        except OSError:
            continue
        removed.append(path)
    return removed


def folder_kind(path: str | os.PathLike[str]) -> tuple[str | None, list[str]]:
    """What an output folder holds, and the names that say so.

    Parameters
    ----------
    path : path-like
        A folder (it need not exist).

    Returns
    -------
    (str or None, list of str)
        ``None`` when the folder is absent or empty (hidden entries, such as a
        writer's temporary files, are not counted); ``"sweep"``, ``"report"``,
        ``"experiments"`` or ``"run"`` (:data:`FOLDER_MARKERS`); a folder
        holding only files a run writes or that are drawn from one
        (:data:`RUN_FILES`, :data:`DERIVED_FILES`) is a ``"run"`` too; anything
        else is ``"other"``. The list holds the names found (at most three).
    """
    d = Path(path)
    if not d.is_dir():
        return None, []
    names = sorted(e.name for e in os.scandir(d) if not e.name.startswith("."))
    if not names:
        return None, []
    present = set(names)
    if STUDY_JSON in present:  # a study's first file names its kind
        kind = _study_kind(d)
        if kind is not None:
            return kind, [STUDY_JSON]
    for kind, markers in FOLDER_MARKERS.items():
        found = [m for m in markers if m in present]
        if found:
            return kind, found[:3]
    if present <= set(RUN_FILES) | set(DERIVED_FILES):
        return "run", names[:3]
    return "other", [n for n in names if n not in RUN_FILES and n not in DERIVED_FILES][:3]


def check_writable(folder: str | os.PathLike[str], label: str) -> None:
    """Refuse a folder in which nothing can be written, by writing (and removing) a probe.

    Permission bits alone do not tell (root passes ``os.access`` everywhere,
    even in ``/proc`` or on a read-only file system).

    Raises
    ------
    InputError
        ``<label> (<reason>)``.
    """
    import tempfile

    try:
        fd, probe = tempfile.mkstemp(prefix=".quadimpact-probe-", dir=os.fspath(folder))
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise InputError(f"{label} ({reason})") from None
    os.close(fd)
    os.unlink(probe)


def check_out_dir(
    path: str | os.PathLike[str],
    kind: str,
    *,
    where: str = "--out",
    refuse_other: bool | None = None,
) -> Path:
    """Check, before any work, that ``path`` can be the output folder of a ``kind``.

    Parameters
    ----------
    path : path-like
        The output folder (created later, if absent).
    kind : str
        ``"run"``, ``"sweep"``, ``"recovery"``, ``"report"`` or ``"experiments"``.
    where : str, keyword
        How the folder was given, for the message (``"--out"``).
    refuse_other : bool, keyword
        Refuse a folder that holds files of no kind (default: yes, for every
        kind: quadimpact's files would be mixed with them).

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    InputError
        One line: the path is too long, a parent is a file, the folder cannot
        be created (permissions), it is a file, or it holds another kind of
        output (what it holds and what to do).
    """
    d = Path(path)
    label = f"{where} {_short(d)}" if where else _short(d)
    try:
        exists = d.exists()
        if exists and not d.is_dir():
            raise InputError(f"{label}: is a file, not a folder")
        ancestor = d
        while not ancestor.exists() and ancestor != ancestor.parent:
            ancestor = ancestor.parent
    except OSError as exc:
        if exc.errno == errno.ENAMETOOLONG:
            raise InputError(f"{label}: path too long for the file system") from None
        raise InputError(f"{label}: cannot be used ({exc.strerror or exc})") from None
    if not exists:
        if not ancestor.is_dir():
            raise InputError(
                f"{label}: cannot be created: {_short(ancestor)} is a file, not a folder"
            )
        if not os.access(ancestor, os.W_OK | os.X_OK):
            raise InputError(
                f"{label}: cannot be created: no write permission in {_short(ancestor)}"
            )
        for part in d.relative_to(ancestor).parts if ancestor != d else ():
            if len(os.fsencode(part)) > 255:
                raise InputError(f"{label}: a folder name is longer than 255 bytes")
        check_writable(ancestor, f"{label}: cannot be created in {_short(ancestor)}")
        return d
    if not os.access(d, os.W_OK | os.X_OK):
        raise InputError(f"{label}: no write permission in the folder")
    check_writable(d, f"{label}: cannot be written")
    held, names = folder_kind(d)
    if refuse_other is None:
        refuse_other = True
    if held is None or held == kind or (held == "other" and not refuse_other):
        return d
    advice = {
        "run": "a new or empty folder, or a run folder (whose run it replaces)",
        "sweep": "a new or empty folder, or this sweep's own folder (to resume it)",
    }.get(kind, f"a new or empty folder, or a folder of {kind_words(kind)} (to resume it)")
    raise InputError(f"{label}: holds {kind_words(held)} ({', '.join(names)}); use {advice}")


@contextlib.contextmanager
def staged_folder(path: str | os.PathLike[str], replaces: tuple[str, ...] = ()) -> Iterator[Path]:
    """Write a folder completely, then move it into place (never a half-written folder).

    Yields a new hidden folder beside ``path`` (``.<name>.partial-<pid>-<random>``,
    created with the umask) to write into. When the block ends normally its
    files are moved into ``path``: the folder itself is renamed there when
    ``path`` is absent; otherwise (the folder and its permissions are kept)
    each file replaces its namesake (``os.replace``) and the names in
    ``replaces`` that the new folder lacks are removed from ``path`` (other
    files in ``path`` are left). When the block raises, the hidden folder is
    removed and ``path`` is left as it was. (A process killed meanwhile
    leaves the hidden folder, which can be deleted.)

    Parameters
    ----------
    path : path-like
        The folder to write (its parent is created if needed).
    replaces : tuple of str
        Names in ``path`` that belong to what is being written (the old
        run's files): removed when the new folder does not have them.
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    stage = target.parent / f".{target.name}.partial-{os.getpid()}-{secrets.token_hex(4)}"
    os.mkdir(stage)
    try:
        yield stage
        if not target.exists():
            try:
                os.rename(stage, target)  # the complete folder appears at once
                return
            except OSError:
                if not target.is_dir():  # made meanwhile: move the files in, below
                    raise
        staged = {e.name for e in os.scandir(stage)}
        for name in sorted(staged):
            try:
                os.replace(stage / name, target / name)
            except OSError as exc:
                if exc.errno != errno.EXDEV:  # another file system (a mount point)
                    raise
                shutil.move(stage / name, target / name)
        for name in replaces:
            if name not in staged:
                (target / name).unlink(missing_ok=True)
        stage.rmdir()
    finally:
        if stage.exists():
            shutil.rmtree(stage, ignore_errors=True)


def write_summary_json(summary: Mapping[str, Any], path: str | os.PathLike[str]) -> Path:
    """Write ``summary`` (or any mapping: ``scenario.json``) as indented JSON, atomically.

    Parameters
    ----------
    summary : mapping
        Run summary; values converted by :func:`to_jsonable` (NaN -> null).
        Floats are written in full (``repr``), so they read back bit for bit.
    path : path-like
        Target file.

    Returns
    -------
    pathlib.Path
        The written file.
    """
    text = json.dumps(to_jsonable(summary), indent=2, allow_nan=False) + "\n"
    return atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def read_summary_json(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Read a file written by :func:`write_summary_json` (``null`` stays ``None``)."""
    with open(path, encoding="utf-8") as fh:
        return json.load(fh)


def write_episodes_csv(df: pd.DataFrame | Mapping[str, Any], path: str | os.PathLike[str]) -> Path:
    """Write the episodes table to CSV, atomically.

    Columns :data:`EPISODES_LEADING_COLUMNS` come first (those present), then
    the others in their table order. Floats are written with full precision
    (``%.17g``). ``df`` is a DataFrame or a mapping of equal-length columns
    (written without pandas, to the same text).
    """
    if not hasattr(df, "columns"):
        return atomic_write(path, lambda tmp: _write_columns_csv(df, tmp))
    lead = [c for c in EPISODES_LEADING_COLUMNS if c in df.columns]
    cols = lead + [c for c in df.columns if c not in lead]
    out = df.loc[:, cols]
    return atomic_write(path, lambda tmp: out.to_csv(tmp, index=False, float_format="%.17g"))


def _csv_text(value: Any) -> str:
    if isinstance(value, (bool, np.bool_)):
        return "True" if value else "False"
    if isinstance(value, (float, np.floating)):
        return "" if math.isnan(value) else f"{value:.17g}"
    return str(value)


def _write_columns_csv(columns: Mapping[str, Any], path: Path) -> None:
    """A table of columns as CSV, the way ``DataFrame.to_csv(index=False, float_format="%.17g")``
    writes it (empty fields for NaN, ``True``/``False``, minimal quoting, ``\\n`` lines)."""
    import csv

    names = list(columns)
    lead = [c for c in EPISODES_LEADING_COLUMNS if c in names]
    names = lead + [c for c in names if c not in lead]
    n = len(columns[names[0]]) if names else 0
    with open(path, "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(names)
        for i in range(n):
            writer.writerow([_csv_text(columns[c][i]) for c in names])


def read_episodes_csv(path: str | os.PathLike[str]) -> pd.DataFrame:
    """Read an episodes CSV back with the table's dtypes (``bumper`` int, ``open`` bool)."""
    import pandas as pd

    # Only empty fields are missing values, so a surface named e.g. "None" survives.
    df = pd.read_csv(path, keep_default_na=False, na_values=[""])
    if "bumper" in df.columns:
        df["bumper"] = df["bumper"].astype("int64")
    if "surface" in df.columns:
        df["surface"] = df["surface"].astype(str)
    if "open" in df.columns:
        if df["open"].dtype != bool:
            df["open"] = df["open"].astype(str).str.lower().map({"true": True, "false": False})
        df["open"] = df["open"].astype(bool)
    for c in df.columns:
        if c not in ("bumper", "surface", "open"):
            df[c] = df[c].astype("float64")
    return df


def write_timeseries_parquet(
    df: pd.DataFrame | Mapping[str, Any], path: str | os.PathLike[str]
) -> Path:
    """Write the time series to Parquet (pyarrow), with column units in the schema.

    The schema metadata key :data:`UNITS_METADATA_KEY` holds a JSON object
    ``{column: unit}`` (units from :func:`column_unit`). ``df`` is a DataFrame
    or a mapping of equal-length NumPy columns (written without pandas).
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    if hasattr(df, "columns"):
        table = pa.Table.from_pandas(df, preserve_index=False)
    else:
        table = pa.Table.from_arrays(
            [_float_array(pa, v) for v in df.values()], names=[str(k) for k in df]
        )
    units = {str(c): column_unit(str(c)) for c in (df.columns if hasattr(df, "columns") else df)}
    meta = dict(table.schema.metadata or {})
    meta[UNITS_METADATA_KEY.encode()] = json.dumps(units).encode()
    table = table.replace_schema_metadata(meta)
    return atomic_write(path, lambda tmp: pq.write_table(table, tmp))


def _float_array(pa: Any, values: Any) -> Any:
    """A float64 Arrow array over a NumPy column, without type inference (which imports pandas)."""
    x = np.ascontiguousarray(values, dtype=np.float64)
    return pa.Array.from_buffers(pa.float64(), len(x), [None, pa.py_buffer(x)])


def write_imu_parquet(df: pd.DataFrame, path: str | os.PathLike[str]) -> Path:
    """Write the IMU samples to Parquet, with column units (as the time series)."""
    return write_timeseries_parquet(df, path)


def read_timeseries_parquet(path: str | os.PathLike[str]) -> pd.DataFrame:
    """Read a time series written by :func:`write_timeseries_parquet`."""
    import pyarrow.parquet as pq

    return pq.read_table(path).to_pandas()


def read_timeseries_units(path: str | os.PathLike[str]) -> dict[str, str]:
    """Column units stored in a time-series Parquet file (empty if absent)."""
    import pyarrow.parquet as pq

    meta = pq.read_schema(path).metadata or {}
    raw = meta.get(UNITS_METADATA_KEY.encode())
    return json.loads(raw) if raw else {}
