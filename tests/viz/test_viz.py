"""Pictures of a run: scene geometry, snapshots, movies, the HTML viewer, the commands.

One short run of the paper's example (1 s, 200 Hz output) feeds every test.
The browser tests need headless Chromium (``make test`` installs it from
Debian's packages when run as root) and skip, saying so, without it.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import quadimpact.errors
from quadimpact import WallApproach, load_vehicle, simulate
from quadimpact.core import layout as L
from quadimpact.core.geometry import contact_record
from quadimpact.inputs.world import Plane
from quadimpact.packing.vehicle_block import pack_features
from quadimpact.packing.world_block import pack_surfaces
from quadimpact.rotations import euler_zyx_to_quat, quat_to_matrix
from quadimpact.viz.render import SceneArtists
from quadimpact.viz.scene import Camera, Scene, VehicleDrawing, to_inertial

from helpers import run_cli

SRC = Path(quadimpact.errors.__file__).resolve().parents[1]
SPIRI = load_vehicle()
WALL_D = 1.5
FINAL_T = 1.0


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The paper's example (replica), 1 s at 200 Hz: bumper 4 hits the wall at t = 0.5 s."""
    out = tmp_path_factory.mktemp("viz") / "example"
    result = simulate(
        WallApproach(
            heading_deg=45,
            inclination_deg=15,
            speed_m_s=0.75,
            model="paper-replica",
            final_time_s=FINAL_T,
            output_rate_hz=200,
            wall_distance_m=WALL_D,
        )
    )
    result.write(out)
    return out


@pytest.fixture(scope="module")
def fine_scene(run_dir: Path) -> Scene:
    """Circles drawn with 7200 segments: the drawn rim is the exact rim to < 0.1 mm."""
    return Scene.from_dir(run_dir, n_points=7200)


def copy_run(run_dir: Path, tmp_path: Path) -> Path:
    target = tmp_path / "run"
    shutil.copytree(run_dir, target)
    return target


# ------------------------------------------------------------------ scene geometry
def test_drawn_circles_are_the_contact_laws_circles(fine_scene: Scene) -> None:
    """Centre on rotor j, radius Rb, in the plane of normal n_j (docs/MODEL.md 4)."""
    sc = fine_scene
    t = sc.first_contact_s + 0.05
    fr = sc.frame(t)
    x = sc.state_at(t)
    C = quat_to_matrix(x[L.X_QUAT : L.X_QUAT + 4])
    centres, _u, n = SPIRI.bumper_frames()
    for j in range(4):
        c_i = x[0:3] + C @ centres[j]
        rel = fr.circles[j] - c_i
        np.testing.assert_allclose(np.linalg.norm(rel, axis=1), SPIRI.bumper_radius_m, atol=1e-12)
        np.testing.assert_allclose(rel @ (C @ n[j]), 0.0, atol=1e-12)


def test_drawn_deepest_point_is_the_computed_contact_point(fine_scene: Scene) -> None:
    sc = fine_scene
    wall = pack_surfaces([Plane.wall(WALL_D)])
    feat = pack_features(SPIRI, 0.0)
    t = float(sc.t[np.searchsorted(sc.t, sc.first_contact_s + 0.08)])  # a sample, in contact
    fr = sc.frame(t)
    x = np.ascontiguousarray(sc.state_at(t))
    C = np.ascontiguousarray(quat_to_matrix(x[L.X_QUAT : L.X_QUAT + 4]))
    computed = {}
    for j in range(4):
        d, _dd, rx, ry, rz, *_ = contact_record(x, C, feat, wall, j, 0)
        p_c = x[0:3] + C @ np.array([rx, ry, rz])
        computed[j + 1] = (d, p_c)
        # the deepest point of the drawn rim (brute force over its points)
        depth = fr.circles[j][:, 0] - WALL_D
        k = int(np.argmax(depth))
        assert depth[k] == pytest.approx(d, abs=1e-7)
        np.testing.assert_allclose(fr.circles[j][k], p_c, atol=2e-4)
    # only bumper 4 touches, and the mark is the compiled contact point
    assert [c.bumper for c in fr.contacts] == [4]
    mark = fr.contacts[0]
    d4, p4 = computed[4]
    np.testing.assert_allclose(mark.point, p4, atol=1e-12)
    assert mark.delta_m == pytest.approx(d4, abs=1e-12)
    ts_delta = sc.deltas[np.searchsorted(sc.t, t), 3]
    assert mark.delta_m == pytest.approx(ts_delta, rel=1e-6)  # the simulation's own deflection
    assert mark.surface_point[0] == pytest.approx(WALL_D, abs=1e-12)  # on the wall
    np.testing.assert_allclose(mark.normal, [-1.0, 0.0, 0.0])
    assert mark.force_n == pytest.approx(sc.forces[np.searchsorted(sc.t, t), 3], rel=1e-9)
    # the force arrow points out of the wall, 1 cm per N
    assert mark.arrow_tip[0] == pytest.approx(WALL_D - 0.01 * mark.force_n, abs=1e-12)

    # and the drawn marker sits at the camera's projection of that point
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure()
    FigureCanvasAgg(fig)
    cam = Camera(follow="wall")
    art = SceneArtists(fig.add_subplot(), sc, cam)
    art.update(t)
    xs, ys = art.points[0].get_data()
    np.testing.assert_allclose([xs[0], ys[0]], cam.project(mark.point, sc.anchor), atol=1e-12)
    assert art.points[0].get_visible() and not art.points[1].get_visible()


def test_first_contact_is_bumper_4_on_the_wall(fine_scene: Scene) -> None:
    sc = fine_scene
    fr = sc.frame(sc.first_contact_s + 1e-3)
    assert [c.bumper for c in fr.contacts] == [4]
    assert sc.surfaces[0].point_m[0] == WALL_D and sc.wall_x_m == WALL_D


def test_numbering_frames_and_camera() -> None:
    """Bumper 1 starboard front, 2 starboard rear, 3 port rear, 4 port front; altitude up."""
    d = VehicleDrawing.from_vehicle(SPIRI)
    C = quat_to_matrix(euler_zyx_to_quat(0.0, 0.0, 0.0))
    pos = np.array([0.0, 0.0, -2.0])
    centres = to_inertial(d.centres, pos, C)
    signs = np.sign(centres[:, :2])
    np.testing.assert_array_equal(signs, [[1, 1], [-1, 1], [-1, -1], [1, -1]])
    assert np.all(-centres[:, 2] > 2.0)  # rotors above the CM (altitude = -Z)
    # heading 90 deg (nose to +Y): bumper 1 is then toward -X? no: starboard of +Y is -X
    C90 = quat_to_matrix(euler_zyx_to_quat(0.0, 0.0, math.pi / 2))
    c90 = to_inertial(d.centres, pos, C90)
    assert c90[0, 1] > 0 and c90[0, 0] < 0  # starboard front: ahead (+Y) and to the right (-X)
    # side camera from starboard: +X to the right, up is up, +Y toward the viewer
    cam = Camera(azimuth_deg=90.0, elevation_deg=0.0)
    right, up, fwd = cam.basis()
    np.testing.assert_allclose(right, [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(up, [0, 0, -1], atol=1e-12)
    np.testing.assert_allclose(fwd, [0, -1, 0], atol=1e-12)
    # from behind: +Y to the right (NED: Y is the right of X)
    right, up, _ = Camera(azimuth_deg=180.0, elevation_deg=0.0).basis()
    np.testing.assert_allclose(right, [0, 1, 0], atol=1e-12)
    # equal scaling: an orthonormal basis for any view, altitude never down on screen
    for az, el in [(110, 20), (-37, 65), (200, -30)]:
        cam = Camera(azimuth_deg=az, elevation_deg=el)
        basis = np.array(cam.basis())
        np.testing.assert_allclose(basis @ basis.T, np.eye(3), atol=1e-12)
        assert cam.project(np.array([0.0, 0.0, -1.0]), np.zeros(3))[1] > 0
    with pytest.raises(ValueError):
        Camera(follow="ceiling")  # type: ignore[arg-type]


# ------------------------------------------------------------------ snapshots
def test_snapshots_png_and_pdf(run_dir: Path, tmp_path: Path) -> None:
    from PIL import Image

    from quadimpact.viz.snapshots import PAPER_FIGURE_TIMES, make_snapshots, write_snapshots

    d = copy_run(run_dir, tmp_path)
    png, pdf, warnings = write_snapshots(d)
    assert png == d / "snapshots.png" and pdf == d / "snapshots.pdf" and warnings == []
    assert pdf.read_bytes()[:5] == b"%PDF-"
    with Image.open(png) as im:
        assert im.width > 4 * im.height  # a strip
    sc = Scene.from_dir(d)
    fig = make_snapshots(sc, PAPER_FIGURE_TIMES[8])
    labels = [ax.get_xlabel() for ax in fig.axes]
    assert labels == ["0.000 s", "0.070 s", "0.100 s", "0.130 s", "0.215 s", "0.250 s"]
    # times outside the run are skipped with a warning; Figure 7's times fit in 1 s
    _, _, warnings = write_snapshots(d, times=[0.0, 0.1, 0.9])
    assert len(warnings) == 1 and "0.9" in warnings[0]
    _, _, warnings = write_snapshots(d, paper_figure=7)
    assert warnings == []


# ------------------------------------------------------------------ movies
def test_movie_frame_count_and_size(run_dir: Path, tmp_path: Path) -> None:
    imageio_ffmpeg = pytest.importorskip("imageio_ffmpeg", reason="pip install 'quadimpact[viz]'")
    from PIL import Image

    from quadimpact.viz.animation import frame_times, write_animation

    d = copy_run(run_dir, tmp_path)
    info = write_animation(
        d, fps=10, slow=2.0, start=0.4, end=0.9, size=(320, 240), gif=True, gif_fps=5
    )
    expected = int(round((0.9 - 0.4) * 10 * 2.0)) + 1  # 11 frames, 0.05 s of simulation apart
    assert info.n_frames == expected == len(frame_times(0.4, 0.9, 10, 2.0))
    assert info.mp4 == d / "animation.mp4" and info.gif == d / "animation.gif"
    reader = imageio_ffmpeg.read_frames(str(info.mp4))
    meta = next(reader)
    assert tuple(meta["size"]) == (320, 240)
    frames = [np.frombuffer(f, np.uint8) for f in reader]
    assert len(frames) == expected
    assert frames[0].size == 320 * 240 * 3
    assert np.abs(frames[0].astype(int) - frames[-1].astype(int)).mean() > 0.5  # it moves
    with Image.open(info.gif) as gif:
        assert gif.n_frames == math.ceil(expected / 2) and gif.width == 640


def test_render_time_per_frame_is_small(run_dir: Path) -> None:
    """A 3-s run at 30 fps is 91 frames: well under a minute means well under 0.6 s a frame."""
    import time

    from quadimpact.viz.animation import DEFAULT_ANIMATION_CAMERA, AnimationFigure

    fig = AnimationFigure(Scene.from_dir(run_dir), DEFAULT_ANIMATION_CAMERA, 1280, 720)
    fig.render(0.5)
    start = time.perf_counter()
    for t in np.linspace(0.0, FINAL_T, 10):
        px = fig.render(float(t))
    per_frame = (time.perf_counter() - start) / 10
    assert px.shape == (720, 1280, 3)
    assert per_frame < 0.5, f"{per_frame:.3f} s per frame"


def test_the_movie_reads_the_canvas_itself_and_the_picture_is_its_rgb(run_dir: Path) -> None:
    """The encoder gets the RGBA canvas (no copy per frame); ``render`` is its RGB part."""
    from quadimpact.viz.animation import DEFAULT_ANIMATION_CAMERA, AnimationFigure

    fig = AnimationFigure(Scene.from_dir(run_dir), DEFAULT_ANIMATION_CAMERA, 320, 180)
    rgba = fig.render_rgba(0.5)
    assert rgba.shape == (180, 320, 4) and rgba.dtype == np.uint8 and rgba.flags.c_contiguous
    assert np.shares_memory(rgba, np.asarray(fig.canvas.buffer_rgba()))
    rgb = fig.render(0.5)
    assert rgb.flags.c_contiguous and np.array_equal(rgb, rgba[:, :, :3])
    right, up, forward = DEFAULT_ANIMATION_CAMERA.basis()
    assert DEFAULT_ANIMATION_CAMERA.basis()[0] is right and not right.flags.writeable
    assert abs(right @ up) < 1e-15 and abs(np.linalg.norm(forward) - 1.0) < 1e-15


def test_stamped_frames_are_the_frames_drawn_in_full(run_dir: Path) -> None:
    """The texts pasted from stamps (viz/stamps.py) leave each frame as matplotlib draws it
    in full, but for rounding: a text a pixel over, its edges anti-aliased a bit apart."""
    from quadimpact.viz.animation import DEFAULT_ANIMATION_CAMERA, AnimationFigure

    scene = Scene.from_dir(run_dir)
    stamped = AnimationFigure(scene, DEFAULT_ANIMATION_CAMERA, 640, 360)
    drawn = AnimationFigure(scene, DEFAULT_ANIMATION_CAMERA, 640, 360)
    assert len([s for s in stamped._stamps.values() if s is not None]) == 8  # x y z, 1-4, compass
    bare = AnimationFigure(scene, DEFAULT_ANIMATION_CAMERA, 640, 360)
    bare._stamps = dict.fromkeys(bare._stamps)  # every stamped artist left out
    drawn._stamps = {}
    for t in (0.0, 0.4, 0.9, 1.2):
        a = stamped.render_rgba(t).astype(int)
        b = drawn.render_rgba(t).astype(int)
        without = bare.render_rgba(t).astype(int)
        assert (np.abs(a - without).max(axis=2) > 8).sum() > 100  # the pasted texts are there
        near = np.full(a.shape[:2], 255)  # each pixel against the drawn one or a neighbour
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                shifted = np.roll(b, (dy, dx), axis=(0, 1))
                near = np.minimum(near, np.abs(a - shifted).max(axis=2))
        # Agg renders a glyph at its sub-pixel offset: an edge pixel may differ by a third
        # of full scale from the drawn one's neighbours (here at most 78, on up to 32
        # pixels); the stamps pasted two pixels off give 181-211, on 165-173 pixels
        assert near.max() < 100 and (near > 32).sum() < 50, (near.max(), (near > 32).sum())


# ------------------------------------------------------------------ viewer
def test_viewer_is_one_self_contained_file(run_dir: Path, tmp_path: Path) -> None:
    import json

    from quadimpact.viz.viewer import write_viewer

    d = copy_run(run_dir, tmp_path)
    path = write_viewer(d)
    html = path.read_text(encoding="utf-8")
    assert path == d / "viewer.html"
    assert "://" not in html  # nothing fetched: no URL at all
    assert not re.search(r"<(script|link|img|iframe)[^>]*(src|href)=", html, re.I)
    assert "@import" not in html and "url(" not in html
    data = json.loads(re.search(r'type="application/json">(.*?)</script>', html, re.S).group(1))
    frames = data["frames"]
    assert len(frames["t"]) == len(frames["pos"]) == len(frames["contacts"]) > 100
    # contacts in the page are those of the scene (bumper 4 first, on the wall)
    k = next(i for i, c in enumerate(frames["contacts"]) if c)
    assert frames["contacts"][k][0][0] == 4
    assert frames["contacts"][k][0][4] == pytest.approx(WALL_D, abs=1e-5)


def chromium() -> str | None:
    for name in ("/usr/bin/chromium", "/usr/bin/chromium-browser"):
        if os.access(name, os.X_OK):
            return name
    return shutil.which("chromium")


CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
    "--force-device-scale-factor=1",
    "--window-size=1200,760",
]


def browse(url: str, tmp_path: Path, *action: str) -> subprocess.CompletedProcess:
    profile = tmp_path / f"profile-{len(list(tmp_path.glob('profile-*')))}"
    return subprocess.run(
        [chromium(), *CHROMIUM_FLAGS, f"--user-data-dir={profile}", *action, url],
        capture_output=True,
        text=True,
        timeout=90,
    )


needs_chromium = pytest.mark.skipif(
    chromium() is None,
    reason="headless Chromium not installed (make test installs it as root: "
    "apt-get install chromium chromium-driver)",
)


@pytest.mark.browser
@needs_chromium
def test_viewer_renders_in_headless_chromium(run_dir: Path, tmp_path: Path) -> None:
    from PIL import Image

    from quadimpact.viz.viewer import write_viewer

    d = copy_run(run_dir, tmp_path)
    url = write_viewer(d).resolve().as_uri()
    shots, attrs = [], []
    for t in (0.3, 0.9):
        page = f"{url}#t={t}&follow=wall"
        shot = tmp_path / f"shot-{t}.png"
        proc = browse(page, tmp_path, f"--screenshot={shot}")
        assert shot.is_file(), proc.stderr[-2000:]
        dom = browse(page, tmp_path, "--dump-dom").stdout
        body = re.search(r"<body([^>]*)>", dom).group(1)
        attrs.append(dict(re.findall(r'data-([a-z-]+)="([^"]*)"', body)))
        with Image.open(shot) as im:
            shots.append(np.asarray(im.convert("RGB")).astype(int))
    a0, a1 = attrs
    assert float(a0["t"]) == pytest.approx(0.3) and float(a1["t"]) == pytest.approx(0.9)
    left, top, width, height = (int(v) for v in a0["canvas"].split(","))
    assert width > 300 and height > 300
    crops = [s[top : top + height, left : left + width] for s in shots]
    for crop in crops:  # a drawn canvas: many colours (lines, antialiasing), not blank
        colours = np.unique(crop.reshape(-1, 3), axis=0)
        assert len(colours) > 100, len(colours)
        assert (crop.sum(axis=2) < 600).mean() > 0.002  # dark pixels: lines are drawn
    # the vehicle moved: the drawn CM moved and the canvas pixels changed
    moved = math.hypot(float(a1["cm-x"]) - float(a0["cm-x"]), float(a1["cm-y"]) - float(a0["cm-y"]))
    assert moved > 20, (a0, a1)
    assert np.abs(crops[0] - crops[1]).max(axis=2).astype(bool).mean() > 0.01


# ------------------------------------------------------------------ commands
def test_commands_write_their_files(run_dir: Path, tmp_path: Path) -> None:
    pytest.importorskip("imageio_ffmpeg", reason="pip install 'quadimpact[viz]'")
    d = copy_run(run_dir, tmp_path)
    proc = run_cli("view", str(d), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == str((d / "viewer.html").resolve())
    proc = run_cli("snapshots", str(d), "--times", "0,0.05,0.1", "--azimuth", "100", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (d / "snapshots.png").is_file() and (d / "snapshots.pdf").is_file()
    proc = run_cli(
        "animate",
        str(d),
        "--fps",
        "5",
        "--size",
        "160x120",
        "--gif",
        "--start",
        "0.4",
        "--end",
        "0.8",
        cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    assert (d / "animation.mp4").stat().st_size > 0 and (d / "animation.gif").is_file()


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (("view", "no-such-dir"), "result folder not found"),
        (("snapshots", "{d}", "--times", "0,abc"), "--times"),
        (("snapshots", "{d}", "--times", "5,6"), "snapshot times (5 to 6 s after"),
        (("snapshots", "{d}", "--times", "0", "--paper-figure", "7"), "not both"),
        (("animate", "{d}", "--size", "321x240"), "--size"),
        (("view", "{d}", "--elevation", "95"), "elevation"),
    ],
)
def test_command_errors_are_one_line(run_dir: Path, tmp_path: Path, args, fragment) -> None:
    proc = run_cli(*(a.format(d=run_dir) for a in args), cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("quadimpact: error: "), proc.stderr
    assert fragment in lines[0]


def test_run_viz_flag(tmp_path: Path) -> None:
    pytest.importorskip("imageio_ffmpeg", reason="pip install 'quadimpact[viz]'")
    out = tmp_path / "r"
    proc = run_cli(
        "run",
        "--final-time",
        "0.8",
        "--output-rate",
        "100",
        "--viz",
        "--out",
        str(out),
        cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    for name in ("snapshots.png", "snapshots.pdf", "animation.mp4", "viewer.html"):
        assert (out / name).is_file(), name


# ------------------------------------------------------------------ the world the run recorded
SLOPE = Plane(name="slope", point_m=(0.3, 0.0, 0.0), normal=(-1.0, 0.0, -0.5))
OVERRIDES = {
    "bumper_radius_m": 0.15,
    "bumper_tilt_deg": 4.0,
    "bumper_centres_m": [
        [0.16, 0.15, -0.03],
        [-0.15, 0.15, -0.03],
        [-0.15, -0.15, -0.03],
        [0.16, -0.15, -0.03],
    ],
}
SLOPE_TOML = """\
kind = "flight"
position_m = [0.0, 0.0, -1.0]
velocity_m_s = [1.0, 0.0, 0.0]
final_time_s = 0.9
output_rate_hz = 200

[[surfaces]]
name = "slope"
point_m = [0.3, 0.0, 0.0]
normal = [-1.0, 0.0, -0.5]

[vehicle_overrides]
bumper_radius_m = 0.15
bumper_tilt_deg = 4.0
bumper_centres_m = [[0.16, 0.15, -0.03], [-0.15, 0.15, -0.03], [-0.15, -0.15, -0.03],
                    [0.16, -0.15, -0.03]]
"""


def viewer_json(path: Path) -> dict:
    import json

    html = path.read_text(encoding="utf-8")
    return json.loads(re.search(r'type="application/json">(.*?)</script>', html, re.S).group(1))


@pytest.fixture(scope="module")
def slope_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``quadimpact run FILE --viz``: a flight onto a slope with a bumper override."""
    pytest.importorskip("imageio_ffmpeg", reason="pip install 'quadimpact[viz]'")
    base = tmp_path_factory.mktemp("slope")
    (base / "slope.toml").write_text(SLOPE_TOML, encoding="utf-8")
    out = base / "run"
    proc = run_cli("run", "slope.toml", "--viz", "--out", str(out), cwd=base)
    assert proc.returncode == 0, proc.stderr
    return out


@pytest.mark.slow
def test_run_viz_draws_the_recorded_slope_and_bumpers(slope_dir: Path) -> None:
    """The viewer of ``run FILE --viz`` draws the file's plane and bumpers, and its contact
    marks are the contact law's deepest points at the same states."""
    import pandas as pd

    for name in ("scenario.json", "snapshots.png", "animation.mp4", "viewer.html"):
        assert (slope_dir / name).is_file(), name
    data = viewer_json(slope_dir / "viewer.html")
    # the slope where the file put it (and the reference ground, not a contact surface)
    contact_surfaces = [s for s in data["surfaces"] if s["contact"]]
    assert [s["name"] for s in contact_surfaces] == ["slope"]
    np.testing.assert_allclose(contact_surfaces[0]["point"], SLOPE.point_m, atol=0)
    unit = np.array(SLOPE.normal)
    np.testing.assert_allclose(contact_surfaces[0]["normal"], unit, atol=1e-15)
    np.testing.assert_allclose(unit, np.array([-1.0, 0.0, -0.5]) / math.sqrt(1.25), atol=1e-15)
    # the bumpers of the override: its centres and radius
    veh = data["vehicle"]
    np.testing.assert_allclose(veh["centres"], OVERRIDES["bumper_centres_m"], atol=1e-6)
    rims = np.asarray(veh["circles"]) - np.asarray(veh["centres"])[:, None, :]
    np.testing.assert_allclose(np.linalg.norm(rims, axis=2), 0.15, atol=2e-5)
    # every drawn contact point is contact_record's at the sample's state, computed
    # here from the file's own numbers (not from what the run recorded)
    feat = pack_features(load_vehicle().with_overrides(**OVERRIDES), 0.0)
    surf = pack_surfaces([SLOPE])
    ts = pd.read_parquet(slope_dir / "timeseries.parquet")
    state_cols = ["x_m", "y_m", "z_m", "u_m_s", "v_m_s", "w_m_s", "q0", "q1", "q2", "q3",
                  "p_rad_s", "q_rad_s", "r_rad_s",
                  *(f"omega{j}_rad_s" for j in (1, 2, 3, 4))]  # fmt: skip
    frames = data["frames"]
    n_marks = 0
    for k, marks in enumerate(frames["contacts"]):
        if not marks:
            continue
        i = int(np.argmin(np.abs(ts["t_s"].to_numpy() - frames["t"][k])))
        x = np.ascontiguousarray(ts[state_cols].to_numpy(dtype=float)[i])
        C = np.ascontiguousarray(quat_to_matrix(x[L.X_QUAT : L.X_QUAT + 4]))
        for mark in marks:
            d, _dd, rx, ry, rz, *_ = contact_record(x, C, feat, surf, mark[0] - 1, 0)
            assert d > 0
            np.testing.assert_allclose(mark[1:4], x[0:3] + C @ np.array([rx, ry, rz]), atol=1e-5)
            assert mark[10] == pytest.approx(1e3 * d, abs=1e-3)  # deflection, mm
            n_marks += 1
    assert n_marks > 5  # the run does hit the slope


def test_scene_of_a_flight_is_its_recorded_world(slope_dir: Path) -> None:
    """Drawn rim, deepest point and deflection on the slope: the contact law's, exactly."""
    sc = Scene.from_dir(slope_dir, n_points=7200)
    assert [s.name for s in sc.surfaces] == ["slope"]
    vehicle = load_vehicle().with_overrides(**OVERRIDES)
    assert sc.drawing.vehicle == vehicle and sc.drawing.radius_m == 0.15
    np.testing.assert_array_equal(sc.surf, pack_surfaces([SLOPE]))  # as the kernel had it
    feat = pack_features(vehicle, 0.0)
    m = np.array(SLOPE.normal)
    touching = np.flatnonzero(sc.deltas.max(axis=1) > 1e-3)
    assert len(touching) > 2
    for i in touching[:: max(1, len(touching) // 4)]:
        t = float(sc.t[i])
        fr = sc.frame(t)
        x = np.ascontiguousarray(sc.state_at(t))
        C = np.ascontiguousarray(quat_to_matrix(x[L.X_QUAT : L.X_QUAT + 4]))
        assert fr.contacts
        for mark in fr.contacts:
            j = mark.bumper - 1
            d, _dd, rx, ry, rz, *_ = contact_record(x, C, feat, sc.surf, j, 0)
            p_c = x[0:3] + C @ np.array([rx, ry, rz])
            np.testing.assert_allclose(mark.point, p_c, atol=1e-12)
            assert mark.delta_m == pytest.approx(sc.deltas[i, j], rel=1e-6)
            # the deepest point of the drawn rim, by brute force over its points
            depth = -(fr.circles[j] - np.array(SLOPE.point_m)) @ m
            k = int(np.argmax(depth))
            assert depth[k] == pytest.approx(d, abs=1e-7)
            np.testing.assert_allclose(fr.circles[j][k], p_c, atol=2e-4)
            assert (mark.surface_point - np.array(SLOPE.point_m)) @ m == pytest.approx(0, abs=1e-12)


@pytest.fixture(scope="module")
def trial_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An impact trial (the Navi, recovery controller): stages 0 to 4 within 1 s.

    Stage 5 (the hover after stage 4, entered a tick later in this trial) is off, so
    that each of stages 0-4 lasts long enough to be drawn.
    """
    from quadimpact import ImpactTrial

    out = tmp_path_factory.mktemp("trial") / "run"
    # the classic law: its stages each last long enough to be drawn (the default's often
    # pass in a tick or two)
    trial = ImpactTrial(final_time_s=1.0, output_rate_hz=200, controller_params={"hover": False},
                        model="classic")  # fmt: skip
    simulate(trial).write(out)
    return out


def test_navi_is_drawn_with_its_own_bumper_centres(trial_dir: Path) -> None:
    navi = load_vehicle("navi")
    sc = Scene.from_dir(trial_dir, n_points=720)
    assert sc.drawing.vehicle == navi
    centres = np.array(navi.bumper_centres_m)
    assert np.abs(centres - navi.rotor_positions).max() > 5e-3  # apart from the hubs
    np.testing.assert_array_equal(sc.drawing.centres, centres)
    rim = sc.drawing.circles - centres[:, None, :]
    np.testing.assert_allclose(np.linalg.norm(rim, axis=2), navi.bumper_radius_m, atol=1e-12)
    assert [(s.name, s.point_m) for s in sc.surfaces] == [("wall", (0.0, 0.0, 0.0))]
    t = sc.first_contact_s + 0.005
    fr = sc.frame(t)
    x = np.ascontiguousarray(sc.state_at(t))
    C = np.ascontiguousarray(quat_to_matrix(x[L.X_QUAT : L.X_QUAT + 4]))
    for mark in fr.contacts:
        d, _dd, rx, ry, rz, *_ = contact_record(x, C, pack_features(navi, 0.0),
                                                pack_surfaces([Plane.wall(0.0)]),
                                                mark.bumper - 1, 0)  # fmt: skip
        np.testing.assert_allclose(mark.point, x[0:3] + C @ np.array([rx, ry, rz]), atol=1e-12)
    assert fr.contacts


def test_folders_without_scenario_json_are_drawn_as_before(
    run_dir: Path, slope_dir: Path, tmp_path: Path
) -> None:
    """Older folders: the wall from wall_distance_m, the bundled vehicle named in the summary."""
    from quadimpact import read_result

    d = copy_run(run_dir, tmp_path)
    (d / "scenario.json").unlink()
    result = read_result(d)
    assert result.world == {} and result.vehicle() is None
    sc = Scene.from_dir(d)
    assert [(s.name, s.point_m, s.normal) for s in sc.surfaces] == [
        ("wall", (WALL_D, 0.0, 0.0), (-1.0, 0.0, 0.0))
    ]
    assert sc.drawing.vehicle == SPIRI
    assert [c.bumper for c in sc.frame(sc.first_contact_s + 1e-3).contacts] == [4]
    result.write(d)  # written back: still no scenario.json, nothing made up
    assert not (d / "scenario.json").exists()
    # a flight folder without it: no plane to draw (its planes were only in scenario.json)
    old = tmp_path / "old-slope"
    shutil.copytree(slope_dir, old)
    (old / "scenario.json").unlink()
    sc = Scene.from_dir(old)
    assert sc.surfaces == [] and sc.drawing.vehicle == SPIRI
    with_world = Scene.from_dir(slope_dir)
    assert [s.name for s in with_world.surfaces] == ["slope"]


# ------------------------------------------------------------------ recovery stages
def test_stage_label_follows_the_recovery_run(trial_dir: Path, run_dir: Path) -> None:
    """Clock of the movie and the viewer: "stage k: name", changing at the stage entries."""
    import json

    from quadimpact.viz.animation import DEFAULT_ANIMATION_CAMERA, AnimationFigure
    from quadimpact.viz.viewer import viewer_data

    summary = json.loads((trial_dir / "summary.json").read_text())
    entries = [summary["t_detect_s"]] + [summary[f"t_stage{k}_s"] for k in (2, 3, 4)]
    assert all(a < b for a, b in zip(entries, entries[1:], strict=False))
    names = ["stage 0: before detection", "stage 1: detected", "stage 2: tilted away",
             "stage 3: level", "stage 4: recovered"]  # fmt: skip
    sc = Scene.from_dir(trial_dir)
    assert sc.has_stages
    fig = AnimationFigure(sc, DEFAULT_ANIMATION_CAMERA, 640, 360)
    probes = [entries[0] - 0.01] + [t + 0.01 for t in entries]
    for t, expected in zip(probes, names, strict=True):
        assert sc.stage_at(t) == names.index(expected)
        fig.render(t)
        lines = fig.clock.get_text().splitlines()
        assert expected in lines, (t, lines)
        assert sum(line.startswith("stage ") for line in lines) == 1
    data = viewer_data(sc)
    stage = np.array(data["frames"]["stage"])
    frame_t = np.array(data["frames"]["t"])
    assert len(stage) == len(frame_t)
    assert data["stage_labels"] == {str(k): names[k] for k in range(5)}
    # the frames' stage steps 0 -> 4 at the recorded entries (within a frame's spacing)
    changes = frame_t[1:][np.diff(stage) != 0]
    assert list(stage[np.r_[0, np.flatnonzero(np.diff(stage)) + 1]]) == [0, 1, 2, 3, 4]
    np.testing.assert_allclose(changes, entries, atol=np.median(np.diff(frame_t)) + 1e-9)
    # a run without stages (the paper's controller) shows none
    plain = Scene.from_dir(run_dir)
    assert not plain.has_stages and plain.stage_at(0.6) is None
    fig = AnimationFigure(plain, DEFAULT_ANIMATION_CAMERA, 640, 360)
    fig.render(0.6)
    assert not any(line.startswith("stage") for line in fig.clock.get_text().splitlines())
    data = viewer_data(plain)
    assert data["frames"]["stage"] is None and data["stage_labels"] is None


@pytest.mark.browser
@needs_chromium
def test_viewer_shows_the_stage_in_chromium(trial_dir: Path, run_dir: Path, tmp_path: Path) -> None:
    """The page's clock names the stage in force, and a run without stages names none."""
    import json

    from quadimpact.viz.viewer import write_viewer

    summary = json.loads((trial_dir / "summary.json").read_text())
    url = write_viewer(copy_run(trial_dir, tmp_path)).resolve().as_uri()
    probes = [(summary["t_detect_s"] - 0.01, 0, "stage 0: before detection"),
              (summary["t_stage2_s"] + 0.01, 2, "stage 2: tilted away"),
              (summary["t_stage4_s"] + 0.01, 4, "stage 4: recovered")]  # fmt: skip
    for t, stage, label in probes:
        dom = browse(f"{url}#t={t:.4f}", tmp_path, "--dump-dom").stdout
        body = dict(re.findall(r'data-([a-z-]+)="([^"]*)"', re.search(r"<body([^>]*)>", dom)[1]))
        assert body["stage"] == str(stage), (t, body)
        clock = re.search(r'<span id="clock">([^<]*)</span>', dom)[1]
        assert clock.endswith(label), clock
    plain = tmp_path / "plain"
    shutil.copytree(run_dir, plain)
    dom = browse(write_viewer(plain).resolve().as_uri() + "#t=0.6", tmp_path, "--dump-dom").stdout
    assert 'data-stage=""' in dom and "stage" not in re.search(r'id="clock">([^<]*)<', dom)[1]


# ------------------------------------------------------------------ readable defaults
@pytest.mark.parametrize(
    ("camera", "paper_figure"),
    [
        ("snapshots", 7),
        ("snapshots", 8),
        ("animation", 7),
        ("viewer", 8),
    ],
)
def test_default_views_read(run_dir: Path, camera: str, paper_figure: int) -> None:
    """At the default cameras: the wall panel beside the vehicle, cut where it was first
    touched; bumper numbers and force values inside the frame, never on each other."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from quadimpact.viz.animation import DEFAULT_ANIMATION_CAMERA
    from quadimpact.viz.snapshots import DEFAULT_SNAPSHOT_CAMERA, PAPER_FIGURE_TIMES
    from quadimpact.viz.viewer import DEFAULT_VIEWER_CAMERA

    cam = {"snapshots": DEFAULT_SNAPSHOT_CAMERA, "animation": DEFAULT_ANIMATION_CAMERA,
           "viewer": DEFAULT_VIEWER_CAMERA}[camera]  # fmt: skip
    sc = Scene.from_dir(run_dir)
    cut = sc.first_contact_points()["wall"]
    assert cut[0] == pytest.approx(WALL_D)
    fig = Figure(figsize=(4, 4))
    FigureCanvasAgg(fig)
    art = SceneArtists(fig.add_subplot(), sc, cam)
    right, _, _ = cam.basis()
    for tau in PAPER_FIGURE_TIMES[paper_figure]:
        t = sc.t_ref + tau
        art.update(t)
        target = sc.target(t, cam)
        wall = next(poly for _p, _m, (w, _n), poly, _g in art.planes if w is not None)
        xs = wall.get_xy()[:, 0]
        edge = cam.project(cut, target)[0]
        # one vertical edge of the panel is at the first contact point, the panel on the
        # side of it away from the vehicle (whose centre projects on the other side)
        assert min(abs(xs - edge)) < 1e-9
        centre = cam.project(sc.state_at(t)[0:3], target)[0]
        assert (xs.mean() - edge) * (centre - edge) < 0
        labels = np.array([lab.get_position() for lab in art.labels])
        for x, y in labels:
            assert abs(x) < art.half_w and abs(y) < art.half_h
        for txt in art.force_texts:
            if txt.get_visible() and txt.get_text():
                x, y = txt.get_position()
                assert abs(x) < art.half_w and abs(y) < art.half_h
                gaps = np.hypot(labels[:, 0] - x, labels[:, 1] - y)
                assert gaps.min() > 0.02 * 2 * art.half_h, (tau, txt.get_text())


# ------------------------------------------------- issue 20 item 19: labels and margins
def test_bumper_numbers_stay_off_every_ring() -> None:
    """The numbers of a tilted vehicle were drawn on rings (its own or another's)."""
    from quadimpact import WallApproach, simulate
    from quadimpact.viz.render import LABEL_CLEARANCE, place_labels
    from quadimpact.viz.snapshots import DEFAULT_SNAPSHOT_CAMERA

    result = simulate(WallApproach(heading_deg=45, inclination_deg=15, model="paper-replica"))
    scene = Scene.from_result(result)
    cam = DEFAULT_SNAPSHOT_CAMERA
    clearance = LABEL_CLEARANCE * cam.span_m
    t0 = scene.first_contact_s
    for dt in (0.0, 0.07, 0.1, 0.13, 0.215, 0.25):
        fr = scene.frame(t0 + dt)
        target = scene.target(t0 + dt, cam)
        rings = np.stack([cam.project(fr.circles[j], target) for j in range(4)])
        xy = place_labels(rings, cam.project(fr.label_points, target), clearance)
        for j in range(4):
            gap = np.min(np.hypot(*(rings.reshape(-1, 2) - xy[j]).T))
            assert gap >= clearance * 0.999, (dt, j, gap)
        pairs = [np.hypot(*(xy[a] - xy[b])) for a in range(4) for b in range(a + 1, 4)]
        assert min(pairs) >= clearance * 0.999


def test_the_run_figures_keep_their_axis_labels_inside() -> None:
    """fig6.png cut its "Y (m)" label (tick labels like -0.005 took the margin)."""
    from quadimpact import WallApproach, simulate
    from quadimpact.results.figures import make_fig5, make_fig6

    result = simulate(WallApproach(heading_deg=45, inclination_deg=15, model="paper-replica"))
    ts = result.timeseries
    for fig in (make_fig5(ts, "t"), make_fig6(ts, result.references, 1.5, "t")):
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        for ax in fig.axes:
            box = ax.yaxis.label.get_window_extent(renderer)
            assert box.x0 >= 0, (ax.get_ylabel(), box.x0)
