"""The camera of the 3D pictures, and each command's default view (NumPy only).

:class:`Camera` is an orthographic view from a given azimuth and elevation,
altitude always up on screen and one metre the same length in every
direction (equal scaling), following the vehicle or fixed at the impact point
on the wall. This module imports neither Matplotlib nor the simulator, so
that the commands check their camera options before loading the drawing
code.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

__all__ = [
    "DEFAULT_ANIMATION_CAMERA",
    "DEFAULT_SNAPSHOT_CAMERA",
    "DEFAULT_VIEWER_CAMERA",
    "Camera",
]


@dataclass(frozen=True)
class Camera:
    """An orthographic camera: altitude up on screen, equal scaling.

    Attributes
    ----------
    azimuth_deg : float
        Direction from the target to the camera seen from above, deg from +X
        (toward the wall) toward +Y (right); 90 looks from the starboard side
        (the wall on the right of the picture), 180 from behind.
    elevation_deg : float
        Height of the camera above the horizontal through the target, deg in
        [-89, 89]; positive looks down on the vehicle.
    follow : {"vehicle", "wall"}
        ``"vehicle"``: centred on the CM at every instant; ``"wall"``: fixed,
        centred on the CM at the first contact (the impact point on the wall).
    span_m : float
        Height of the picture, m (the width follows from the aspect ratio).
    """

    azimuth_deg: float = 120.0
    elevation_deg: float = 20.0
    follow: Literal["vehicle", "wall"] = "vehicle"
    span_m: float = 0.9

    def __post_init__(self) -> None:
        if self.follow not in ("vehicle", "wall"):
            raise ValueError(f"follow must be 'vehicle' or 'wall' (got {self.follow!r})")
        if not -89.0 <= self.elevation_deg <= 89.0:
            raise ValueError("elevation_deg must lie in [-89, 89]")
        if not self.span_m > 0:
            raise ValueError("span_m must be > 0")

    def basis(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Screen right, screen up and viewing direction (into the screen), NED unit vectors.

        Computed once per azimuth and elevation (read-only arrays: a movie
        projects with them many times a frame).
        """
        return _basis(float(self.azimuth_deg), float(self.elevation_deg))

    def project(self, points: np.ndarray, target: np.ndarray) -> np.ndarray:
        """Screen coordinates (m, right and up from the picture centre) of NED points (..., 3)."""
        right, up, _ = self.basis()
        rel = np.asarray(points, dtype=float) - np.asarray(target, dtype=float)
        return np.stack([rel @ right, rel @ up], axis=-1)

    def depth(self, points: np.ndarray, target: np.ndarray) -> np.ndarray:
        """Distance along the viewing direction (larger = farther from the camera), m."""
        _, _, forward = self.basis()
        return (np.asarray(points, dtype=float) - np.asarray(target, dtype=float)) @ forward


@functools.lru_cache(maxsize=64)
def _basis(azimuth_deg: float, elevation_deg: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    az = math.radians(azimuth_deg)
    el = math.radians(elevation_deg)
    to_camera = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), -math.sin(el)])
    forward = -to_camera
    world_up = np.array([0.0, 0.0, -1.0])  # NED: up is -Z
    right = np.cross(forward, world_up)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    for v in (right, up, forward):
        v.flags.writeable = False
    return right, up, forward


#: Movies follow the vehicle by default (a crash falls out of any fixed view).
DEFAULT_ANIMATION_CAMERA = Camera(
    azimuth_deg=110.0, elevation_deg=20.0, follow="vehicle", span_m=0.9
)
#: Snapshots default to a camera fixed at the impact point, from the starboard
#: side and slightly behind, looking a little down.
DEFAULT_SNAPSHOT_CAMERA = Camera(azimuth_deg=120.0, elevation_deg=20.0, follow="wall", span_m=1.0)
#: The viewer opens on the vehicle, as the movie does.
DEFAULT_VIEWER_CAMERA = Camera(azimuth_deg=110.0, elevation_deg=20.0, follow="vehicle", span_m=0.9)
