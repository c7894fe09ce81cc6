"""Figures of one run, after the paper's Figures 5 and 6.

Figures are built as :class:`matplotlib.figure.Figure` objects on an Agg
canvas, never through ``pyplot``, so nothing leaks into global state and the
functions work in worker processes without a display. ``make_*`` return the
figure (for inspection and tests); ``plot_*`` build it and write a PNG.

Input is the time-series table of :func:`quadimpact.analysis.timeseries_frame`
(inertial NED positions, ``altitude_m = -z``, ZYX Euler angles in degrees).
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from quadimpact.io import atomic_write

__all__ = [
    "BUMPER_COLORS",
    "FIG_DPI",
    "break_wraps",
    "make_fig5",
    "make_fig6",
    "plot_fig5",
    "plot_fig6",
    "save_figure",
]

#: Resolution of the written PNG files (dots per inch).
FIG_DPI = 150

#: Line colour of bumpers 1-4 (shared by every plot of bumper quantities).
BUMPER_COLORS: dict[int, str] = {1: "tab:blue", 2: "tab:orange", 3: "tab:green", 4: "tab:red"}

_REF_STYLE = {"color": "k", "linestyle": "--", "linewidth": 1.0}


def _new_figure(width_in: float, height_in: float) -> Figure:
    fig = Figure(figsize=(width_in, height_in), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def save_figure(fig: Figure, path: str | os.PathLike[str]) -> Path:
    """Write ``fig`` as PNG to ``path`` (atomically: temporary file, then rename)."""
    return atomic_write(path, lambda tmp: fig.savefig(tmp, format="png", dpi=FIG_DPI))


def break_wraps(
    t: np.ndarray, angle_deg: np.ndarray, jump_deg: float = 180.0
) -> tuple[np.ndarray, np.ndarray]:
    """Insert a NaN sample wherever a wrapped angle jumps by more than ``jump_deg``.

    Keeps a wrapped angle (e.g. yaw in (-180, 180]) from being drawn as a
    vertical line across the panel when it passes +-180 deg. Returns the
    inputs unchanged (as float arrays) when there is no such jump.
    """
    t = np.asarray(t, dtype=np.float64)
    y = np.asarray(angle_deg, dtype=np.float64)
    jumps = np.flatnonzero(np.abs(np.diff(y)) > jump_deg)
    if jumps.size == 0:
        return t, y
    idx = jumps + 1
    return np.insert(t, idx, np.nan), np.insert(y, idx, np.nan)


def make_fig5(ts: pd.DataFrame, title: str | None = None) -> Figure:
    """Bumper deflections against time (paper Figure 5).

    Parameters
    ----------
    ts : pandas.DataFrame
        Time series with ``t_s`` (s) and ``delta1_m``..``delta4_m`` (m).
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
        One axes; line ``j-1`` is bumper ``j`` in millimetres.
    """
    fig = _new_figure(7.0, 3.8)
    ax = fig.add_subplot()
    t = ts["t_s"].to_numpy(dtype=np.float64)
    for j in (1, 2, 3, 4):
        delta_mm = 1e3 * ts[f"delta{j}_m"].to_numpy(dtype=np.float64)
        ax.plot(t, delta_mm, color=BUMPER_COLORS[j], linewidth=1.2, label=f"Bumper {j}")
    ax.set_xlabel("Time (s)")
    ax.set_ylabel("Bumper deflection (mm)")
    ax.grid(True, alpha=0.4)
    ax.legend(loc="best")
    if len(t):
        ax.set_xlim(float(t[0]), float(t[-1]))
    if title:
        ax.set_title(title)
    return fig


def make_fig6(
    ts: pd.DataFrame,
    refs: Mapping[str, float],
    wall_x_m: float | None = None,
    title: str | None = None,
) -> Figure:
    """Vehicle states against time (paper Figure 6).

    Six panels sharing the time axis: left column X (with the wall plane
    ``X = wall_x_m`` dashed), Y, altitude (with its reference dashed), all in
    metres (inertial NED position; altitude = -Z); right column roll, pitch,
    yaw (ZYX Euler, degrees) each with its reference dashed.

    Parameters
    ----------
    ts : pandas.DataFrame
        Time series with ``t_s``, ``x_m``, ``y_m``, ``altitude_m``,
        ``roll_deg``, ``pitch_deg``, ``yaw_deg``.
    refs : mapping
        ``roll_rad``, ``pitch_rad``, ``yaw_rad`` (rad) and ``altitude_m`` (m);
        a missing or ``None`` entry draws no reference line.
    wall_x_m : float, optional
        Inertial X of the wall plane (m).
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
        Axes in order X, roll, Y, pitch, altitude, yaw (row-major). In each
        axes the first line is the simulated quantity.
    """
    fig = _new_figure(10.0, 7.5)
    axes = fig.subplots(3, 2, sharex=True)
    t = ts["t_s"].to_numpy(dtype=np.float64)

    def ref_value(key: str, scale: float = 1.0) -> float | None:
        v = refs.get(key)
        if v is None or not math.isfinite(float(v)):
            return None
        return float(v) * scale

    left = (
        ("x_m", "X (m)", wall_x_m, "wall"),
        ("y_m", "Y (m)", None, None),
        ("altitude_m", "Altitude (m)", ref_value("altitude_m"), "reference"),
    )
    for ax, (col, label, ref, ref_label) in zip(axes[:, 0], left, strict=True):
        ax.plot(t, ts[col].to_numpy(dtype=np.float64), color="tab:blue", label="simulated")
        if ref is not None and math.isfinite(ref):
            ax.axhline(ref, label=ref_label, **_REF_STYLE)
        ax.set_ylabel(label)

    deg = 180.0 / math.pi
    right = (
        ("roll_deg", "Roll φ (deg)", ref_value("roll_rad", deg)),
        ("pitch_deg", "Pitch θ (deg)", ref_value("pitch_rad", deg)),
        ("yaw_deg", "Yaw ψ (deg)", ref_value("yaw_rad", deg)),
    )
    for ax, (col, label, ref) in zip(axes[:, 1], right, strict=True):
        tt, yy = break_wraps(t, ts[col].to_numpy(dtype=np.float64))
        ax.plot(tt, yy, color="tab:blue", label="simulated")
        if ref is not None:
            ax.axhline(ref, label="reference", **_REF_STYLE)
        ax.set_ylabel(label)

    for ax in axes.flat:
        ax.grid(True, alpha=0.4)
        if len(ax.get_legend_handles_labels()[0]) > 1:
            ax.legend(loc="best", fontsize="small")
    for ax in axes[-1, :]:
        ax.set_xlabel("Time (s)")
    if len(t):
        axes[0, 0].set_xlim(float(t[0]), float(t[-1]))
    if title:
        fig.suptitle(title)
    return fig


def plot_fig5(ts: pd.DataFrame, path: str | os.PathLike[str], title: str | None = None) -> Path:
    """Write the bumper-deflection figure (:func:`make_fig5`) to ``path`` as PNG."""
    return save_figure(make_fig5(ts, title=title), path)


def plot_fig6(
    ts: pd.DataFrame,
    refs: Mapping[str, float],
    path: str | os.PathLike[str],
    wall_x_m: float | None = None,
    title: str | None = None,
) -> Path:
    """Write the states figure (:func:`make_fig6`) to ``path`` as PNG."""
    return save_figure(make_fig6(ts, refs, wall_x_m=wall_x_m, title=title), path)
