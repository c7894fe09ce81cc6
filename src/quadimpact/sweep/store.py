"""The sweep's Parquet store: the table's schema, its rows, part files, resume and merge.

The run rows (:func:`flatten_summary`, :data:`SUMMARY_COLUMNS`) are written in
small atomic part files as the runs finish (:class:`PartWriter`), each named
after the SHA-256 of its bytes (``part-000012-<16 hex digits>.parquet``) and
with Parquet's page checksums. A sweep run again checks every part fully
(checksum, schema, every value decoded) and ``runs.parquet`` row group by row
group; what fails is redone, with a warning naming the file
(:func:`scan_done`). Finally everything is merged, sorted by ``run_id``, into
``runs.parquet`` (:func:`consolidate`). ``sweep.json`` records the sweep
(:func:`check_folder`), and a lock keeps two sweeps from writing one folder
(:func:`folder_lock`)."""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import re
import time
from collections.abc import Callable, Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any

from quadimpact.errors import InputError, one_line
from quadimpact.results.files import atomic_write
from quadimpact.results.schema import SUMMARY_KEYS
from quadimpact.sweep.spec import SweepSpec
from quadimpact.sweep.values import canonical, plain

FLUSH_ROWS = 1024
"""A part file is written when this many completed runs are waiting..."""
FLUSH_SECONDS = 1.0
"""... or when the oldest waiting run completed this long ago (so a kill loses
the runs in flight plus at most about this much finished work)."""
CONSOLIDATE_WINDOW = 20_000
"""Rows per row group of ``runs.parquet`` (the merge reads one window at a time)."""
FORMAT_VERSION = 1

# Column kinds: f float64, i int64, b bool, s string, j JSON text.

_ARROW_KINDS = ("f", "i", "b", "s", "j")


def _is_time_measurement(key: str) -> bool:
    """Flattened summary keys that measure wall-clock time (not deterministic)."""
    return key.startswith("integrator__") and "time" in key


SUMMARY_COLUMNS: tuple[tuple[str, str], ...] = (
    *((k.name, k.kind) for k in SUMMARY_KEYS if not _is_time_measurement(k.name)),
    ("summary_extra", "j"),
)
"""Summary columns of ``runs.parquet`` and their kinds (``f`` float64, ``i``
nullable int64, ``b`` nullable bool, ``s`` string, ``j`` JSON text): the
summary schema (``quadimpact.results.schema.SUMMARY_KEYS``) without the
wall-clock timings, so that a table is the same whatever ran it. Summary keys
outside the schema land, as JSON, in ``summary_extra`` (null when none)."""

_SUMMARY_KIND = dict(SUMMARY_COLUMNS)

COST_COLUMNS: tuple[str, ...] = tuple(k for k, _ in SUMMARY_COLUMNS if k.startswith("cost__"))
"""The columns that measure what a run cost (CPU time where it ran): the only ones
that differ between two runs of the same sweep (docs/RESULTS.md)."""


def without_costs(table: Any) -> Any:
    """A sweep table (pandas or Arrow) without :data:`COST_COLUMNS`: what is the same bit
    for bit however and wherever the sweep ran."""
    names = [c for c in COST_COLUMNS if c in getattr(table, "column_names", table.columns)]
    if hasattr(table, "drop_columns"):  # a pyarrow.Table
        return table.drop_columns(names)
    return table.drop(columns=names)


# ------------------------------------------------------------ the worker
def flatten_summary(summary: Mapping[str, Any], skip: Iterable[str] = ()) -> dict[str, Any]:
    """One ``runs.parquet`` row (without run_id and inputs) from a run's summary.

    Nested tables are joined with ``__``; lists become JSON text; wall-clock
    timings are dropped; keys outside :data:`SUMMARY_COLUMNS` go, as JSON, to
    ``summary_extra``; missing keys are null. Values take their column's type.
    The row's keys are in the order of :data:`SUMMARY_COLUMNS`.
    """
    names = tuple(skip)
    plan = _ROW_PLANS.get(names)
    if plan is None:
        if len(_ROW_PLANS) >= 64:  # a process that flattens for many sweeps
            _ROW_PLANS.clear()
        plan = _ROW_PLANS[names] = _row_plan(set(names))
    template, kinds = plan
    row = template.copy()
    extra: dict[str, Any] = {}

    def walk(prefix: str, table: Mapping[str, Any]) -> None:
        for k, value in table.items():
            key = prefix + k if prefix else k
            t = type(value)
            if t is dict or (t not in _LEAF_TYPES and isinstance(value, Mapping)):
                walk(key + "__", value)
                continue
            kind = kinds.get(key)
            if kind is None:  # skipped (an input), a timing, or outside the columns
                if key not in names and not _is_time_measurement(key):
                    extra[key] = plain(value)
            elif kind == "x":  # summary_extra's own key, kept as extra
                extra[key] = plain(value)
            elif value is None:  # the common cases of _typed, inline
                pass
            elif t is float and kind == "f":
                row[key] = None if value != value else value
            elif t is _EXACT_TYPE.get(kind):
                row[key] = value
            elif t is tuple:  # the same tuples run after run (model options): typed once
                row[key] = _typed_tuple(value, kind)
            else:
                row[key] = _typed(value, kind)

    walk("", summary)
    row["summary_extra"] = canonical(extra) if extra else None
    return row


_ROW_PLANS: dict[tuple[str, ...], tuple[dict[str, None], dict[str, str]]] = {}
"""Per set of skipped (input) columns: a row of nulls, and each row key's column kind
(``"x"`` for ``summary_extra``, whose own key is kept as extra)."""
_TYPED_TUPLES: dict[tuple[str, str], Any] = {}


def _row_plan(skip: set[str]) -> tuple[dict[str, None], dict[str, str]]:
    """Every summary column not skipped, null (timings are not columns), and its kind."""
    template = {key: None for key, _kind in SUMMARY_COLUMNS if key not in skip}
    kinds = {key: "x" if key == "summary_extra" else _SUMMARY_KIND[key] for key in template}
    return template, kinds


def _typed_tuple(value: tuple[Any, ...], kind: str) -> Any:
    """:func:`_typed` of a tuple, kept for the next rows when its items are plain.

    Kept under its ``repr`` (which tells ``1`` from ``1.0`` and ``0.0`` from
    ``-0.0``, unlike ``==``); at most 256 kept.
    """
    if not all(type(v) in _PLAIN_TYPES for v in value):
        return _typed(value, kind)
    key = (kind, repr(value))
    typed = _TYPED_TUPLES.get(key)
    if typed is None:
        typed = _typed(value, kind)
        if len(_TYPED_TUPLES) >= 256:
            _TYPED_TUPLES.clear()
        _TYPED_TUPLES[key] = typed
    return typed


_PLAIN_TYPES = (float, int, str, bool)
_LEAF_TYPES = frozenset((float, int, str, bool, list, type(None)))
_EXACT_TYPE = {"i": int, "b": bool, "s": str}
_JSON_TEXT = json.JSONEncoder(separators=(",", ":"))  # = json.dumps(v, separators=...)


def _plain_list(value: Any) -> bool:
    return type(value) is list and all(type(v) in _PLAIN_TYPES for v in value)


def _typed(value: Any, kind: str) -> Any:
    if value is None:
        return None
    if type(value) not in _PLAIN_TYPES and not _plain_list(value):
        value = plain(value)
    if kind == "f":
        return None if isinstance(value, float) and math.isnan(value) else float(value)
    if kind == "i":
        return int(value)
    if kind == "b":
        return bool(value)
    if kind == "s":
        return str(value)
    return _JSON_TEXT.encode(value)


def failed_row(reason: str, skip: Iterable[str]) -> dict[str, Any]:
    from quadimpact import __version__

    row = flatten_summary({}, skip)
    if "status" in row:
        row["status"] = "failed"
    if "reason" in row:
        row["reason"] = one_line(reason)
    if "quadimpact_version" in row:
        row["quadimpact_version"] = __version__
    return row


# ---------------------------------------------------------------- storage
def schema_of(spec: SweepSpec) -> Any:
    import pyarrow as pa

    types = {
        "f": pa.float64(),
        "i": pa.int64(),
        "b": pa.bool_(),
        "s": pa.string(),
        "j": pa.string(),
    }
    fields = [pa.field("run_id", pa.int64(), nullable=False)]
    fields += [pa.field(k, types[kind]) for k, kind in spec.columns.items()]
    fields += [pa.field(k, types[kind]) for k, kind in SUMMARY_COLUMNS if k not in spec.columns]
    meta = {
        "quadimpact.sweep": canonical(
            {"inputs": list(spec.columns), "n_runs": spec.n_runs, "format": FORMAT_VERSION}
        )
    }
    return pa.schema(fields, metadata=meta)


def _to_pandas(table: Any) -> Any:
    import pandas as pd
    import pyarrow as pa

    mapping = {pa.int64(): pd.Int64Dtype(), pa.bool_(): pd.BooleanDtype()}
    df = table.to_pandas(types_mapper=mapping.get)
    # run_id is never null: a plain int64 column
    if "run_id" in df:
        df["run_id"] = df["run_id"].astype("int64")
    return df


def read_runs(out_dir: str | os.PathLike[str]) -> Any:
    """Read ``DIR/runs.parquet`` as a pandas DataFrame (nullable ints and bools).

    Integer columns are ``Int64`` and booleans ``boolean`` (so a failed run's
    nulls never change a column's type); floats are float64 (null as NaN);
    text is object (null as None).
    """
    import pyarrow.parquet as pq

    path = Path(out_dir) / "runs.parquet"
    if not path.is_file():
        raise InputError(f"{path}: file not found")
    return _to_pandas(pq.read_table(path))


class PartWriter:
    """Buffers finished rows and writes them as atomic part files."""

    def __init__(self, parts: Path, schema: Any, start_seq: int) -> None:
        self.parts = parts
        self.schema = schema
        self.seq = start_seq
        self.buffer: list[dict[str, Any]] = []
        self.oldest = 0.0
        self.rows_written = 0

    def add(self, rows: list[dict[str, Any]]) -> None:
        """Buffer ``rows`` (may be empty: a clock tick) and write a part when due."""
        if rows:
            if not self.buffer:
                self.oldest = time.monotonic()
            self.buffer.extend(rows)
        if self.buffer and (
            len(self.buffer) >= FLUSH_ROWS or time.monotonic() - self.oldest >= FLUSH_SECONDS
        ):
            self.flush()

    def flush(self) -> None:
        """Write the waiting rows as one part."""
        if not self.buffer:
            return
        import pyarrow as pa

        self.write(pa.Table.from_pylist(self.buffer, schema=self.schema).sort_by("run_id"))
        self.buffer = []

    def write(self, table: Any) -> Path:
        """Write ``table`` as the next part: checksummed, atomic and durable."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        stream = pa.BufferOutputStream()
        pq.write_table(table, stream, write_page_checksum=True)
        data = stream.getvalue().to_pybytes()
        self.seq += 1
        path = self.parts / f"part-{self.seq:06d}-{_digest(data)}.parquet"
        atomic_write(path, lambda tmp: tmp.write_bytes(data), durable=True)
        self.rows_written += table.num_rows
        return path


def _digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()[:16]


_PART_RE = re.compile(r"^part-(\d+)(?:-([0-9a-f]{16}))?\.parquet$")
"""A part's name: its number and the start of its SHA-256 (absent in older parts)."""


class BadFile(Exception):
    """A part or table that fails its checks (the message says which check)."""


def _check_schema(found: Any, schema: Any) -> None:
    expected = {f.name: f.type for f in schema}
    have = {f.name: f.type for f in found}
    for name, kind in expected.items():
        if name not in have:
            raise BadFile(f"column {name!r} missing")
        if have[name] != kind:
            raise BadFile(f"column {name!r} is {have[name]}, expected {kind}")
    extra = sorted(set(have) - set(expected))
    if extra:
        raise BadFile(f"unexpected column {extra[0]!r}")


def _check_ids(table: Any, n_runs: int) -> Any:
    ids = table.column("run_id")
    if ids.null_count:
        raise BadFile("null run_id")
    ids = ids.to_numpy()
    if len(ids) and (ids.min() < 0 or ids.max() >= n_runs):
        raise BadFile(f"run_id outside 0..{n_runs - 1}")
    return ids


def check_part(path: Path, schema: Any, n_runs: int) -> Any:
    """The run_ids of a part that passes every check; else :class:`BadFile`.

    Checks: its bytes against the checksum in its name, its schema (every
    column, with its type, and no other), every page decoded with its
    Parquet checksum verified, run_ids in range.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    match = _PART_RE.match(path.name)
    data = path.read_bytes()
    if match and match.group(2) and _digest(data) != match.group(2):
        raise BadFile("its checksum does not match its content")
    try:
        file = pq.ParquetFile(pa.BufferReader(data), page_checksum_verification=True)
        _check_schema(file.schema_arrow, schema)
        table = file.read()
    except BadFile:
        raise
    except Exception as exc:
        raise BadFile(one_line(f"{type(exc).__name__}: {exc}")) from None
    return _check_ids(table, n_runs)


def _check_table(path: Path, schema: Any, n_runs: int, writer: PartWriter) -> tuple[Any, str]:
    """run_ids of ``runs.parquet`` that pass the checks, and what failed ('' if nothing).

    Checked row group by row group (flat memory); if one fails, the good ones
    are written as new parts and ``runs.parquet`` is removed. A file that
    cannot be opened at all (empty, truncated, not Parquet) or has another
    schema is removed too: its runs are redone, and the merge rebuilds it.
    """
    import numpy as np
    import pyarrow.parquet as pq

    try:
        file = pq.ParquetFile(path, page_checksum_verification=True)
    except Exception as exc:  # empty, truncated, not Parquet: nothing of it can be kept
        path.unlink()
        return np.zeros(0, dtype=np.int64), one_line(f"{type(exc).__name__}: {exc}")
    try:
        _check_schema(file.schema_arrow, schema)
    except Exception as exc:
        file.close()
        path.unlink()  # a table of another schema cannot be merged: its runs are redone
        detail = str(exc) if isinstance(exc, BadFile) else f"{type(exc).__name__}: {exc}"
        return np.zeros(0, dtype=np.int64), one_line(detail)
    good, problem = [], ""
    with file:
        for i in range(file.num_row_groups):
            try:
                group = file.read_row_group(i)
                good.append((group, _check_ids(group, n_runs)))
            except Exception as exc:
                detail = str(exc) if isinstance(exc, BadFile) else f"{type(exc).__name__}: {exc}"
                problem = problem or one_line(f"row group {i}: {detail}")
    if not problem:
        return np.concatenate([ids for _, ids in good] or [np.zeros(0, np.int64)]), ""
    for group, _ids in good:
        writer.write(group.cast(schema))
    path.unlink()
    return np.concatenate([ids for _, ids in good] or [np.zeros(0, np.int64)]), problem


def scan_done(out: Path, n_runs: int, schema: Any, warn: Callable[[str], None]) -> tuple[Any, int]:
    """Mask of the run_ids already written (runs.parquet and parts), and the last part number.

    Every part and ``runs.parquet`` is checked (:func:`check_part`); a part
    that fails is removed, and so are the unreadable row groups of
    ``runs.parquet`` (its good ones become parts): their runs will be redone,
    and ``warn`` is told the file and what failed.
    """
    import numpy as np

    done = np.zeros(n_runs, dtype=bool)
    parts = out / "parts"
    last = 0
    found = []
    if parts.is_dir():
        for p in sorted(parts.iterdir()):
            if p.name.startswith(".") and p.name.endswith(".tmp"):
                p.unlink(missing_ok=True)  # left by a kill mid-write
            elif m := _PART_RE.match(p.name):
                last = max(last, int(m.group(1)))
                found.append(p)
    for p in found:
        try:
            done[check_part(p, schema, n_runs)] = True
        except BadFile as exc:
            warn(f"{p}: {exc}; its runs will be redone")
            p.unlink(missing_ok=True)
    table = out / "runs.parquet"
    if table.is_file():
        writer = PartWriter(parts, schema, last)
        ids, problem = _check_table(table, schema, n_runs, writer)
        done[ids] = True
        last = writer.seq
        if problem:
            warn(
                f"{table}: {problem}; its {n_runs - int(done.sum())} missing runs will be redone"
                + (f" (the {len(ids)} readable ones are kept)" if len(ids) else "")
            )
    return done, last


def consolidate(out: Path, schema: Any, n_runs: int) -> None:
    """Merge runs.parquet and the parts into runs.parquet, sorted, one window at a time."""
    import numpy as np
    import pyarrow as pa
    import pyarrow.parquet as pq

    parts_dir = out / "parts"
    parts = (
        sorted(p for p in parts_dir.iterdir() if _PART_RE.match(p.name))
        if parts_dir.is_dir()
        else []
    )
    target = out / "runs.parquet"
    if not parts and target.is_file():
        meta = pq.read_metadata(target)
        if meta.num_rows == n_runs and pq.read_schema(target).equals(schema, check_metadata=False):
            return
    sources = ([target] if target.is_file() else []) + parts

    def read(src: Path, **kwargs: Any) -> Any:
        try:
            return pq.read_table(src, **kwargs)
        except Exception as exc:
            raise RuntimeError(
                f"{src}: unreadable ({type(exc).__name__}: {one_line(str(exc))}); run the "
                "sweep again: the file will be checked and its runs redone"
            ) from None

    spans = []
    for src in sources:
        ids = read(src, columns=["run_id"]).column("run_id").to_numpy()
        if len(ids):
            spans.append((src, int(ids.min()), int(ids.max())))

    def merge(tmp: Path) -> None:
        total = 0
        with pq.ParquetWriter(tmp, schema, write_page_checksum=True) as writer:
            for lo in range(0, n_runs, CONSOLIDATE_WINDOW):
                hi = lo + CONSOLIDATE_WINDOW
                pieces = []
                for src, a, b in spans:
                    if b < lo or a >= hi:
                        continue
                    t = read(src, filters=[("run_id", ">=", lo), ("run_id", "<", hi)])
                    pieces.append(t.select(schema.names).cast(schema))
                if not pieces:
                    continue
                t = pa.concat_tables(pieces).sort_by("run_id")
                ids = t.column("run_id").to_numpy()
                keep = np.ones(len(ids), dtype=bool)
                keep[1:] = ids[1:] != ids[:-1]
                if not keep.all():
                    t = t.filter(pa.array(keep))
                total += t.num_rows
                writer.write_table(t, row_group_size=CONSOLIDATE_WINDOW)
        if total != n_runs:
            raise RuntimeError(f"{out}: merged {total} runs, expected {n_runs}")

    atomic_write(target, merge, durable=True)
    for p in parts:
        p.unlink(missing_ok=True)


def finished_before(out: Path) -> bool:
    """Whether ``out`` looks like a finished sweep: ``runs.parquet`` and no part (a guess,
    for what to ready before the sweep starts; :func:`scan_done` checks)."""
    parts = out / "parts"
    return (out / "runs.parquet").is_file() and not (
        parts.is_dir() and any(parts.glob("part-*.parquet"))
    )


def check_folder(out: Path, spec: SweepSpec, schema: Any) -> None:
    """Write sweep.json, or check that the folder holds this very sweep."""
    from quadimpact import __version__

    record = {
        "format": FORMAT_VERSION,
        "quadimpact_version": __version__,
        "n_runs": spec.n_runs,
        "fingerprint": spec.fingerprint(),
        "columns": [[f.name, str(f.type)] for f in schema],
        "spec": spec.to_dict(),
    }
    path = out / "sweep.json"
    if path.is_file():
        try:
            old = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            raise InputError(
                f"{path}: unreadable ({exc}); delete the folder to start over"
            ) from None
        if old != json.loads(canonical(record)):
            differs = [
                k
                for k in ("spec", "quadimpact_version", "n_runs", "columns", "fingerprint")
                if old.get(k) != json.loads(canonical(record)).get(k)
            ]
            detail = differs[0] if differs else "format"
            if detail == "spec":
                keys = [
                    k
                    for k in ("base", "grid", "runs", "sample")
                    if (old.get("spec") or {}).get(k) != json.loads(canonical(spec.to_dict()))[k]
                ]
                detail = " or ".join(keys or ["spec"])
            raise InputError(
                f"{out}: holds a different sweep (not the same {detail}, see sweep.json); "
                "use another output folder, or delete this one to start over"
            )
        return
    if (out / "runs.parquet").exists() or any((out / "parts").glob("part-*.parquet")):
        raise InputError(f"{out}: has sweep results but no sweep.json; use another output folder")
    text = _record_text(record) + "\n"
    atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8"), durable=True)


def _record_text(value: Any, depth: int = 0) -> str:
    """``sweep.json``'s text: keys sorted, one key per line down to the spec's fields, and
    one run per line in a list of runs (a million-run study's is written by the C
    encoder, not by ``json``'s indenting one in Python, which took 0.1 ms a run)."""
    pad, inner = " " * depth, " " * (depth + 1)
    if isinstance(value, dict) and value and depth < 3:
        items = [f"{inner}{json.dumps(str(k))}: {_record_text(value[k], depth + 1)}" for k in
                 sorted(value)]  # fmt: skip
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(value, list) and value and depth < 3:
        return "[\n" + ",\n".join(inner + _record_text(v, 3) for v in value) + "\n" + pad + "]"
    return json.dumps(value, sort_keys=True, allow_nan=False, separators=(", ", ": "))


@contextlib.contextmanager
def folder_lock(out: Path) -> Iterator[None]:
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock
        yield
        return
    fd = os.open(out / ".lock", os.O_RDWR | os.O_CREAT, 0o666)  # the umask decides
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise InputError(f"{out}: another sweep is writing to this folder") from None
        yield
    finally:
        os.close(fd)
