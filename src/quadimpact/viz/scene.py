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
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from pydantic import ValidationError

from quadimpact.core import layout as L
from quadimpact.errors import input_error_from_validation
from quadimpact.inputs.vehicle import Vehicle, load_vehicle
from quadimpact.inputs.world import GROUND, Box, Cylinder, Plane, obstacle_from
from quadimpact.rotations import quat_to_matrix, unwrap_deg
from quadimpact.simulation.packing import pack_features, pack_surface_records, pack_surfaces
from quadimpact.viz.camera import Camera

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

#: Where each bumper sits on the Spiri (rotor j, body FRD).
BUMPER_NAMES = {1: "starboard front", 2: "starboard rear", 3: "port rear", 4: "port front"}

#: Bumper colours, the same as the plots' ``BUMPER_COLORS`` (matplotlib tab10).
BUMPER_COLORS_HEX = {1: "#1f77b4", 2: "#ff7f0e", 3: "#2ca02c", 4: "#d62728"}
#: Colours of named features, in order (matplotlib tab10 after the bumpers').
FEATURE_COLORS_HEX = ("#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf")
#: Drawn radius of a point feature's marker circles, m.
POINT_MARK_M = 0.012


def feature_color(j: int, name: str) -> str:
    """Colour of feature ``j`` (1-based): a bumper's ``"1"``-``"4"`` colour, else the palette's."""
    if name.isdigit() and int(name) in BUMPER_COLORS_HEX:
        return BUMPER_COLORS_HEX[int(name)]
    return FEATURE_COLORS_HEX[(j - 1) % len(FEATURE_COLORS_HEX)]


#: Rotor discs are drawn with this fraction of the bumper radius (a drawing
#: choice: the parameter file has no propeller radius).
ROTOR_DISC_FRACTION = 0.8

#: Length of the force arrows, m per N (10 N is drawn 10 cm long).
FORCE_SCALE_M_PER_N = 0.01

#: Length of the drawn body axes, m.
AXIS_LENGTH_M = 0.09

#: Half size of the drawn hub square, m.
HUB_HALF_M = 0.035


def to_inertial(points_b: np.ndarray, position: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Body-frame points (..., 3) to inertial NED: ``p + C r``."""
    return np.asarray(position, dtype=float) + np.asarray(points_b, dtype=float) @ C.T


def rim_points(
    centre: np.ndarray, u: np.ndarray, n: np.ndarray, radius: float, beta: np.ndarray
) -> np.ndarray:
    """Points ``c + R (cos b u + sin b (n x u))`` of a circle (docs/MODEL.md 4), (len(beta), 3)."""
    w = np.cross(n, u)
    b = np.asarray(beta, dtype=float)[:, None]
    return centre + radius * (np.cos(b) * u + np.sin(b) * w)


@dataclass(frozen=True)
class VehicleDrawing:
    """Body-frame polylines of a vehicle, built from its parameters.

    Attributes
    ----------
    vehicle : Vehicle
        The vehicle drawn.
    centres, u, n : numpy.ndarray, shape (4, 3)
        Bumper circle centres, in-plane outward and normal unit vectors
        (:meth:`Vehicle.bumper_frames`), body FRD.
    radius_m : float
        Bumper radius Rb, m.
    circles : numpy.ndarray, shape (4, N + 1, 3)
        Closed bumper rims (last point = first), body FRD, m.
    discs : numpy.ndarray, shape (4, N + 1, 3)
        Closed rotor discs (in the body x-y plane through each hub).
    hub : numpy.ndarray, shape (5, 3)
        Closed hub square.
    arms : numpy.ndarray, shape (4, 2, 3)
        Segments from the CM to each rotor.
    axes : numpy.ndarray, shape (3, 3)
        Tips of the body x, y, z axes (rows).
    label_points : numpy.ndarray, shape (n_features, 3)
        Where the feature labels go (outside each rim, along ``u_j``).
    packed : numpy.ndarray
        The vehicle's contact features as the compiled core's ``F_*`` table.
    line_feature : numpy.ndarray, shape (n_lines,)
        The feature (0-based) each of ``circles`` draws (a sphere has three,
        a point three small ones).
    names : tuple of str
        The features' names (``"1"``-``"4"`` for the bumpers).
    colors : tuple of str
        Their colours (:func:`feature_color`).
    """

    vehicle: Vehicle
    centres: np.ndarray
    u: np.ndarray
    n: np.ndarray
    radius_m: float
    circles: np.ndarray
    discs: np.ndarray
    hub: np.ndarray
    arms: np.ndarray
    axes: np.ndarray
    label_points: np.ndarray
    packed: np.ndarray
    line_feature: np.ndarray = field(default_factory=lambda: np.arange(4))
    names: tuple[str, ...] = ("1", "2", "3", "4")
    colors: tuple[str, ...] = tuple(BUMPER_COLORS_HEX[j] for j in (1, 2, 3, 4))

    @property
    def n_features(self) -> int:
        return len(self.names)

    @classmethod
    def from_vehicle(cls, vehicle: Vehicle, n_points: int = 72) -> VehicleDrawing:
        """Build the drawing of ``vehicle`` with ``n_points`` segments per circle."""
        if vehicle.features is not None:
            return cls._from_features(vehicle, n_points)
        centres, u, n = vehicle.bumper_frames()
        rb = float(vehicle.bumper_radius_m)
        beta = np.linspace(0.0, 2.0 * math.pi, n_points + 1)
        circles = np.stack([rim_points(centres[j], u[j], n[j], rb, beta) for j in range(4)])
        e_z = np.array([0.0, 0.0, 1.0])
        e_x = np.array([1.0, 0.0, 0.0])
        discs = np.stack(
            [rim_points(centres[j], e_x, -e_z, ROTOR_DISC_FRACTION * rb, beta) for j in range(4)]
        )
        z_hub = float(np.mean(centres[:, 2]))
        h = HUB_HALF_M
        hub = np.array(
            [[h, h, z_hub], [-h, h, z_hub], [-h, -h, z_hub], [h, -h, z_hub], [h, h, z_hub]]
        )
        arms = np.stack([np.stack([np.zeros(3), centres[j]]) for j in range(4)])
        axes = AXIS_LENGTH_M * np.eye(3)
        label_points = centres + 1.3 * rb * u
        return cls(
            vehicle=vehicle,
            centres=centres,
            u=u,
            n=n,
            radius_m=rb,
            circles=circles,
            discs=discs,
            hub=hub,
            arms=arms,
            axes=axes,
            label_points=label_points,
            packed=pack_features(vehicle, 0.0),
        )

    @classmethod
    def _from_features(cls, vehicle: Vehicle, n_points: int) -> VehicleDrawing:
        """The drawing of a vehicle with its own ``[[features]]``."""
        beta = np.linspace(0.0, 2.0 * math.pi, n_points + 1)
        features = vehicle.contact_features()
        lines, owner, labels = [], [], []
        eye = np.eye(3)
        for k, f in enumerate(features):
            c = np.asarray(f.centre_m, dtype=float)
            if f.kind == "ring":
                nrm = np.asarray(f.normal, dtype=float)
                u = np.cross(nrm, eye[int(np.argmin(np.abs(nrm)))])
                u /= np.linalg.norm(u)
                lines.append(rim_points(c, u, nrm, f.radius_m, beta))
                owner.append(k)
                labels.append(c + 1.3 * f.radius_m * u)
                continue
            radius = f.radius_m if f.kind == "sphere" else POINT_MARK_M
            for axis in range(3):  # three great circles (a point: three small ones)
                lines.append(rim_points(c, eye[(axis + 1) % 3], eye[axis], radius, beta))
                owner.append(k)
            outward = c / np.linalg.norm(c) if np.linalg.norm(c) > 1e-9 else eye[0]
            labels.append(c + (radius + 0.03) * outward)
        rotors = vehicle.rotor_positions
        arm = float(np.mean(np.linalg.norm(rotors[:, :2], axis=1)))
        e_z = np.array([0.0, 0.0, 1.0])
        discs = np.stack([rim_points(rotors[j], eye[0], -e_z, 0.5 * arm, beta) for j in range(4)])
        z_hub = float(np.mean(rotors[:, 2]))
        h = HUB_HALF_M
        hub = np.array(
            [[h, h, z_hub], [-h, h, z_hub], [-h, -h, z_hub], [h, -h, z_hub], [h, h, z_hub]]
        )
        names = tuple(f.name for f in features)
        return cls(
            vehicle=vehicle,
            centres=np.array([f.centre_m for f in features], dtype=float),
            u=np.zeros((len(features), 3)),
            n=np.array([f.normal for f in features], dtype=float),
            radius_m=float(max(f.radius_m for f in features)),
            circles=np.stack(lines),
            discs=discs,
            hub=hub,
            arms=np.stack([np.stack([np.zeros(3), rotors[j]]) for j in range(4)]),
            axes=AXIS_LENGTH_M * np.eye(3),
            label_points=np.array(labels),
            packed=pack_features(vehicle, 0.0),
            line_feature=np.array(owner),
            names=names,
            colors=tuple(feature_color(k + 1, name) for k, name in enumerate(names)),
        )


def _world_part(world: Mapping[str, Any] | None, key: str) -> Any:
    return world.get(key) if isinstance(world, Mapping) else None


def scene_vehicle(summary: Mapping[str, Any], world: Mapping[str, Any] | None = None) -> Vehicle:
    """The vehicle of a run: the world record's (overrides applied), else the named bundled one.

    Raises
    ------
    InputError
        A world record whose vehicle breaks a rule, or (without a record) a
        vehicle name that is not bundled.
    """
    data = _world_part(world, "vehicle")
    if isinstance(data, Mapping):
        try:
            return Vehicle.model_validate(dict(data))
        except ValidationError as exc:
            raise input_error_from_validation(exc, "scenario.json: vehicle") from None
    return load_vehicle(summary.get("vehicle") or None)


def scene_surfaces(
    summary: Mapping[str, Any],
    episodes: pd.DataFrame | None = None,
    world: Mapping[str, Any] | None = None,
) -> list[Plane | Cylinder | Box]:
    """The contact surfaces of a run: the world record's, else from the summary and episodes.

    With a world record (``scenario.json``), exactly its ``surfaces``, in the
    kernel's order (possibly none). Without one (a folder written before that
    file existed): the wall ``X = wall_distance_m`` (normal -X) of a wall
    approach, and the ground (altitude 0, normal up) when an episode touched it.
    """
    records = _world_part(world, "surfaces")
    if isinstance(records, Sequence):
        return [_surface_of_record(r) for r in records]
    out: list[Plane] = []
    if summary.get("wall_distance_m") is not None:
        out.append(Plane.wall(summary["wall_distance_m"]))
    touched = set()
    if episodes is not None and len(episodes) and "surface" in episodes:
        touched = {str(x) for x in episodes["surface"]}
    if "ground" in touched and "ground" not in {s.name for s in out}:
        out.append(GROUND)
    return out


def _surface_of_record(r: Mapping[str, Any]) -> Plane | Cylinder | Box:
    """The shape of a ``scenario.json`` surface record (its drawing; the kernel's numbers are
    packed from the records themselves)."""
    kind = r.get("kind", "plane")
    if kind == "cylinder":
        return obstacle_from(
            {k: r[k] for k in ("name", "point_m", "axis", "radius_m", "length_m")}
            | {"kind": "cylinder"}
        )
    if kind == "box":
        # the box's axes as recorded: its drawing reads them from the packed row
        return Box(name=str(r["name"]), centre_m=r["centre_m"], half_extents_m=r["half_extents_m"])
    return Plane(
        name=str(r["name"]),
        point_m=tuple(float(c) for c in r["point_m"]),
        normal=tuple(float(c) for c in r["normal"]),
        is_ground=bool(r.get("is_ground", False)),
    )


def shape_lines(row: np.ndarray, centre: np.ndarray, extent: float = 1.5) -> list[np.ndarray]:
    """Polylines (inertial NED) drawing a packed cylinder or box (``SH_*``); a plane: none.

    A cylinder: its two end rims (an infinite one: ``extent`` m each way of
    ``centre``'s axial coordinate) and eight generators; a box: its twelve
    edges.
    """
    kind = int(row[L.SH_KIND])
    o = row[L.SH_POINT : L.SH_POINT + 3]
    if kind == L.SHAPE_CYLINDER:
        e = row[L.SH_NORMAL : L.SH_NORMAL + 3]
        r = float(row[L.SH_RADIUS])
        length = float(row[L.SH_LENGTH])
        if np.isfinite(length):
            z0, z1 = -0.5 * length, 0.5 * length
        else:
            zc = float((np.asarray(centre, dtype=float) - o) @ e)
            z0, z1 = zc - extent, zc + extent
        k = np.eye(3)[int(np.argmin(np.abs(e)))]
        u = np.cross(e, k)
        u /= np.linalg.norm(u)
        beta = np.linspace(0.0, 2.0 * math.pi, 73)
        lines = [rim_points(o + z * e, u, e, r, beta) for z in (z0, z1)]
        for b in np.linspace(0.0, 2.0 * math.pi, 8, endpoint=False):
            p = rim_points(o, u, e, r, np.array([b]))[0]
            lines.append(np.array([p + z0 * e, p + z1 * e]))
        return lines
    if kind == L.SHAPE_BOX:
        axes = row[L.SH_ROT : L.SH_ROT + 9].reshape(3, 3)
        half = row[L.SH_HALF : L.SH_HALF + 3]
        lines = []
        for i in range(3):
            j, k = (i + 1) % 3, (i + 2) % 3
            for sj in (-1.0, 1.0):
                for sk in (-1.0, 1.0):
                    base = o + sj * half[j] * axes[j] + sk * half[k] * axes[k]
                    lines.append(np.array([base - half[i] * axes[i], base + half[i] * axes[i]]))
        return lines
    return []


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
        Packed surfaces (:func:`quadimpact.simulation.packing.pack_surfaces`).

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


def plane_axes(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors spanning a plane: ``e1`` horizontal (for a non-horizontal
    plane), ``e2 = m x e1`` its steepest direction."""
    m = np.asarray(normal, dtype=float)
    m = m / np.linalg.norm(m)
    ref = np.array([0.0, 0.0, 1.0]) if abs(m[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    e1 = np.cross(m, ref)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(m, e1)


def plane_grid(
    point: np.ndarray,
    normal: np.ndarray,
    centre: np.ndarray,
    half_size: float,
    step: float = 0.1,
    range1: tuple[float, float] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """A rectangular patch of a plane around ``centre`` and grid lines fixed in space.

    Parameters
    ----------
    point, normal : array_like
        The plane (NED).
    centre : array_like
        Point whose projection onto the plane is the patch's reference.
    half_size : float
        Extent each way along ``e2`` (:func:`plane_axes`), m.
    step : float
        Grid spacing, m; the lines sit at multiples of ``step`` from ``point``.
    range1 : (float, float), optional
        Extent along ``e1`` from the reference, m; default ``(-half_size, half_size)``.
        A wall drawn with ``(-w, 0)`` or ``(0, w)`` is cut by the vertical plane
        through ``centre``, so the cut edge shows where the vehicle meets it.

    Returns
    -------
    outline : numpy.ndarray, shape (5, 3)
        Closed rectangle in the plane.
    segments : numpy.ndarray, shape (k, 2, 3)
        Grid lines inside it.
    """
    p0 = np.asarray(point, dtype=float)
    e1, e2 = plane_axes(normal)
    rel = np.asarray(centre, dtype=float) - p0
    a0, b0 = float(rel @ e1), float(rel @ e2)
    lo1, hi1 = (-half_size, half_size) if range1 is None else range1
    ranges = ((a0 + lo1, a0 + hi1), (b0 - half_size, b0 + half_size))
    (a_lo, a_hi), (b_lo, b_hi) = ranges
    corners = [(a_lo, b_lo), (a_hi, b_lo), (a_hi, b_hi), (a_lo, b_hi), (a_lo, b_lo)]
    outline = np.array([p0 + a * e1 + b * e2 for a, b in corners])
    segs = []
    for axis, other, (lo, hi), (olo, ohi) in ((e1, e2, *ranges), (e2, e1, *ranges[::-1])):
        for k in range(math.ceil(lo / step - 1e-9), math.floor(hi / step + 1e-9) + 1):
            base = p0 + k * step * axis
            segs.append([base + olo * other, base + ohi * other])
    return outline, np.array(segs, dtype=float).reshape(-1, 2, 3)


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
        records = _world_part(self.world, "surfaces")
        if surfaces is not None:
            self.surfaces = list(surfaces)
        else:
            self.surfaces = scene_surfaces(summary, episodes, self.world)
        if surfaces is None and isinstance(records, Sequence):
            self.surf = pack_surface_records(records)  # the kernel's numbers, bit for bit
        elif self.surfaces:
            self.surf = pack_surfaces(self.surfaces)
        else:
            self.surf = np.zeros((0, L.NSHAPE))
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
            n_exp = float(self.drawing.packed[j, L.F_N])
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
        from quadimpact.simulation.metrics import response_type_applies

        s = self.summary
        parts = []
        scenario = _world_part(self.world, "scenario") or {}
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
