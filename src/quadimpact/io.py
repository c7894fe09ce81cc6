"""Writers and readers of a result folder.

A result folder holds:

- ``summary.json``: the run summary (NaN and infinities written as ``null``),
  plus the attitude/altitude ``references`` and integrator ``stats`` so the
  folder can be re-plotted;
- ``episodes.csv``: one row per contact episode (see docs/RESULTS.md);
- ``timeseries.parquet``: the sampled states, with the unit of every column
  as JSON in the schema metadata key ``quadimpact.units``;
- ``fig5.png``, ``fig6.png``: the plots.

Every writer writes a temporary file next to the target and renames it into
place (``os.replace``), so a reader never sees a half-written file.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import tempfile
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from quadimpact.analysis import EPISODE_COLUMNS

if TYPE_CHECKING:
    from quadimpact.result import SimulationResult

__all__ = [
    "EPISODES_CSV",
    "EPISODES_LEADING_COLUMNS",
    "SUMMARY_JSON",
    "TIMESERIES_PARQUET",
    "UNITS_METADATA_KEY",
    "atomic_write",
    "column_unit",
    "read_episodes_csv",
    "read_result",
    "read_summary_json",
    "read_timeseries_parquet",
    "read_timeseries_units",
    "to_jsonable",
    "write_episodes_csv",
    "write_summary_json",
    "write_timeseries_parquet",
]

SUMMARY_JSON = "summary.json"
EPISODES_CSV = "episodes.csv"
TIMESERIES_PARQUET = "timeseries.parquet"

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
    ("_deg", "deg"),
    ("_rad", "rad"),
    ("_mm", "mm"),
    ("_nm", "N m"),
    ("_n", "N"),
    ("_m", "m"),
    ("_s", "s"),
)


def column_unit(name: str) -> str:
    """Unit of a column from its name's suffix (``"1"`` when dimensionless).

    ``t_s`` -> ``s``, ``vx_m_s`` -> ``m/s``, ``p_rad_s`` -> ``rad/s``,
    ``force1_n`` -> ``N``, ``roll_deg`` -> ``deg``, ``q0`` -> ``1``.
    """
    for suffix, unit in _UNIT_SUFFIXES:
        if name.endswith(suffix) and len(name) > len(suffix):
            return unit
    return "1"


def to_jsonable(obj: Any) -> Any:
    """Convert ``obj`` into plain JSON types.

    NaN and infinities become ``None``; NumPy scalars and arrays, tuples,
    sets, paths, dataclasses and pydantic models become their plain
    equivalents. Anything else raises ``TypeError`` (nothing is silently
    turned into a string).
    """
    if obj is None or isinstance(obj, bool | str):
        return obj
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, int | np.integer):
        return int(obj)
    if isinstance(obj, float | np.floating):
        f = float(obj)
        return f if math.isfinite(f) else None
    if isinstance(obj, np.ndarray):
        return [to_jsonable(v) for v in obj.tolist()]
    if isinstance(obj, Mapping):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple | set | frozenset):
        items = sorted(obj) if isinstance(obj, set | frozenset) else obj
        return [to_jsonable(v) for v in items]
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return to_jsonable(dataclasses.asdict(obj))
    model_dump = getattr(obj, "model_dump", None)
    if callable(model_dump):
        return to_jsonable(model_dump(mode="json"))
    if obj is pd.NA or obj is pd.NaT:
        return None
    raise TypeError(f"summary: cannot write a value of type {type(obj).__name__} to JSON")


def atomic_write(path: str | os.PathLike[str], write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp)`` on a temporary file beside ``path``, then rename it to ``path``."""
    target = Path(path)
    fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        write(tmp)
        os.replace(tmp, target)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return target


def write_summary_json(summary: Mapping[str, Any], path: str | os.PathLike[str]) -> Path:
    """Write ``summary`` as indented JSON (NaN -> null), atomically.

    Parameters
    ----------
    summary : mapping
        Run summary; values converted by :func:`to_jsonable`.
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
    """Read a summary written by :func:`write_summary_json` (``null`` stays ``None``)."""
    with open(path, encoding="utf-8") as fh:
        return json.load(fh)


def write_episodes_csv(df: pd.DataFrame, path: str | os.PathLike[str]) -> Path:
    """Write the episodes table to CSV, atomically.

    Columns :data:`EPISODES_LEADING_COLUMNS` come first (those present), then
    the others in their table order. Floats are written with full precision.
    """
    lead = [c for c in EPISODES_LEADING_COLUMNS if c in df.columns]
    cols = lead + [c for c in df.columns if c not in lead]
    out = df.loc[:, cols]
    return atomic_write(path, lambda tmp: out.to_csv(tmp, index=False, float_format="%.17g"))


def read_episodes_csv(path: str | os.PathLike[str]) -> pd.DataFrame:
    """Read an episodes CSV back with the table's dtypes (``bumper`` int, ``open`` bool)."""
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


def write_timeseries_parquet(df: pd.DataFrame, path: str | os.PathLike[str]) -> Path:
    """Write the time series to Parquet (pyarrow), with column units in the schema.

    The schema metadata key :data:`UNITS_METADATA_KEY` holds a JSON object
    ``{column: unit}`` (units from :func:`column_unit`).
    """
    table = pa.Table.from_pandas(df, preserve_index=False)
    units = {str(c): column_unit(str(c)) for c in df.columns}
    meta = dict(table.schema.metadata or {})
    meta[UNITS_METADATA_KEY.encode()] = json.dumps(units).encode()
    table = table.replace_schema_metadata(meta)
    return atomic_write(path, lambda tmp: pq.write_table(table, tmp))


def read_timeseries_parquet(path: str | os.PathLike[str]) -> pd.DataFrame:
    """Read a time series written by :func:`write_timeseries_parquet`."""
    return pq.read_table(path).to_pandas()


def read_timeseries_units(path: str | os.PathLike[str]) -> dict[str, str]:
    """Column units stored in a time-series Parquet file (empty if absent)."""
    meta = pq.read_schema(path).metadata or {}
    raw = meta.get(UNITS_METADATA_KEY.encode())
    return json.loads(raw) if raw else {}


def read_result(directory: str | os.PathLike[str]) -> SimulationResult:
    """Load a result folder written by :meth:`SimulationResult.write`.

    Returns a :class:`~quadimpact.result.SimulationResult` with ``summary``,
    ``episodes``, ``timeseries``, and ``references``/``stats`` taken from the
    summary (empty dicts if absent); ``scenario`` is ``None``. Enough to
    re-plot the folder.
    """
    from quadimpact.result import SimulationResult

    d = Path(directory)
    if not d.is_dir():
        raise FileNotFoundError(f"result folder not found: {d}")
    summary = read_summary_json(d / SUMMARY_JSON)
    episodes = read_episodes_csv(d / EPISODES_CSV)
    timeseries = read_timeseries_parquet(d / TIMESERIES_PARQUET)
    references = dict(summary.get("references") or {})
    stats = dict(summary.get("stats") or {})
    return SimulationResult(
        summary=summary,
        episodes=episodes,
        timeseries=timeseries,
        references=references,
        scenario=None,
        stats=stats,
    )
