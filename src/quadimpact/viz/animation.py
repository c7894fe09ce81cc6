"""Movies of a run: MP4 (imageio-ffmpeg) and GIF (Pillow).

The figure (3D view on the left; bumper deflections and attitude on the
right, drawn as the clock runs) is built once. The clock in the 3D view
shows the time, the time after impact and, for a run whose controller has
stages (the ``recovery`` controller), the stage in force ("stage 2: tilted
away"). Its static part (axes, ticks,
legends, the faint whole-run curves) is rendered once and kept as a
background; every frame restores it, moves the changing artists
(:class:`~quadimpact.viz.render.SceneArtists`, the live lines, cursors and
clock) and draws only those (blitting), then hands the pixels to ffmpeg's
pipe: a 3-s run at 30 fps (91 frames) renders in a few seconds. The texts
that only move (the body axes' names, the bumper numbers) and the compass are
drawn once and pasted at each frame (:mod:`quadimpact.viz.stamps`): a recovery
trial's 91 frames took 1.24 s of CPU instead of 1.71 s.

Frame ``k`` shows simulated time ``t0 + k / (fps * slow)``; the movie has
``round((t1 - t0) * fps * slow) + 1`` frames, so ``slow = 4`` plays the run
four times slower than real time.
"""

from __future__ import annotations

import logging
import math
import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from quadimpact.results.figures import fit_title, set_time_limits, stage_label
from quadimpact.results.files import atomic_write
from quadimpact.viz.camera import DEFAULT_ANIMATION_CAMERA, Camera
from quadimpact.viz.render import SceneArtists
from quadimpact.viz.scene import Scene
from quadimpact.viz.stamps import Stamp, TextStamp
from quadimpact.viz.vehicle_drawing import BUMPER_COLORS_HEX

__all__ = [
    "ANIMATION_GIF",
    "ANIMATION_MP4",
    "DEFAULT_ANIMATION_CAMERA",
    "AnimationFigure",
    "AnimationInfo",
    "frame_times",
    "write_animation",
]

ANIMATION_MP4 = "animation.mp4"
ANIMATION_GIF = "animation.gif"


_ATTITUDE_COLORS = {"roll": "#1b9e77", "pitch": "#d95f02", "yaw": "#7570b3"}
#: From this movie height on (pixels) the plots' legends sit above their panels, over no
#: curve; a smaller movie has no room there and keeps them in the panels' upper right.
LEGENDS_ABOVE_PX = 360


def frame_times(t0: float, t1: float, fps: float, slow: float = 1.0) -> np.ndarray:
    """Frame times ``t0 + k / (fps slow)``, k = 0 .. round((t1 - t0) fps slow), in s."""
    if not fps > 0 or not slow > 0:
        raise ValueError("fps and slow must be > 0")
    if not t1 >= t0:
        raise ValueError("the end time must not precede the start time")
    n = int(round((t1 - t0) * fps * slow)) + 1
    return np.minimum(t0 + np.arange(n) / (fps * slow), t1)


class AnimationFigure:
    """The movie's figure at a fixed pixel size; :meth:`render` draws one instant.

    Parameters
    ----------
    scene : Scene
        The run.
    camera : Camera
        The 3D view.
    width, height : int
        Pixels (even numbers keep H.264 happy).
    t0, t1 : float
        Span of the plots' time axes, s.
    slow : float
        Slow-down factor, shown in the clock.
    """

    def __init__(
        self,
        scene: Scene,
        camera: Camera,
        width: int = 1280,
        height: int = 720,
        t0: float | None = None,
        t1: float | None = None,
        slow: float = 1.0,
    ) -> None:
        self.scene = scene
        self.width, self.height = int(width), int(height)
        self.slow = slow
        dpi = 100.0
        fig = Figure(figsize=(self.width / dpi, self.height / dpi), dpi=dpi, layout="constrained")
        self.canvas = FigureCanvasAgg(fig)
        self.fig = fig
        gs = fig.add_gridspec(2, 2, width_ratios=[1.55, 1.0])
        ax3d = fig.add_subplot(gs[:, 0])
        ax_d = fig.add_subplot(gs[0, 1])
        ax_a = fig.add_subplot(gs[1, 1], sharex=ax_d)
        # the 3D axes' box aspect: its share of the figure width over the height
        aspect = (1.55 / 2.55) * self.width / self.height * 0.97
        self.view = SceneArtists(ax3d, scene, camera, aspect=aspect, linewidth=2.0)
        fit_title(fig, scene.describe(), fontsize=11)
        self.clock = ax3d.text(
            0.02,
            0.98,
            "",
            transform=ax3d.transAxes,
            ha="left",
            va="top",
            fontsize=11,
            family="monospace",
            zorder=20,
            bbox={"boxstyle": "round", "facecolor": "white", "alpha": 0.8, "edgecolor": "#cccccc"},
        )

        t0 = scene.t_start if t0 is None else t0
        t1 = scene.t_end if t1 is None else t1
        self._t = scene.t
        self._plot_deflections(ax_d)
        self._plot_attitude(ax_a)
        for ax in (ax_d, ax_a):
            ax.grid(True, alpha=0.35)
            set_time_limits(ax, [t0, t1])
            if scene.first_contact_s is not None:
                ax.axvline(scene.first_contact_s, color="k", linestyle=":", linewidth=0.8)
            if scene.crash_time_s is not None:
                ax.axvline(scene.crash_time_s, color="k", linestyle="--", linewidth=0.8)
            ax.tick_params(labelsize=8)
        self.cursors = [ax.axvline(t0, color="#555555", linewidth=1.0) for ax in (ax_d, ax_a)]
        self._prepare_blitting(ax3d, ax_d, ax_a)

    def _plot_deflections(self, ax_d: Axes) -> None:
        """Deflections (mm): the whole run faint, the part up to the clock bold (live)."""
        scene, t = self.scene, self._t
        self.defl_live = []
        self.defl_dots = []
        for j in (1, 2, 3, 4):
            y = 1e3 * scene.deltas[:, j - 1]
            c = BUMPER_COLORS_HEX[j]
            ax_d.plot(t, y, color=c, alpha=0.2, linewidth=1.0)
            self.defl_live.append(ax_d.plot([], [], color=c, linewidth=1.6, label=f"bumper {j}")[0])
            self.defl_dots.append(ax_d.plot([], [], "o", color=c, markersize=4)[0])
        ax_d.set_ylabel("deflection (mm)")
        # the legends above their panels, where the movie is tall enough for them: the
        # curves drawn as the clock runs then go under none
        above = self.height >= LEGENDS_ABOVE_PX
        where = {"loc": "lower right", "bbox_to_anchor": (1.0, 1.0), "borderaxespad": 0.2}
        ax_d.legend(**(where if above else {"loc": "upper right"}), fontsize=8,
                    ncol=4 if above else 2)  # fmt: skip
        ymax = max(1.0, float(np.nanmax(1e3 * scene.deltas)) * 1.1)
        ax_d.set_ylim(-0.03 * ymax, ymax)

    def _plot_attitude(self, ax_a: Axes) -> None:
        """Attitude (deg): the whole run faint, the part up to the clock bold (live)."""
        scene, t = self.scene, self._t
        self.att_live = []
        self.att_data = []
        for k, name in enumerate(("roll", "pitch", "yaw")):
            tb, yb = t, scene.euler_deg[:, k]  # roll and yaw unwrapped (Scene)
            c = _ATTITUDE_COLORS[name]
            ax_a.plot(tb, yb, color=c, alpha=0.2, linewidth=1.0)
            self.att_live.append(ax_a.plot([], [], color=c, linewidth=1.4, label=name)[0])
            self.att_data.append((tb, yb))
        ax_a.set_ylabel("attitude (deg)")
        ax_a.set_xlabel("time (s)")
        above = self.height >= LEGENDS_ABOVE_PX
        where = {"loc": "lower right", "bbox_to_anchor": (1.0, 1.0), "borderaxespad": 0.2}
        ax_a.legend(**(where if above else {"loc": "upper right"}), fontsize=8, ncol=3)

    def _prepare_blitting(self, ax3d: Axes, ax_d: Axes, ax_a: Axes) -> None:
        """Mark what changes every frame; stamp what never does (the rest is the background)."""
        # blitting: these change every frame; the rest is the background
        self.dynamic = [
            (ax3d, [*self.view.artists(), self.clock]),
            (ax_d, [*self.defl_live, *self.defl_dots, self.cursors[0]]),
            (ax_a, [*self.att_live, self.cursors[1]]),
        ]
        for _ax, arts in self.dynamic:
            for art in arts:
                art.set_animated(True)
        # the texts that never change and the compass: drawn once, pasted (viz/stamps.py);
        # None marks the compass's other artists, pasted with its first
        self._stamps: dict[Artist, Stamp | None] = {
            text: TextStamp(text) for text in self.view.constant_texts()
        }
        compass = self.view.compass
        if compass:
            self._stamps[compass[0]] = Stamp(compass, lambda: (0.0, 0.0))  # it stays put
            self._stamps.update(dict.fromkeys(compass[1:]))
        self._background = None

    def render(self, t: float) -> np.ndarray:
        """Draw time ``t``; return the pixels, shape (height, width, 3), uint8 (a copy)."""
        return np.ascontiguousarray(self.render_rgba(t)[:, :, :3])

    def render_rgba(self, t: float) -> np.ndarray:
        """Draw time ``t``; return the canvas itself, shape (height, width, 4), uint8 RGBA.

        A view of the figure's pixels (no copy), valid until the next frame is
        drawn: what the movie's encoder reads (it drops the alpha channel).
        """
        sc = self.scene
        self.view.update(t)
        k = int(np.searchsorted(self._t, t, side="right"))
        deltas, forces, _ = sc.values_at(t)
        for j in range(4):
            self.defl_live[j].set_data(self._t[:k], 1e3 * sc.deltas[:k, j])
            self.defl_dots[j].set_data([t], [1e3 * deltas[j]])
        for line, (tb, yb) in zip(self.att_live, self.att_data, strict=True):
            kk = int(np.searchsorted(np.nan_to_num(tb, nan=-np.inf), t, side="right"))
            line.set_data(tb[:kk], yb[:kk])
        for c in self.cursors:
            c.set_xdata([t, t])
        tau = t - sc.t_ref
        lines = [f"t = {t:6.3f} s", f"impact {tau:+6.3f} s"]
        if self.slow != 1:
            lines.append(f"{self.slow:g}x slower")
        stage = sc.stage_at(t)
        if stage is not None:
            lines.append(stage_label(stage))
        if sc.crash_time_s is not None and t >= sc.crash_time_s - 1e-9:
            lines.append("CRASH")
        self.clock.set_text("\n".join(lines))
        if self._background is None:  # layout and static part drawn once
            self.canvas.draw()
            self.fig.set_layout_engine("none")
            self._background = self.canvas.copy_from_bbox(self.fig.bbox)
            for stamp in self._stamps.values():
                if stamp is not None:
                    stamp.capture(self.canvas)
        self.canvas.restore_region(self._background)
        buf = np.asarray(self.canvas.buffer_rgba())
        stamps = self._stamps
        for ax, arts in self.dynamic:
            for art in sorted(arts, key=lambda a: a.get_zorder()):
                if art not in stamps:
                    ax.draw_artist(art)
                elif stamps[art] is not None:
                    stamps[art].paste(buf)  # in its turn: what lies over it still does
        if buf.shape[:2] != (self.height, self.width):
            raise RuntimeError(
                f"canvas is {buf.shape[1]}x{buf.shape[0]}, expected {self.width}x{self.height}"
            )
        return buf


@dataclass
class AnimationInfo:
    """What :func:`write_animation` wrote and how long it took."""

    mp4: Path | None
    gif: Path | None
    n_frames: int
    fps: float
    size: tuple[int, int]
    seconds: float


def write_animation(
    result_dir: str | os.PathLike[str],
    fps: float = 30.0,
    slow: float = 1.0,
    start: float | None = None,
    end: float | None = None,
    camera: Camera | None = None,
    size: tuple[int, int] = (1280, 720),
    mp4: bool = True,
    gif: bool = False,
    gif_fps: float = 15.0,
    gif_width: int = 640,
    out_dir: str | os.PathLike[str] | None = None,
    scene: Scene | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> AnimationInfo:
    """Write ``animation.mp4`` (and ``animation.gif``) of a result folder.

    Parameters
    ----------
    result_dir : path
        Folder written by ``quadimpact run``.
    fps : float
        Frames per second of the movie.
    slow : float
        Slow-down factor (1 = real time).
    start, end : float, optional
        Simulated span, s (default: the whole run).
    camera : Camera, optional
        Default :data:`DEFAULT_ANIMATION_CAMERA` (following the vehicle).
    size : (int, int)
        Width and height in pixels (even numbers).
    mp4, gif : bool
        Which files to write.
    gif_fps, gif_width : float, int
        The GIF keeps every ``round(fps / gif_fps)``-th frame, scaled to this width.
    out_dir : path, optional
        Where to write (default ``result_dir``).
    scene : Scene, optional
        An already built scene of the run.
    progress : callable, optional
        Called as ``progress(k, n)`` after each frame.
    """
    started = time.perf_counter()
    w, h = int(size[0]), int(size[1])
    if w % 2 or h % 2 or w < 64 or h < 64:
        raise ValueError(f"movie size must be even and at least 64x64 (got {w}x{h})")
    scene = scene or Scene.from_dir(result_dir)
    t0 = scene.t_start if start is None else max(float(start), scene.t_start)
    t1 = scene.t_end if end is None else min(float(end), scene.t_end)
    times = frame_times(t0, t1, fps, slow)
    out = Path(out_dir if out_dir is not None else result_dir)
    out.mkdir(parents=True, exist_ok=True)
    fig = AnimationFigure(scene, camera or DEFAULT_ANIMATION_CAMERA, w, h, t0, t1, slow)

    gif_frames: list[Any] | None = [] if gif else None
    gif_step = max(1, int(round(fps / gif_fps))) if gif else 0
    render = partial(_render_frames, fig, times, fps=fps, gif_frames=gif_frames,
                     gif_step=gif_step, gif_width=gif_width, progress=progress)  # fmt: skip
    mp4_path = out / ANIMATION_MP4
    if mp4:
        atomic_write(mp4_path, render, suffix=".mp4")  # ffmpeg reads the format from the name
    else:
        render(None)
    gif_path = None
    if gif_frames is not None:
        gif_path = _write_gif(out / ANIMATION_GIF, gif_frames, int(round(1000.0 * gif_step / fps)))
    return AnimationInfo(
        mp4=mp4_path if mp4 else None,
        gif=gif_path,
        n_frames=len(times),
        fps=fps,
        size=(w, h),
        seconds=time.perf_counter() - started,
    )


def _render_frames(
    fig: AnimationFigure,
    times: np.ndarray,
    movie: Path | None,
    *,
    fps: float,
    gif_frames: list[Any] | None,
    gif_step: int,
    gif_width: int,
    progress: Callable[[int, int], None] | None,
) -> None:
    """Draw ``fig`` at each of ``times`` (simulated s): into the movie ``movie`` (H.264 at
    ``fps`` frames per second; None: no movie) and, every ``gif_step``-th frame scaled to
    ``gif_width`` pixels, onto ``gif_frames`` (None: no GIF); ``progress(k, n)`` after
    each frame."""
    writer = None if movie is None else _movie_writer(movie, (fig.width, fig.height), fps)
    sent = 0
    try:
        for k, t in enumerate(times):
            pixels = fig.render_rgba(float(t))
            if writer is not None:
                writer.send(pixels)  # written to ffmpeg's pipe from the canvas's memory
                sent += 1
            if gif_frames is not None and k % gif_step == 0:
                gif_frames.append(_gif_frame(pixels[:, :, :3], gif_width))
            if progress is not None:
                progress(k + 1, len(times))
    finally:
        if writer is not None:
            _close_movie(writer, sent)


def _movie_writer(movie: Path, size: tuple[int, int], fps: float) -> Any:
    """A started ffmpeg writer of H.264 frames (RGBA in, as the canvas holds them)."""
    import imageio_ffmpeg

    writer = imageio_ffmpeg.write_frames(
        str(movie),
        size,
        fps=fps,
        codec="libx264",
        pix_fmt_in="rgba",  # the canvas as it is: no copy to RGB per frame
        pix_fmt_out="yuv420p",
        quality=7,
        # x264's "veryfast": 40 % less of ffmpeg's CPU than its default
        # ("medium") for a 2 % larger file at the same quality setting
        output_params=["-preset", "veryfast"],
        macro_block_size=2,
        ffmpeg_log_level="error",
    )
    writer.send(None)
    return writer


def _close_movie(writer: Any, sent: int) -> None:
    """Close the writer; when it failed before its first frame, the error says why, not
    ffmpeg's "No frames have been written" (the half movie is removed anyway)."""
    log = logging.getLogger("imageio_ffmpeg")
    quiet, log.disabled = log.disabled, log.disabled or sent == 0
    try:
        writer.close()
    finally:
        log.disabled = quiet


def _write_gif(path: Path, frames: list[Any], duration_ms: int) -> Path:
    """The GIF of ``frames`` (each shown ``duration_ms``), written atomically."""
    return atomic_write(
        path,
        lambda tmp: frames[0].save(
            tmp,
            format="GIF",
            save_all=True,
            append_images=frames[1:],
            duration=duration_ms,
            loop=0,
            disposal=1,
        ),
    )


def _gif_frame(pixels: np.ndarray, width: int):  # -> PIL.Image.Image
    from PIL import Image

    im = Image.fromarray(pixels)
    if width and im.width != width:
        height = max(2, int(math.floor(im.height * width / im.width)))
        im = im.resize((width, height), Image.Resampling.LANCZOS)
    return im.quantize(colors=128, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
