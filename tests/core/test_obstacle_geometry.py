"""The contact geometry of every (feature, shape) pair against brute force and a library.

For each pair, on random poses, the compiled record (``core.geometry``) is
compared with an independent NumPy reference (``tests/geometry_reference.py``):

* sphere and point features against planes, cylinders (finite and
  infinite) and boxes: depth, point and normal against the reference depth
  (a sphere's depth is its penetration, ``R`` minus the signed distance of
  its centre) and brute force over the sphere's surface (dense sampling,
  then local refinement), to 1e-9 m; where the collision library
  ``python-fcl`` is installed (the ``dev`` extra), also against its
  sphere-box, sphere-cylinder and sphere-halfspace contacts;
* rings against cylinders (finite, infinite) and boxes: depth against brute
  force over the circle (20,000 samples, golden-section refinement of the
  best) to 1e-12 m; the point lies on the circle and is that deep; the
  normal is the reference's (a numerical gradient) there;
* the velocity of every record is the material velocity of its point.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from geometry_reference import (
    box_row,
    circle,
    cylinder_row,
    depth,
    plane_row,
    random_ring,
    random_shape,
    ring_brute_force,
    rotation,
)

from quadimpact.core import feature_slots as FS
from quadimpact.core import geometry
from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP
from quadimpact.core.geometry.plane import ring_plane_bound
from quadimpact.core.geometry.ring import ring_deepest
from quadimpact.core.geometry.ring_box import ring_box_exact

SHAPES = ("plane", "box", "cylinder", "infinite cylinder")


def _shape(rng, kind):
    if kind == "plane":
        return plane_row(rng.uniform(-0.1, 0.1, 3), rng.standard_normal(3))
    return random_shape(rng, kind)


def _state(rng):
    """A random rigid-body state: position, body velocity, attitude, body rates."""
    x = np.zeros(L.NX)
    x[L.X_POS : L.X_POS + 3] = rng.uniform(-0.05, 0.05, 3)
    x[L.X_VEL : L.X_VEL + 3] = rng.standard_normal(3)
    q = rng.standard_normal(4)
    x[L.X_QUAT : L.X_QUAT + 4] = q / np.linalg.norm(q)
    x[L.X_OMEGA : L.X_OMEGA + 3] = 3.0 * rng.standard_normal(3)
    return x


def _rotation(x):
    q0, q1, q2, q3 = x[L.X_QUAT : L.X_QUAT + 4]
    return np.array(
        [
            [1 - 2 * (q2 * q2 + q3 * q3), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
            [2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1 * q1 + q3 * q3), 2 * (q2 * q3 - q0 * q1)],
            [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1 * q1 + q2 * q2)],
        ]
    )


def _feature(kind, centre, radius=0.0, normal=(0.0, 0.0, -1.0)):
    feat = np.zeros((1, FS.NFEAT))
    feat[0, FS.F_KIND] = {"ring": L.FEAT_RING, "sphere": L.FEAT_SPHERE, "point": L.FEAT_POINT}[kind]
    feat[0, FS.F_CENTRE : FS.F_CENTRE + 3] = centre
    feat[0, FS.F_NORMAL : FS.F_NORMAL + 3] = np.asarray(normal) / np.linalg.norm(normal)
    feat[0, FS.F_RADIUS] = radius
    feat[0, [FS.F_K, FS.F_N, FS.F_E]] = (100.0, 1.0, 0.9)
    return feat


def _record(x, feat, row):
    C = _rotation(x)
    rec = geometry.contact_record(x, C, feat, row[None, :], 0, 0)
    delta, delta_dot = rec[0], rec[1]
    rc = np.array(rec[2:5])
    vc = np.array(rec[5:8])
    n = np.array(rec[8:11])
    return C, delta, delta_dot, rc, vc, n


def _numerical_normal(p, row, h=1e-6):
    """Minus the gradient of the reference depth (the outward normal), central differences."""
    g = np.array([(depth(p + h * e, row) - depth(p - h * e, row)) / (2 * h) for e in np.eye(3)])
    return -g / np.linalg.norm(g)


def _check_velocity(x, C, rc, vc, n, delta_dot):
    """The record's velocity is the material velocity of its point, delta_dot = -v . n."""
    v_body = x[L.X_VEL : L.X_VEL + 3] + np.cross(x[L.X_OMEGA : L.X_OMEGA + 3], rc)
    np.testing.assert_allclose(vc, C @ v_body, rtol=0, atol=1e-12)
    assert delta_dot == pytest.approx(-vc @ n, abs=1e-12)


def _sphere_brute_force(c, r, row, n=4000):
    """The deepest point of a sphere: Fibonacci directions, then Nelder-Mead on two angles."""
    from scipy.optimize import minimize

    k = np.arange(n) + 0.5
    polar = np.arccos(1 - 2 * k / n)
    azim = math.pi * (1 + 5**0.5) * k

    def points(a, b):
        return c + r * np.stack([np.sin(a) * np.cos(b), np.sin(a) * np.sin(b), np.cos(a)], axis=-1)

    vals = depth(points(polar, azim), row)
    i = int(np.argmax(vals))
    res = minimize(
        lambda v: -float(depth(points(v[0], v[1]), row)),
        [polar[i], azim[i]],
        method="Nelder-Mead",
        options={"xatol": 1e-13, "fatol": 1e-16, "maxiter": 4000},
    )
    return -res.fun, points(res.x[0], res.x[1])


@pytest.mark.parametrize("shape", SHAPES)
def test_points_against_the_reference_depth(shape):
    rng = np.random.default_rng(11)
    for _ in range(60):
        row = _shape(rng, shape)
        x = _state(rng)
        feat = _feature("point", rng.uniform(-0.25, 0.25, 3))
        C, delta, delta_dot, rc, vc, n = _record(x, feat, row)
        p = x[L.X_POS : L.X_POS + 3] + C @ feat[0, FS.F_CENTRE : FS.F_CENTRE + 3]
        np.testing.assert_allclose(x[L.X_POS : L.X_POS + 3] + C @ rc, p, atol=1e-12)
        assert delta == pytest.approx(float(depth(p, row)), abs=1e-12)
        np.testing.assert_allclose(n, _numerical_normal(p, row), atol=1e-8)
        _check_velocity(x, C, rc, vc, n, delta_dot)


@pytest.mark.parametrize("shape", SHAPES)
def test_spheres_against_brute_force(shape):
    """A sphere's depth is its penetration ``R - signed distance(centre)`` (what fcl reports).

    Brute force over the sphere's surface: no point of the sphere is deeper
    than that (the depth is 1-Lipschitz), and a sphere that does not
    penetrate has its deepest point exactly that deep, at ``centre - R m``.
    """
    rng = np.random.default_rng(12)
    separated = 0
    for _ in range(40):
        row = _shape(rng, shape)
        x = _state(rng)
        radius = float(rng.uniform(0.03, 0.15))
        feat = _feature("sphere", rng.uniform(-0.3, 0.3, 3), radius)
        C, delta, delta_dot, rc, vc, n = _record(x, feat, row)
        c = x[L.X_POS : L.X_POS + 3] + C @ feat[0, FS.F_CENTRE : FS.F_CENTRE + 3]
        assert delta == pytest.approx(radius + float(depth(c, row)), abs=1e-12)
        p = x[L.X_POS : L.X_POS + 3] + C @ rc
        assert np.linalg.norm(p - c) == pytest.approx(radius, abs=1e-12)
        np.testing.assert_allclose(n, _numerical_normal(c, row), atol=1e-8)
        best, point = _sphere_brute_force(c, radius, row)
        assert best <= delta + 1e-12
        if delta <= 0.0:
            separated += 1
            assert best == pytest.approx(delta, abs=1e-9)
            assert float(depth(p, row)) == pytest.approx(delta, abs=1e-12)
            np.testing.assert_allclose(p, point, atol=1e-5)  # Nelder-Mead's point
        _check_velocity(x, C, rc, vc, n, delta_dot)
    assert separated >= 5


@pytest.mark.parametrize("shape", ("box", "cylinder", "infinite cylinder"))
def test_rings_against_brute_force_to_1e_12(shape):
    rng = np.random.default_rng({"box": 21, "cylinder": 22, "infinite cylinder": 23}[shape])
    worst = 0.0
    for _ in range(80):
        row = random_shape(rng, shape)
        ring = random_ring(rng)
        b, g, mx, my, mz = ring_deepest(ring, row[None, :], 0)
        best, best_t = ring_brute_force(ring, row)
        worst = max(worst, abs(g - best))
        assert g == pytest.approx(best, abs=1e-12)
        p = circle(ring, [b])[0]
        assert float(depth(p, row)) == pytest.approx(g, abs=1e-12)
        # the point: where the maximum is sharp it is the brute force's; a flat maximum
        # fixes its point only to sqrt(1e-12 m / curvature)
        assert (
            np.linalg.norm(p - circle(ring, [best_t])[0]) < 2e-5
            or abs(float(depth(circle(ring, [best_t])[0], row)) - g) < 1e-12
        )
    assert worst < 1e-12


def test_ring_records_carry_the_point_normal_and_velocity():
    rng = np.random.default_rng(31)
    for shape in ("box", "cylinder", "infinite cylinder"):
        for _ in range(20):
            row = random_shape(rng, shape)
            x = _state(rng)
            normal = rng.standard_normal(3)
            feat = _feature("ring", rng.uniform(-0.15, 0.15, 3), rng.uniform(0.05, 0.15), normal)
            C, delta, delta_dot, rc, vc, n = _record(x, feat, row)
            p = x[L.X_POS : L.X_POS + 3] + C @ rc
            centre = C @ feat[0, FS.F_CENTRE : FS.F_CENTRE + 3] + x[L.X_POS : L.X_POS + 3]
            nrm = C @ feat[0, FS.F_NORMAL : FS.F_NORMAL + 3]
            assert np.linalg.norm(p - centre) == pytest.approx(feat[0, FS.F_RADIUS], abs=1e-12)
            assert (p - centre) @ nrm == pytest.approx(0.0, abs=1e-12)
            assert float(depth(p, row)) == pytest.approx(delta, abs=1e-12)
            if abs(float(depth(p, row))) > 1e-6:
                # away from creases the normal is the gradient's; at a crease either face's
                numerical = _numerical_normal(p, row)
                if np.linalg.norm(numerical - n) > 1e-6:
                    assert delta > 0 and shape != "infinite cylinder"
            _check_velocity(x, C, rc, vc, n, delta_dot)


def test_the_ring_plane_pair_is_unchanged_and_agrees_with_the_search():
    """The closed form against a plane equals the certified search and the brute force."""
    from quadimpact.core.geometry.ring import ring_frame

    rng = np.random.default_rng(41)
    for _ in range(40):
        row = plane_row(rng.uniform(-0.1, 0.1, 3), rng.standard_normal(3))
        x = _state(rng)
        feat = _feature("ring", rng.uniform(-0.15, 0.15, 3), 0.125, rng.standard_normal(3))
        C, delta, *_ = _record(x, feat, row)
        ring = ring_frame(x, C, feat, 0)
        assert ring_deepest(ring, row[None, :], 0)[1] == pytest.approx(delta, abs=1e-13)
        assert ring_brute_force(ring, row, n=4000)[0] == pytest.approx(delta, abs=1e-12)


def test_rings_around_a_bar_take_the_branch_and_bound_and_stay_exact():
    """A bar through the ring's hole: the shortest way in leans inward, no one-point certificate."""
    rng = np.random.default_rng(51)
    for _ in range(20):
        row = cylinder_row(rng.uniform(-0.01, 0.01, 3), rng.standard_normal(3), 0.03)
        ring = random_ring(rng, spread=0.02)
        _, g, *_ = ring_deepest(ring, row[None, :], 0)
        assert g == pytest.approx(ring_brute_force(ring, row)[0], abs=1e-12)


def _ring_at_a_corner(rng, row, off):
    """A circle centred near a corner of the box ``row`` (within ``off``), any orientation."""
    axes = row[SHP.SH_ROT : SHP.SH_ROT + 9].reshape(3, 3)
    signs = rng.choice([-1.0, 1.0], 3)
    corner = row[SHP.SH_POINT : SHP.SH_POINT + 3] + axes.T @ (
        signs * row[SHP.SH_HALF : SHP.SH_HALF + 3]
    )
    ring = random_ring(rng, spread=off)
    return (*(np.array(ring[:3]) + corner), *ring[3:])


@pytest.mark.parametrize("off", (0.02, 0.1))
def test_a_box_corner_in_the_rings_disk_is_solved_exactly(off):
    """A corner or an edge through the ring's disk (no one-point certificate): the closed form
    (``ring_box.ring_box_exact``), inside and outside the box, equals brute force to rounding."""
    rng = np.random.default_rng({0.02: 61, 0.1: 62}[off])
    inside = outside = 0
    for _ in range(30):
        row = box_row(rng.uniform(-0.1, 0.1, 3), rng.uniform(0.05, 0.3, 3), rotation(rng))
        ring = _ring_at_a_corner(rng, row, off)
        ok, b, g, *_ = ring_box_exact(ring, row[None, :], 0)
        best, _ = ring_brute_force(ring, row)
        assert ok
        assert g == pytest.approx(best, abs=1e-13)
        assert float(depth(circle(ring, [b])[0], row)) == pytest.approx(g, abs=1e-13)
        assert ring_deepest(ring, row[None, :], 0)[1] == pytest.approx(best, abs=1e-12)
        inside += g > 0.0
        outside += g <= 0.0
    assert inside >= 5 and outside >= 5


def test_the_corner_depth_is_continuous_along_a_path():
    """A ring sliding across a box's corner: the depth moves by no more than the path (the
    depth is 1-Lipschitz) between close poses, whichever method certified each."""
    rng = np.random.default_rng(63)
    row = box_row(np.zeros(3), np.array([0.2, 0.2, 0.2]), rotation(rng))
    start = np.array(_ring_at_a_corner(rng, row, 0.05))
    step = rng.standard_normal(3)
    step *= 2e-5 / np.linalg.norm(step)
    previous = None
    for k in range(-2000, 2000):
        ring = (*(start[:3] + k * step), *start[3:])
        g = ring_deepest(ring, row[None, :], 0)[1]
        if previous is not None:
            assert abs(g - previous) <= 2e-5 + 1e-12
        previous = g


def _ring_points_along(feat, row, positions):
    """The contact point (inertial) of the ring ``feat`` against ``row`` at each CM position."""
    x = np.zeros(L.NX)
    x[L.X_QUAT] = 1.0
    points = []
    for p in positions:
        x[L.X_POS : L.X_POS + 3] = p
        _, _, _, rc, _, _ = _record(x, feat, row)
        points.append(p + rc)
    return np.array(points)


def test_a_ring_around_a_pole_has_a_smooth_contact_point():
    """A pole through the ring's hole (the branch and bound): the deepest point is a smooth
    function of the pose, its second differences along a straight path at rounding level.

    The branch and bound alone returned the best angle it sampled, within about 1e-6 rad of
    the maximum, which made the contact point (and moment) jump by up to a micrometre from
    one evaluation to the next (issue 59: the pole trial at pitch -30 deg)."""
    rng = np.random.default_rng(71)
    for _ in range(5):
        row = cylinder_row(rng.uniform(-0.01, 0.01, 3), rng.standard_normal(3), 0.03)
        feat = _feature("ring", np.zeros(3), 0.1, rng.standard_normal(3))
        step = rng.standard_normal(3)
        step *= 1e-7 / np.linalg.norm(step)
        points = _ring_points_along(feat, row, [k * step for k in range(400)])
        assert np.abs(np.diff(points, 2, axis=0)).max() < 1e-11


def test_a_ring_across_a_box_edge_moves_its_point_continuously():
    """A hoop across a box's edge, its two crossings of the edge equally deep: the contact
    point moves from one crossing to the other continuously as the tilt passes through the
    tie (the crossings within ``TWIN_BAND`` share the point), instead of jumping by the chord.

    The jump made the contact moment discontinuous and the integrator chatter between the two
    points (issue 59: the pole-replica's edge trial at pitch -42 deg, offset 0.2 m)."""
    half = 0.5
    row = box_row(np.array([half, half, 0.0]), np.array([half, half, 1.0]), np.eye(3))
    u0, radius = 1e-3, 0.125  # the ring's centre 1 mm inside both faces of the edge
    n0 = np.array([1.0, 1.0, 0.0]) / math.sqrt(2.0)  # the ring's plane: x + y = 2 u0
    up = np.array([0.0, 0.0, 1.0])
    points = []
    for theta in np.linspace(-2e-5, 2e-5, 4001):  # tilt: the top crossing leans out or in
        feat = _feature(
            "ring", np.array([u0, u0, 0.0]), radius, math.cos(theta) * n0 + math.sin(theta) * up
        )
        points.append(_ring_points_along(feat, row, [np.zeros(3)])[0])
    points = np.array(points)
    assert np.linalg.norm(points[-1] - points[0]) > 1.9 * radius  # from one crossing to the other
    assert np.linalg.norm(np.diff(points, axis=0), axis=1).max() < 2e-3


# ------------------------------------------------------------------ python-fcl
def _fcl():
    return pytest.importorskip(
        "fcl", reason="python-fcl is not installed (pip install -e '.[dev]' brings it)"
    )


def _fcl_shape(fcl, row):
    """The fcl geometry and transform of a shape row (an infinite cylinder: 100 m long)."""
    kind = int(row[SHP.SH_KIND])
    o = row[SHP.SH_POINT : SHP.SH_POINT + 3]
    if kind == L.SHAPE_PLANE:
        n = row[SHP.SH_NORMAL : SHP.SH_NORMAL + 3]
        # fcl's halfspace n . p <= d is the solid: ours is behind the outward normal
        return fcl.Halfspace(n, float(n @ o)), fcl.Transform()
    if kind == L.SHAPE_BOX:
        axes = row[SHP.SH_ROT : SHP.SH_ROT + 9].reshape(3, 3)
        half = row[SHP.SH_HALF : SHP.SH_HALF + 3]
        return fcl.Box(*(2 * half)), fcl.Transform(axes.T, o)
    e = row[SHP.SH_NORMAL : SHP.SH_NORMAL + 3]
    k = np.eye(3)[np.argmin(np.abs(e))]
    a = np.cross(e, k)
    a /= np.linalg.norm(a)
    R = np.column_stack([a, np.cross(e, a), e])  # fcl's cylinder axis is its local z
    length = row[SHP.SH_LENGTH] if np.isfinite(row[SHP.SH_LENGTH]) else 100.0
    return fcl.Cylinder(row[SHP.SH_RADIUS], length), fcl.Transform(R, o)


@pytest.mark.parametrize("shape", SHAPES)
def test_spheres_and_points_agree_with_python_fcl(shape):
    """fcl's sphere-box, sphere-cylinder and sphere-halfspace contacts (exact solvers)."""
    fcl = _fcl()
    rng = np.random.default_rng(61)
    checked = 0
    for _ in range(200):
        row = _shape(rng, shape)
        if shape == "plane":
            row[SHP.SH_POINT : SHP.SH_POINT + 3] = 0.0
        for kind in ("sphere", "point"):
            radius = float(rng.uniform(0.03, 0.15)) if kind == "sphere" else 1e-4
            x = _state(rng)
            feat = _feature(kind, rng.uniform(-0.2, 0.2, 3), radius if kind == "sphere" else 0)
            C, delta, _, rc, _, n = _record(x, feat, row)
            c = x[L.X_POS : L.X_POS + 3] + C @ feat[0, FS.F_CENTRE : FS.F_CENTRE + 3]
            geom, tf = _fcl_shape(fcl, row)
            req = fcl.CollisionRequest(enable_contact=True, num_max_contacts=1)
            res = fcl.CollisionResult()
            hit = fcl.collide(
                fcl.CollisionObject(fcl.Sphere(radius), fcl.Transform(c)),
                fcl.CollisionObject(geom, tf),
                req,
                res,
            )
            own = delta + (radius if kind == "point" else 0.0)
            if not hit or float(depth(c, row)) > 0.0:  # separated, or the centre inside
                continue
            contact = res.contacts[0]
            assert own == pytest.approx(contact.penetration_depth, abs=1e-9)
            np.testing.assert_allclose(n, -np.asarray(contact.normal), atol=1e-9)
            if kind == "sphere":
                p = x[L.X_POS : L.X_POS + 3] + C @ rc
                mid = p + 0.5 * delta * n  # fcl reports the middle of the overlap
                np.testing.assert_allclose(mid, contact.pos, atol=1e-9)
            checked += 1
    assert checked >= 20


def test_box_axes_are_rows_and_depths_are_those_of_the_rotated_box():
    """``SH_ROT``'s row i is the box's axis i: a box turned 90 degrees about Z swaps X and Y."""
    R = rotation(np.random.default_rng(0))
    row = box_row([0.0, 0.0, 0.0], [0.1, 0.2, 0.3], R)
    p = 0.05 * R[1]  # along the box's second axis: 0.15 from its face
    feat = _feature("point", [0.0, 0.0, 0.0])
    x = np.zeros(L.NX)
    x[L.X_POS : L.X_POS + 3] = p
    x[L.X_QUAT] = 1.0
    _, delta, *_ = _record(x, feat, row)
    assert delta == pytest.approx(0.1, abs=1e-15)


@pytest.mark.parametrize("shape", ("box", "cylinder", "infinite cylinder"))
def test_the_broad_phase_bounds_a_rings_depth_and_rate(shape):
    """The broad phase never claims a ring apart that touches: its depth bound is above the
    ring's depth and its rate bound above the size of the depth's rate, near and far."""
    rng = np.random.default_rng({"box": 51, "cylinder": 52, "infinite cylinder": 53}[shape])
    proved_apart = 0
    for _ in range(300):
        row = random_shape(rng, shape)
        x = _state(rng)
        x[L.X_POS : L.X_POS + 3] = rng.uniform(-0.4, 0.4, 3)  # from inside to well apart
        feat = _feature(
            "ring", rng.uniform(-0.15, 0.15, 3), rng.uniform(0.05, 0.15), rng.standard_normal(3)
        )
        C, delta, delta_dot, *_ = _record(x, feat, row)
        kind = (int(feat[0, FS.F_KIND]), int(row[SHP.SH_KIND]))
        pairs = np.array([[0, 0, geometry.geometry_id(*kind)]], dtype=np.int64)
        assert geometry.has_bound(pairs, 0)
        bound, rate = geometry.pair_bound(x, C, feat, row[None, :], pairs, 0)
        assert delta <= bound
        assert abs(delta_dot) <= rate
        proved_apart += bound < 0.0
    assert 30 < proved_apart < 270  # both cases were met (apart and not proved apart)


def test_the_plane_broad_phase_bounds_a_rings_depth_and_rate():
    """A ring against a plane: the CM's distance against the ring's reach never claims a
    ring apart that touches, and its rate bound is above the size of the depth's rate."""
    rng = np.random.default_rng(55)
    proved_apart = 0
    for _ in range(300):
        row = _shape(rng, "plane")
        x = _state(rng)
        x[L.X_POS : L.X_POS + 3] = rng.uniform(-0.4, 0.4, 3)  # from behind to well apart
        feat = _feature(
            "ring", rng.uniform(-0.15, 0.15, 3), rng.uniform(0.05, 0.15), rng.standard_normal(3)
        )
        _, delta, delta_dot, *_ = _record(x, feat, row)
        speed = float(np.linalg.norm(x[L.X_VEL : L.X_VEL + 3]))
        spin = float(np.linalg.norm(x[L.X_OMEGA : L.X_OMEGA + 3]))
        bound, rate = ring_plane_bound(x, speed, spin, feat, 0, row[None, :], 0)
        assert delta <= bound
        assert abs(delta_dot) <= rate
        proved_apart += bound < 0.0
    assert 30 < proved_apart < 270  # both cases were met (apart and not proved apart)


def test_closed_form_pairs_have_no_broad_phase():
    """A sphere, a point, or a ring against a plane: no search to bound (the ring against a
    plane has its own broad phase in the event checks, ``plane.ring_plane_bound``)."""
    rng = np.random.default_rng(54)
    x = _state(rng)
    C = _rotation(x)
    for feature, shape in (("sphere", "box"), ("point", "cylinder"), ("ring", "plane")):
        feat = _feature(feature, (0.1, 0.0, 0.0), 0.1)
        row = _shape(rng, shape)
        kind = (int(feat[0, FS.F_KIND]), int(row[SHP.SH_KIND]))
        pairs = np.array([[0, 0, geometry.geometry_id(*kind)]], dtype=np.int64)
        assert not geometry.has_bound(pairs, 0)
        assert geometry.pair_bound(x, C, feat, row[None, :], pairs, 0) == (math.inf, math.inf)
