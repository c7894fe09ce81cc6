"""Geometry of the 3D scene of an impact, in NumPy (no drawing here).

Everything is computed in the inertial NED frame (X toward the wall, Y right,
Z down) from the world the run recorded (``scenario.json``: the vehicle with
its overrides applied and the contact surfaces as the kernel received them)
and the sampled states of a run:

* the vehicle (:class:`VehicleDrawing`): its contact features exactly as the
  contact law defines them (the four bumper circles of docs/MODEL.md 4:
  circle ``j`` of radius ``Rb`` centred on ``c_j``, the rotor hub or the
  vehicle's ``bumper_centres_m``, in-plane outward ``u_j``, normal ``n_j``; or
  the features of its file: rings, spheres as three great circles, points as
  small circles), the rotor discs, the hub, the arms and the body axes, as
  body-frame polylines;
* the contact surfaces (every shape of the run: walls, slopes, the ground when
  it was a contact surface, cylinders as their rims and generators, boxes as
  their twelve edges; :func:`shape_lines`) and the ground plane
  ``altitude = 0`` for reference. A folder written before ``scenario.json`` existed is drawn as
  before: the wall ``X = wall_distance_m`` of the summary, the ground if an
  episode touched it, and the bundled vehicle named in the summary;
* during contact, per feature and surface, the deepest point given by the
  compiled contact function :func:`quadimpact.core.geometry.contact_record`
  (so the drawing shows the point the simulation pushed on), the deflection
  (the segment from that point along the contact normal, of length delta) and
  the normal force as an arrow along the contact normal;
* the camera is :class:`quadimpact.viz.camera.Camera` (re-exported here).

A :class:`Scene` holds one run; :meth:`Scene.frame` gives every polyline and
contact of one instant, and :meth:`Camera.project` puts points on the screen.
The vehicle's drawing is :mod:`quadimpact.viz.vehicle_drawing`, the surfaces'
:mod:`quadimpact.viz.world_drawing` (their names are importable from here too).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from quadimpact.core import feature_slots as FS
from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP
from quadimpact.inputs.vehicle import Vehicle
from quadimpact.inputs.world import Plane
from quadimpact.packing.world_block import pack_surface_records, pack_surfaces
from quadimpact.rotations import quat_to_matrix, unwrap_deg
from quadimpact.viz.camera import Camera

# the vehicle and the world as drawn, each in its module; here too, with the scene
from quadimpact.viz.vehicle_drawing import (
    AXIS_LENGTH_M,
    BUMPER_COLORS_HEX,
    BUMPER_NAMES,
    ROTOR_DISC_FRACTION,
    VehicleDrawing,
    scene_vehicle,
    to_inertial,
)
from quadimpact.viz.world_drawing import (
    plane_axes,
    plane_grid,
    rim_points,
    scene_surfaces,
    shape_lines,
    world_part,
)

__all__ = [
    "AXIS_LENGTH_M",
    "BUMPER_COLORS_HEX",
    "BUMPER_NAMES",
    "FORCE_SCALE_M_PER_N",
    "ROTOR_DISC_FRACTION",
    "Camera",
    "ContactMark",
    "Scene",
    "SceneFrame",
    "VehicleDrawing",
    "contact_points",
    "plane_axes",
    "plane_grid",
    "rim_points",
    "scene_surfaces",
    "scene_vehicle",
    "shape_lines",
    "to_inertial",
]

#: Length of the force arrows, m per N (10 N is drawn 10 cm long).
FORCE_SCALE_M_PER_N = 0.01


def contact_points(
    x: np.ndarray, drawing: VehicleDrawing, surf: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Deepest point of every feature against every surface, by the compiled contact law.

    Parameters
    ----------
    x : numpy.ndarray, shape (NX,)
        State (layout ``X_*``).
    drawing : VehicleDrawing
        The vehicle.
    surf : numpy.ndarray
        Packed surfaces (:func:`quadimpact.packing.world_block.pack_surfaces`).

    Returns
    -------
    points : numpy.ndarray, shape (n_features, n_surfaces, 3)
        Deepest points, inertial NED, m.
    depths : numpy.ndarray, shape (n_features, n_surfaces)
        Penetrations delta, m (positive in contact).
    normals : numpy.ndarray, shape (n_features, n_surfaces, 3)
        Contact normals (unit, out of the shape), inertial NED.
    """
    from quadimpact.core.geometry import contact_record

    xq = np.ascontiguousarray(x, dtype=float)
    C = np.ascontiguousarray(quat_to_matrix(xq[L.X_QUAT : L.X_QUAT + 4]))
    ns = surf.shape[0]
    nf = drawing.packed.shape[0]
    points = np.zeros((nf, ns, 3))
    depths = np.zeros((nf, ns))
    normals = np.zeros((nf, ns, 3))
    for j in range(nf):
        for s in range(ns):
            rec = contact_record(xq, C, drawing.packed, surf, j, s)
            points[j, s] = xq[L.X_POS : L.X_POS + 3] + C @ np.array(rec[2:5])
            depths[j, s] = rec[0]
            m = np.array(rec[8:11])
            normals[j, s] = m / np.linalg.norm(m)
    return points, depths, normals


@dataclass
class ContactMark:
    """One bumper touching one surface at one instant (inertial NED, SI)."""

    bumper: int  # the feature, 1-based (bumpers 1-4)
    surface: str
    delta_m: float
    point: np.ndarray  # deepest rim point (inside the surface)
    surface_point: np.ndarray  # its projection on the surface: point + delta m
    normal: np.ndarray  # surface unit normal (out of the obstacle)
    force_n: float
    arrow_tip: np.ndarray  # surface_point + FORCE_SCALE_M_PER_N * force * normal


@dataclass
class SceneFrame:
    """Everything drawn at one instant: inertial NED polylines and contacts."""

    t: float
    position: np.ndarray
    C: np.ndarray
    circles: np.ndarray  # (n_lines, N+1, 3): the features' rims
    discs: np.ndarray  # (4, N+1, 3)
    hub: np.ndarray  # (5, 3)
    arms: np.ndarray  # (4, 2, 3)
    axes: np.ndarray  # (3, 2, 3): CM -> tip of body x, y, z
    label_points: np.ndarray  # (n_features, 3)
    contacts: list[ContactMark] = field(default_factory=list)
    deltas: np.ndarray = field(default_factory=lambda: np.zeros(4))
    forces: np.ndarray = field(default_factory=lambda: np.zeros(4))


def _drawable_rows(ts: pd.DataFrame) -> pd.DataFrame:
    """The samples that can be drawn: time, pose, deflections, forces and attitude finite.

    Raises
    ------
    ValueError
        When no sample can be drawn (a run whose state is NaN throughout).
    """
    from quadimpact.results.schema import feature_columns

    per_feature = [c for _, d, f in feature_columns(ts.columns) for c in (d, f)]
    columns = ["t_s", "x_m", "y_m", "z_m", "q0", "q1", "q2", "q3", "roll_deg", "pitch_deg",
               "yaw_deg", *per_feature]  # fmt: skip
    present = [c for c in columns if c in ts]
    ok = np.all(np.isfinite(ts[present].to_numpy(dtype=float)), axis=1)
    if not ok.any():
        raise ValueError(
            "nothing to draw: every sample of the run is NaN or infinite "
            "(its summary.json says why: status and reason)"
        )
    return ts if ok.all() else ts[ok]


_STATE_COLUMNS = (
    ["x_m", "y_m", "z_m", "u_m_s", "v_m_s", "w_m_s", "q0", "q1", "q2", "q3"]
    + ["p_rad_s", "q_rad_s", "r_rad_s"]
    + [f"omega{j}_rad_s" for j in (1, 2, 3, 4)]
)


class Scene:
    """One run, ready to be drawn at any instant.

    Parameters
    ----------
    timeseries : pandas.DataFrame
        The run's samples (``timeseries.parquet``).
    summary : mapping
        The run's summary (``summary.json``).
    episodes : pandas.DataFrame, optional
        The run's episodes (without a world record: to know whether the
        ground was a contact surface).
    vehicle : Vehicle, optional
        Default: :func:`scene_vehicle` (the world record's).
    surfaces : list of Plane, optional
        Default: :func:`scene_surfaces` (the world record's, packed exactly as
        recorded).
    n_points : int
        Segments per drawn circle.
    world : mapping, optional
        The run's world record (``scenario.json``,
        ``SimulationResult.world``); without it, the fallback of older folders.
    """

    def __init__(
        self,
        timeseries: pd.DataFrame,
        summary: Mapping[str, Any],
        episodes: pd.DataFrame | None = None,
        vehicle: Vehicle | None = None,
        surfaces: list[Plane] | None = None,
        n_points: int = 72,
        world: Mapping[str, Any] | None = None,
        imu: pd.DataFrame | None = None,
    ) -> None:
        if len(timeseries) == 0:
            raise ValueError("the run has no samples to draw")
        self.summary = dict(summary)
        self.world = dict(world or {})
        if vehicle is None:
            vehicle = scene_vehicle(summary, self.world)
        self.drawing = VehicleDrawing.from_vehicle(vehicle, n_points)
        records = world_part(self.world, "surfaces")
        if surfaces is not None:
            self.surfaces = list(surfaces)
        else:
            self.surfaces = scene_surfaces(summary, episodes, self.world)
        if surfaces is None and isinstance(records, Sequence):
            self.surf = pack_surface_records(records)  # the kernel's numbers, bit for bit
        elif self.surfaces:
            self.surf = pack_surfaces(self.surfaces)
        else:
            self.surf = np.zeros((0, SHP.NSHAPE))
        ts = _drawable_rows(timeseries)
        self.t = ts["t_s"].to_numpy(dtype=float)
        self.states = np.zeros((len(ts), L.NX))
        for k, col in enumerate(_STATE_COLUMNS):
            if col in ts:
                self.states[:, k] = ts[col].to_numpy(dtype=float)
        from quadimpact.results.schema import feature_columns

        cols = feature_columns(ts.columns)
        self.deltas = np.stack([ts[d].to_numpy(dtype=float) for _, d, _ in cols], 1)
        self.forces = np.stack([ts[f].to_numpy(dtype=float) for _, _, f in cols], 1)
        # roll and yaw continuous through +-180 deg (drawn and interpolated so)
        self.euler_deg = np.stack(
            [unwrap_deg(ts["roll_deg"]), ts["pitch_deg"].to_numpy(dtype=float),
             unwrap_deg(ts["yaw_deg"])], 1
        )  # fmt: skip
        self.altitude = -self.states[:, 2]
        fc = summary.get("first_contact_s")
        self.first_contact_s: float | None = None if fc is None else float(fc)
        crash = summary.get("crash_time_s")
        self.crash_time_s: float | None = None if crash is None else float(crash)
        wall = summary.get("wall_distance_m")
        self.wall_x_m: float | None = None if wall is None else float(wall)
        stage = ts["stage"].to_numpy(dtype=float) if "stage" in ts else None
        self.stages: np.ndarray | None = None
        if stage is not None and (summary.get("controller") == "recovery" or np.any(stage != 0)):
            self.stages = np.rint(np.nan_to_num(stage)).astype(int)
        self.anchor = self.state_at(
            self.t[0] if self.first_contact_s is None else self.first_contact_s
        )[0:3].copy()
        self.q_hat = self.attitude_error_deg = None
        if imu is not None and "q0_hat" in imu and summary.get("estimator") not in (None, "ideal"):
            self._estimate(imu)

    def _estimate(self, imu: pd.DataFrame) -> None:
        """The estimator's attitude at each sample of the run (the last IMU sample's, held)."""
        t_imu = imu["t_s"].to_numpy(dtype=float)
        if len(t_imu) == 0:
            return
        k = np.clip(np.searchsorted(t_imu, self.t + 1e-12, side="right") - 1, 0, len(t_imu) - 1)
        q = np.stack([imu[f"q{j}_hat"].to_numpy(dtype=float) for j in range(4)], 1)
        self.q_hat = q[k]
        self.attitude_error_deg = imu["attitude_error_deg"].to_numpy(dtype=float)[k]

    @classmethod
    def from_result(cls, result: Any, vehicle: Vehicle | None = None, **kw: Any) -> Scene:
        """Scene of a :class:`~quadimpact.results.result.SimulationResult` (its world record)."""
        kw.setdefault("world", getattr(result, "world", None))
        if result.summary.get("estimator") not in (None, "ideal"):
            kw.setdefault("imu", result.imu)
        return cls(result.timeseries, result.summary, result.episodes, vehicle=vehicle, **kw)

    @classmethod
    def from_dir(cls, directory: Any, vehicle: Vehicle | None = None, **kw: Any) -> Scene:
        """Scene of a result folder (``quadimpact.results.result.read_result``)."""
        from quadimpact.results.result import read_result

        return cls.from_result(read_result(directory), vehicle=vehicle, **kw)

    # ------------------------------------------------------------ time
    @property
    def t_start(self) -> float:
        return float(self.t[0])

    @property
    def t_end(self) -> float:
        return float(self.t[-1])

    @property
    def t_ref(self) -> float:
        """Origin of "time after impact": the first contact, else the first sample."""
        return self.t_start if self.first_contact_s is None else self.first_contact_s

    def _interp(self, table: np.ndarray, t: float) -> np.ndarray:
        tt = self.t
        if t <= tt[0]:
            return table[0].copy()
        if t >= tt[-1]:
            return table[-1].copy()
        k = int(np.searchsorted(tt, t, side="right")) - 1
        w = (t - tt[k]) / (tt[k + 1] - tt[k])
        return (1.0 - w) * table[k] + w * table[k + 1]

    def state_at(self, t: float) -> np.ndarray:
        """State (layout ``X_*``) at time ``t``: linear between samples, quaternion normalised."""
        x = self._interp(self.states, float(t))
        q = x[L.X_QUAT : L.X_QUAT + 4]
        x[L.X_QUAT : L.X_QUAT + 4] = q / np.linalg.norm(q)
        return x

    @property
    def has_stages(self) -> bool:
        """Whether the run's controller reports stages (the ``recovery`` controller's 0-4)."""
        return self.stages is not None

    def stage_at(self, t: float) -> int | None:
        """The controller's stage in force at time ``t`` (that of the last sample at or
        before ``t``); ``None`` when the run has no stages."""
        if self.stages is None:
            return None
        k = int(np.searchsorted(self.t, float(t) + 1e-12, side="right")) - 1
        return int(self.stages[max(k, 0)])

    def values_at(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Deflections (m), forces (N) and Euler angles (deg) at time ``t`` (linear)."""
        return (
            self._interp(self.deltas, t),
            self._interp(self.forces, t),
            self._interp(self.euler_deg, t),
        )

    # ------------------------------------------------------------ geometry
    def frame(self, t: float) -> SceneFrame:
        """Every polyline and contact of the scene at time ``t`` (inertial NED)."""
        x = self.state_at(t)
        pos = x[0:3]
        C = quat_to_matrix(x[L.X_QUAT : L.X_QUAT + 4])
        d = self.drawing
        deltas, forces, _ = self.values_at(t)
        tips = to_inertial(d.axes, pos, C)
        frame = SceneFrame(
            t=float(t),
            position=pos,
            C=C,
            circles=to_inertial(d.circles, pos, C),
            discs=to_inertial(d.discs, pos, C),
            hub=to_inertial(d.hub, pos, C),
            arms=to_inertial(d.arms, pos, C),
            axes=np.stack([np.stack([pos, tips[k]]) for k in range(3)]),
            label_points=to_inertial(d.label_points, pos, C),
            deltas=deltas,
            forces=forces,
        )
        if self.surf.shape[0]:
            frame.contacts = self._contacts(x, deltas, forces)
        return frame

    def _contacts(self, x: np.ndarray, deltas: np.ndarray, forces: np.ndarray) -> list[ContactMark]:
        points, depths, normals = contact_points(x, self.drawing, self.surf)
        marks: list[ContactMark] = []
        for j in range(self.drawing.packed.shape[0]):
            n_exp = float(self.drawing.packed[j, FS.F_N])
            if not (deltas[j] > 0.0 or forces[j] > 0.0):
                continue  # the simulation had no active contact on this bumper
            touching = [s for s in range(self.surf.shape[0]) if depths[j, s] > 0.0]
            if not touching:
                continue
            weights = np.array([depths[j, s] ** n_exp for s in touching])
            weights = weights / weights.sum()
            for w, s in zip(weights, touching, strict=True):
                m = normals[j, s]
                delta = float(depths[j, s])
                f = float(forces[j] * w)
                on_surface = points[j, s] + delta * m
                marks.append(
                    ContactMark(
                        bumper=j + 1,
                        surface=self.surfaces[s].name,
                        delta_m=delta,
                        point=points[j, s].copy(),
                        surface_point=on_surface,
                        normal=m.copy(),
                        force_n=f,
                        arrow_tip=on_surface + FORCE_SCALE_M_PER_N * f * m,
                    )
                )
        return marks

    def first_contact_points(self) -> dict[str, np.ndarray]:
        """Where each surface was touched at the run's first contact (NED), by surface name.

        A wall panel is drawn cut there (``render.wall_range``, the viewer), so
        that its edge is where the vehicle met it, whatever the camera follows.
        """
        if self.first_contact_s is None:
            return {}
        points: dict[str, np.ndarray] = {}
        for dt in (0.0, 1e-3, 5e-3):  # at the onset the deflection may still be zero
            for c in self.frame(min(self.first_contact_s + dt, self.t_end)).contacts:
                points.setdefault(c.surface, np.asarray(c.surface_point, dtype=float))
            if points:
                break
        return points

    def target(self, t: float, camera: Camera) -> np.ndarray:
        """Point at the picture centre at time ``t`` for ``camera``."""
        if camera.follow == "vehicle":
            return self.state_at(t)[0:3]
        return self.anchor

    def describe(self) -> str:
        """One line naming the run (kind, heading, inclination, speed, model, outcome type)."""
        from quadimpact.simulation.response_types import response_type_applies

        s = self.summary
        parts = []
        scenario = world_part(self.world, "scenario") or {}
        kind = scenario.get("kind")
        if kind in ("flight", "impact-trial"):
            parts.append(str(kind).replace("-", " "))
        if s.get("heading_deg") is not None:
            parts.append(f"heading {s['heading_deg']:g}°")
        if s.get("inclination_deg") is not None:
            parts.append(f"inclination {s['inclination_deg']:g}°")
        if kind == "impact-trial" and scenario.get("speed_m_s") is not None:
            parts.append(f"initial speed {float(scenario['speed_m_s']):.2f} m/s")
        if s.get("impact_speed_m_s") is not None:
            parts.append(f"impact speed {s['impact_speed_m_s']:.2f} m/s")
        if s.get("model"):
            parts.append(str(s["model"]))
        if s.get("response_type") and response_type_applies(kind, scenario.get("ground")):
            parts.append(f"type {s['response_type']}")
        return ", ".join(parts) or "quadimpact run"
