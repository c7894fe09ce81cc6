"""The vehicle as drawn, in NumPy (no drawing here): body-frame polylines from its parameters.

:class:`VehicleDrawing` draws a vehicle's contact features exactly as the
contact law defines them (the four bumper circles of docs/MODEL.md 4, or the
features of its file: rings, spheres as three great circles, points as small
circles), its rotor discs, hub, arms and body axes, with a colour per feature;
:func:`scene_vehicle` is the vehicle a run recorded. Body FRD, m.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from pydantic import ValidationError

from quadimpact.errors import input_error_from_validation
from quadimpact.inputs.vehicle import Vehicle, load_vehicle
from quadimpact.packing.vehicle_block import pack_features
from quadimpact.viz.world_drawing import rim_points, world_part

__all__ = [
    "AXIS_LENGTH_M",
    "BUMPER_COLORS_HEX",
    "BUMPER_NAMES",
    "FEATURE_COLORS_HEX",
    "HUB_HALF_M",
    "POINT_MARK_M",
    "ROTOR_DISC_FRACTION",
    "VehicleDrawing",
    "feature_color",
    "scene_vehicle",
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
#: Length of the drawn body axes, m.
AXIS_LENGTH_M = 0.09

#: Half size of the drawn hub square, m.
HUB_HALF_M = 0.035


def to_inertial(points_b: np.ndarray, position: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Body-frame points (..., 3) to inertial NED: ``p + C r``."""
    return np.asarray(position, dtype=float) + np.asarray(points_b, dtype=float) @ C.T


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
        n = len(rotors)  # every rotor of the vehicle (4 to 8)
        disc = 0.5 * arm if n == 4 else arm * math.sin(math.pi / n)  # n > 4: discs do not overlap
        discs = np.stack([rim_points(rotors[j], eye[0], -e_z, disc, beta) for j in range(n)])
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
            arms=np.stack([np.stack([np.zeros(3), rotors[j]]) for j in range(n)]),
            axes=AXIS_LENGTH_M * np.eye(3),
            label_points=np.array(labels),
            packed=pack_features(vehicle, 0.0),
            line_feature=np.array(owner),
            names=names,
            colors=tuple(feature_color(k + 1, name) for k, name in enumerate(names)),
        )


def scene_vehicle(summary: Mapping[str, Any], world: Mapping[str, Any] | None = None) -> Vehicle:
    """The vehicle of a run: the world record's (overrides applied), else the named bundled one.

    Raises
    ------
    InputError
        A world record whose vehicle breaks a rule, or (without a record) a
        vehicle name that is not bundled.
    """
    data = world_part(world, "vehicle")
    if isinstance(data, Mapping):
        try:
            return Vehicle.model_validate(dict(data))
        except ValidationError as exc:
            raise input_error_from_validation(exc, "scenario.json: vehicle") from None
    return load_vehicle(summary.get("vehicle") or None)
