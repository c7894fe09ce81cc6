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

import os
from pathlib import Path
from typing import Any

import pandas as pd
from matplotlib.figure import Figure

from quadimpact.errors import InputError
from quadimpact.results.figures import fit_title, legend_below, new_figure, save_figure
from quadimpact.results.sweep_figures import (
    INVALID_LABEL,
    TYPE_COLOURS,
    check_columns,
    facet_panels,
    field_label,
    field_unit,
    field_value,
    invalid_runs,
    sorted_levels,
    type_map_figure,
)
from quadimpact.sweep.plot_plan import (  # noqa: F401  (here as before)
    MAX_AUTO_RUNS,
    choose_plot_fields,
    plot_plan,
    record_plots,
)
from quadimpact.sweep.store import read_runs

__all__ = ["TYPE_COLORS", "plot_metric", "plot_type_map", "auto_plots"]

TYPE_COLORS = TYPE_COLOURS
"""The type map's colours (:data:`quadimpact.results.sweep_figures.TYPE_COLOURS`)."""


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
        Column on the vertical axis (lengths are drawn in mm). Failed runs
        (null metric) leave gaps; runs deeper than the bumper radius
        (``bumper_model_valid`` false) are marked with a black cross.
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
    check_columns(table, x, metric, by, facet)
    label, scale = field_label(metric), field_unit(metric)[1]
    panels = facet_panels(table, facet)
    if not panels:
        raise InputError(f"plot: {facet}: no values")
    fig = new_figure(1.0 + 4.2 * len(panels), 3.6)
    axes = fig.subplots(1, len(panels), sharey=True, squeeze=False)[0]
    marked = False  # the mark of runs deeper than the bumper radius, in the legend once
    for ax, (fv, sub) in zip(axes, panels, strict=True):
        bad_x, bad_y = _draw_curves(ax, sub, x, metric, scale, by)
        if bad_x:  # after the curves: last in the legend
            ax.plot(bad_x, bad_y, "x", color="black", markersize=6, zorder=5,
                    label=INVALID_LABEL if not marked else None)  # fmt: skip
            marked = True
        ax.set_xlabel(field_label(x))
        if fv is not None:
            ax.set_title(field_value(facet, fv), fontsize=10)
        ax.grid(True, alpha=0.3)
    axes[0].set_ylabel(label)
    if by is not None or marked:  # one legend below the panels: it covers no curve
        entries = {}
        for ax in axes:
            for handle, text in zip(*ax.get_legend_handles_labels(), strict=True):
                entries.setdefault(text, handle)
        legend_below(fig, list(entries.values()), list(entries), fontsize=8)
    if title:
        fit_title(fig, title)
    if path is not None:
        save_figure(fig, path)
    return fig


def _draw_curves(
    ax: Any, sub: pd.DataFrame, x: str, metric: str, scale: float, by: str | None
) -> tuple[list[Any], list[float]]:
    """Draw a panel's curves on ``ax``: ``metric`` (times ``scale``, its unit as drawn)
    against ``x``, one curve per value of ``by`` (one without it), failed runs as gaps.
    Returns the points of the runs deeper than the bumper radius (``x`` values, drawn
    metric), to be marked."""
    groups = (
        [(None, sub)] if by is None else [(v, sub[sub[by] == v]) for v in sorted_levels(sub[by])]
    )
    bad_x: list[Any] = []
    bad_y: list[float] = []
    for bv, g in groups:
        g = g.sort_values(x)
        y = pd.to_numeric(g[metric], errors="coerce").to_numpy(dtype=float) * scale
        ax.plot(
            g[x].to_numpy(),
            y,
            marker="o",
            markersize=3,
            linewidth=1.2,
            label=None if bv is None else field_value(by, bv),
        )
        bad = invalid_runs(g).to_numpy()
        bad_x.extend(g[x].to_numpy()[bad])
        bad_y.extend(y[bad])
    return bad_x, bad_y


def plot_type_map(
    table: pd.DataFrame,
    x: str,
    y: str,
    path: str | os.PathLike[str] | None = None,
    facet: str | None = None,
    *,
    title: str | None = None,
) -> Figure:
    """Response type over two fields, one panel per ``facet`` value: the type map
    (:func:`quadimpact.results.sweep_figures.type_map_figure`) of a sweep table, with
    ``n_subsequent_impacts`` in the cells."""
    return type_map_figure(table, x, y, facet, title=title, path=path)


def auto_plots(out_dir: str | os.PathLike[str], spec: Any) -> list[Path]:
    """The plots ``quadimpact sweep`` writes in ``DIR/plots`` for a grid sweep (drawn anew).

    For a grid (no runs list or sample) of one to three varied fields, at
    least one numeric (see :func:`choose_plot_fields`): ``delta_init_m``
    against ``x`` (``delta_init_m_vs_<x>.png``, one curve per ``by``, if it
    has at most 12 values) and, with two or more varied fields, the type map
    over ``x`` and ``by`` (``types_<x>_<by>.png``).

    Returns
    -------
    list of pathlib.Path
        The files written (none for other sweeps, or above
        :data:`MAX_AUTO_RUNS` runs: :func:`~quadimpact.sweep.plot_plan.plot_plan`).
        What they were drawn from is recorded in ``plots/.drawn.json``
        (:func:`~quadimpact.sweep.plot_plan.drawn_plots`).
    """
    choice, names = plot_plan(spec)
    if choice is None:
        return []
    x, by, facet = choice
    table = read_runs(out_dir)
    folder = Path(out_dir) / "plots"
    folder.mkdir(parents=True, exist_ok=True)
    fixed = fixed_parameters(spec)
    written = []
    for name in names:
        path = folder / name
        if name.startswith("delta_init_m_vs_"):
            title = f"Initial deflection δ_init; {fixed}"
            plot_metric(table, x, "delta_init_m", by=by, facet=facet, path=path, title=title)
        else:
            plot_type_map(table, x, by, path=path, facet=facet, title=f"Response type; {fixed}")
        written.append(path)
    record_plots(out_dir, written)
    return written


#: Scenario fields a sweep plot's title names when they are not swept.
TITLE_FIELDS = ("model", "controller", "vehicle", "heading_deg", "inclination_deg", "speed_m_s",
                "ground")  # fmt: skip


def fixed_parameters(spec: Any) -> str:
    """What a sweep's runs share, for a plot's title: ``model default, speed V_c = 0.75 m/s``.

    The usual scenario fields (:data:`TITLE_FIELDS`) that are not swept, at
    their value in the base scenario (its defaults filled in), then every other
    field the base sets and every vehicle override (``vehicle_overrides``).
    """
    from quadimpact.inputs.scenarios import scenario_from_dict

    varied = set(spec.varying_fields()) | {k for e in spec.runs or [] for k in e}
    if spec.sample is not None:
        varied |= set(spec.sample["ranges"]) | set(spec.sample["choices"])
    if spec.trials is not None:
        varied |= set(spec.columns) - set(spec.grid)
    scenario = scenario_from_dict(spec.base, where="sweep: base").model_dump(mode="json")
    scenario.update({k: v[0] for k, v in spec.grid.items() if len(v) == 1})
    names = [f for f in TITLE_FIELDS if f in scenario]
    names += [f for f in spec.base if f not in names and f != "vehicle_overrides"]
    names += [f for f in spec.grid if len(spec.grid[f]) == 1 and f not in names]
    parts = []
    for name in names:
        value = scenario.get(name, spec.grid.get(name, [None])[0])
        if name in varied or isinstance(value, (dict, list)) or value is None:
            continue
        parts.append(f"{name} {value}" if isinstance(value, str) else field_value(name, value))
    overrides = dict(spec.base.get("vehicle_overrides") or {})
    parts += [field_value(k, v) for k, v in overrides.items() if not isinstance(v, (list, dict))]
    return ", ".join(parts) if parts else "the paper's wall approach"
