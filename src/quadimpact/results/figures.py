"""Figures: of one run (the paper's Figures 5 and 6), and the shared figure helpers.

Figures are built as :class:`matplotlib.figure.Figure` objects on an Agg
canvas, never through ``pyplot``, so nothing leaks into global state and the
functions work in worker processes without a display. ``make_*`` return the
figure (for inspection and tests); ``plot_*`` build it and write a PNG.

Input of Figures 5 and 6 is the time-series table (``timeseries.parquet``:
inertial NED positions, ``altitude_m = -z``, ZYX Euler angles in degrees).
:func:`new_figure` and :func:`save_figure` serve every figure of the package;
the figures of a sweep table (the response-type map among them) are in
:mod:`quadimpact.results.sweep_figures`.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.text import Text

from quadimpact.results.files import atomic_write
from quadimpact.rotations import unwrap_deg

if TYPE_CHECKING:  # pandas only where a table is drawn
    import pandas as pd

__all__ = [
    "BUMPER_COLORS",
    "FIG_DPI",
    "STAGE_NAMES",
    "break_wraps",
    "unwrap_deg",
    "fig_margins",
    "fit_title",
    "legend_below",
    "make_fig5",
    "make_fig6",
    "new_figure",
    "plot_fig5",
    "plot_fig6",
    "save_figure",
    "set_time_limits",
    "stage_label",
]

#: Resolution of the written PNG files (dots per inch).
FIG_DPI = 150

#: Line colour of bumpers 1-4 (shared by every plot of bumper quantities).
BUMPER_COLORS: dict[int, str] = {1: "tab:blue", 2: "tab:orange", 3: "tab:green", 4: "tab:red"}


def _feature_lines(ts) -> list[tuple[str, str, str]]:
    """(label, deflection column, colour) of every contact feature of a time series."""
    from quadimpact.results.schema import feature_columns

    out = []
    for k, (name, delta, _) in enumerate(feature_columns(list(ts.keys()))):
        if name.isdigit() and int(name) in BUMPER_COLORS:
            out.append((f"Bumper {name}", delta, BUMPER_COLORS[int(name)]))
        elif name.isdigit():  # a bumper beyond the fourth (a vehicle with more rotors)
            out.append((f"Bumper {name}", delta, f"C{(k + 4) % 10}"))
        else:
            out.append((name, delta, f"C{(k + 4) % 10}"))
    return out


_REF_STYLE = {"color": "k", "linestyle": "--", "linewidth": 1.0}


def new_figure(
    width_in: float, height_in: float, margins: Mapping[str, float] | None = None
) -> Figure:
    """An empty figure on its own Agg canvas: no pyplot state.

    By default the layout is Matplotlib's constrained layout. With ``margins``
    (``left``, ``right``, ``bottom``, ``top``, ``hspace``, ``wspace`` in figure
    fractions, as ``Figure.subplots_adjust``) the subplots get fixed margins
    instead: the per-run figures use that, since the layout engine costs as much
    as drawing them.
    """
    if margins is None:
        fig = Figure(figsize=(width_in, height_in), layout="constrained")
    else:
        fig = Figure(figsize=(width_in, height_in))
        fig.subplots_adjust(**margins)
    FigureCanvasAgg(fig)
    return fig


def save_figure(fig: Figure, path: str | os.PathLike[str]) -> Path:
    """Write ``fig`` as PNG to ``path`` (atomically: temporary file, then rename)."""
    return atomic_write(path, lambda tmp: fig.savefig(tmp, format="png", dpi=FIG_DPI))


#: Left margin of the per-run figures, in: a y label and six-character tick labels.
LEFT_MARGIN_IN = 1.0


def compact_ticks(ax: Any) -> None:
    """Y tick labels of at most about six characters: powers of ten beyond 1e-3..1e4 go
    to the axis' offset text (``1e-3`` above it) instead of widening every label."""
    try:
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4), useOffset=False)
    except AttributeError:  # a non-scalar formatter (none here): leave it
        pass


def fig_margins(
    width_in: float,
    height_in: float,
    title: str | None,
    hspace: float = 0.2,
    wspace: float = 0.2,
    *,
    bottom_in: float = 0.55,
    right_in: float = 0.2,
) -> dict[str, float]:
    """Fixed margins of a figure, in inches turned into figure fractions.

    The left margin holds a y label and tick labels of up to six characters
    (``-0.005``, ``1000``: :func:`compact_ticks` keeps them that short); the
    bottom one an x label and one line of tick labels (more for rotated ones:
    ``bottom_in``). ``hspace``, ``wspace``: as ``Figure.subplots_adjust``.
    """
    top_in = 0.55 if title else 0.25
    return {
        "left": LEFT_MARGIN_IN / width_in,
        "right": 1.0 - right_in / width_in,
        "bottom": bottom_in / height_in,
        "top": 1.0 - top_in / height_in,
        "hspace": hspace,
        "wspace": wspace,
    }


#: Share of the figure's (or the axes') width a title may take before it is wrapped.
TITLE_WIDTH = 0.96


def _wrap_to_width(text: Text, width_px: float) -> int:
    """Wrap a text artist at its spaces until no line is wider than ``width_px``; its lines.

    A text that fits is left as it is (the same pixels as before); a single
    word wider than the width stays whole.
    """
    import textwrap

    renderer = text.get_figure(root=True).canvas.get_renderer()
    whole = text.get_text()
    wide = text.get_window_extent(renderer).width
    if wide <= width_px or " " not in whole.strip():
        return whole.count("\n") + 1
    chars = max(8, int(max(map(len, whole.split("\n"))) * width_px / wide))
    while True:  # each of its own lines wrapped alike
        lines = [wrapped for line in whole.split("\n") for wrapped in textwrap.wrap(
            line, chars, break_long_words=False, break_on_hyphens=False) or [""]]  # fmt: skip
        text.set_text("\n".join(lines))
        if text.get_window_extent(renderer).width <= width_px or chars <= 8:
            return len(lines)
        chars -= max(1, chars // 10)


def fit_title(where: Figure | Any, title: str, **kwargs: Any) -> Text:
    """A title that fits: the figure's (``suptitle``) or an axes' (``set_title``), wrapped.

    ``where``: a figure or an axes; ``kwargs`` go to ``suptitle`` or
    ``set_title``. A title wider than :data:`TITLE_WIDTH` of the figure (or
    of the axes) is wrapped at its spaces onto more lines; a figure with
    fixed margins (:func:`fig_margins`) then lowers its subplots' top by the
    added lines, so that the title is neither cut at the canvas' sides nor
    drawn over the panels (constrained layout makes the room itself).
    """
    fig = where if isinstance(where, Figure) else where.get_figure(root=True)
    if isinstance(where, Figure):
        text = fig.suptitle(title, **kwargs)
        width = fig.bbox.width
    else:
        text = where.set_title(title, **kwargs)
        width = where.get_position().width * fig.bbox.width
    extra = _wrap_to_width(text, TITLE_WIDTH * width) - (title.count("\n") + 1)
    if extra > 0 and fig.get_layout_engine() is None:
        line_px = 1.2 * text.get_fontsize() * fig.dpi / 72.0
        fig.subplots_adjust(top=fig.subplotpars.top - extra * line_px / fig.bbox.height)
    return text


def legend_below(fig: Figure, handles: list[Any], labels: list[str], **kwargs: Any) -> Any:
    """One legend for the whole figure, below its panels (constrained layout makes the room),
    in as many columns as fit the figure's width: it covers no data and is not cut."""
    renderer = fig.canvas.get_renderer()
    for ncols in range(len(labels), 0, -1):
        legend = fig.legend(handles, labels, loc="outside lower center", ncols=ncols, **kwargs)
        if ncols == 1 or legend.get_window_extent(renderer).width <= fig.bbox.width:
            return legend
        legend.remove()
    return None


def set_time_limits(ax: Any, t: Any) -> None:
    """The time axis from the first to the last finite sample (a run of one sample: as is)."""
    t = np.asarray(t, dtype=np.float64)
    t = t[np.isfinite(t)]
    if len(t) and t[-1] > t[0]:
        ax.set_xlim(float(t[0]), float(t[-1]))


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
    fig = new_figure(7.0, 3.8, margins=fig_margins(7.0, 3.8, title))
    ax = fig.add_subplot()
    t = np.asarray(ts["t_s"], dtype=np.float64)
    lines = _feature_lines(ts)
    for label, col, colour in lines:
        delta_mm = 1e3 * np.asarray(ts[col], dtype=np.float64)
        ax.plot(t, delta_mm, color=colour, linewidth=1.2, label=label)
    ax.set_xlabel("Time (s)")
    rings = all(label.startswith("Bumper ") for label, _, _ in lines)
    ax.set_ylabel("Bumper deflection (mm)" if rings else "Deflection (mm)")
    ax.grid(True, alpha=0.4)
    compact_ticks(ax)
    ax.legend(loc="best")
    set_time_limits(ax, t)
    if title:
        fit_title(ax, title)
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
    yaw (ZYX Euler, degrees) each with its reference dashed; roll and yaw
    unwrapped (:func:`unwrap_deg`), so that they do not jump at +-180 deg.

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
    fig = new_figure(10.0, 7.5, margins=fig_margins(10.0, 7.5, title, hspace=0.12, wspace=0.25))
    axes = fig.subplots(3, 2, sharex=True)
    t = np.asarray(ts["t_s"], dtype=np.float64)
    _draw_positions(axes[:, 0], t, ts, refs, wall_x_m)
    _draw_angles(axes[:, 1], t, ts, refs)
    for ax in axes.flat:
        ax.grid(True, alpha=0.4)
        compact_ticks(ax)
        if len(ax.get_legend_handles_labels()[0]) > 1:
            ax.legend(loc="best", fontsize="small")
    for ax in axes[-1, :]:
        ax.set_xlabel("Time (s)")
    set_time_limits(axes[0, 0], t)
    if title:
        fit_title(fig, title)
    return fig


def _reference(refs: Mapping[str, float], key: str, scale: float = 1.0) -> float | None:
    """``refs[key]`` times ``scale``; None where it is missing, None or not finite."""
    v = refs.get(key)
    if v is None or not math.isfinite(float(v)):
        return None
    return float(v) * scale


def _draw_positions(
    axes: Any, t: np.ndarray, ts: pd.DataFrame, refs: Mapping[str, float], wall_x_m: float | None
) -> None:
    """Figure 6's left column on ``axes``: X with the wall plane (``wall_x_m``), Y, and
    the altitude with its reference (``refs["altitude_m"]``), in m against ``t`` (s),
    references dashed."""
    left = (
        ("x_m", "X (m)", wall_x_m, "wall"),
        ("y_m", "Y (m)", None, None),
        ("altitude_m", "Altitude (m)", _reference(refs, "altitude_m"), "reference"),
    )
    for ax, (col, label, ref, ref_label) in zip(axes, left, strict=True):
        ax.plot(t, np.asarray(ts[col], dtype=np.float64), color="tab:blue", label="simulated")
        if ref is not None and math.isfinite(ref):
            ax.axhline(ref, label=ref_label, **_REF_STYLE)
        ax.set_ylabel(label)


def _draw_angles(axes: Any, t: np.ndarray, ts: pd.DataFrame, refs: Mapping[str, float]) -> None:
    """Figure 6's right column on ``axes``: roll, pitch and yaw (ZYX Euler, deg) against
    ``t`` (s), each with its reference (``refs``, rad) dashed; roll and yaw unwrapped
    (:func:`unwrap_deg`), their references moved to the same branch."""
    deg = 180.0 / math.pi
    right = (
        ("roll_deg", "Roll φ (deg)", _reference(refs, "roll_rad", deg), True),
        ("pitch_deg", "Pitch θ (deg)", _reference(refs, "pitch_rad", deg), False),
        ("yaw_deg", "Yaw ψ (deg)", _reference(refs, "yaw_rad", deg), True),
    )
    for ax, (col, label, ref, wrapped) in zip(axes, right, strict=True):
        yy = np.asarray(ts[col], dtype=np.float64)
        if wrapped:  # continuous through +-180 deg; the reference on the same branch
            yy = unwrap_deg(yy)
            first = yy[np.isfinite(yy)][:1]
            if ref is not None and len(first):
                ref += 360.0 * round((float(first[0]) - ref) / 360.0)
        ax.plot(t, yy, color="tab:blue", label="simulated")
        if ref is not None:
            ax.axhline(ref, label="reference", **_REF_STYLE)
        ax.set_ylabel(label)


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


STAGE_COLORS = {1: "tab:red", 2: "tab:orange", 3: "tab:olive", 4: "tab:green", 5: "tab:cyan"}
#: The recovery controller's stages (docs/RECOVERY.md 3.4), as drawn in the
#: figures, the movie's clock and the viewer.
STAGE_NAMES = {
    0: "before detection",
    1: "detected",
    2: "tilted away",
    3: "level",
    4: "recovered",
    5: "hover",
}


def stage_label(stage: int) -> str:
    """``"stage 2: tilted away"``: a controller stage as the movie and the viewer show it.

    A stage without a name (a plug-in controller's) is ``"stage N"``.
    """
    name = STAGE_NAMES.get(int(stage))
    return f"stage {int(stage)}: {name}" if name else f"stage {int(stage)}"


def mark_stages(ax: Any, summary: Mapping[str, Any] | None, *, label: bool = False) -> None:
    """Vertical lines at the detection and at each recovery stage's entry (from the summary)."""
    if not summary:
        return
    t_detect = summary.get("t_detect_s")
    if isinstance(t_detect, numbers.Real):
        ax.axvline(t_detect, color="black", linestyle=":", linewidth=1.0,
                   label="detection" if label else None)  # fmt: skip
    for k in (2, 3, 4):
        t = summary.get(f"t_stage{k}_s")
        if isinstance(t, numbers.Real):
            ax.axvline(t, color=STAGE_COLORS[k], linestyle="--", linewidth=1.0,
                       label=f"stage {k} {STAGE_NAMES[k]}" if label else None)  # fmt: skip


def make_imu(
    imu: pd.DataFrame,
    ts: pd.DataFrame | None = None,
    summary: Mapping[str, Any] | None = None,
    title: str | None = None,
) -> Figure:
    """The IMU samples beside the bumper deflections: the impact spike and its detection.

    Panels sharing the time axis: bumper deflections (mm, from the time
    series), the measured specific force (body FRD, m/s^2) with the detector's
    horizontal measure and its threshold, and the measured body rates (rad/s).
    The detection and each recovery stage's entry are marked (from the
    summary, when given).
    """
    n_panels = 3 if ts is not None and len(ts["t_s"]) else 2
    height = 2.4 * n_panels + 0.4
    fig = new_figure(8.0, height, margins=fig_margins(8.0, height, title, hspace=0.12))
    axes = list(np.atleast_1d(fig.subplots(n_panels, 1, sharex=True)))
    t = np.asarray(imu["t_s"], dtype=np.float64)
    if n_panels == 3:
        ax = axes.pop(0)
        tt = np.asarray(ts["t_s"], dtype=np.float64)
        for label, col, colour in _feature_lines(ts):
            ax.plot(tt, 1e3 * np.asarray(ts[col], dtype=np.float64),
                    color=colour, linewidth=1.0, label=label)  # fmt: skip
        ax.set_ylabel("Deflection (mm)")
        mark_stages(ax, summary)
        ax.legend(loc="upper right", fontsize="small", ncols=2)
        ax.grid(True, alpha=0.4)
        compact_ticks(ax)
        first = ax
    else:
        first = axes[0]
    ax_f, ax_w = axes
    axis_colors = ("tab:blue", "tab:orange", "tab:green")
    for col, color in zip(("fx_m_s2", "fy_m_s2", "fz_m_s2"), axis_colors, strict=True):
        ax_f.plot(t, np.asarray(imu[col], dtype=np.float64), color=color, linewidth=1.0,
                  label=col.split("_")[0])  # fmt: skip
    ax_f.plot(t, np.asarray(imu["f_horizontal_m_s2"], dtype=np.float64), color="black",
              linewidth=1.2, label="|f_xy| (detector)")  # fmt: skip
    threshold = (summary or {}).get("detection_threshold_m_s2")
    if isinstance(threshold, numbers.Real):
        ax_f.axhline(threshold, color="gray", linestyle="-.", linewidth=1.0, label="threshold")
    ax_f.set_ylabel("Specific force (m/s²)")
    mark_stages(ax_f, summary, label=True)
    ax_f.legend(loc="upper right", fontsize="small", ncols=3)
    for col, color in zip(("p_rad_s", "q_rad_s", "r_rad_s"), axis_colors, strict=True):
        ax_w.plot(t, np.asarray(imu[col], dtype=np.float64), color=color, linewidth=1.0,
                  label=col.split("_")[0])  # fmt: skip
    ax_w.set_ylabel("Body rate (rad/s)")
    ax_w.set_xlabel("Time (s)")
    mark_stages(ax_w, summary)
    ax_w.legend(loc="upper right", fontsize="small", ncols=3)
    for ax in (ax_f, ax_w):
        ax.grid(True, alpha=0.4)
        compact_ticks(ax)
    set_time_limits(first, t)
    if title:
        fit_title(fig, title)
    return fig


def plot_imu(
    imu: pd.DataFrame,
    ts: pd.DataFrame | None,
    path: str | os.PathLike[str],
    summary: Mapping[str, Any] | None = None,
    title: str | None = None,
) -> Path:
    """Write the IMU figure (:func:`make_imu`) to ``path`` as PNG."""
    return save_figure(make_imu(imu, ts, summary=summary, title=title), path)
