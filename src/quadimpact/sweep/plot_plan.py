"""Which plots ``quadimpact sweep`` draws for a sweep, and whether they are already drawn.

:func:`plot_plan` says, from the sweep alone, which files ``DIR/plots`` gets
(:func:`quadimpact.sweep.plots.auto_plots` draws them); :func:`drawn_plots`
reads ``DIR/plots/.drawn.json``, which :func:`record_plots` writes after
drawing: the table (``runs.parquet``'s size and modification time) and the
drawing code they were drawn from. A rerun of a finished sweep whose plots
are still there, drawn from the same table by the same code, does not draw
them again (nor import Matplotlib). No Matplotlib or pandas here.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from quadimpact.results.files import atomic_write

__all__ = ["MAX_AUTO_RUNS", "choose_plot_fields", "drawn_plots", "plot_plan", "record_plots"]

MAX_AUTO_RUNS = 50_000
"""``auto_plots`` does nothing for larger sweeps (keep ``quadimpact sweep`` cheap)."""
RECORD = ".drawn.json"
"""What ``DIR/plots`` was drawn from (:func:`record_plots`)."""
#: The modules whose code draws the plots (their bytes are part of the record).
DRAWING_CODE = ("sweep/plots.py", "sweep/plot_plan.py", "results/sweep_figures.py",
                "results/figures.py")  # fmt: skip


def choose_plot_fields(
    columns: dict[str, str], grid: dict[str, Sequence[Any]]
) -> tuple[str, str | None, str | None] | None:
    """(x, by, facet) for the automatic plots of a grid, or None if not plottable.

    ``x`` is the numeric varied field with the most values; with two other
    varied fields, the one with fewer values (at most 4) makes the panels.
    """
    varying = [k for k, v in grid.items() if len(v) > 1]
    numeric = [k for k in varying if columns.get(k) == "f"]
    if not numeric or len(varying) > 3:
        return None
    x = max(numeric, key=lambda k: (len(grid[k]), -varying.index(k)))
    rest = [k for k in varying if k != x]
    by = facet = None
    if len(rest) == 2:
        facet = min(rest, key=lambda k: (len(grid[k]), rest.index(k)))
        if len(grid[facet]) > 4:
            return None
        by = rest[0] if rest[1] == facet else rest[1]
    elif len(rest) == 1:
        by = rest[0]
    return x, by, facet


def plot_plan(spec: Any) -> tuple[tuple[str, str | None, str | None] | None, list[str]]:
    """The fields of a sweep's automatic plots and their file names in ``DIR/plots``.

    For a grid (no runs list, sample or drawn trials) of at most :data:`MAX_AUTO_RUNS` runs
    and one to three varied fields, at least one numeric
    (:func:`choose_plot_fields`): ``delta_init_m_vs_<x>.png`` if ``by`` has at
    most 12 values, and ``types_<x>_<by>.png`` with two or more varied fields
    (``by`` with at most 200 values). Otherwise ``(None, [])``.
    """
    drawn = spec.sample is not None or spec.trials is not None
    if spec.runs or drawn or spec.n_runs > MAX_AUTO_RUNS:
        return None, []
    choice = choose_plot_fields(spec.columns, spec.grid)
    if choice is None:
        return None, []
    x, by, _facet = choice
    names = []
    if by is None or len(spec.grid[by]) <= 12:
        names.append(f"delta_init_m_vs_{x}.png")
    if by is not None and len(spec.grid[by]) <= 200:
        names.append(f"types_{x}_{by}.png")
    return choice, names


def _source() -> dict[str, Any]:
    """What the plots of ``DIR`` are drawn from: the table's size and time, and the code."""
    root = Path(__file__).resolve().parents[1]
    code = hashlib.sha256()
    for name in DRAWING_CODE:
        code.update((root / name).read_bytes())
    return {"code_sha256": code.hexdigest()}


def _table(out: Path) -> list[int] | None:
    try:
        st = (out / "runs.parquet").stat()
    except OSError:
        return None
    return [st.st_size, st.st_mtime_ns]


def drawn_plots(out_dir: str | os.PathLike[str], names: Sequence[str]) -> list[Path] | None:
    """The plots ``names`` in ``DIR/plots`` if drawn from this very table by this code; else None.

    None also when the record is missing or unreadable, or one of the files is gone.
    """
    out = Path(out_dir)
    try:
        record = json.loads((out / "plots" / RECORD).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    table = _table(out)
    if (
        table is None
        or not isinstance(record, dict)
        or record.get("table") != table
        or record.get("source") != _source()
        or record.get("files") != list(names)
    ):
        return None
    paths = [out / "plots" / name for name in names]
    return paths if all(p.is_file() for p in paths) else None


def record_plots(out_dir: str | os.PathLike[str], paths: Sequence[Path]) -> None:
    """Write ``DIR/plots/.drawn.json``: the plots just drawn, their table and code."""
    out = Path(out_dir)
    record = {"files": [p.name for p in paths], "table": _table(out), "source": _source()}
    text = json.dumps(record, indent=1) + "\n"
    atomic_write(out / "plots" / RECORD, lambda tmp: tmp.write_text(text, encoding="utf-8"))
