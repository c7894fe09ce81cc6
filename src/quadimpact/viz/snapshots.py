"""A strip of 3D snapshots at given times after impact (the paper's Figures 7 and 8).

``write_snapshots(DIR)`` reads a result folder and writes ``DIR/snapshots.png``
and ``DIR/snapshots.pdf``: one panel per time, the time after the first
contact under each, all panels seen by the same camera (by default fixed at
the impact point, so the motion shows from panel to panel).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from quadimpact.results.figures import fit_title
from quadimpact.results.files import atomic_write
from quadimpact.viz.camera import DEFAULT_SNAPSHOT_CAMERA, Camera
from quadimpact.viz.render import SceneArtists
from quadimpact.viz.scene import Scene

__all__ = [
    "DEFAULT_SNAPSHOT_CAMERA",
    "PAPER_FIGURE_TIMES",
    "PAPER_VIDEO_TIMES",
    "SNAPSHOTS_PDF",
    "SNAPSHOTS_PNG",
    "make_snapshots",
    "select_times",
    "write_snapshots",
]

SNAPSHOTS_PNG = "snapshots.png"
SNAPSHOTS_PDF = "snapshots.pdf"

#: Times after impact (s) of the simulated frames of the paper's Figure 7
#: (crash 3, type B) and Figure 8 (crash 6, type D).
PAPER_FIGURE_TIMES: dict[int, tuple[float, ...]] = {
    7: (0.0, 0.13, 0.2, 0.265, 0.33, 0.365),
    8: (0.0, 0.07, 0.1, 0.13, 0.215, 0.25),
}
#: Times of the video frames set beside them in Figure 7.
PAPER_VIDEO_TIMES: dict[int, tuple[float, ...]] = {7: (0.0, 0.1, 0.167, 0.233, 0.267, 0.333)}


SNAPSHOT_DPI = 150


def requested_times(
    times: Sequence[float] | None = None, paper_figure: int | None = None
) -> list[float]:
    """The times after impact asked for: ``times``, else the paper figure's (default 8)."""
    if times is not None:
        return [float(t) for t in times]
    fig = 8 if paper_figure is None else int(paper_figure)
    if fig not in PAPER_FIGURE_TIMES:
        raise ValueError(f"paper figure must be 7 or 8 (got {paper_figure})")
    return [float(t) for t in PAPER_FIGURE_TIMES[fig]]


def select_times(
    scene: Scene, times: Sequence[float] | None = None, paper_figure: int | None = None
) -> tuple[list[float], list[str]]:
    """Times after impact to draw, and warnings for those outside the run.

    ``times`` wins over ``paper_figure``; with neither, Figure 8's times.
    """
    kept, warnings = [], []
    for tau in requested_times(times, paper_figure):
        t = scene.t_ref + float(tau)
        if scene.t_start - 1e-9 <= t <= scene.t_end + 1e-9:
            kept.append(float(tau))
        else:
            warnings.append(
                f"time {tau:g} s after impact (t = {t:.3f} s) is outside the run "
                f"[{scene.t_start:.3f}, {scene.t_end:.3f}] s; skipped"
            )
    return kept, warnings


def make_snapshots(
    scene: Scene,
    times_after_impact: Sequence[float],
    camera: Camera | None = None,
    title: str | None = None,
    panel_in: float = 2.3,
) -> Figure:
    """The strip figure: one panel per time after impact, the time under each.

    Parameters
    ----------
    scene : Scene
        The run.
    times_after_impact : sequence of float
        Seconds after the first contact (or after the first sample when the
        run has no contact).
    camera : Camera, optional
        Default :data:`DEFAULT_SNAPSHOT_CAMERA`.
    title : str, optional
        Default: the run's description.
    panel_in : float
        Width and height of each panel, inches.
    """
    if not times_after_impact:
        raise ValueError("no snapshot times to draw")
    cam = camera or DEFAULT_SNAPSHOT_CAMERA
    n = len(times_after_impact)
    fig = Figure(figsize=(panel_in * n, panel_in + 0.75), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, n, squeeze=False)[0]
    for k, (ax, tau) in enumerate(zip(axes, times_after_impact, strict=True)):
        art = SceneArtists(ax, scene, cam, aspect=1.0, labels=True, compass=(k == 0), linewidth=1.6)
        art.update(scene.t_ref + tau)
        ax.set_xlabel(f"{tau:.3f} s", fontsize=10)
    origin = "first contact" if scene.first_contact_s is not None else "start"
    head = title if title is not None else scene.describe()
    fit_title(
        fig,
        f"{head}\ntime after {origin} (t = {scene.t_ref:.3f} s); camera az {cam.azimuth_deg:g}°, "
        f"el {cam.elevation_deg:g}°, {cam.span_m:g} m high",
        fontsize=9,
    )
    return fig


def write_snapshots(
    result_dir: str | os.PathLike[str],
    times: Sequence[float] | None = None,
    paper_figure: int | None = None,
    camera: Camera | None = None,
    out_dir: str | os.PathLike[str] | None = None,
    scene: Scene | None = None,
) -> tuple[Path, Path, list[str]]:
    """Write ``snapshots.png`` and ``snapshots.pdf`` of a result folder.

    Parameters
    ----------
    result_dir : path
        Folder written by ``quadimpact run``.
    times : sequence of float, optional
        Seconds after the first contact; default the paper's Figure 8 times
        (or Figure 7's with ``paper_figure=7``).
    paper_figure : {7, 8}, optional
        Use that figure's times.
    camera : Camera, optional
        Default :data:`DEFAULT_SNAPSHOT_CAMERA`.
    out_dir : path, optional
        Where to write (default ``result_dir``).
    scene : Scene, optional
        An already built scene of the run.

    Returns
    -------
    png, pdf : pathlib.Path
        The files written.
    warnings : list of str
        Times skipped because they fall outside the run.
    """
    scene = scene or Scene.from_dir(result_dir)
    kept, warnings = select_times(scene, times, paper_figure)
    if not kept:
        asked = requested_times(times, paper_figure)
        first, last = min(asked), max(asked)
        raise ValueError(
            f"none of the snapshot times ({first:g} to {last:g} s after the impact at "
            f"t = {scene.t_ref:.3f} s) falls inside the run [{scene.t_start:.3f}, "
            f"{scene.t_end:.3f}] s; times from {scene.t_start - scene.t_ref:.3g} to "
            f"{scene.t_end - scene.t_ref:.3g} s after the impact are inside it"
        )
    fig = make_snapshots(scene, kept, camera)
    out = Path(out_dir if out_dir is not None else result_dir)
    out.mkdir(parents=True, exist_ok=True)
    png = atomic_write(
        out / SNAPSHOTS_PNG, lambda tmp: fig.savefig(tmp, format="png", dpi=SNAPSHOT_DPI)
    )
    pdf = atomic_write(out / SNAPSHOTS_PDF, lambda tmp: fig.savefig(tmp, format="pdf"))
    return Path(png), Path(pdf), warnings
