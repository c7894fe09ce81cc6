"""Figures of a sweep table: its fields in words and units, its levels and panels, and the
response-type map.

A sweep's fields are drawn with their names in words (:data:`FIELD_NAMES`,
else the column's name) and lengths in mm (:func:`field_label`,
:func:`field_value`); :func:`type_map_figure` (with :data:`TYPE_COLOURS`)
draws the response type of every run over two fields, one panel per value of
a third, for ``quadimpact sweep`` (:mod:`quadimpact.sweep.plots`) and the
paper's Table II. Built on :func:`quadimpact.results.figures.new_figure`
(Agg, no ``pyplot``).
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.patches import Patch, Rectangle

from quadimpact.errors import InputError
from quadimpact.results.figures import fit_title, new_figure, save_figure
from quadimpact.results.files import split_unit

if TYPE_CHECKING:  # pandas only where a table is drawn
    import pandas as pd

__all__ = [
    "FIELD_NAMES",
    "INVALID_LABEL",
    "MAX_TEXT_CELLS",
    "TYPE_COLOURS",
    "check_columns",
    "facet_panels",
    "field_label",
    "field_name",
    "field_unit",
    "field_value",
    "format_level",
    "invalid_runs",
    "sorted_levels",
    "type_map_figure",
]

#: Fill colour of each response type in type maps (failed runs: black).
TYPE_COLOURS: dict[str, str] = {
    "A": "#4daf4a",
    "B": "#377eb8",
    "C": "#ff7f00",
    "D": "#e41a1c",
    "Other": "#999999",
    "failed": "#000000",
}
_TYPES = list(TYPE_COLOURS)
MAX_TEXT_CELLS = 400
"""Type maps write each cell's text up to this many cells per panel."""


#: Names of the usual fields in plots (the rest: the field's name in words).
FIELD_NAMES: dict[str, str] = {
    "heading_deg": "heading ψ",
    "inclination_deg": "inclination ι",
    "speed_m_s": "impact speed V_c",
    "delta_init_m": "δ_init",
    "max_penetration_m": "deepest penetration",
    "peak_force_n": "peak force",
    "friction_coefficient": "friction coefficient μ",
}
_PLOT_UNITS = {"m": ("mm", 1e3), "1": ("", 1.0)}  # lengths of a sweep are drawn in mm


def field_name(field: str) -> str:
    """A field in words, without its unit: ``inclination_deg`` -> ``inclination ι``."""
    return FIELD_NAMES.get(field, split_unit(field)[0].replace("_", " "))


def field_unit(field: str) -> tuple[str, float]:
    """The unit a field is drawn in, and the scale from its stored unit (metres as mm)."""
    unit = split_unit(field)[1]
    return _PLOT_UNITS.get(unit, (unit, 1.0))


def field_label(field: str) -> str:
    """An axis label: ``inclination ι (deg)``, ``δ_init (mm)``, ``restitution``."""
    unit, _ = field_unit(field)
    return f"{field_name(field)} ({unit})" if unit else field_name(field)


def field_value(field: str, value: Any) -> str:
    """A field's value for a legend or a panel: ``impact speed V_c = 0.5 m/s``."""
    unit, scale = field_unit(field)
    shown = format_level(value * scale if isinstance(value, numbers.Real) else value)
    return f"{field_name(field)} = {shown}{' ' + unit if unit else ''}"


def format_level(value: Any) -> str:
    """A field's value as an axis or panel label (floats without trailing zeros)."""
    if isinstance(value, (float, np.floating)):
        return f"{float(value):g}"
    return str(value)


def invalid_runs(table: pd.DataFrame) -> pd.Series:
    """Runs deeper than the bumper radius (``bumper_model_valid`` false: the model's answer,
    not a prediction); all false without that column."""
    import pandas as pd

    if "bumper_model_valid" not in table:
        return pd.Series(False, index=table.index)
    return table["bumper_model_valid"].astype(object).eq(False)


INVALID_LABEL = "run deeper than the bumper radius (the bumper model does not hold)"


def check_columns(table: pd.DataFrame, *names: str | None) -> None:
    """Raise a one-line InputError for a name (not None) that is not a column of ``table``."""
    for name in names:
        if name is not None and name not in table.columns:
            raise InputError(f"plot: {name}: no such column in the sweep table")


def sorted_levels(series: pd.Series) -> list[Any]:
    """The distinct values of a column, sorted (as text when they do not compare)."""
    values = series.dropna().unique().tolist()
    try:
        return sorted(values)
    except TypeError:
        return sorted(values, key=str)


def facet_panels(table: pd.DataFrame, facet: str | None) -> list[tuple[Any, pd.DataFrame]]:
    """(value, rows) per value of ``facet``; one panel of every row without it."""
    if facet is None:
        return [(None, table)]
    return [(v, table[table[facet] == v]) for v in sorted_levels(table[facet])]


# ------------------------------------------------------ sweep tables: type map
def _mode(values: pd.Series) -> Any:
    if len(values) == 1:  # one run per cell (a grid): no counting needed
        return values.iloc[0]
    counts = values.value_counts(dropna=False)
    return counts.index[0] if len(counts) else None


def _cell_texts(sub: pd.DataFrame, label: Callable[[pd.Series], str] | None) -> list[str | None]:
    """Each run's cell text: ``label(row)``, or its ``n_subsequent_impacts`` (None if absent)."""
    if label is not None:
        return [label(r) for _, r in sub.iterrows()]
    if "n_subsequent_impacts" not in sub:
        return [None] * len(sub)
    import pandas as pd

    return [None if pd.isna(n) else str(int(n)) for n in sub["n_subsequent_impacts"]]


def type_map_figure(
    table: pd.DataFrame,
    x: str,
    y: str,
    facet: str | None = None,
    *,
    title: str | None = None,
    label: Callable[[pd.Series], str] | None = None,
    text_meaning: str | None = None,
    path: str | os.PathLike[str] | None = None,
) -> Figure:
    """Response type over two fields (categorical colours), one panel per ``facet`` value.

    Parameters
    ----------
    table : pandas.DataFrame
        A sweep table with ``response_type``, ``status`` and ``n_subsequent_impacts``.
    x, y : str
        Fields along the horizontal and vertical axes (each value one cell,
        evenly spaced, in sorted order).
    facet : str, optional
        One panel (stacked vertically) per value of this field.
    title : str, optional
        Figure title.
    label : callable, optional
        The text of a cell from its run's row (the paper's Table II writes
        ``C3``: the type and the count); default ``n_subsequent_impacts``.
    text_meaning : str, optional
        What a cell's text is, for the legend; default (with the default
        ``label``) "number: subsequent impacts".
    path : path-like, optional
        Also write the figure there as PNG.

    Returns
    -------
    matplotlib.figure.Figure

    Notes
    -----
    A cell holding several runs (other fields varying) shows the most
    frequent type. Cells show their text (``n_subsequent_impacts``, the paper's
    Table II count, or ``label``) when a panel has at most
    :data:`MAX_TEXT_CELLS` cells, as large as the cell allows; failed runs
    (black) have none. A cell holding a run deeper than the bumper radius
    (``bumper_model_valid`` false) is hatched. Axes and panels are labelled
    with the fields' names and units (:func:`field_label`).
    """
    check_columns(table, x, y, facet, "response_type", "status")
    xs, ys = sorted_levels(table[x]), sorted_levels(table[y])
    if not xs or not ys:
        raise InputError("plot: type map of an empty table")
    panels = facet_panels(table, facet)
    width = min(18.0, 1.8 + 0.36 * len(xs))
    cell_h = 0.4
    height = 0.9 + len(panels) * (0.6 + cell_h * len(ys))
    fig = new_figure(width, height + 0.6)
    cell_pt = 72.0 * min(cell_h, (width - 1.8) / max(1, len(xs)))
    axes = fig.subplots(len(panels), 1, squeeze=False)[:, 0]
    text_pt = cell_pt if len(xs) * len(ys) <= MAX_TEXT_CELLS else None
    drawn = _Drawn(set())
    for ax, (fv, sub) in zip(axes, panels, strict=True):
        grid = _fill_cells(ax, _panel_cells(sub, x, y, label), xs, ys, text_pt, drawn)
        _draw_grid(ax, grid, xs, ys)
        ax.set_xlabel(field_label(x))
        ax.set_ylabel(field_label(y))
        if fv is not None:
            ax.set_title(field_value(facet, fv), fontsize=10)
    _type_map_legend(fig, drawn, label, text_meaning, width)
    if title:
        fit_title(fig, title)
    if path is not None:
        save_figure(fig, path)
    return fig


@dataclass
class _Drawn:
    """What a type map's panels drew, for its legend: the response types of its cells
    (``types``), whether a cell has text (``text``) and whether a cell holds a run deeper
    than the bumper radius (``invalid``, hatched)."""

    types: set[str]
    text: bool = False
    invalid: bool = False


def _panel_cells(
    sub: pd.DataFrame, x: str, y: str, label: Callable[[pd.Series], str] | None
) -> pd.DataFrame:
    """A panel's runs as cells: their ``x`` and ``y`` values (rows without either left
    out), type (``"failed"`` for a failed run), text (:func:`_cell_texts`) and whether the
    run is deeper than the bumper radius (``bad``)."""
    import pandas as pd

    kind = sub["response_type"].astype(object).where(sub["status"] != "failed", "failed")
    return pd.DataFrame(
        {
            "x": sub[x].to_numpy(),
            "y": sub[y].to_numpy(),
            "t": kind.to_numpy(),
            "n": _cell_texts(sub, label),
            "bad": invalid_runs(sub).to_numpy(),
        }
    ).dropna(subset=["x", "y"])


def _fill_cells(
    ax: Any,
    cells: pd.DataFrame,
    xs: list[Any],
    ys: list[Any],
    text_pt: float | None,
    drawn: _Drawn,
) -> np.ndarray:
    """Each cell's type (the most frequent of its runs) as its index in :data:`TYPE_COLOURS`
    on a (len(ys), len(xs)) grid (NaN: no run, or none of a known type); a cell holding a
    run deeper than the bumper radius is hatched on ``ax``, and a cell's text written when
    ``text_pt`` (the cell's size, points) is given. What was drawn goes to ``drawn``."""
    col = {v: i for i, v in enumerate(xs)}
    row = {v: i for i, v in enumerate(ys)}
    grid = np.full((len(ys), len(xs)), np.nan)
    for (xv, yv), g in cells.groupby(["x", "y"], sort=False):
        t = _mode(g["t"])
        if t is None or (isinstance(t, float) and math.isnan(t)) or t not in _TYPES:
            continue
        drawn.types.add(t)
        grid[row[yv], col[xv]] = _TYPES.index(t)
        if g["bad"].any():
            drawn.invalid = True
            ax.add_patch(Rectangle((col[xv] - 0.5, row[yv] - 0.5), 1.0, 1.0, fill=False,
                                   hatch="//", edgecolor="0.25", linewidth=0.0,
                                   zorder=3))  # fmt: skip
        if text_pt is not None and t != "failed":
            text = g.loc[g["t"] == t, "n"].iloc[0]
            if text is not None:
                drawn.text = True
                _write_cell_text(ax, col[xv], row[yv], text, t, text_pt)
    return grid


def _write_cell_text(ax: Any, i: int, j: int, text: str, kind: str, cell_pt: float) -> None:
    """Write ``text`` in the cell of column ``i`` and row ``j`` (of type ``kind``): as large
    as the cell (``cell_pt``, points) allows for its height and the text's length, 5 to 12
    points, white on the dark types (B, D)."""
    size = min(0.45 * cell_pt, 0.9 * cell_pt / (0.62 * max(1, len(str(text)))))
    ax.text(
        i,
        j,
        text,
        ha="center",
        va="center",
        fontsize=max(5.0, min(12.0, size)),
        color="white" if kind in ("B", "D") else "black",
        zorder=4,
    ).set_in_layout(False)  # inside its cell: no margin to make room for


def _draw_grid(ax: Any, grid: np.ndarray, xs: list[Any], ys: list[Any]) -> None:
    """Colour the cells of ``grid`` (:func:`_fill_cells`) on ``ax``, one colour per type,
    and label the axes' ticks with the values ``xs`` (at most about 21 shown) and ``ys``."""
    ax.pcolormesh(
        np.arange(len(xs) + 1) - 0.5,
        np.arange(len(ys) + 1) - 0.5,
        np.ma.masked_invalid(grid),
        cmap=ListedColormap([TYPE_COLOURS[t] for t in _TYPES]),
        vmin=-0.5,
        vmax=len(_TYPES) - 0.5,
        edgecolors="white",
        linewidth=0.5,
    )
    step = max(1, math.ceil(len(xs) / 21))
    ax.set_xticks(range(0, len(xs), step), [format_level(v) for v in xs[::step]], fontsize=8)
    ax.set_yticks(range(len(ys)), [format_level(v) for v in ys], fontsize=8)
    ax.set_xlim(-0.5, len(xs) - 0.5)
    ax.set_ylim(-0.5, len(ys) - 0.5)


def _type_map_legend(
    fig: Figure,
    drawn: _Drawn,
    label: Callable[[pd.Series], str] | None,
    text_meaning: str | None,
    width: float,
) -> None:
    """The legend below the panels: the types drawn, what a cell's text is (``text_meaning``,
    else said from ``label``) and the hatch, those that appear; in up to 5 columns on a
    figure at least 9 in wide (``width``), else 2."""
    handles = [Patch(color=TYPE_COLOURS[t], label=t) for t in _TYPES if t in drawn.types]
    if drawn.text:
        meaning = text_meaning or (
            "number: subsequent impacts" if label is None else "cell text: the run's label"
        )
        handles.append(Patch(facecolor="white", edgecolor="0.6", label=meaning))
    if drawn.invalid:
        handles.append(Patch(facecolor="white", edgecolor="0.25", hatch="//",
                             label=INVALID_LABEL))  # fmt: skip
    if handles:
        fig.legend(handles=handles, loc="outside lower center", fontsize=8,
                   ncols=min(len(handles), 5 if width >= 9.0 else 2))  # fmt: skip
