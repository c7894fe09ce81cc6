"""Command-line commands ``quadimpact animate``, ``snapshots`` and ``view``.

Registered on the group in :mod:`quadimpact.cli`. Each reads a result
folder written by ``quadimpact run`` and writes into it:

* ``animate DIR``: ``DIR/animation.mp4`` (and ``DIR/animation.gif`` with ``--gif``);
* ``snapshots DIR``: ``DIR/snapshots.png`` and ``DIR/snapshots.pdf``;
* ``view DIR``: ``DIR/viewer.html``, whose path is printed.
"""

from __future__ import annotations

import errno
import functools
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from quadimpact.cli.options import (
    FiniteFloat,
    defaulted_option,
    number_option,
    result_dir_argument,
)
from quadimpact.errors import InputError

__all__ = ["animate", "make_all", "snapshots", "view"]


def _camera_options(func: Callable[..., Any]) -> Callable[..., Any]:
    """--azimuth, --elevation, --follow, --span (defaults depend on the command)."""
    opts = [
        number_option(
            "--azimuth",
            "DEG",
            "Camera direction from the vehicle seen from above, deg from +X (toward "
            "the wall) toward +Y (right): 90 = from starboard, wall on the right. "
            "[default: 120 snapshots, 110 otherwise]",
        ),
        number_option(
            "--elevation",
            "DEG",
            "Camera height above the horizontal, deg in [-89, 89]. [default: 20]",
        ),
        click.option(
            "--follow",
            type=click.Choice(["vehicle", "wall"]),
            help="'vehicle': centred on the vehicle; 'wall': fixed at the impact point. "
            "[default: wall for snapshots, vehicle otherwise]",
        ),
        number_option(
            "--span", "M", "Height of the 3D view, m. [default: 1.0 snapshots, 0.9 otherwise]"
        ),
        click.option(
            "--vehicle",
            metavar="NAME_OR_PATH",
            help="Vehicle to draw instead of the one the run recorded in scenario.json; "
            "needed only for a folder without scenario.json (written by an older "
            "version) whose vehicle is not a bundled one.",
        ),
    ]
    for opt in reversed(opts):
        func = opt(func)
    return func


def _camera(
    default: Any,
    azimuth: float | None,
    elevation: float | None,
    follow: str | None,
    span: float | None,
) -> Any:
    from quadimpact.viz.camera import Camera

    try:
        return Camera(
            azimuth_deg=default.azimuth_deg if azimuth is None else azimuth,
            elevation_deg=default.elevation_deg if elevation is None else elevation,
            follow=default.follow if follow is None else follow,
            span_m=default.span_m if span is None else span,
        )
    except ValueError as exc:
        raise InputError(f"camera: {exc}") from None


def _scene(result_dir: Path, vehicle: str | None) -> Any:
    """The scene of a result folder, with input errors as one line.

    The folder is checked and read before the drawing code (and the simulator
    it draws with) is imported: a wrong folder is said at once.
    """
    from quadimpact.results.files import SUMMARY_JSON, TIMESERIES_PARQUET, check_writable
    from quadimpact.results.result import read_result

    if not result_dir.is_dir():
        raise InputError(f"{result_dir}: result folder not found")
    for name in (SUMMARY_JSON, TIMESERIES_PARQUET):
        if not (result_dir / name).is_file():
            raise InputError(f"{result_dir}: no {name} (not a folder written by 'quadimpact run')")
    veh = None
    if vehicle is not None:
        from quadimpact.inputs.vehicle import load_vehicle

        veh = load_vehicle(vehicle)
    result = read_result(result_dir)  # a file that cannot be read: one line naming it
    check_writable(result_dir, f"{result_dir}: the pictures cannot be written there")
    from quadimpact.viz.scene import Scene

    try:
        return Scene.from_result(result, vehicle=veh)
    except InputError as exc:
        raise InputError(f"{exc} (pass --vehicle with the run's vehicle file)") from None
    except ValueError as exc:
        raise InputError(f"{result_dir}: {exc}") from None
    except (KeyError, TypeError, AttributeError, IndexError) as exc:  # a hand-edited record
        raise InputError(
            f"{result_dir / 'scenario.json'}: damaged or not written by quadimpact "
            f"({type(exc).__name__}: {exc})"
        ) from None


def _value_errors(func: Callable[..., Any]) -> Callable[..., Any]:
    """A ValueError, or a folder that refuses the files, as an input error (exit 2)."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return func(*args, **kwargs)
        except ValueError as exc:
            raise InputError(str(exc)) from None
        except OSError as exc:
            if exc.errno not in (errno.EACCES, errno.EPERM, errno.EROFS):
                raise
            where = exc.filename or kwargs.get("result_dir") or "the result folder"
            raise InputError(f"{where}: cannot be written ({exc.strerror or exc})") from None

    return wrapper


def _parse_times(text: str) -> list[float]:
    parts = [p for p in text.replace(",", " ").split() if p]
    try:
        times = [float(p) for p in parts]
    except ValueError:
        raise InputError(
            f"--times: numbers separated by commas, e.g. 0,0.07,0.1 (got {text!r})"
        ) from None
    if not times:
        raise InputError("--times: give at least one time")
    return times


#: The largest movie frame, pixels (8K UHD): a frame is drawn whole in memory (4 bytes a pixel).
MAX_FRAME_PIXELS = 7680 * 4320
#: The most frames of a snapshot strip without --max-frames (one row of panels).
MAX_SNAPSHOT_FRAMES = 24


def _parse_size(text: str) -> tuple[int, int]:
    w, sep, h = text.lower().partition("x")
    try:
        size = (int(w), int(h))
    except ValueError:
        size = (0, 0)
    if not sep or size[0] < 64 or size[1] < 64 or size[0] % 2 or size[1] % 2:
        raise InputError(f"--size: WIDTHxHEIGHT in pixels, even, at least 64 (got {text!r})")
    pixels = size[0] * size[1]
    if pixels > MAX_FRAME_PIXELS:
        raise InputError(
            f"--size {text}: a frame of {pixels / 1e6:,.0f} Mpx ({4 * pixels / 2**30:,.1f} GiB "
            f"to draw) is larger than 8K (7680x4320, {MAX_FRAME_PIXELS / 1e6:.1f} Mpx), the "
            "largest movie size quadimpact draws"
        )
    return size


def _check_frames(times: list[float], max_frames: int) -> None:
    """Refuse a snapshot strip of more than ``max_frames`` frames, with its picture size."""
    from quadimpact.viz.snapshots import SNAPSHOT_DPI

    if len(times) <= max_frames:
        return
    width = round(2.3 * SNAPSHOT_DPI * len(times))
    raise InputError(
        f"--times: {len(times)} frames would make a {width:,} pixel wide strip (one row of "
        f"panels, each drawn in 3D), more than the {max_frames} frames allowed; give fewer "
        "times, or --max-frames N to allow more (for a movie: quadimpact animate)"
    )


# ------------------------------------------------------------------ animate
@click.command("animate")
@result_dir_argument
@defaulted_option("--fps", FiniteFloat(min=1, max=240), 30.0, "Frames per second of the movie.")
@defaulted_option(
    "--slow",
    FiniteFloat(min=0.01, max=1000),
    1.0,
    "Slow-down factor: 1 = real time, 4 = four times slower.",
)
@number_option("--start", "S", "First simulated time shown, s. [default: start of the run]")
@number_option("--end", "S", "Last simulated time shown, s. [default: end of the run]")
@click.option("--gif", is_flag=True, help="Also write animation.gif (smaller, 15 fps, for slides).")
@click.option(
    "--size",
    default="1280x720",
    show_default=True,
    metavar="WxH",
    help="Movie size in pixels (even, at least 64x64, at most 8K: 7680x4320 pixels).",
)
@_camera_options
@_value_errors
def animate(
    result_dir: Path,
    fps: float,
    slow: float,
    start: float | None,
    end: float | None,
    gif: bool,
    size: str,
    vehicle: str | None,
    **cam: Any,
) -> None:
    """Write RESULT_DIR/animation.mp4 (and .gif with --gif) of a run.

    The 3D view (following the vehicle by default) beside the bumper
    deflections and the attitude drawn as the clock runs. Example, four
    times slower than real time around the impact:

    \b
      quadimpact animate results/paper-example-replica --slow 4 --start 0.4 --end 1.4
    """
    from quadimpact.viz.camera import DEFAULT_ANIMATION_CAMERA

    if start is not None and end is not None and end < start:
        raise InputError(f"--start {start:g}, --end {end:g}: --end must not precede --start")
    wh = _parse_size(size)
    camera = _camera(DEFAULT_ANIMATION_CAMERA, **cam)
    scene = _scene(result_dir, vehicle)
    _check_span(start, end, scene.t_start, scene.t_end)
    _need_ffmpeg()
    from quadimpact.viz.animation import write_animation

    info = write_animation(
        result_dir,
        fps=fps,
        slow=slow,
        start=start,
        end=end,
        camera=camera,
        size=wh,
        gif=gif,
        scene=scene,
    )
    click.echo(str(info.mp4))
    if info.gif is not None:
        click.echo(str(info.gif))
    click.echo(
        f"quadimpact: {info.n_frames} frames {wh[0]}x{wh[1]} at {fps:g} fps "
        f"in {info.seconds:.1f} s",
        err=True,
    )


def _check_span(start: float | None, end: float | None, t_start: float, t_end: float) -> None:
    """Refuse a ``--start`` after the run's end or an ``--end`` before its start, s."""
    span = f"the run spans {t_start:g} to {t_end:g} s"
    if start is not None and start > t_end:
        raise InputError(f"--start {start:g}: after the end of the run ({span})")
    if end is not None and end < t_start:
        raise InputError(f"--end {end:g}: before the start of the run ({span})")


def _need_ffmpeg() -> None:
    try:
        import imageio_ffmpeg

        imageio_ffmpeg.get_ffmpeg_exe()
    except Exception as exc:  # ImportError, or no binary for this platform
        raise click.ClickException(
            f"MP4 output needs imageio-ffmpeg ({exc}); "
            "install it with: pip install 'quadimpact[viz]'"
        ) from None


# ------------------------------------------------------------------ snapshots
@click.command("snapshots")
@result_dir_argument
@click.option(
    "--times",
    metavar="T1,T2,...",
    help="Times after the first contact, s, separated by commas. "
    "[default: the paper's Figure 8 times 0,0.07,0.1,0.13,0.215,0.25]",
)
@click.option(
    "--paper-figure",
    type=click.Choice(["7", "8"]),
    help="Use the times of the paper's Figure 7 (0,0.13,0.2,0.265,0.33,0.365) or 8.",
)
@click.option(
    "--max-frames",
    type=click.IntRange(min=1),
    default=MAX_SNAPSHOT_FRAMES,
    show_default=True,
    metavar="N",
    help="Most frames --times may give (the strip is one row of 3D panels).",
)
@_camera_options
@_value_errors
def snapshots(
    result_dir: Path,
    times: str | None,
    paper_figure: str | None,
    max_frames: int,
    vehicle: str | None,
    **cam: Any,
) -> None:
    """Write RESULT_DIR/snapshots.png and .pdf: 3D frames at times after impact.

    All frames are seen by the same camera, fixed at the impact point by
    default, with the time after the first contact under each.
    """
    from quadimpact.viz.camera import DEFAULT_SNAPSHOT_CAMERA

    if times is not None and paper_figure is not None:
        raise InputError("--times and --paper-figure: give one of them, not both")
    parsed = None if times is None else _parse_times(times)
    if parsed is not None:
        _check_frames(parsed, max_frames)
    camera = _camera(DEFAULT_SNAPSHOT_CAMERA, **cam)
    scene = _scene(result_dir, vehicle)
    from quadimpact.viz.snapshots import write_snapshots

    png, pdf, warnings = write_snapshots(
        result_dir, parsed, None if paper_figure is None else int(paper_figure), camera, scene=scene
    )
    for w in warnings:
        click.echo(f"quadimpact: warning: {w}", err=True)
    click.echo(str(png))
    click.echo(str(pdf))


# ------------------------------------------------------------------ view
@click.command("view")
@result_dir_argument
@defaulted_option(
    "--rate",
    FiniteFloat(min=1, max=10000),
    250.0,
    "Frames per simulated second in the page.",
)
@_camera_options
@_value_errors
def view(result_dir: Path, rate: float, vehicle: str | None, **cam: Any) -> None:
    """Write RESULT_DIR/viewer.html, an interactive viewer, and print its path.

    One self-contained file: open it in a browser, offline. 3D view (drag to
    turn, wheel to zoom), time slider, play/pause, deflection and attitude
    plots linked to the slider. URL parameters: viewer.html#t=0.6&az=110&el=20.
    """
    from quadimpact.viz.camera import DEFAULT_VIEWER_CAMERA

    camera = _camera(DEFAULT_VIEWER_CAMERA, **cam)
    scene = _scene(result_dir, vehicle)
    from quadimpact.viz.viewer import write_viewer

    path = write_viewer(result_dir, rate_hz=rate, camera=camera, scene=scene)
    click.echo(str(path.resolve()))


# ------------------------------------------------------------------ quadimpact run --viz
def make_all(out: Path, result: Any) -> list[Path]:
    """Snapshots, animation (if imageio-ffmpeg is installed) and viewer of a run just written.

    Used by ``quadimpact run --viz``; returns the files written.
    """
    from quadimpact.viz.animation import write_animation
    from quadimpact.viz.scene import Scene
    from quadimpact.viz.snapshots import write_snapshots
    from quadimpact.viz.viewer import write_viewer

    scene = Scene.from_result(result)  # the world the run recorded (scenario.json)
    files: list[Path] = []
    try:
        png, pdf, warnings = write_snapshots(out, scene=scene)
        files += [png, pdf]
    except ValueError as exc:  # e.g. a run too short for the default times
        warnings = [f"no snapshots: {exc}"]
    for w in warnings:
        click.echo(f"quadimpact: warning: {w}", err=True)
    try:
        _need_ffmpeg()
    except click.ClickException as exc:
        click.echo(f"quadimpact: warning: no animation: {exc.format_message()}", err=True)
    else:
        files.append(write_animation(out, scene=scene).mp4)
    files.append(write_viewer(out, scene=scene))
    return files
