"""The recovery study's figures (from the trials table; ``report.md`` shows them).

* ``success_map.png``: success rate over inclination bin x speed bin, each
  cell with its ``recovered/trials`` count;
* ``success_by_bin.png``: success rate by inclination bin and by speed bin,
  with 95 % Wilson intervals;
* ``distributions.png``: histograms and empirical CDFs of the time to recover,
  the height loss and the horizontal drift of the recovered trials;
* ``example/recovery.png``: the example trial's attitude, tilt and altitude
  with the detection and each stage's entry marked.

Inclination is toward the wall, ``-pitch`` (deg); speed toward the wall (m/s).
"""

from __future__ import annotations

import io
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from quadimpact import libm
from quadimpact.results.figures import (
    FIG_DPI,
    STAGE_COLORS,
    STAGE_NAMES,
    break_wraps,
    fig_margins,
    fit_title,
    mark_stages,
    new_figure,
    save_figure,
)
from quadimpact.results.files import atomic_write
from quadimpact.studies.recovery import recovery_analysis as analysis

__all__ = [
    "FIGURES",
    "compare_by_bin_figure",
    "distributions_figure",
    "distributions_png",
    "example_figure",
    "success_by_bin_figure",
    "success_map_figure",
    "write_example",
    "write_figures",
]

FIGURES = ("success_map.png", "success_by_bin.png", "distributions.png")
#: The distributions drawn: column, axis label, scale to the drawn unit.
DISTRIBUTIONS = (
    ("time_to_recover_s", "time to recover (s)", 1.0),
    ("height_loss_m", "height loss (m)", 1.0),
    ("horizontal_drift_m", "horizontal drift (m)", 1.0),
)
#: The table's columns :func:`distributions_figure` reads.
DISTRIBUTION_COLUMNS = ("outcome_class", *(column for column, _, _ in DISTRIBUTIONS))


def success_map_figure(table: pd.DataFrame, title: str | None = None) -> Figure:
    """Success rate (colour) over inclination bin (x) and speed bin (y), counts in the cells."""
    valid = table[analysis.valid_mask(table)]  # the excluded trials are not in the rates
    cells = (
        valid.assign(success=analysis.success_mask(valid))
        .groupby(["speed_bin", "inclination_bin"], observed=False)["success"]
        .agg(["sum", "count"])
    )
    xs = list(table["inclination_bin"].cat.categories)
    ys = list(table["speed_bin"].cat.categories)
    grid = np.full((len(ys), len(xs)), np.nan)
    w, h = max(6.0, 1.6 + 0.95 * len(xs)), max(3.5, 1.4 + 0.55 * len(ys))
    fig = new_figure(w, h, margins=fig_margins(w, h, "title", bottom_in=0.85, right_in=0.1))
    ax = fig.add_subplot()
    for (yv, xv), r in cells.iterrows():
        i, j = ys.index(yv), xs.index(xv)
        if r["count"]:
            grid[i, j] = r["sum"] / r["count"]
            ax.text(j, i, f"{int(r['sum'])}/{int(r['count'])}", ha="center", va="center",
                    fontsize=7, color="black" if 0.3 < grid[i, j] < 0.85 else "white")  # fmt: skip
    mesh = ax.pcolormesh(
        np.arange(len(xs) + 1) - 0.5, np.arange(len(ys) + 1) - 0.5,
        np.ma.masked_invalid(grid), cmap="RdYlGn", vmin=0.0, vmax=1.0, edgecolors="white",
    )  # fmt: skip
    ax.set_xticks(range(len(xs)), xs, rotation=30, fontsize=8)
    ax.set_yticks(range(len(ys)), ys, fontsize=8)
    ax.set_xlabel("inclination toward the wall, -pitch (deg)")
    ax.set_ylabel("speed toward the wall (m/s)")
    fig.colorbar(mesh, ax=ax, label="success rate (recovered / valid trials)")
    fit_title(ax, title or "Success rate; cells: recovered / trials")
    return fig


def _rate_points(ax: Any, x: np.ndarray, rates: pd.DataFrame, **style: Any) -> None:
    """Each non-empty bin's rate at ``x`` with its Wilson interval as error bars."""
    shown = rates["n"].to_numpy() > 0
    y = rates["rate"].to_numpy(dtype=float)
    err = np.vstack([y - rates["low"].to_numpy(float), rates["high"].to_numpy(float) - y])
    err = np.clip(err, 0.0, None)  # rounding at k = 0 or k = n
    ax.errorbar(x[shown], y[shown], yerr=err[:, shown], fmt="o", capsize=3, **style)


def _rate_panel(ax: Any, rates: pd.DataFrame, xlabel: str) -> None:
    x = np.arange(len(rates))
    _rate_points(
        ax, x, rates, color="tab:blue", label="recovered / valid trials, 95 % Wilson interval"
    )
    for xi, r in zip(x, rates.itertuples(), strict=True):
        if r.n:
            ax.annotate(f"n={r.n}", (xi, 1.08), ha="center", fontsize=7, color="0.35")
    ax.set_xticks(x, rates["bin"], rotation=30, fontsize=8)
    ax.set_ylim(0.0, 1.14)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("success rate")
    ax.grid(alpha=0.3)


def success_by_bin_figure(numbers: dict[str, Any], title: str | None = None) -> Figure:
    """Success rate by inclination bin and by speed bin (``analysis.summarise`` numbers)."""
    fig = new_figure(
        11.0,
        4.0,
        margins=fig_margins(11.0, 4.0, "title", wspace=0.15, bottom_in=0.95, right_in=0.45),
    )
    left, right = fig.subplots(1, 2, sharey=True)
    _rate_panel(left, numbers["by_inclination"], "inclination toward the wall, -pitch (deg)")
    _rate_panel(right, numbers["by_speed"], "speed toward the wall (m/s)")
    left.legend(loc="lower left", fontsize=8)
    s = numbers["success"]
    fit_title(fig, title or f"Success rate {s.value:.1%} [{s.low:.1%}, {s.high:.1%}] over "
              f"{s.n} trials")  # fmt: skip
    return fig


def compare_by_bin_figure(
    numbers: dict[str, dict[str, Any]], key: str = "by_inclination", title: str | None = None
) -> Figure:
    """Success rate by bin of several studies side by side (label -> ``summarise`` numbers).

    ``key``: ``"by_inclination"`` or ``"by_speed"``. The studies must share their bins.
    """
    fig = new_figure(8.0, 4.0)
    ax = fig.add_subplot()
    labels = list(numbers)
    width = 0.7 / max(1, len(labels))
    bins: list[str] = []
    for k, label in enumerate(labels):
        rates = numbers[label][key]
        bins = list(rates["bin"])
        x = np.arange(len(rates)) + (k - (len(labels) - 1) / 2) * width
        s = numbers[label]["success"]
        _rate_points(ax, x, rates, label=f"{label}: {s.value:.1%} over {s.n}")
    ax.set_xticks(range(len(bins)), bins, rotation=30, fontsize=8)
    ax.set_ylim(0.0, 1.05)
    ax.set_xlabel("inclination toward the wall, -pitch (deg)" if key == "by_inclination"
                  else "speed toward the wall (m/s)")  # fmt: skip
    ax.set_ylabel("success rate (95 % Wilson interval)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower left")
    if title:
        fit_title(ax, title)
    return fig


def distributions_figure(table: pd.DataFrame, title: str | None = None) -> Figure:
    """Histogram (top) and empirical CDF (bottom) of each recovery measure, recovered trials."""
    good = table[table["outcome_class"].astype(str) == "recovered"]
    fig = new_figure(12.0, 6.0, margins=fig_margins(12.0, 6.0, "title", hspace=0.3, wspace=0.3))
    axes = fig.subplots(2, len(DISTRIBUTIONS), squeeze=False)
    for k, (column, label, scale) in enumerate(DISTRIBUTIONS):
        v = good[column].to_numpy(dtype=float) * scale
        v = np.sort(v[np.isfinite(v)])
        hist, ecdf = axes[0, k], axes[1, k]
        if v.size:
            hist.hist(v, bins=min(60, max(5, int(np.sqrt(v.size)))), color="tab:blue", alpha=0.8)
            ecdf.step(v, np.arange(1, v.size + 1) / v.size, where="post", color="tab:blue")
            q = analysis.quantiles(pd.Series(v))
            for ax in (hist, ecdf):
                ax.axvline(q["median"], color="black", ls="--", lw=1, label="median")
                ax.axvline(q["p90"], color="tab:red", ls=":", lw=1.2, label="90th percentile")
        hist.set_ylabel("trials")
        ecdf.set_ylabel("share of recovered trials")
        ecdf.set_xlabel(label)
        ecdf.set_ylim(0, 1.02)
        for ax in (hist, ecdf):
            ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    fit_title(fig, title or f"Recovered trials ({len(good)}): detection to stage 4")
    return fig


def example_figure(result: Any, title: str | None = None) -> Figure:
    """The example trial: roll, pitch, yaw; tilt; altitude; X; stage entries marked.

    ``result`` is a :class:`~quadimpact.results.result.SimulationResult`.
    """
    ts, summary = result.timeseries, result.summary
    t = ts["t_s"].to_numpy(dtype=float)
    # fixed margins (the layout engine would cost about as much as the drawing)
    fig = new_figure(9.0, 8.0, margins=fig_margins(9.0, 8.0, "title", hspace=0.22))
    axes = fig.subplots(4, 1, sharex=True)
    for col, color in (("roll_deg", "tab:blue"), ("pitch_deg", "tab:orange"),
                       ("yaw_deg", "tab:green")):  # fmt: skip
        tt, yy = break_wraps(t, ts[col].to_numpy(dtype=float))
        axes[0].plot(tt, yy, color=color, lw=1.2, label=col.split("_")[0])
    axes[0].set_ylabel("attitude (deg)")
    q = ts[["q0", "q1", "q2", "q3"]].to_numpy(dtype=float)
    c33 = q[:, 0] ** 2 - q[:, 1] ** 2 - q[:, 2] ** 2 + q[:, 3] ** 2  # body z . inertial Z
    axes[1].plot(t, np.degrees(libm.arccos(np.clip(c33, -1, 1))), color="tab:purple", lw=1.2,
                 label="tilt")  # fmt: skip
    axes[1].set_ylabel("tilt from vertical (deg)")
    axes[2].plot(t, ts["altitude_m"].to_numpy(dtype=float), color="tab:blue", lw=1.2,
                 label="altitude")  # fmt: skip
    axes[2].set_ylabel("altitude (m)")
    axes[3].plot(t, ts["x_m"].to_numpy(dtype=float), color="tab:blue", lw=1.2, label="X")
    wall = summary.get("wall_distance_m")
    if wall is not None:
        axes[3].axhline(float(wall), color="0.4", ls="--", lw=1, label="wall")
    axes[3].set_ylabel("X (m)")
    axes[3].set_xlabel("time (s)")
    for k, ax in enumerate(axes):
        mark_stages(ax, summary, label=k == 0)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=7, ncols=3)
    stage = ts["stage"].to_numpy() if "stage" in ts else None
    if stage is not None and len(t):
        for k in (1, 2, 3, 4):
            on = stage == k
            if on.any():
                axes[1].fill_between(t, 0, 1, where=on, transform=axes[1].get_xaxis_transform(),
                                     color=STAGE_COLORS[k], alpha=0.08, lw=0,
                                     label=None)  # fmt: skip
        reached = [STAGE_NAMES[k] for k in (1, 2, 3, 4) if (stage == k).any()]
        axes[1].set_title("stages: " + ", ".join(reached), fontsize=8)
        axes[0].set_xlim(float(t[0]), float(t[-1]))
    fit_title(fig, title or "Example trial")
    return fig


def distributions_png(table: pd.DataFrame) -> bytes:
    """:func:`distributions_figure` of ``table`` as PNG bytes (what another process renders)."""
    buffer = io.BytesIO()
    distributions_figure(table).savefig(buffer, format="png", dpi=FIG_DPI)
    return buffer.getvalue()


def write_figures(
    table: pd.DataFrame,
    out_dir: str | os.PathLike[str],
    numbers: dict[str, Any] | None = None,
    *,
    submit: Callable[..., Any] | None = None,
) -> list[Path]:
    """Write :data:`FIGURES` into ``out_dir`` and return their paths.

    ``numbers`` are the table's :func:`analysis.summarise` (computed if not given).
    ``submit(fn, *args)``: a future of ``fn(*args)`` on another process (the
    study's idle example process, ``example.EarlyExample.submit``), or None:
    the distributions figure (about half of the three figures' CPU time) is
    then rendered there while this process draws the other two, and written
    here; a failure there renders it here instead.
    """
    out = Path(out_dir)
    numbers = analysis.summarise(table) if numbers is None else numbers
    future = None
    if submit is not None:
        future = submit(distributions_png, table[list(DISTRIBUTION_COLUMNS)])
    paths = [
        save_figure(success_map_figure(table), out / FIGURES[0]),
        save_figure(success_by_bin_figure(numbers), out / FIGURES[1]),
    ]
    png = None
    if future is not None:
        try:
            png = future.result()
        except Exception:  # the other process failed or died: render it here
            png = None
    if png is None:
        paths.append(save_figure(distributions_figure(table), out / FIGURES[2]))
    else:
        paths.append(atomic_write(out / FIGURES[2], lambda tmp: tmp.write_bytes(png)))
    return paths


def write_example(result: Any, path: str | os.PathLike[str], run_id: int) -> Path:
    """Write the example trial's figure (:func:`example_figure`) to ``path``."""
    s = result.summary
    scenario = result.scenario
    title = (
        f"Trial {run_id}: roll {scenario.roll_deg:.1f}°, pitch {scenario.pitch_deg:.1f}°, "
        f"yaw {scenario.yaw_deg:.1f}°, {scenario.speed_m_s:.2f} m/s; "
        + ("recovered" if s.get("recovered") else "not recovered")
    )
    return save_figure(example_figure(result, title=title), path)
