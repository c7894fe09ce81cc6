"""Event functions and their location on the integrator's dense output.

Events of a run (docs/NUMERICS.md):

* ``EV_GAP``: the contact gap of one contact pair crosses 0 (contact onset
  upward, contact end downward): the penetration ``delta``, or with the
  recovery replica's gate ``min(delta, gate - d_CM)`` (``contact.contact_gap``);
* ``EV_RATE``: ``delta_dot`` of an active contact crosses 0 downward (the
  peak deflection of the episode: located, not sampled);
* ``EV_ALTITUDE``: the CM altitude ``h = -Z`` crosses the crash level.

Roots are found on the dense output of the accepted step (the step from the
state ``d.x`` with the coefficients ``w.Q``) with the Illinois variant of
regula falsi, bracketing all along, to ``opts[O_EVENT_TOL]`` in time.
"""

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.contact import contact_gap
from quadimpact.core.contact_slots import CS_ACTIVE
from quadimpact.core.geometry import pair_depth
from quadimpact.core.integrator import dense_eval
from quadimpact.core.layout import O_EVENT_TOL, X_POS, X_QUAT
from quadimpact.core.quaternion import rotation_matrix
from quadimpact.core.records import Data, Model, Work
from quadimpact.core.rotors import active_states

EV_GAP = 0
EV_RATE = 1
EV_ALTITUDE = 2
NO_EVENT = 2.0  # "no event in this step" (fractions of a step are in [0, 1])
NEAR_GRAZE_SAMPLES = 3  # interior dense-output checks of near-grazing contacts


@compiled
def event_value(kind: int, c: int, level: float, xs: np.ndarray, C: np.ndarray, m: Model) -> float:
    """Value of event function ``kind`` for pair ``c`` (or level ``level``) at state ``xs``.

    ``C`` is work space (it receives the rotation of ``xs``).
    """
    if kind == EV_ALTITUDE:
        return -xs[X_POS + 2] - level
    rotation_matrix(xs[X_QUAT : X_QUAT + 4], C)
    d, dd = pair_depth(xs, C, m.feat, m.shapes, m.pairs, c)
    if kind == EV_GAP:
        return contact_gap(xs, d, m, c)
    return dd


@compiled
def pair_values(
    x: np.ndarray, m: Model, w: Work, g: np.ndarray, gd: np.ndarray, bnd: np.ndarray, c: int
) -> float:
    """Pair ``c``'s gap and penetration rate at ``x`` into ``g[c]``, ``gd[c]`` (``bnd[c] = 0``).

    What ``interval.contact_values`` computes for a pair without its broad
    phase, bit for bit (``w.C`` receives the rotation of ``x``). Returns the gap.
    """
    rotation_matrix(x[X_QUAT : X_QUAT + 4], w.C)
    d, dd = pair_depth(x, w.C, m.feat, m.shapes, m.pairs, c)
    g[c] = contact_gap(x, d, m, c)
    gd[c] = dd
    bnd[c] = 0.0
    return g[c]


@compiled
def locate(
    kind: int,
    c: int,
    level: float,
    m: Model,
    d: Data,
    w: Work,
    h: float,
    ga: float,
    gb: float,
    sb: float,
) -> float:
    """Root of an event function on ``[0, sb]`` (fractions of the step ``h`` from ``d.x``).

    ``ga`` is its value at 0 and ``gb`` at ``sb``, of opposite "sides"
    (``ga <= 0 < gb`` or ``ga > 0 >= gb``). Returns the fraction of the step at
    the root, on the side where the event has happened (the sign of ``gb``),
    within ``opts[O_EVENT_TOL]`` seconds.
    """
    tol = m.opts[O_EVENT_TOL]
    sa = 0.0
    side_b = gb > 0.0
    fa = ga
    fb = gb
    last = 0
    for _ in range(200):
        if (sb - sa) * h <= tol:
            break
        denom = fb - fa
        s = sb - fb * (sb - sa) / denom if denom != 0.0 else 0.5 * (sa + sb)
        if not (sa < s < sb):
            s = 0.5 * (sa + sb)
        dense_eval(d.x[: active_states(m.veh)], w.Q, h, s, w.xs)
        fs = event_value(kind, c, level, w.xs, w.C, m)
        if (fs > 0.0) == side_b:
            sb = s
            fb = fs
            if last == 1:
                fa *= 0.5
            last = 1
        else:
            sa = s
            fa = fs
            if last == -1:
                fb *= 0.5
            last = -1
    return sb


@compiled(inline="always")
def contact_event(c: int, m: Model, d: Data, w: Work, h: float) -> float:
    """Fraction of the step at which pair ``c`` begins or ends (``NO_EVENT``: neither).

    ``w.g_a[c]``/``w.g_b[c]`` are its gap at the step's start and end,
    ``w.gd_a[c]``/``w.gd_b[c]`` the penetration rates there. An inactive
    contact begins where the gap rises through 0; if both ends are negative but
    within the distance the contact point can travel in the step, the dense
    output is also sampled inside the step so that a graze is not stepped over.
    An active contact ends where the gap falls through 0 (at once if it never
    penetrated after its onset).

    A gap and rate held as the broad phase's bounds (``w.bnd_a[c]``,
    ``w.bnd_b[c]``: an upper bound on the gap, below 0, and one on the rate's
    size) decide only what they prove: no onset, and no graze within reach.
    Otherwise the values are computed (:func:`pair_values`), so every event
    is located from the same numbers as without a broad phase.
    """
    ga = w.g_a[c]
    gb = w.g_b[c]
    if d.cs[c, CS_ACTIVE] < 0.5:
        if gb > 0.0:
            if w.bnd_a[c] > 0.5:  # apart at the start by its bound: the gap itself
                ga = pair_values(d.x, m, w, w.g_a, w.gd_a, w.bnd_a, c)
            return locate(EV_GAP, c, 0.0, m, d, w, h, ga, gb, 1.0)
        band = h * (abs(w.gd_a[c]) + abs(w.gd_b[c]))
        if -ga < band or -gb < band:
            if w.bnd_a[c] > 0.5 or w.bnd_b[c] > 0.5:
                # the broad phase's bounds (gaps above, rates above in size) do not settle
                # it: the values, and the test again on them
                if w.bnd_a[c] > 0.5:
                    ga = pair_values(d.x, m, w, w.g_a, w.gd_a, w.bnd_a, c)
                if w.bnd_b[c] > 0.5:
                    gb = pair_values(w.x_new, m, w, w.g_b, w.gd_b, w.bnd_b, c)
                band = h * (abs(w.gd_a[c]) + abs(w.gd_b[c]))
                if not (-ga < band or -gb < band):
                    return NO_EVENT
            for k in range(1, NEAR_GRAZE_SAMPLES + 1):
                sm = k / (NEAR_GRAZE_SAMPLES + 1.0)
                dense_eval(d.x[: active_states(m.veh)], w.Q, h, sm, w.xs)
                gm = event_value(EV_GAP, c, 0.0, w.xs, w.C, m)
                if gm > 0.0:
                    return locate(EV_GAP, c, 0.0, m, d, w, h, ga, gm, sm)
        return NO_EVENT
    if gb > 0.0:
        return NO_EVENT
    if ga > 0.0:
        return locate(EV_GAP, c, 0.0, m, d, w, h, ga, gb, 1.0)
    return 0.0  # touched and left at once (a graze)
