"""A ring against a convex solid (a cylinder, a box): the deepest point of a circle.

The record of a ring is that of its deepest point: the maximum over the
circle ``P(b) = c + R (cos b a + sin b b')`` of the depth ``g(P(b))`` of a
point in the solid (``box.box_depth``, ``cylinder.cylinder_depth``). Against a
plane this has a closed form (``plane.ring_plane``); against a cylinder or a
box it has none (the authors solved a quartic for the pole), so it is
searched, and the answer is **certified**.

The certificate. The depth ``g`` of a convex solid is a concave function of
the point (minus a convex signed distance), so at any point ``P_k`` with
supergradient ``xi_k`` (minus the normal there; at a crease between two
faces any convex combination of theirs)::

    g(p) <= g(P_k) + xi_k . (p - P_k)          for every p in space

and on the circle that bound is a sinusoid of ``b``, the *cut* of ``P_k``.
Its maximum over the circle is ``g(P_k) + R (|xi_in| - xi_in . u_k)``, with
``xi_in`` the part of ``xi_k`` in the ring's plane and ``u_k`` the radial unit
vector at ``b_k``. So when ``xi_in`` points along ``u_k`` (the shortest way
into the solid leans outward from the ring at that point, the ordinary case
of a ring touching an obstacle from outside), ``b_k`` is the global maximum:
the excess ``R (|xi_in| - xi_in . u_k)`` bounds how far any point of the ring
can be deeper.

The search (:func:`ring_deepest`):

1. start at the angle where the cut of the ring's centre peaks; iterate the
   secant method on ``dg/db`` (its first step goes to the peak of the
   current point's cut), stopping as soon as the excess is below
   :data:`TOL` (1e-13 m); when two iterates lie on two different pieces of
   the solid's depth (two faces, a side and a cap) with slopes of opposite
   signs, the crease between them is solved for (regula falsi on the
   difference of the two pieces) and certified with the convex combination
   of their normals whose slope along the ring is zero;
2. if that does not certify within :data:`MAX_LOCAL` evaluations: against a
   box (a corner or an edge of the box through the ring's disk), the exact
   solution from the box's pieces (``ring_box.ring_box_exact``: closed-form
   candidates, evaluated with the box's depth); against an infinite cylinder
   (a ring around a pole), every stationary point of the distance from the
   axis (:func:`_ring_around_axis`, a quartic); against a finite one (a ring
   around a bar, a maximum on the far side), a branch and bound over arcs of
   the circle: every arc's bound is the largest value of the lower of its two
   end cuts (closed form: the ends, the cuts' peaks and their crossings);
   arcs whose bound exceeds the best point found by more than :data:`TOL` are
   halved, until none is left (at most :data:`MAX_EVALS` evaluations); its
   best angle is then refined (:func:`_polish`).

Each returns a point whose depth is within :data:`TOL` of the maximum over
the circle (the exact box solution: to rounding), so the depth is continuous
in time up to that tolerance (a jump of the arg-max between two equally deep
points changes the point, not the depth). On a crease of the solid (two
faces, or a side and a cap, equally near) the contact normal is the blend of
the two that certifies the maximum (:func:`_crease_normal`; not of unit
length there: the depth's gradient), so that the force does not flip between
two faces from one evaluation to the next and stays conservative. Cost: a
typical evaluation is 3 to 6 point depths (one sine and cosine each); the
exact box solution, rare, a few microseconds; the branch and bound, rare and
for cylinders only, about 100 to 300 point depths.
"""

import math

import numpy as np
from numba import njit

from quadimpact.core.compiled import allocating, compiled
from quadimpact.core.feature_slots import (
    F_CENTRE,
    F_NORMAL,
    F_RADIUS,
)
from quadimpact.core.geometry.box import box_depth, box_piece
from quadimpact.core.geometry.contact_record import ContactRecord, material_record
from quadimpact.core.geometry.cylinder import cylinder_depth, cylinder_piece
from quadimpact.core.geometry.plane import plane_depth, plane_distance
from quadimpact.core.geometry.ring_box import ring_box_exact
from quadimpact.core.layout import (
    SHAPE_BOX,
    SHAPE_CYLINDER,
    X_OMEGA,
    X_POS,
    X_VEL,
)
from quadimpact.core.shape_slots import (
    SH_KIND,
    SH_LENGTH,
    SH_NORMAL,
    SH_POINT,
)

TOL = 1e-13  # m: how far the returned depth may be below the circle's maximum
CREASE_TOL = 1e-9  # m: two faces this close in depth at the deepest point: a crease
MAX_LOCAL = 16  # point depths of the local search before the branch and bound
N_ARCS = 32  # initial arcs of the branch and bound
MAX_EVALS = 4000  # point depths of the branch and bound at most
STACK = 512
TWO_PI = 2.0 * math.pi
POLISH_ITERS = 8  # secant steps refining the branch and bound's best angle
POLISH_STEP = 1e-6  # rad: the refinement's first secant step
POLISH_REACH = 1e-3  # rad: how far the refinement may move the angle
TWIN_BAND = 1e-6  # m: a second crease this close in depth shares the contact point
BOUND_MARGIN = 1e-9  # m: added to the broad phase's depth bound (rounding of the point depths)
RATE_MARGIN = 1e-9  # relative: added to its rate bound

Ring = tuple[float, float, float, float, float, float, float, float, float, float]
"""(cx, cy, cz, ax, ay, az, bx, by, bz, R): centre, two orthonormal in-plane axes, radius."""


@njit(cache=True, inline="always")
def solid_depth(
    px: float, py: float, pz: float, shapes: np.ndarray, s: int
) -> tuple[float, float, float, float, int]:
    """Depth, outward normal and piece of the point ``p`` in the convex shape ``s``."""
    kind = int(shapes[s, SH_KIND])
    if kind == SHAPE_BOX:
        return box_depth(px, py, pz, shapes, s)
    if kind == SHAPE_CYLINDER:
        return cylinder_depth(px, py, pz, shapes, s)
    return plane_depth(px, py, pz, shapes, s)


@compiled
def solid_piece(
    px: float, py: float, pz: float, shapes: np.ndarray, s: int, k: int
) -> tuple[float, float, float, float]:
    """Piece ``k``'s depth of ``p`` in shape ``s`` (extended beyond the piece) and its normal."""
    kind = int(shapes[s, SH_KIND])
    if kind == SHAPE_BOX:
        return box_piece(px, py, pz, shapes, s, k)
    if kind == SHAPE_CYLINDER:
        return cylinder_piece(px, py, pz, shapes, s, k)
    return (
        -plane_distance(px, py, pz, shapes, s),
        shapes[s, SH_NORMAL],
        shapes[s, SH_NORMAL + 1],
        shapes[s, SH_NORMAL + 2],
    )


@njit(cache=True, inline="always")
def _point(ring: Ring, b: float) -> tuple[float, float, float, float, float, float]:
    """The circle's point at angle ``b`` and its tangent ``dP/db``."""
    cx, cy, cz, ax, ay, az, bx, by, bz, r = ring
    cb = math.cos(b)
    sb = math.sin(b)
    return (
        cx + r * (cb * ax + sb * bx),
        cy + r * (cb * ay + sb * by),
        cz + r * (cb * az + sb * bz),
        r * (-sb * ax + cb * bx),
        r * (-sb * ay + cb * by),
        r * (-sb * az + cb * bz),
    )


@njit(cache=True, inline="always")
def _excess(ring: Ring, b: float, xx: float, xy: float, xz: float) -> float:
    """How far the cut with supergradient ``xi`` at angle ``b`` rises above its value there (m)."""
    _, _, _, ax, ay, az, bx, by, bz, r = ring
    wa = xx * ax + xy * ay + xz * az
    wb = xx * bx + xy * by + xz * bz
    return r * (math.sqrt(wa * wa + wb * wb) - (wa * math.cos(b) + wb * math.sin(b)))


@njit(cache=True, inline="always")
def _cut(ring: Ring, b: float, g: float, mx: float, my: float, mz: float):
    """The cut of the point at ``b`` (depth ``g``, normal ``m``): ``c + A cos + B sin``."""
    _, _, _, ax, ay, az, bx, by, bz, r = ring
    a_ = -r * (mx * ax + my * ay + mz * az)
    b_ = -r * (mx * bx + my * by + mz * bz)
    return g - a_ * math.cos(b) - b_ * math.sin(b), a_, b_


@njit(cache=True, inline="always")
def _min_cuts(c1, a1, b1, c2, a2, b2, t):
    return min(c1 + a1 * math.cos(t) + b1 * math.sin(t), c2 + a2 * math.cos(t) + b2 * math.sin(t))


@allocating
def _arc_bound(lo: float, hi: float, cuts: tuple) -> float:
    """Largest value on ``[lo, hi]`` of the lower of two cuts (closed form)."""
    c1, a1, b1, c2, a2, b2 = cuts
    best = max(_min_cuts(c1, a1, b1, c2, a2, b2, lo), _min_cuts(c1, a1, b1, c2, a2, b2, hi))
    cand = np.empty(4)
    n = 0
    if a1 != 0.0 or b1 != 0.0:
        cand[n] = math.atan2(b1, a1)
        n += 1
    if a2 != 0.0 or b2 != 0.0:
        cand[n] = math.atan2(b2, a2)
        n += 1
    da = a1 - a2
    db = b1 - b2
    amp = math.sqrt(da * da + db * db)
    if amp > 0.0:
        ratio = -(c1 - c2) / amp
        if -1.0 <= ratio <= 1.0:
            phi = math.atan2(db, da)
            half = math.acos(ratio)
            cand[n] = phi + half
            cand[n + 1] = phi - half
            n += 2
    for i in range(n):
        t = lo + ((cand[i] - lo) % TWO_PI)
        if t <= hi:
            best = max(best, _min_cuts(c1, a1, b1, c2, a2, b2, t))
    return best


@compiled
def _crease(ring: Ring, b1: float, k1: int, b2: float, k2: int, shapes: np.ndarray, s: int):
    """The crease between pieces ``k1`` (active at ``b1``) and ``k2`` (at ``b2``), certified.

    Returns (certified, angle, depth, normal).
    """
    lo = b1
    hi = b2
    p = _point(ring, lo)
    f_lo = solid_piece(p[0], p[1], p[2], shapes, s, k1)[0]
    f_lo -= solid_piece(p[0], p[1], p[2], shapes, s, k2)[0]
    p = _point(ring, hi)
    f_hi = solid_piece(p[0], p[1], p[2], shapes, s, k1)[0]
    f_hi -= solid_piece(p[0], p[1], p[2], shapes, s, k2)[0]
    mid = lo
    side = 0
    for _ in range(100):
        if f_hi == f_lo or abs(hi - lo) <= 1e-15 * (1.0 + abs(hi)):
            break
        mid = hi - f_hi * (hi - lo) / (f_hi - f_lo)
        if not (min(lo, hi) < mid < max(lo, hi)):
            mid = 0.5 * (lo + hi)
        p = _point(ring, mid)
        fm = solid_piece(p[0], p[1], p[2], shapes, s, k1)[0]
        fm -= solid_piece(p[0], p[1], p[2], shapes, s, k2)[0]
        if fm == 0.0:
            lo = mid
            hi = mid
            break
        if (fm > 0.0) == (f_hi > 0.0):
            hi = mid
            f_hi = fm
            if side == 1:
                f_lo *= 0.5
            side = 1
        else:
            lo = mid
            f_lo = fm
            if side == -1:
                f_hi *= 0.5
            side = -1
    b = hi if abs(f_hi) <= abs(f_lo) else lo
    px, py, pz, tx, ty, tz = _point(ring, b)
    v1, n1x, n1y, n1z = solid_piece(px, py, pz, shapes, s, k1)
    v2, n2x, n2y, n2z = solid_piece(px, py, pz, shapes, s, k2)
    g, mx, my, mz, _ = solid_depth(px, py, pz, shapes, s)
    s1 = -(n1x * tx + n1y * ty + n1z * tz)
    s2 = -(n2x * tx + n2y * ty + n2z * tz)
    if g < min(v1, v2) - TOL or s1 * s2 > 0.0:
        return False, b, g, mx, my, mz
    lam = 0.5 if s1 == s2 else s2 / (s2 - s1)
    xx = -(lam * n1x + (1.0 - lam) * n2x)
    xy = -(lam * n1y + (1.0 - lam) * n2y)
    xz = -(lam * n1z + (1.0 - lam) * n2z)
    return _excess(ring, b, xx, xy, xz) <= TOL, b, g, mx, my, mz


@allocating
def _branch_and_bound(ring: Ring, shapes: np.ndarray, s: int, best: tuple):
    """The global search over arcs (see the module docstring), from the best point so far."""
    b_best, g_best, bmx, bmy, bmz = best
    arcs = np.empty((STACK, 9))  # lo, hi, c1, a1, b1, c2, a2, b2, bound
    b0 = b_best
    step = TWO_PI / N_ARCS
    prev = (0.0, 0.0, 0.0)
    first = (0.0, 0.0, 0.0)
    n = 0
    evals = 0
    for k in range(N_ARCS + 1):
        b = b0 + k * step
        if k < N_ARCS:
            px, py, pz, _, _, _ = _point(ring, b)
            g, mx, my, mz, _ = solid_depth(px, py, pz, shapes, s)
            evals += 1
            if g > g_best:
                b_best, g_best, bmx, bmy, bmz = b, g, mx, my, mz
            cut = _cut(ring, b, g, mx, my, mz)
            if k == 0:
                first = cut
        else:
            cut = first
        if k > 0:
            lo = b - step
            cuts = (prev[0], prev[1], prev[2], cut[0], cut[1], cut[2])
            arcs[n, 0] = lo
            arcs[n, 1] = b
            arcs[n, 2:8] = cuts
            arcs[n, 8] = _arc_bound(lo, b, cuts)
            n += 1
        prev = cut
    while n > 0 and evals < MAX_EVALS:
        n -= 1
        lo = arcs[n, 0]
        hi = arcs[n, 1]
        if arcs[n, 8] <= g_best + TOL or hi - lo <= 1e-13:
            continue
        left = (arcs[n, 2], arcs[n, 3], arcs[n, 4])
        right = (arcs[n, 5], arcs[n, 6], arcs[n, 7])
        b = 0.5 * (lo + hi)
        px, py, pz, _, _, _ = _point(ring, b)
        g, mx, my, mz, _ = solid_depth(px, py, pz, shapes, s)
        evals += 1
        if g > g_best:
            b_best, g_best, bmx, bmy, bmz = b, g, mx, my, mz
        cut = _cut(ring, b, g, mx, my, mz)
        for half in range(2):
            if n >= STACK:
                break
            if half == 0:
                a_lo, a_hi = lo, b
                cuts = (left[0], left[1], left[2], cut[0], cut[1], cut[2])
            else:
                a_lo, a_hi = b, hi
                cuts = (cut[0], cut[1], cut[2], right[0], right[1], right[2])
            bound = _arc_bound(a_lo, a_hi, cuts)
            if bound > g_best + TOL:
                arcs[n, 0] = a_lo
                arcs[n, 1] = a_hi
                arcs[n, 2:8] = cuts
                arcs[n, 8] = bound
                n += 1
    return b_best, g_best, bmx, bmy, bmz


@compiled
def ring_deepest(ring: Ring, shapes: np.ndarray, s: int):
    """The deepest point of the circle ``ring`` in the convex shape ``s``, certified.

    Returns ``(angle, depth, mx, my, mz)``: the angle on the circle, the depth
    there (m, within :data:`TOL` of the circle's maximum) and the contact
    normal there: the solid's outward normal, or on a crease the blend of
    its two faces' normals whose slope along the ring is zero
    (:func:`_crease_normal`).
    """
    b, g, mx, my, mz = _search(ring, shapes, s)
    return _crease_normal(ring, b, g, mx, my, mz, shapes, s)


@compiled
def _crease_normal(
    ring: Ring, b: float, g: float, mx: float, my: float, mz: float, shapes: np.ndarray, s: int
):
    """The contact normal at the deepest point ``b``: on a crease, the blend of two faces.

    Inside a box or a finite cylinder the deepest point of a ring often sits
    on a crease (two faces, or the side and a cap, equally near: the maximum
    of the lower of two sinusoids), where the solid's own normal flips from
    one face to the other. The contact normal there is the blend
    ``lam m_i + (1 - lam) m_j`` whose slope along the ring is zero (the
    supergradient that certifies the maximum), left unnormalised: it is the
    gradient of the ring's depth with respect to the vehicle's motion, of
    length between ``cos(half the faces' angle)`` and 1, so that
    ``delta_dot = -v . n`` is the depth's exact rate and the elastic force
    ``k delta^n n`` does exactly the work of its energy. It tends to ``m_i``
    or ``m_j`` where the maximum leaves the crease, so the force's direction
    is continuous too. Elsewhere: ``m`` unchanged (unit).
    """
    n_pieces = _crease_pieces(g, shapes, s)
    if n_pieces == 0:
        return b, g, mx, my, mz
    px, py, pz, tx, ty, tz = _point(ring, b)
    _, _, _, _, k = solid_depth(px, py, pz, shapes, s)
    nx, ny, nz = _crease_blend((px, py, pz, tx, ty, tz), k, n_pieces, g, (mx, my, mz), shapes, s)
    return b, g, nx, ny, nz


@njit(cache=True, inline="always")
def _crease_pieces(g: float, shapes: np.ndarray, s: int) -> int:
    """How many pieces the depth of shape ``s`` has where a ring is ``g`` deep (0: no crease
    to look for: out of contact, or an infinite cylinder, whose depth is smooth)."""
    if g <= 0.0:
        return 0
    kind = int(shapes[s, SH_KIND])
    if kind == SHAPE_BOX:
        return 6
    if kind == SHAPE_CYLINDER and shapes[s, SH_LENGTH] < math.inf:
        return 3
    return 0


@compiled
def _crease_blend(
    pt: tuple[float, float, float, float, float, float],
    k: int,
    n_pieces: int,
    g: float,
    m: tuple[float, float, float],
    shapes: np.ndarray,
    s: int,
) -> tuple[float, float, float]:
    """:func:`_crease_normal`'s normal at the deepest point ``pt = (p, t)`` (its tangent
    ``t``, its piece ``k``), the solid's normal there ``m``."""
    px, py, pz, tx, ty, tz = pt
    mx, my, mz = m
    j = -1
    vj = math.inf
    for i in range(n_pieces):
        if i == k:
            continue
        v = solid_piece(px, py, pz, shapes, s, i)[0]
        if v < vj:
            vj = v
            j = i
    if j < 0 or vj > g + CREASE_TOL:
        return mx, my, mz
    _, nkx, nky, nkz = solid_piece(px, py, pz, shapes, s, k)
    _, njx, njy, njz = solid_piece(px, py, pz, shapes, s, j)
    sk = -(nkx * tx + nky * ty + nkz * tz)
    sj = -(njx * tx + njy * ty + njz * tz)
    if sk * sj > 0.0:
        return mx, my, mz
    lam = 0.5 if sk == sj else sj / (sj - sk)
    return (
        lam * nkx + (1.0 - lam) * njx,
        lam * nky + (1.0 - lam) * njy,
        lam * nkz + (1.0 - lam) * njz,
    )


@compiled
def _search(ring: Ring, shapes: np.ndarray, s: int):
    """The certified deepest point: local secant search, then branch and bound if needed."""
    cx, cy, cz, ax, ay, az, bx, by, bz, r = ring
    _, mx, my, mz, _ = solid_depth(cx, cy, cz, shapes, s)
    wa = -(mx * ax + my * ay + mz * az)
    wb = -(mx * bx + my * by + mz * bz)
    b = math.atan2(wb, wa)
    b_prev = 0.0
    fp_prev = 0.0
    k_prev = -2
    best = (b, -math.inf, mx, my, mz)
    for it in range(MAX_LOCAL):
        px, py, pz, tx, ty, tz = _point(ring, b)
        g, mx, my, mz, k = solid_depth(px, py, pz, shapes, s)
        if g > best[1]:
            best = (b, g, mx, my, mz)
        if _excess(ring, b, -mx, -my, -mz) <= TOL:
            return b, g, mx, my, mz
        fp = -(mx * tx + my * ty + mz * tz)
        if it > 0 and k != k_prev and k >= 0 and k_prev >= 0 and fp * fp_prev < 0.0:
            ok, bk, gk, kx, ky, kz = _crease(ring, b_prev, k_prev, b, k, shapes, s)
            if ok:
                return bk, gk, kx, ky, kz
            if gk > best[1]:
                best = (bk, gk, kx, ky, kz)
        if it > 0 and fp != fp_prev:
            step = -fp * (b - b_prev) / (fp - fp_prev)
        else:
            target = math.atan2(-(mx * bx + my * by + mz * bz), -(mx * ax + my * ay + mz * az))
            step = (target - b + math.pi) % TWO_PI - math.pi
        step = max(-1.0, min(1.0, step))
        b_prev = b
        fp_prev = fp
        k_prev = k
        b = b + step
    if int(shapes[s, SH_KIND]) == SHAPE_BOX:
        # the exact solution (ring_box.py); never below a point already seen
        ok, bx_, gx, kx, ky, kz = ring_box_exact(ring, shapes, s)
        if ok and gx >= best[1]:
            return bx_, gx, kx, ky, kz
        if ok and gx >= best[1] - TOL:
            return best
    if int(shapes[s, SH_KIND]) == SHAPE_CYLINDER and not shapes[s, SH_LENGTH] < math.inf:
        # a ring around a pole: every stationary point of the distance from the axis
        ok, ba, ga, ax_, ay_, az_ = _ring_around_axis(ring, shapes, s)
        if ok and ga >= best[1] - TOL:
            return ba, ga, ax_, ay_, az_
    return _polish(ring, shapes, s, _branch_and_bound(ring, shapes, s, best))


@compiled
def _ring_around_axis(ring: Ring, shapes: np.ndarray, s: int):
    """The deepest point of a circle in the infinite cylinder ``s``, from all candidates.

    The squared distance of the circle's point ``P(b)`` from the axis is a
    trigonometric polynomial of degree 2, ``D(b) = D0 + al cos b + be sin b
    + ga cos 2b + de sin 2b``; its stationary points are the roots on the unit
    circle of a quartic in ``z = exp(i b)``, all four found by the
    Durand-Kerner iteration and each polished by Newton steps on ``D'(b)``.
    The deepest point is the one with the least ``D``: the maximum to
    rounding, a pure function of the pose (no sampled angle). Returns
    ``(ok, angle, depth, normal)``; ``ok`` false: a degenerate quartic (the
    circle's projection across the axis a circle), left to the branch and bound.
    """
    cx, cy, cz, ax, ay, az, bx, by, bz, r = ring
    ex = shapes[s, SH_NORMAL]
    ey = shapes[s, SH_NORMAL + 1]
    ez = shapes[s, SH_NORMAL + 2]
    dx = cx - shapes[s, SH_POINT]
    dy = cy - shapes[s, SH_POINT + 1]
    dz = cz - shapes[s, SH_POINT + 2]
    t = dx * ex + dy * ey + dz * ez
    dx, dy, dz = dx - t * ex, dy - t * ey, dz - t * ez
    t = ax * ex + ay * ey + az * ez
    ux, uy, uz = ax - t * ex, ay - t * ey, az - t * ez
    t = bx * ex + by * ey + bz * ez
    vx, vy, vz = bx - t * ex, by - t * ey, bz - t * ez
    du = dx * ux + dy * uy + dz * uz
    dv = dx * vx + dy * vy + dz * vz
    uu = ux * ux + uy * uy + uz * uz
    vv = vx * vx + vy * vy + vz * vz
    uv = ux * vx + uy * vy + uz * vz
    al = 2.0 * r * du
    be = 2.0 * r * dv
    ga = 0.5 * r * r * (uu - vv)
    de = r * r * uv
    # 2 z^2 D'(b) = c4 z^4 + c3 z^3 + c1 z + c0
    c4 = complex(2.0 * de, 2.0 * ga)
    c3 = complex(be, al)
    c1 = complex(be, -al)
    c0 = complex(2.0 * de, -2.0 * ga)
    if not abs(c4) > 1e-9 * (abs(c3) + abs(c0)):
        return False, 0.0, 0.0, 0.0, 0.0, 0.0
    p3 = c3 / c4
    p1 = c1 / c4
    p0 = c0 / c4
    seed = complex(0.4, 0.9)
    z1 = complex(1.0, 0.0)
    z2 = seed
    z3 = seed * seed
    z4 = z3 * seed
    for _ in range(200):
        f = (((z1 + p3) * z1) * z1 + p1) * z1 + p0
        n1 = f / ((z1 - z2) * (z1 - z3) * (z1 - z4))
        z1 = z1 - n1
        f = (((z2 + p3) * z2) * z2 + p1) * z2 + p0
        n2 = f / ((z2 - z1) * (z2 - z3) * (z2 - z4))
        z2 = z2 - n2
        f = (((z3 + p3) * z3) * z3 + p1) * z3 + p0
        n3 = f / ((z3 - z1) * (z3 - z2) * (z3 - z4))
        z3 = z3 - n3
        f = (((z4 + p3) * z4) * z4 + p1) * z4 + p0
        n4 = f / ((z4 - z1) * (z4 - z2) * (z4 - z3))
        z4 = z4 - n4
        if max(abs(n1), abs(n2), abs(n3), abs(n4)) <= 1e-15:
            break
    d_best = math.inf
    b_best = 0.0
    for k in range(4):
        z = z1 if k == 0 else (z2 if k == 1 else (z3 if k == 2 else z4))
        if not (abs(z.real) < math.inf and abs(z.imag) < math.inf):
            return False, 0.0, 0.0, 0.0, 0.0, 0.0
        b = math.atan2(z.imag, z.real)
        for _ in range(4):
            c = math.cos(b)
            sn = math.sin(b)
            c2 = c * c - sn * sn
            s2 = 2.0 * sn * c
            d1 = -al * sn + be * c - 2.0 * ga * s2 + 2.0 * de * c2
            d2 = -al * c - be * sn - 4.0 * ga * c2 - 4.0 * de * s2
            if d2 == 0.0:
                break
            step = d1 / d2
            if abs(step) > 0.1:
                break
            b -= step
        c = math.cos(b)
        sn = math.sin(b)
        wx = dx + r * (c * ux + sn * vx)
        wy = dy + r * (c * uy + sn * vy)
        wz = dz + r * (c * uz + sn * vz)
        dd = wx * wx + wy * wy + wz * wz
        if dd < d_best:
            d_best = dd
            b_best = b
    px, py, pz, _, _, _ = _point(ring, b_best)
    g, mx, my, mz, _ = solid_depth(px, py, pz, shapes, s)
    return True, b_best, g, mx, my, mz


@compiled
def _polish(ring: Ring, shapes: np.ndarray, s: int, best: tuple):
    """The branch and bound's best angle refined to the stationary point of its piece's depth.

    The branch and bound returns the best of the angles it sampled: its depth
    is within :data:`TOL` of the maximum, but the angle only within about
    ``sqrt(TOL / R)`` (1e-6 rad), and which sampled angle wins changes from one
    state to the next. That made the contact point (and so the contact
    moment) jump by up to a micrometre between evaluations, a discontinuous
    right-hand side that held the integrator to sub-microsecond steps (a ring
    around a pole: docs/NUMERICS.md, "Pathological trials"). Secant steps on
    ``dg/db`` on the same piece of the solid move the angle to the maximum to
    rounding; kept only if they stay on that piece, near the angle, and no
    shallower than ``TOL`` below it (else the branch and bound's point).
    """
    b0, g0, _, _, _ = best
    px, py, pz, tx, ty, tz = _point(ring, b0)
    g, mx, my, mz, k = solid_depth(px, py, pz, shapes, s)
    fp_prev = -(mx * tx + my * ty + mz * tz)
    b_prev = b0
    b = b0 + (POLISH_STEP if fp_prev > 0.0 else -POLISH_STEP)
    for _ in range(POLISH_ITERS):
        px, py, pz, tx, ty, tz = _point(ring, b)
        g, mx, my, mz, kb = solid_depth(px, py, pz, shapes, s)
        if kb != k:
            return best
        fp = -(mx * tx + my * ty + mz * tz)
        if fp == fp_prev:
            break
        step = -fp * (b - b_prev) / (fp - fp_prev)
        b_prev = b
        fp_prev = fp
        b += step
        if abs(b - b0) > POLISH_REACH:
            return best
        if abs(step) <= 4e-16 * (1.0 + abs(b)):
            break
    px, py, pz, _, _, _ = _point(ring, b)
    g, mx, my, mz, kb = solid_depth(px, py, pz, shapes, s)
    if kb != k or not g >= g0 - TOL:
        return best
    return b, g, mx, my, mz


@compiled
def _crease_twin(
    ring: Ring, b: float, g: float, shapes: np.ndarray, s: int
) -> tuple[float, float, float, float, float, float, float]:
    """The other crossing of the circle with the box crease its deepest point ``b`` sits on.

    A ring across an edge of a box (two adjacent faces) crosses the edge's crease twice; when both
    crossings are local maxima equally deep (a hoop leaning on an edge), the
    deepest point jumps from one to the other at every evaluation, and so
    does the contact moment: the integrator then chatters between them. The
    two crossings within :data:`TWIN_BAND` in depth share the contact: the
    returned weight ``w`` (0 to 1/2, a C1 ramp of the depth difference; 0
    beyond the band) goes to the twin. Returns ``(w, point, normal)``, the
    twin's point (inertial) and its certifying normal (as
    :func:`_crease_normal`'s); ``w = 0``: no twin.
    """
    px, py, pz, _, _, _ = _point(ring, b)
    _, _, _, _, k = solid_depth(px, py, pz, shapes, s)
    return _crease_twin_at(ring, b, g, px, py, pz, k, shapes, s)


@compiled
def _crease_twin_at(
    ring: Ring,
    b: float,
    g: float,
    px: float,
    py: float,
    pz: float,
    k: int,
    shapes: np.ndarray,
    s: int,
) -> tuple[float, float, float, float, float, float, float]:
    """:func:`_crease_twin` with the deepest point ``p = P(b)`` and its piece ``k`` given."""
    none = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    if k < 0:
        return none
    j = -1
    vj = math.inf
    for i in range(6):
        if i != k:
            v = box_piece(px, py, pz, shapes, s, i)[0]
            if v < vj:
                vj = v
                j = i
    if j < 0 or vj > g + CREASE_TOL or j // 2 == k // 2:
        return none  # no crease, or two opposite faces (a ring through a slab): not an edge
    # the faces' depths are affine in the point: their difference on the circle is
    # c0 + A cos + B sin, zero at b and at the twin
    cx, cy, cz, ax, ay, az, bx, by, bz, r = ring
    vk, nkx, nky, nkz = box_piece(cx, cy, cz, shapes, s, k)
    vj, njx, njy, njz = box_piece(cx, cy, cz, shapes, s, j)
    c0 = vk - vj
    dx = njx - nkx
    dy = njy - nky
    dz = njz - nkz
    a_ = r * (dx * ax + dy * ay + dz * az)
    b_ = r * (dx * bx + dy * by + dz * bz)
    amp = math.sqrt(a_ * a_ + b_ * b_)
    if not amp > abs(c0):
        return none
    phi = math.atan2(b_, a_)
    half = math.acos(-c0 / amp)
    b1 = phi + half
    b2 = phi - half
    d1 = abs((b1 - b + math.pi) % TWO_PI - math.pi)
    d2 = abs((b2 - b + math.pi) % TWO_PI - math.pi)
    bt = b1 if d1 > d2 else b2
    qx, qy, qz, tx, ty, tz = _point(ring, bt)
    gt, _, _, _, _ = solid_depth(qx, qy, qz, shapes, s)
    if not gt > g - TWIN_BAND or gt <= 0.0:
        return none
    vk, nkx, nky, nkz = box_piece(qx, qy, qz, shapes, s, k)
    vj, njx, njy, njz = box_piece(qx, qy, qz, shapes, s, j)
    if abs(gt - min(vk, vj)) > CREASE_TOL:
        return none  # another face is nearer there: not the same crease
    sk = -(nkx * tx + nky * ty + nkz * tz)
    sj = -(njx * tx + njy * ty + njz * tz)
    if sk * sj > 0.0:
        return none  # not a local maximum of the depth on the circle
    lam = 0.5 if sk == sj else sj / (sj - sk)
    u = min(1.0, max(-1.0, (gt - g) / TWIN_BAND))
    w = 0.5 + 0.75 * u - 0.25 * u * u * u
    return (
        w,
        qx,
        qy,
        qz,
        lam * nkx + (1.0 - lam) * njx,
        lam * nky + (1.0 - lam) * njy,
        lam * nkz + (1.0 - lam) * njz,
    )


@njit(cache=True, inline="always")
def ring_frame(x: np.ndarray, C: np.ndarray, feat: np.ndarray, f: int) -> Ring:
    """Ring feature ``f`` in inertial components: centre, two in-plane axes, radius.

    The in-plane axes are fixed in the body (the normal crossed with its
    least aligned body axis, and the normal crossed with that).
    """
    nb0 = feat[f, F_NORMAL]
    nb1 = feat[f, F_NORMAL + 1]
    nb2 = feat[f, F_NORMAL + 2]
    a0 = abs(nb0)
    a1 = abs(nb1)
    a2 = abs(nb2)
    if a0 <= a1 and a0 <= a2:
        u0, u1, u2 = 0.0, nb2, -nb1
    elif a1 <= a2:
        u0, u1, u2 = -nb2, 0.0, nb0
    else:
        u0, u1, u2 = nb1, -nb0, 0.0
    un = math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    u0 /= un
    u1 /= un
    u2 /= un
    v0 = nb1 * u2 - nb2 * u1
    v1 = nb2 * u0 - nb0 * u2
    v2 = nb0 * u1 - nb1 * u0
    cb0 = feat[f, F_CENTRE]
    cb1 = feat[f, F_CENTRE + 1]
    cb2 = feat[f, F_CENTRE + 2]
    return (
        x[X_POS] + C[0, 0] * cb0 + C[0, 1] * cb1 + C[0, 2] * cb2,
        x[X_POS + 1] + C[1, 0] * cb0 + C[1, 1] * cb1 + C[1, 2] * cb2,
        x[X_POS + 2] + C[2, 0] * cb0 + C[2, 1] * cb1 + C[2, 2] * cb2,
        C[0, 0] * u0 + C[0, 1] * u1 + C[0, 2] * u2,
        C[1, 0] * u0 + C[1, 1] * u1 + C[1, 2] * u2,
        C[2, 0] * u0 + C[2, 1] * u1 + C[2, 2] * u2,
        C[0, 0] * v0 + C[0, 1] * v1 + C[0, 2] * v2,
        C[1, 0] * v0 + C[1, 1] * v1 + C[1, 2] * v2,
        C[2, 0] * v0 + C[2, 1] * v1 + C[2, 2] * v2,
        feat[f, F_RADIUS],
    )


@compiled
def ring_solid(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, f: int, shapes: np.ndarray, s: int
) -> ContactRecord:
    """Ring feature ``f`` against the cylinder or box ``s``: the certified deepest point."""
    ring = ring_frame(x, C, feat, f)
    b, g, mx, my, mz = _search(ring, shapes, s)
    px, py, pz, tx, ty, tz = _point(ring, b)
    n_pieces = _crease_pieces(g, shapes, s)
    k = -1
    if n_pieces > 0:  # ring_deepest's normal, and the crease's twin, from this one point
        _, _, _, _, k = solid_depth(px, py, pz, shapes, s)
        pt = (px, py, pz, tx, ty, tz)
        mx, my, mz = _crease_blend(pt, k, n_pieces, g, (mx, my, mz), shapes, s)
    if n_pieces == 6:  # a box
        w, qx, qy, qz, nx, ny, nz = _crease_twin_at(ring, b, g, px, py, pz, k, shapes, s)
        if w > 0.0:
            px += w * (qx - px)
            py += w * (qy - py)
            pz += w * (qz - pz)
            mx += w * (nx - mx)
            my += w * (ny - my)
            mz += w * (nz - mz)
    return material_record(x, C, g, px - x[X_POS], py - x[X_POS + 1], pz - x[X_POS + 2], mx, my, mz)


@compiled
def ring_solid_bound(
    x: np.ndarray, C: np.ndarray, feat: np.ndarray, f: int, shapes: np.ndarray, s: int
) -> tuple[float, float]:
    """Certified bounds on ring ``f``'s record against the cylinder or box ``s``: the broad phase.

    Every point of the circle lies within ``R`` of its centre ``c`` and the
    solid's point depth is 1-Lipschitz, so the depth :func:`ring_solid`
    returns (the depth of a point of the circle) is at most ``g(c) + R``;
    its rate ``-v_P . n`` (``|n| <= 1``) is at most the largest speed of a
    point of the ring, ``|v| + |omega| (|c_b| + R)``. Returns ``(depth bound
    (m), rate bound (m/s))``, each with a margin for rounding
    (:data:`BOUND_MARGIN`, :data:`RATE_MARGIN`): one point depth, against
    :func:`ring_solid`'s three to six and its contact point's velocity.
    """
    cb0 = feat[f, F_CENTRE]
    cb1 = feat[f, F_CENTRE + 1]
    cb2 = feat[f, F_CENTRE + 2]
    cx = x[X_POS] + C[0, 0] * cb0 + C[0, 1] * cb1 + C[0, 2] * cb2
    cy = x[X_POS + 1] + C[1, 0] * cb0 + C[1, 1] * cb1 + C[1, 2] * cb2
    cz = x[X_POS + 2] + C[2, 0] * cb0 + C[2, 1] * cb1 + C[2, 2] * cb2
    r = feat[f, F_RADIUS]
    g = solid_depth(cx, cy, cz, shapes, s)[0]
    u = x[X_VEL]
    v = x[X_VEL + 1]
    w = x[X_VEL + 2]
    p = x[X_OMEGA]
    q = x[X_OMEGA + 1]
    rr = x[X_OMEGA + 2]
    reach = math.sqrt(cb0 * cb0 + cb1 * cb1 + cb2 * cb2) + r
    speed = math.sqrt(u * u + v * v + w * w) + math.sqrt(p * p + q * q + rr * rr) * reach
    return g + r + BOUND_MARGIN, speed * (1.0 + RATE_MARGIN)
