"""The pole study's figures (from its trials table; ``report.md`` shows them).

* ``maps.png``: for each controller, the height lost over the run (colour,
  m) over |pitch| (x, deg) and the sideways offset (y, m); a cross marks
  each trial that lost 2 m or more (a failure of the authors' criterion);
* ``success_by_pitch.png``: the share of trials losing less than 2 m, by
  pitch band, for every controller, with 95 % Wilson intervals.

A study of a variant (``pole-replica``) has three arms, the baseline, the
variant's recovery and the default law's recovery: three panels and three
series.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.colors import Normalize
from matplotlib.figure import Figure

from quadimpact.results.figures import fit_title, new_figure, save_figure
from quadimpact.studies.statistics import rate

__all__ = ["FIGURES", "arm_titles", "maps_figure", "success_by_pitch_figure", "write_figures"]

FIGURES = ("maps.png", "success_by_pitch.png")
TITLES = {
    "baseline": "without recovery (baseline)",
    "recovery": "with recovery",
    "recovery-default": "with recovery, default law",
}
ARM_ORDER = tuple(TITLES)


def arm_titles(model: str = "default") -> dict[str, str]:
    """Each arm's title; the recovery arm of a variant says its variant."""
    titles = dict(TITLES)
    if model != "default":
        titles["recovery"] = f"with recovery, {model}"
    return titles


def _cells(part: pd.DataFrame) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """|pitch| values, offsets, height lost (offset x pitch) and success of one arm."""
    pitches = np.sort(part["abs_pitch_deg"].unique())
    offsets = np.sort(part["lateral_offset_m"].unique())
    lost = np.full((offsets.size, pitches.size), np.nan)
    ok = np.zeros((offsets.size, pitches.size), dtype=bool)
    i = np.searchsorted(offsets, part["lateral_offset_m"].to_numpy(dtype=float))
    j = np.searchsorted(pitches, part["abs_pitch_deg"].to_numpy(dtype=float))
    lost[i, j] = part["height_lost_m"].to_numpy(dtype=float)
    ok[i, j] = part["success"].to_numpy(dtype=bool)
    return pitches, offsets, lost, ok


def _edges(values: np.ndarray) -> np.ndarray:
    if values.size == 1:
        return np.array([values[0] - 0.5, values[0] + 0.5])
    mid = 0.5 * (values[1:] + values[:-1])
    return np.concatenate([[2 * values[0] - mid[0]], mid, [2 * values[-1] - mid[-1]]])


def maps_figure(table: pd.DataFrame, title: str | None = None, model: str = "default") -> Figure:
    """Height lost (colour) over |pitch| x offset, one panel per controller, failures crossed."""
    arms = [a for a in ARM_ORDER if (table["arm"] == a).any()]
    titles = arm_titles(model)
    fig = new_figure(5.2 * len(arms) + 1.2, 4.6)
    axes = fig.subplots(1, len(arms), sharey=True, squeeze=False)[0]
    finite = table["height_lost_m"].to_numpy(dtype=float)
    finite = finite[np.isfinite(finite)]
    norm = Normalize(vmin=min(0.0, float(finite.min()) if finite.size else 0.0), vmax=4.0)
    mesh = None
    for ax, arm in zip(axes, arms, strict=True):
        pitches, offsets, lost, ok = _cells(table[table["arm"] == arm])
        mesh = ax.pcolormesh(
            _edges(pitches), _edges(offsets), lost, cmap="viridis", norm=norm, shading="flat"
        )
        jj, ii = np.meshgrid(np.arange(pitches.size), np.arange(offsets.size))
        bad = ~ok & np.isfinite(lost)
        ax.plot(pitches[jj[bad]], offsets[ii[bad]], "x", color="white", markersize=2.5,
                markeredgewidth=0.6, label="lost 2 m or more")  # fmt: skip
        share = ok.mean() if ok.size else float("nan")
        ax.set_title(f"{titles[arm]}: {100 * share:.1f} % lose < 2 m", fontsize="medium")
        ax.set_xlabel("|pitch| toward the pole (deg)")
    axes[0].set_ylabel("offset from the pole's centre line (m)")
    if mesh is not None:
        fig.colorbar(mesh, ax=list(axes), label="height lost over the run (m)", extend="max")
    axes[0].legend(loc="lower left", fontsize="small", framealpha=0.6)
    if title:
        fit_title(fig, title)
    return fig


def success_by_pitch_figure(
    table: pd.DataFrame, title: str | None = None, model: str = "default"
) -> Figure:
    """Share of trials losing less than 2 m by pitch band, every controller, Wilson intervals."""
    fig = new_figure(7.0, 3.8)
    ax = fig.add_subplot()
    bands = sorted(set(table["pitch_band"]), key=lambda b: float(b.split("-")[0]))
    x = np.arange(len(bands), dtype=float)
    arms = [a for a in ARM_ORDER if (table["arm"] == a).any()]
    titles = arm_titles(model)
    for k, arm in enumerate(arms):
        rates = []
        for band in bands:
            part = table[(table["arm"] == arm) & (table["pitch_band"] == band)]
            rates.append(rate(int(part["success"].sum()), len(part)))
        v = np.array([r.value for r in rates])
        lo = v - np.array([r.low for r in rates])
        hi = np.array([r.high for r in rates]) - v
        ax.errorbar(x + (k - 0.5 * (len(arms) - 1)) * 0.2, 100 * v,
                    yerr=100 * np.vstack([lo, hi]), fmt="o", capsize=3,
                    label=titles[arm])  # fmt: skip
    ax.set_xticks(x, bands)
    ax.set_xlabel("|pitch| band (deg)")
    ax.set_ylabel("trials losing < 2 m (%)")
    ax.set_ylim(-5, 105)
    ax.grid(True, alpha=0.4)
    ax.legend(loc="best", fontsize="small")
    if title:
        fit_title(ax, title)
    return fig


def write_figures(
    table: pd.DataFrame, out_dir: str | os.PathLike[str], model: str = "default"
) -> list[Path]:
    """Write :data:`FIGURES` into ``out_dir``; return their paths.

    ``model``: the recovery arm's model variant (its panels' titles).
    """
    out = Path(out_dir)
    paths = [out / name for name in FIGURES]
    save_figure(maps_figure(table, model=model), paths[0])
    save_figure(success_by_pitch_figure(table, model=model), paths[1])
    return paths
