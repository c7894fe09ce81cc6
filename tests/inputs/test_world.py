"""Contact surfaces: one validated plane type, for scenarios, results and the kernel."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from quadimpact.inputs.world import GROUND, Plane


def test_the_papers_wall_and_the_ground() -> None:
    wall = Plane.wall(1.5)
    assert (wall.name, wall.point_m, wall.normal, wall.is_ground) == (
        "wall",
        (1.5, 0.0, 0.0),
        (-1.0, 0.0, 0.0),
        False,
    )
    assert GROUND.is_ground and GROUND.normal == (0.0, 0.0, -1.0) and GROUND.name == "ground"


def test_plane_is_validated_and_hashable() -> None:
    p = Plane(name="slope", point_m=(0, 0, 0), normal=(0.0, 3.0, -4.0))
    assert p.normal == pytest.approx((0.0, 0.6, -0.8))
    assert len({p, Plane(name="slope", point_m=(0, 0, 0), normal=(0.0, 3.0, -4.0))}) == 1
    with pytest.raises(ValidationError):
        Plane(name="bad", point_m=(0, 0, 0), normal=(0, 0, 0))
    with pytest.raises(ValidationError):
        Plane(name="bad", point_m=(0, 0, 0), normal=(0, 0, 1), extra=1)
