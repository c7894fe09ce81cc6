"""The interactive viewer: one self-contained HTML file per run.

``write_viewer(DIR)`` writes ``DIR/viewer.html``: the page template shipped
with the package (``viewer_template.html``: vanilla JavaScript drawing on
``<canvas>`` with its own orthographic projection, the same as
:class:`~quadimpact.viz.camera.Camera`) with the run's data embedded as JSON.
It opens offline from the file system: no server, no external script, style
sheet or font, nothing fetched.

The page has the 3D scene (drag to turn, wheel to zoom), a time slider,
play/pause at a chosen slow-down, and the bumper deflection and attitude
plots with a cursor linked to the slider (click a plot to jump there). For a
run whose controller has stages (the ``recovery`` controller), the clock
shows the stage in force ("stage 2: tilted away"). URL
parameters set the initial state: ``viewer.html#t=0.6&az=110&el=20&span=0.9&follow=wall``
(``ti=`` is the time after impact, ``play=1`` starts playing).

The vehicle's polylines are sent in the body frame and moved by each frame's
quaternion in the page; contact points, deflections and force arrows are
computed here with the compiled contact function (one source of geometry).
"""

from __future__ import annotations

import json
import os
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from quadimpact.inputs.world import Plane
from quadimpact.results.figures import stage_label
from quadimpact.results.files import atomic_write
from quadimpact.viz.camera import DEFAULT_VIEWER_CAMERA, Camera
from quadimpact.viz.render import WALL_WIDTH_M
from quadimpact.viz.scene import Scene
from quadimpact.viz.vehicle_drawing import BUMPER_NAMES
from quadimpact.viz.world_drawing import shape_lines

__all__ = ["DEFAULT_VIEWER_CAMERA", "VIEWER_HTML", "viewer_data", "viewer_html", "write_viewer"]

VIEWER_HTML = "viewer.html"
DEFAULT_RATE_HZ = 250.0
_TEMPLATE = "viewer_template.html"
_DATA_MARK = "__QUADIMPACT_DATA__"
_TITLE_MARK = "__QUADIMPACT_TITLE__"


def _r(a: Any, digits: int) -> Any:
    """Rounded nested lists (JSON-friendly; NaN -> None)."""
    arr = np.round(np.asarray(a, dtype=float), digits)
    out = arr.tolist()
    if np.isnan(arr).any():
        return _nan_to_none(out)
    return out


def _nan_to_none(x: Any) -> Any:
    if isinstance(x, list):
        return [_nan_to_none(v) for v in x]
    return None if isinstance(x, float) and x != x else x


def viewer_data(
    scene: Scene, rate_hz: float = DEFAULT_RATE_HZ, camera: Camera | None = None
) -> dict[str, Any]:
    """Everything the page needs, as plain JSON-able data.

    Frames are taken every ``1 / rate_hz`` s (at most the run's own samples)
    from the start to the end of the run.
    """
    cam = camera or DEFAULT_VIEWER_CAMERA
    idx = _frame_indices(scene.t, rate_hz)
    stages = None if scene.stages is None else scene.stages[idx]
    s = scene.summary
    origin = "first contact" if scene.first_contact_s is not None else "start"
    subtitle = (
        f"vehicle {scene.drawing.vehicle.name}; status {s.get('status', 'n/a')}; "
        f"{s.get('outcome', '')}; time after {origin} at t = {scene.t_ref:.3f} s"
    )
    surfaces, solids = _world(scene)
    return {
        "title": f"quadimpact: {scene.describe()}",
        "subtitle": subtitle,
        "t_ref": scene.t_ref,
        "first_contact": scene.first_contact_s,
        "crash": scene.crash_time_s,
        "wall_x": scene.wall_x_m,
        "wall_width": WALL_WIDTH_M,
        "anchor": _r(scene.anchor, 5),
        "camera": {
            "az": cam.azimuth_deg,
            "el": cam.elevation_deg,
            "follow": cam.follow,
            "span": cam.span_m,
        },
        "surfaces": surfaces,
        "solids": solids,
        # the stage of each frame and the names of the stages met (null: no stages)
        "stage_labels": None
        if stages is None
        else {str(k): stage_label(k) for k in sorted(set(stages.tolist()))},
        "vehicle": _vehicle(scene),
        "frames": _frames(scene, idx, stages),
        "estimator": s.get("estimator"),
    }


def _frame_indices(t_all: np.ndarray, rate_hz: float) -> np.ndarray:
    """The samples shown: every ``1 / rate_hz`` s, and the last one (the crash)."""
    if len(t_all) > 1:
        dt_out = float(np.median(np.diff(t_all)))
        stride = max(1, int(round(1.0 / (rate_hz * dt_out)))) if rate_hz > 0 else 1
    else:
        stride = 1
    idx = np.arange(0, len(t_all), stride)
    if idx[-1] != len(t_all) - 1:
        idx = np.append(idx, len(t_all) - 1)  # keep the last sample (the crash)
    return idx


def _world(scene: Scene) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """The planes (with the ground, drawn for reference) and the solids as fixed polylines."""
    cuts = scene.first_contact_points()  # a wall panel's edge: where it was first touched
    surfaces = [
        {
            "name": s.name,
            "point": list(map(float, s.point_m)),
            "normal": list(map(float, np.asarray(s.normal) / np.linalg.norm(s.normal))),
            "ground": bool(s.is_ground),
            "contact": True,
            "cut": _r(cuts[s.name], 5) if s.name in cuts else None,
        }
        for s in scene.surfaces
        if isinstance(s, Plane)
    ]
    # cylinders and boxes as polylines fixed in space (an infinite cylinder: over the
    # flight's extent along its axis)
    centre = 0.5 * (scene.states[:, 0:3].min(axis=0) + scene.states[:, 0:3].max(axis=0))
    extent = 1.0 + float(np.ptp(scene.states[:, 0:3], axis=0).max())
    solids = [
        {"name": s.name, "lines": [_r(x, 5) for x in shape_lines(scene.surf[k], centre, extent)]}
        for k, s in enumerate(scene.surfaces)
        if not isinstance(s, Plane)
    ]
    if not any(s["ground"] for s in surfaces):
        surfaces.append(
            {
                "name": "ground",
                "point": [0.0, 0.0, 0.0],
                "normal": [0.0, 0.0, -1.0],
                "ground": True,
                "contact": False,
            }
        )
    return surfaces, solids


def _vehicle(scene: Scene) -> dict[str, Any]:
    """The vehicle's drawing in body axes (a coarser circle is plenty on screen)."""
    d = scene.drawing
    step = max(1, (d.circles.shape[1] - 1) // 48)
    return {
        "name": d.vehicle.name,
        "colors": list(d.colors),
        "names": [BUMPER_NAMES[j] for j in (1, 2, 3, 4)]
        if d.vehicle.features is None
        else list(d.names),
        "label_text": list(d.names),
        "kind_name": "bumper" if d.vehicle.features is None else "feature",
        "centres": _r(d.centres, 6),
        "line_centres": _r(d.circles.mean(axis=1), 6),
        "line_feature": [int(f) for f in d.line_feature],
        "circles": _r(d.circles[:, ::step], 5),
        "discs": _r(d.discs[:, ::step], 5),
        "hub": _r(d.hub, 5),
        "arms": _r(d.arms, 5),
        "axes": _r(d.axes, 5),
        "labels": _r(d.label_points, 5),
    }


def _frames(scene: Scene, idx: np.ndarray, stages: np.ndarray | None) -> dict[str, Any]:
    """The shown samples: time, pose, deflections, forces, contacts, stage, the estimate."""
    contacts = []
    for i in idx:
        fr = scene.frame(float(scene.t[i]))
        contacts.append(
            [
                [
                    c.bumper,
                    *_r(c.point, 5),
                    *_r(c.surface_point, 5),
                    *_r(c.arrow_tip, 5),
                    round(1e3 * c.delta_m, 3),
                    round(c.force_n, 3),
                ]
                for c in fr.contacts
            ]
        )
    return {
        "t": _r(scene.t[idx], 5),
        "pos": _r(scene.states[idx, 0:3], 5),
        "quat": _r(scene.states[idx, 6:10], 6),
        "delta": _r(1e3 * scene.deltas[idx], 3),
        "force": _r(scene.forces[idx], 3),
        "euler": _r(scene.euler_deg[idx], 2),
        "alt": _r(scene.altitude[idx], 4),
        "contacts": contacts,
        "stage": None if stages is None else stages.tolist(),
        # the estimator's attitude (null with the ideal estimator) and its error, deg
        "quat_hat": None if scene.q_hat is None else _r(scene.q_hat[idx], 6),
        "att_err": None
        if scene.attitude_error_deg is None
        else _r(scene.attitude_error_deg[idx], 3),
    }


def viewer_html(data: dict[str, Any]) -> str:
    """The page with ``data`` embedded."""
    template = resources.files("quadimpact.viz").joinpath(_TEMPLATE).read_text(encoding="utf-8")
    payload = json.dumps(data, separators=(",", ":"), allow_nan=False)
    # keep the JSON inert inside <script>: no "</" can close the element
    payload = payload.replace("</", "<\\/").replace("<!--", "<\\!--")
    title = (
        str(data.get("title", "quadimpact viewer"))
        .replace("&", "&amp;")
        .replace("<", "&lt;")
        .replace(">", "&gt;")
    )
    return template.replace(_TITLE_MARK, title).replace(_DATA_MARK, payload)


def write_viewer(
    result_dir: str | os.PathLike[str],
    rate_hz: float = DEFAULT_RATE_HZ,
    camera: Camera | None = None,
    out_dir: str | os.PathLike[str] | None = None,
    scene: Scene | None = None,
) -> Path:
    """Write ``viewer.html`` of a result folder and return its path.

    Parameters
    ----------
    result_dir : path
        Folder written by ``quadimpact run``.
    rate_hz : float
        Frames per simulated second in the page (default 250).
    camera : Camera, optional
        Initial view (default: following the vehicle, from starboard).
    out_dir : path, optional
        Where to write (default ``result_dir``).
    scene : Scene, optional
        An already built scene of the run.
    """
    scene = scene or Scene.from_dir(result_dir)
    html = viewer_html(viewer_data(scene, rate_hz, camera))
    out = Path(out_dir if out_dir is not None else result_dir)
    out.mkdir(parents=True, exist_ok=True)
    return atomic_write(out / VIEWER_HTML, lambda tmp: tmp.write_text(html, encoding="utf-8"))
