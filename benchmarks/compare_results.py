"""Two result folders compared bit for bit: every table and every summary, costs aside.

Run: ``python benchmarks/compare_results.py DIR_A DIR_B``

For every Parquet file and every ``summary.json`` under ``DIR_A``, the file of the
same path under ``DIR_B`` must hold the same columns and rows, floats compared by
their bits (NaN equal to NaN), except what a run costs (columns and keys named
``cost``, ``cpu``, ``wall`` or ``elapsed``: times, not results). Prints one line per
file that differs (its first differing column or key) and a count; exits 1 when
any differs or is missing. ``--only-common`` compares only the columns and keys
both folders have (two versions, one of which added a summary key), and
only the files both have (one run with the flight logs, one without).

What it is for: checking that results do not depend on the machine, e.g.
``quadimpact reproduce`` once as is and once with NumPy's dispatch limited to
AVX2 (``NPY_DISABLE_CPU_FEATURES="$(python tests/cpu_dispatch.py)"``) and
OpenBLAS on other kernels (``OPENBLAS_CORETYPE=Haswell``), or two checkouts
that should give the same results.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

TIMES = ("cost", "cpu", "wall", "elapsed", "quadimpact_version", "created")
#: Set by ``--only-common``: compare only what both sides have.
ONLY_COMMON = False


def _is_time(name: str) -> bool:
    return any(t in name.lower() for t in TIMES)


def _same_value(a: Any, b: Any) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        return (math.isnan(a) and math.isnan(b)) or np.float64(a).tobytes() == np.float64(
            b
        ).tobytes()
    return a == b


def _json_diff(a: Any, b: Any, path: str = "") -> str | None:
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if _is_time(k):
                continue
            if k not in a or k not in b:
                if ONLY_COMMON:
                    continue
                return f"{path}{k}: only in one"
            d = _json_diff(a[k], b[k], f"{path}{k}.")
            if d:
                return d
        return None
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return f"{path}: lengths {len(a)} and {len(b)}"
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            d = _json_diff(x, y, f"{path}[{i}].")
            if d:
                return d
        return None
    return None if _same_value(a, b) else f"{path.rstrip('.')}: {a!r} != {b!r}"


def _frame_diff(a: pd.DataFrame, b: pd.DataFrame) -> str | None:
    cols = [c for c in a.columns if not _is_time(str(c))]
    if ONLY_COMMON:
        cols = [c for c in cols if c in b.columns]
    elif sorted(cols) != sorted(c for c in b.columns if not _is_time(str(c))):
        return "columns differ"
    if len(a) != len(b):
        return f"rows {len(a)} and {len(b)}"
    for c in cols:
        x, y = a[c].to_numpy(), b[c].to_numpy()
        if x.dtype.kind == "f" and y.dtype.kind == "f":
            same = (x.view(np.int64) == y.view(np.int64)) | (np.isnan(x) & np.isnan(y))
            if not same.all():
                i = int(np.flatnonzero(~same)[0])
                return f"{c} row {i}: {x[i]!r} != {y[i]!r}"
        elif not a[c].equals(b[c]):
            return f"{c}"
    return None


def compare(first: Path, second: Path) -> int:
    """Print the files that differ; return how many differ or are missing."""
    bad = checked = 0
    for path in sorted(first.rglob("*")):
        rel = path.relative_to(first)
        other = second / rel
        if ONLY_COMMON and not other.is_file():
            continue
        if path.suffix == ".parquet":
            d = (
                _frame_diff(pd.read_parquet(path), pd.read_parquet(other))
                if other.is_file()
                else "missing"
            )
        elif path.name == "summary.json":
            d = (
                _json_diff(json.loads(path.read_text()), json.loads(other.read_text()))
                if other.is_file()
                else "missing"
            )
        else:
            continue
        checked += 1
        if d:
            bad += 1
            print(f"{rel}: {d}")
    print(f"{checked} files compared, {bad} differ")
    return bad


if __name__ == "__main__":
    args = sys.argv[1:]
    if "--only-common" in args:
        ONLY_COMMON = True
        args.remove("--only-common")
    if len(args) != 2:
        sys.exit(__doc__)
    sys.exit(1 if compare(Path(args[0]), Path(args[1])) else 0)
