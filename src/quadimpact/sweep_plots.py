"""Plots of a sweep table (``runs.parquet``): a metric against a swept field, and a type map.

* :func:`plot_metric`: a metric (default ``delta_init_m``, drawn in mm)
  against one swept field, one curve per value of a second field, one panel
  per value of a third: the paper's Figure 4 is
  ``plot_metric(t, "inclination_deg", by="speed_m_s", facet="heading_deg")``.
* :func:`plot_type_map`: the response type (A, B, C, D, Other; failed runs
  black) over two fields, one colour per type, with the number of subsequent
  impacts written in the cells when the grid is small (the paper's Table II).

Figures are :class:`matplotlib.figure.Figure` objects on an Agg canvas (no
pyplot state); with ``path`` they are also written as PNG (atomically).
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from quadimpact.errors import InputError
from quadimpact.plots import save_figure

__all__ = ["TYPE_COLORS", "plot_metric", "plot_type_map", "auto_plots"]

#: Fill colour of each response type in type maps (failed runs: black).
TYPE_COLORS: dict[str, str] = {
    "A": "#4daf4a",
    "B": "#377eb8",
    "C": "#ff7f00",
    "D": "#e41a1c",
    "Other": "#999999",
    "failed": "#000000",
}
_TYPES = list(TYPE_COLORS)
# metric -> (axis label, scale)
_LABELS = {
    "delta_init_m": ("δ_init (mm)", 1e3),
    "max_penetration_m": ("max penetration (mm)", 1e3),
    "peak_force_n": ("peak force (N)", 1.0),
}
MAX_TEXT_CELLS = 400
"""Type maps write n_subsequent_impacts in the cells up to this many cells per panel."""
MAX_AUTO_RUNS = 50_000
"""``auto_plots`` does nothing for larger sweeps (keep ``quadimpact sweep`` cheap)."""


def _new_figure(width_in: float, height_in: float) -> Figure:
    fig = Figure(figsize=(width_in, height_in), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _fmt(value: Any) -> str:
    if isinstance(value, (float, np.floating)):
        return f"{float(value):g}"
    return str(value)


def _check_columns(table: pd.DataFrame, *names: str | None) -> None:
    for name in names:
        if name is not None and name not in table.columns:
            raise InputError(f"plot: {name}: no such column in the sweep table")


def _levels(series: pd.Series) -> list[Any]:
    values = series.dropna().unique().tolist()
    try:
        return sorted(values)
    except TypeError:
        return sorted(values, key=str)


def _panels(table: pd.DataFrame, facet: str | None) -> list[tuple[Any, pd.DataFrame]]:
    if facet is None:
        return [(None, table)]
    return [(v, table[table[facet] == v]) for v in _levels(table[facet])]


def plot_metric(
    table: pd.DataFrame,
    x: str,
    metric: str = "delta_init_m",
    by: str | None = None,
    path: str | os.PathLike[str] | None = None,
    facet: str | None = None,
    *,
    title: str | None = None,
) -> Figure:
    """A metric against a swept field, one curve per value of ``by``, one panel per ``facet``.

    Parameters
    ----------
    table : pandas.DataFrame
        A sweep table (``quadimpact.sweep.read_runs``). Runs must differ only
        in ``x``, ``by`` and ``facet`` (filter the table first otherwise).
    x : str
        Swept field on the horizontal axis.
    metric : str
        Column on the vertical axis (``delta_init_m`` is drawn in mm).
        Failed runs (null metric) leave gaps.
    by : str, optional
        One curve per value of this field.
    path : path-like, optional
        Also write the figure there as PNG.
    facet : str, optional
        One panel per value of this field (side by side, shared y axis).
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    _check_columns(table, x, metric, by, facet)
    label, scale = _LABELS.get(metric, (metric, 1.0))
    panels = _panels(table, facet)
    if not panels:
        raise InputError(f"plot: {facet}: no values")
    fig = _new_figure(1.0 + 4.2 * len(panels), 3.6)
    axes = fig.subplots(1, len(panels), sharey=True, squeeze=False)[0]
    for ax, (fv, sub) in zip(axes, panels, strict=True):
        groups = [(None, sub)] if by is None else [(v, sub[sub[by] == v]) for v in _levels(sub[by])]
        for bv, g in groups:
            g = g.sort_values(x)
            y = pd.to_numeric(g[metric], errors="coerce").to_numpy(dtype=float) * scale
            ax.plot(
                g[x].to_numpy(),
                y,
                marker="o",
                markersize=3,
                linewidth=1.2,
                label=None if bv is None else f"{by} = {_fmt(bv)}",
            )
        ax.set_xlabel(x)
        if fv is not None:
            ax.set_title(f"{facet} = {_fmt(fv)}", fontsize=10)
        ax.grid(True, alpha=0.3)
        if by is not None:
            ax.legend(fontsize=8)
    axes[0].set_ylabel(label)
    if title:
        fig.suptitle(title)
    if path is not None:
        save_figure(fig, path)
    return fig


def _mode(values: pd.Series) -> Any:
    counts = values.value_counts(dropna=False)
    return counts.index[0] if len(counts) else None


def plot_type_map(
    table: pd.DataFrame,
    x: str,
    y: str,
    path: str | os.PathLike[str] | None = None,
    facet: str | None = None,
    *,
    title: str | None = None,
) -> Figure:
    """Response type over two fields (categorical colours), one panel per ``facet`` value.

    Parameters
    ----------
    table : pandas.DataFrame
        A sweep table with ``response_type``, ``status`` and ``n_subsequent_impacts``.
    x, y : str
        Fields along the horizontal and vertical axes (each value one cell,
        evenly spaced, in sorted order).
    path : path-like, optional
        Also write the figure there as PNG.
    facet : str, optional
        One panel (stacked vertically) per value of this field.
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure

    Notes
    -----
    A cell holding several runs (other fields varying) shows the most
    frequent type. Cells show ``n_subsequent_impacts`` (the paper's Table II
    count) when a panel has at most :data:`MAX_TEXT_CELLS` cells.
    """
    _check_columns(table, x, y, facet, "response_type", "status")
    xs, ys = _levels(table[x]), _levels(table[y])
    if not xs or not ys:
        raise InputError("plot: type map of an empty table")
    panels = _panels(table, facet)
    width = min(18.0, 1.8 + 0.32 * len(xs))
    height = 0.9 + len(panels) * (0.6 + 0.32 * len(ys))
    fig = _new_figure(width, height + 0.4)
    axes = fig.subplots(len(panels), 1, squeeze=False)[:, 0]
    cmap = ListedColormap([TYPE_COLORS[t] for t in _TYPES])
    col = {v: i for i, v in enumerate(xs)}
    row = {v: i for i, v in enumerate(ys)}
    present: set[str] = set()
    show_text = len(xs) * len(ys) <= MAX_TEXT_CELLS
    fontsize = max(5.0, min(8.0, 9.0 - 0.05 * len(xs)))
    for ax, (fv, sub) in zip(axes, panels, strict=True):
        label = sub["response_type"].astype(object).where(sub["status"] != "failed", "failed")
        cells = pd.DataFrame(
            {
                "x": sub[x].to_numpy(),
                "y": sub[y].to_numpy(),
                "t": label.to_numpy(),
                "n": sub["n_subsequent_impacts"].to_numpy()
                if "n_subsequent_impacts" in sub
                else None,
            }
        ).dropna(subset=["x", "y"])
        grid = np.full((len(ys), len(xs)), np.nan)
        for (xv, yv), g in cells.groupby(["x", "y"], sort=False):
            t = _mode(g["t"])
            if t is None or (isinstance(t, float) and math.isnan(t)) or t not in _TYPES:
                continue
            present.add(t)
            grid[row[yv], col[xv]] = _TYPES.index(t)
            if show_text and t != "failed":
                n = g.loc[g["t"] == t, "n"].iloc[0]
                if n is not None and not pd.isna(n):
                    ax.text(
                        col[xv],
                        row[yv],
                        str(int(n)),
                        ha="center",
                        va="center",
                        fontsize=fontsize,
                        color="white" if t in ("B", "D") else "black",
                    )
        ax.pcolormesh(
            np.arange(len(xs) + 1) - 0.5,
            np.arange(len(ys) + 1) - 0.5,
            np.ma.masked_invalid(grid),
            cmap=cmap,
            vmin=-0.5,
            vmax=len(_TYPES) - 0.5,
            edgecolors="white",
            linewidth=0.5,
        )
        step = max(1, math.ceil(len(xs) / 21))
        ax.set_xticks(range(0, len(xs), step), [_fmt(v) for v in xs[::step]], fontsize=8)
        ax.set_yticks(range(len(ys)), [_fmt(v) for v in ys], fontsize=8)
        ax.set_xlim(-0.5, len(xs) - 0.5)
        ax.set_ylim(-0.5, len(ys) - 0.5)
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        if fv is not None:
            ax.set_title(f"{facet} = {_fmt(fv)}", fontsize=10)
    handles = [Patch(color=TYPE_COLORS[t], label=t) for t in _TYPES if t in present]
    if handles:
        fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), fontsize=8)
    if title:
        fig.suptitle(title)
    if path is not None:
        save_figure(fig, path)
    return fig


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


def auto_plots(out_dir: str | os.PathLike[str], spec: Any) -> list[Path]:
    """The plots ``quadimpact sweep`` writes in ``DIR/plots`` for a grid sweep.

    For a grid (no runs list or sample) of one to three varied fields, at
    least one numeric (see :func:`choose_plot_fields`): ``delta_init_m``
    against ``x`` (``delta_init_m_vs_<x>.png``, one curve per ``by``, if it
    has at most 12 values) and, with two or more varied fields, the type map
    over ``x`` and ``by`` (``types_<x>_<by>.png``).

    Returns
    -------
    list of pathlib.Path
        The files written (none for other sweeps, or above
        :data:`MAX_AUTO_RUNS` runs).
    """
    from quadimpact.sweep import read_runs

    if spec.runs or spec.sample is not None or spec.n_runs > MAX_AUTO_RUNS:
        return []
    choice = choose_plot_fields(spec.columns, spec.grid)
    if choice is None:
        return []
    x, by, facet = choice
    table = read_runs(out_dir)
    folder = Path(out_dir) / "plots"
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    if by is None or len(spec.grid[by]) <= 12:
        path = folder / f"delta_init_m_vs_{x}.png"
        plot_metric(table, x, "delta_init_m", by=by, facet=facet, path=path)
        written.append(path)
    if by is not None and len(spec.grid[by]) <= 200:
        path = folder / f"types_{x}_{by}.png"
        plot_type_map(table, x, by, path=path, facet=facet)
        written.append(path)
    return written
