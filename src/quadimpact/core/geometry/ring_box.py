"""A ring against a box: the circle's deepest point from the box's pieces, in closed form.

``ring.ring_deepest`` certifies most ring records against a box with its
local search; the rest (a corner of the box pointing into the ring's disk,
an edge through it: about 3 % of the records of a box-corner trial) used to
take the branch and bound, some 100 times the cost. This module solves those
exactly instead, from the structure of a box's depth along a circle.

In the box's coordinates the circle is ``q_i(b) = Q_i + U_i cos b + V_i sin b``
(``i`` = 0, 1, 2), three sinusoids of the angle ``b``, and the depth of a
point (``box.box_depth``) is

* inside, ``F = min_i (h_i - |q_i|)``: the lower envelope of six sinusoids
  (the faces' depths ``h_i -+ q_i``);
* outside, ``-sqrt(D)`` with ``D = sum_i max(0, |q_i| - h_i)^2``: on every arc
  of the circle where the set of violated faces is fixed, ``D`` is the
  squared distance to a face's plane (one violated: a sinusoid squared), to
  an edge's line (two: the squared distance from a point to an ellipse, the
  circle's projection across the edge) or to a vertex (three: a sinusoid).

Everywhere ``depth <= F`` (the largest face violation is at most the
distance), with equality inside. So:

1. **Some point inside** (``max F >= 0``): the circle's maximum is ``max F``,
   attained where one face's sinusoid peaks or two cross (the maximum of a
   lower envelope): 6 peaks and the crossings of the 15 pairs, each in
   closed form (``A cos b + B sin b = C``, no trigonometry).
2. **Every point outside** (``max F < 0``): the maximum is at a breakpoint
   (``q_i = +-h_i``, closed form) or at a stationary point of the arc's
   ``D``: a sinusoid's trough for a face or a vertex; for an edge the
   stationary points of ``|w0 + W z|^2`` on the unit circle ``|z| = 1``,
   ``(M - mu I) z = -m`` with ``M = W^T W``, ``m = W^T w0``: in the
   eigenbasis of ``M`` (``lam1 <= lam2``, ``m = (c1, c2)``) the secular
   equation ``c1^2/(lam1 - mu)^2 + c2^2/(lam2 - mu)^2 = 1`` has its one root
   below ``lam1`` (the global minimum of the edge's distance) and, when the
   minimum of that convex function on ``(lam1, lam2)`` (at ``mu_m``, closed
   form) is negative, two roots there (a local minimum and a local
   maximum); each is found by bracketed Newton on a monotone piece.

Every candidate (a point of the circle) is then evaluated with the box's
own depth, and the deepest is returned: the exact maximum up to rounding
(no tolerance, no iteration count to tune), a pure function of the pose.
Extra candidates cost an evaluation and cannot change the answer, so the
degenerate cases (a repeated eigenvalue, ``c1`` or ``c2`` zero: the
secular equation's hard case) add both signs of the ill-conditioned
component and the eigenvectors ``+-v1``, ``+-v2``.
Cost: about 1 to 3 microseconds, against 10 to 30 for the branch and bound.
"""

import math

import numpy as np
from numba import njit

from quadimpact.core.compiled import allocating, compiled
from quadimpact.core.geometry.box import box_depth
from quadimpact.core.shape_slots import (
    SH_HALF,
    SH_POINT,
    SH_ROT,
)

MAX_CANDIDATES = 160
HARD = 1e-6  # relative size of c1, c2 or lam2 - lam1 below which both signs are tried
TWO_PI = 2.0 * math.pi


@njit(cache=True, inline="always")
def _crossings(a: float, b: float, c: float):
    """The points ``(cos t, sin t)`` of the unit circle where ``a cos t + b sin t = c``."""
    a2 = a * a + b * b
    if a2 == 0.0:
        return 0, 0.0, 0.0, 0.0, 0.0
    disc = a2 - c * c
    if disc < 0.0:
        return 0, 0.0, 0.0, 0.0, 0.0
    r = math.sqrt(disc)
    return (
        2,
        (a * c - b * r) / a2,
        (b * c + a * r) / a2,
        (a * c + b * r) / a2,
        (b * c - a * r) / a2,
    )


@njit(cache=True, inline="always")
def _add(cand: np.ndarray, n: int, z1: float, z2: float) -> int:
    """Append the circle's point ``z / |z|`` (``z`` = (cos, sin)) to the candidates."""
    norm = math.sqrt(z1 * z1 + z2 * z2)
    if n < cand.shape[0] and norm > 0.0 and math.isfinite(norm):
        cand[n, 0] = z1 / norm
        cand[n, 1] = z2 / norm
        n += 1
    return n


@njit(cache=True, inline="always")
def _psi(mu: float, l1: float, l2: float, c1: float, c2: float) -> float:
    """The secular function ``c1^2/(l1 - mu)^2 + c2^2/(l2 - mu)^2 - 1`` (inf at a pole)."""
    f = -1.0
    d1 = l1 - mu
    d2 = l2 - mu
    if c1 != 0.0:
        if d1 == 0.0:
            return math.inf
        f += (c1 / d1) ** 2
    if c2 != 0.0:
        if d2 == 0.0:
            return math.inf
        f += (c2 / d2) ** 2
    return f


@njit(cache=True, inline="always")
def _inv_norm(mu: float, l1: float, l2: float, c1: float, c2: float):
    """``w = 1/|z(mu)|`` (0 at a pole) and its derivative: nearly linear near the poles."""
    d1 = l1 - mu
    d2 = l2 - mu
    if (c1 != 0.0 and d1 == 0.0) or (c2 != 0.0 and d2 == 0.0):
        return 0.0, 0.0
    s = 0.0
    ds = 0.0
    if c1 != 0.0:
        t = c1 / d1
        s += t * t
        ds += 2.0 * t * t / d1
    if c2 != 0.0:
        t = c2 / d2
        s += t * t
        ds += 2.0 * t * t / d2
    if s == 0.0:
        return math.inf, 0.0
    w = 1.0 / math.sqrt(s)
    return w, -0.5 * w * ds / s


@compiled
def _secular_root(l1, l2, c1, c2, lo, hi, increasing, mu):
    """The root of ``|z(mu)| = 1`` on ``[lo, hi]`` (``|z|`` monotone there), from ``mu``.

    Newton on ``1 - 1/|z|`` (nearly linear near a pole; concave below
    ``lam1``, where a start on the pole's side converges monotonically),
    bracketed by bisection.
    """
    if not (lo < mu < hi):
        mu = 0.5 * (lo + hi)
    for _ in range(200):
        w, dw = _inv_norm(mu, l1, l2, c1, c2)
        f = 1.0 - w  # psi > 0 <=> |z| > 1 <=> w < 1
        if f == 0.0:
            return mu
        if (f > 0.0) == increasing:
            hi = mu
        else:
            lo = mu
        nxt = mu + f / dw if dw != 0.0 and math.isfinite(w) else 0.5 * (lo + hi)
        if not (lo < nxt < hi):
            nxt = 0.5 * (lo + hi)
        scale = max(abs(lo), abs(hi))
        if abs(nxt - mu) <= 1e-15 * scale or hi - lo <= 4.5e-16 * scale:
            return nxt
        mu = nxt
    return mu


@njit(cache=True, inline="always")
def _root_candidates(cand, n, mu, eig, hard) -> int:
    """The circle's point of the stationary condition at ``mu``: the component with the
    larger ``|lam - mu|`` directly, the other from ``|z| = 1`` (both signs if ``hard``).

    ``eig = (l1, l2, c1, c2, v1x, v1y, v2x, v2y)``: the eigenvalues, the gradient's
    components along the eigenvectors and the eigenvectors.
    """
    l1, l2, c1, c2, v1x, v1y, v2x, v2y = eig
    d1 = l1 - mu
    d2 = l2 - mu
    if abs(d2) >= abs(d1):
        if d2 == 0.0:
            return n
        y2 = -c2 / d2
        y1 = math.sqrt(max(0.0, 1.0 - y2 * y2))
        if d1 != 0.0 and -c1 / d1 < 0.0:
            y1 = -y1
        n = _add(cand, n, y1 * v1x + y2 * v2x, y1 * v1y + y2 * v2y)
        if hard:
            n = _add(cand, n, -y1 * v1x + y2 * v2x, -y1 * v1y + y2 * v2y)
    else:
        y1 = -c1 / d1
        y2 = math.sqrt(max(0.0, 1.0 - y1 * y1))
        if d2 != 0.0 and -c2 / d2 < 0.0:
            y2 = -y2
        n = _add(cand, n, y1 * v1x + y2 * v2x, y1 * v1y + y2 * v2y)
        if hard:
            n = _add(cand, n, y1 * v1x - y2 * v2x, y1 * v1y - y2 * v2y)
    return n


@compiled
def _edge_candidates(cand, n, a0, a1, a2, b0, b1, b2) -> int:
    """The minima of ``(a0 + a1 z1 + a2 z2)^2 + (b0 + b1 z1 + b2 z2)^2`` on ``|z| = 1``.

    Adds every stationary point of the secular equation's roots below and
    between the eigenvalues (the minima, global and local, and a local
    maximum), and ``+-v1``, ``+-v2``.
    """
    m11 = a1 * a1 + b1 * b1
    m22 = a2 * a2 + b2 * b2
    m12 = a1 * a2 + b1 * b2
    g1 = a1 * a0 + b1 * b0
    g2 = a2 * a0 + b2 * b0
    p = 0.5 * (m11 + m22)
    d = 0.5 * (m11 - m22)
    r = math.sqrt(d * d + m12 * m12)
    l1 = p - r
    l2 = p + r
    th = 0.5 * math.atan2(m12, d)
    v2x = math.cos(th)
    v2y = math.sin(th)
    v1x = -v2y
    v1y = v2x
    c1 = v1x * g1 + v1y * g2
    c2 = v2x * g1 + v2y * g2
    gm = math.sqrt(g1 * g1 + g2 * g2)
    hard = abs(c1) <= HARD * gm or abs(c2) <= HARD * gm or l2 - l1 <= HARD * (l2 + gm)
    if hard:  # the secular equation's degenerate cases: the eigenvectors as well
        n = _add(cand, n, v1x, v1y)
        n = _add(cand, n, -v1x, -v1y)
        n = _add(cand, n, v2x, v2y)
        n = _add(cand, n, -v2x, -v2y)
    # the root below l1 (the global minimum): psi rises from <= 0 at l1 - |m| to its pole
    lo = l1 - gm
    hi = l1
    if _psi(hi, l1, l2, c1, c2) <= 0.0:
        mu = hi
    elif _psi(lo, l1, l2, c1, c2) >= 0.0:
        mu = lo
    else:
        mu = _secular_root(l1, l2, c1, c2, lo, hi, True, l1 - abs(c1))
    eig = (l1, l2, c1, c2, v1x, v1y, v2x, v2y)
    n = _root_candidates(cand, n, mu, eig, hard)
    # the roots between the eigenvalues: psi is convex there, least at mu_m
    if l2 > l1 and c1 != 0.0 and c2 != 0.0:
        rho = (abs(c2) / abs(c1)) ** (2.0 / 3.0)
        mm = (l2 + rho * l1) / (1.0 + rho)
        if l1 < mm < l2 and _psi(mm, l1, l2, c1, c2) < 0.0:
            mu = _secular_root(l1, l2, c1, c2, l1, mm, False, l1 + abs(c1))
            n = _root_candidates(cand, n, mu, eig, hard)
            mu = _secular_root(l1, l2, c1, c2, mm, l2, True, l2 - abs(c2))
            n = _root_candidates(cand, n, mu, eig, hard)
    return n


@allocating
def ring_box_exact(ring, shapes: np.ndarray, s: int):
    """The deepest point of the circle ``ring`` in box ``s``: exact (see the module docstring).

    Returns ``(ok, angle, depth, mx, my, mz)``; ``ok`` is False only if no
    candidate came out (a degenerate input), for the caller's fallback.
    """
    cx, cy, cz, ax, ay, az, bx, by, bz, r = ring
    rx = cx - shapes[s, SH_POINT]
    ry = cy - shapes[s, SH_POINT + 1]
    rz = cz - shapes[s, SH_POINT + 2]
    q0 = np.empty(3)
    qu = np.empty(3)
    qv = np.empty(3)
    h = np.empty(3)
    for i in range(3):
        ex = shapes[s, SH_ROT + 3 * i]
        ey = shapes[s, SH_ROT + 3 * i + 1]
        ez = shapes[s, SH_ROT + 3 * i + 2]
        q0[i] = ex * rx + ey * ry + ez * rz
        qu[i] = r * (ex * ax + ey * ay + ez * az)
        qv[i] = r * (ex * bx + ey * by + ez * bz)
        h[i] = shapes[s, SH_HALF + i]
    cand = np.empty((MAX_CANDIDATES, 2))
    # 1. the lower envelope of the faces' sinusoids: peaks and pairwise crossings
    n = 0
    for i in range(3):
        n = _add(cand, n, qu[i], qv[i])
        n = _add(cand, n, -qu[i], -qv[i])
        k, c1, s1, c2, s2 = _crossings(qu[i], qv[i], -q0[i])
        if k:
            n = _add(cand, n, c1, s1)
            n = _add(cand, n, c2, s2)
        for j in range(i + 1, 3):
            for si in (-1.0, 1.0):
                for sj in (-1.0, 1.0):
                    k, c1, s1, c2, s2 = _crossings(
                        si * qu[i] - sj * qu[j],
                        si * qv[i] - sj * qv[j],
                        h[i] - h[j] - si * q0[i] + sj * q0[j],
                    )
                    if k:
                        n = _add(cand, n, c1, s1)
                        n = _add(cand, n, c2, s2)
    best_f = -math.inf
    best = -1
    for k in range(n):
        f = math.inf
        for i in range(3):
            f = min(f, h[i] - abs(q0[i] + qu[i] * cand[k, 0] + qv[i] * cand[k, 1]))
        if f > best_f:
            best_f = f
            best = k
    if best >= 0 and best_f >= 0.0:
        return _finish(ring, shapes, s, cand[best, 0], cand[best, 1])
    # 2. every point outside: breakpoints, then each arc's stationary points
    n = 0
    angles = np.empty(13)
    na = 0
    for i in range(3):
        for side in (-1.0, 1.0):
            k, c1, s1, c2, s2 = _crossings(qu[i], qv[i], side * h[i] - q0[i])
            if k:
                n = _add(cand, n, c1, s1)
                n = _add(cand, n, c2, s2)
                angles[na] = math.atan2(s1, c1)
                angles[na + 1] = math.atan2(s2, c2)
                na += 2
    if na == 0:
        angles[0] = 0.0
        na = 1
    angles[:na].sort()
    done = 0  # edges already solved: bit 4 (pair) + 2 (sign i) + (sign j)
    sg = np.empty(3)
    for k in range(na):
        lo = angles[k]
        hi = angles[k + 1] if k + 1 < na else angles[0] + TWO_PI
        mid = 0.5 * (lo + hi)
        cm = math.cos(mid)
        sm = math.sin(mid)
        active = 0
        for i in range(3):
            q = q0[i] + qu[i] * cm + qv[i] * sm
            sg[i] = 1.0 if q > h[i] else (-1.0 if q < -h[i] else 0.0)
            if sg[i] != 0.0:
                active += 1
        if active == 0:
            n = _add(cand, n, cm, sm)
        elif active == 1:  # a face: the trough of its violation
            for i in range(3):
                if sg[i] != 0.0:
                    n = _add(cand, n, -sg[i] * qu[i], -sg[i] * qv[i])
        elif active == 3:  # a vertex: the circle's point nearest to it
            wu = 0.0
            wv = 0.0
            for i in range(3):
                wu += (q0[i] - sg[i] * h[i]) * qu[i]
                wv += (q0[i] - sg[i] * h[i]) * qv[i]
            n = _add(cand, n, -wu, -wv)
        else:  # an edge: the secular equation
            i = 0 if sg[0] != 0.0 else 1
            j = 2 if sg[2] != 0.0 else 1
            bit = 1 << (4 * (i + j - 1) + (2 if sg[i] > 0.0 else 0) + (1 if sg[j] > 0.0 else 0))
            if done & bit:
                continue
            done |= bit
            n = _edge_candidates(
                cand,
                n,
                sg[i] * q0[i] - h[i],
                sg[i] * qu[i],
                sg[i] * qv[i],
                sg[j] * q0[j] - h[j],
                sg[j] * qu[j],
                sg[j] * qv[j],
            )
    best_g = -math.inf
    best = -1
    for k in range(n):
        px = cx + r * (cand[k, 0] * ax + cand[k, 1] * bx)
        py = cy + r * (cand[k, 0] * ay + cand[k, 1] * by)
        pz = cz + r * (cand[k, 0] * az + cand[k, 1] * bz)
        g = box_depth(px, py, pz, shapes, s)[0]
        if g > best_g:
            best_g = g
            best = k
    if best < 0:
        return False, 0.0, -math.inf, 0.0, 0.0, 0.0
    return _finish(ring, shapes, s, cand[best, 0], cand[best, 1])


@njit(cache=True, inline="always")
def _finish(ring, shapes: np.ndarray, s: int, z1: float, z2: float):
    """The record at the circle's point ``(cos b, sin b) = z``: its angle, depth and normal."""
    cx, cy, cz, ax, ay, az, bx, by, bz, r = ring
    b = math.atan2(z2, z1)
    cb = math.cos(b)
    sb = math.sin(b)
    g, mx, my, mz, _ = box_depth(
        cx + r * (cb * ax + sb * bx),
        cy + r * (cb * ay + sb * by),
        cz + r * (cb * az + sb * bz),
        shapes,
        s,
    )
    return True, b, g, mx, my, mz
