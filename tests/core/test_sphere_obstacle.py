"""The sphere obstacle, a shape component (``core/geometry/sphere.py`` and one registry line).

Its contact records are checked against a brute-force search over the
ring and against the plane it tends to as its radius grows; a vehicle flies
into one from a scenario file, and the packed shape survives scenario.json.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadimpact import simulate
from quadimpact.core import feature_slots as FS
from quadimpact.core import layout as L
from quadimpact.core.geometry import contact_record, geometry_id
from quadimpact.core.geometry.shapes import by_name, kind_of
from quadimpact.inputs.scenarios import load_scenario_file, scenario_from_dict
from quadimpact.packing.world_block import pack_surface_records, pack_surfaces, surface_records
from quadimpact.rotations import quat_to_matrix


def _row(centre, radius):
    comp = by_name("sphere")
    return comp.pack(comp.settings(name="ball", centre_m=centre, radius_m=radius), kind_of(comp))


def _state(rng):
    x = np.zeros(L.NX)
    x[L.X_POS : L.X_POS + 3] = rng.normal(0.0, 0.3, 3)
    q = rng.normal(size=4)
    x[L.X_QUAT : L.X_QUAT + 4] = q / np.linalg.norm(q)
    x[L.X_VEL : L.X_VEL + 3] = rng.normal(size=3)
    x[L.X_OMEGA : L.X_OMEGA + 3] = rng.normal(size=3)
    return x


def _ring(rng):
    feat = np.zeros((1, FS.NFEAT))
    feat[0, FS.F_KIND] = L.FEAT_RING
    feat[0, FS.F_CENTRE : FS.F_CENTRE + 3] = rng.normal(0.0, 0.1, 3)
    a = rng.normal(size=3)
    feat[0, FS.F_NORMAL : FS.F_NORMAL + 3] = a / np.linalg.norm(a)
    feat[0, FS.F_RADIUS] = 0.12
    return feat


def _ring_points(x, C, feat, n=20000):
    o = x[L.X_POS : L.X_POS + 3] + C @ feat[0, FS.F_CENTRE : FS.F_CENTRE + 3]
    a = C @ feat[0, FS.F_NORMAL : FS.F_NORMAL + 3]
    u = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(a, u)
    b = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    return o + feat[0, FS.F_RADIUS] * (np.outer(np.cos(b), u) + np.outer(np.sin(b), v))


def test_ring_depth_is_the_deepest_point_of_the_ring():
    rng = np.random.default_rng(1)
    for _ in range(200):
        x = _state(rng)
        C = quat_to_matrix(x[L.X_QUAT : L.X_QUAT + 4])
        feat = _ring(rng)
        c = rng.normal(0.0, 0.4, 3)
        shapes = _row(c, 0.25)[None, :]
        rec = contact_record(x, C, feat, shapes, 0, 0)
        pts = _ring_points(x, C, feat)
        depth = 0.25 - np.linalg.norm(pts - c, axis=1)
        # the brute force's grid spacing bounds its error: (2 pi r / n)^2 / R
        assert rec[0] >= depth.max() - 1e-12
        assert rec[0] - depth.max() < 1e-6
        # the contact point is on the ring and its normal points from the centre to it
        p = x[L.X_POS : L.X_POS + 3] + C @ np.array(rec[2:5])
        n = np.array(rec[8:11])
        assert np.min(np.linalg.norm(pts - p, axis=1)) < 1e-4
        assert np.allclose(n, (p - c) / np.linalg.norm(p - c), atol=1e-12)
        # the material velocity's normal part is -delta_dot
        assert rec[1] == pytest.approx(-np.dot(rec[5:8], n), abs=1e-12)


def test_a_large_sphere_is_a_plane():
    # a sphere of radius R touching the plane z = -2 from below is that plane to O(r^2 / R)
    rng = np.random.default_rng(2)
    big = 1e4
    ball = _row((0.0, 0.0, -2.0 + big), big)[None, :]
    plane = pack_surfaces(
        scenario_from_dict(
            {
                "kind": "flight",
                "obstacles": [
                    {"kind": "plane", "name": "p", "point_m": [0, 0, -2], "normal": [0, 0, -1]}
                ],
            }
        ).obstacles
    )
    for _ in range(50):
        x = _state(rng)
        x[L.X_POS + 2] = -2.05
        C = quat_to_matrix(x[L.X_QUAT : L.X_QUAT + 4])
        feat = _ring(rng)
        a = contact_record(x, C, feat, ball, 0, 0)
        b = contact_record(x, C, feat, plane, 0, 0)
        assert a[0] == pytest.approx(b[0], abs=5e-5)  # d^2 / 2R, d < 1 m
        assert np.allclose(a[8:11], b[8:11], atol=1e-4)


def test_every_feature_kind_has_a_row():
    kind = kind_of(by_name("sphere"))
    ids = {geometry_id(f, kind) for f in (L.FEAT_RING, L.FEAT_SPHERE, L.FEAT_POINT)}
    assert len(ids) == 3


def test_point_and_sphere_features_are_exact():
    x = np.zeros(L.NX)
    x[L.X_QUAT] = 1.0
    C = np.eye(3)
    feat = np.zeros((2, FS.NFEAT))
    feat[0, FS.F_KIND] = L.FEAT_POINT
    feat[0, FS.F_CENTRE : FS.F_CENTRE + 3] = (0.3, 0.0, 0.0)
    feat[1, FS.F_KIND] = L.FEAT_SPHERE
    feat[1, FS.F_CENTRE : FS.F_CENTRE + 3] = (0.3, 0.0, 0.0)
    feat[1, FS.F_RADIUS] = 0.05
    shapes = _row((0.5, 0.0, 0.0), 0.25)[None, :]
    assert contact_record(x, C, feat, shapes, 0, 0)[0] == pytest.approx(0.05, abs=1e-15)
    rec = contact_record(x, C, feat, shapes, 1, 0)
    assert rec[0] == pytest.approx(0.10, abs=1e-15)
    assert rec[2:5] == pytest.approx((0.35, 0.0, 0.0), abs=1e-15)
    assert rec[8:11] == pytest.approx((-1.0, 0.0, 0.0), abs=1e-15)


def test_flown_into_from_a_scenario_file_and_recorded(tmp_path):
    path = tmp_path / "ball.toml"
    path.write_text(
        'kind = "flight"\nfinal_time_s = 0.4\ncontroller = "paper"\n'
        "velocity_m_s = [1.5, 0.0, 0.0]\n"
        '[[obstacles]]\nkind = "sphere"\nname = "ball"\n'
        "centre_m = [0.6, 0.0, -2.0]\nradius_m = 0.2\n"
    )
    r = simulate(load_scenario_file(path))
    ep = r.episodes
    assert set(ep["surface"]) == {"ball"} and len(ep) >= 2
    # head on, centred: the two front bumpers touch it at the same time
    assert ep["t_start_s"].max() - ep["t_start_s"].min() < 1e-3
    r.write(tmp_path / "out")
    from quadimpact.results.result import read_result

    back = read_result(tmp_path / "out")
    records = back.world["surfaces"]
    assert records[0]["kind"] == "sphere" and records[0]["radius_m"] == 0.2
    shapes = pack_surface_records(records)
    assert np.array_equal(shapes, pack_surfaces(r.scenario.obstacles))
    assert surface_records(shapes, ["ball"]) == records


def test_bad_sphere_refused_in_one_line():
    with pytest.raises(Exception) as err:
        scenario_from_dict(
            {
                "kind": "flight",
                "obstacles": [
                    {"kind": "sphere", "name": "b", "centre_m": [0, 0, -2], "radius_m": -1}
                ],
            }
        )
    assert "radius_m" in str(err.value) and "\n" not in str(err.value)
