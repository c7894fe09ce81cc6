"""Event functions and their location on the integrator's dense output.

Events of a run (docs/NUMERICS.md):

* ``EV_GAP``: the contact gap of one bumper-surface pair crosses 0 (contact
  onset upward, contact end downward): the penetration ``delta``, or with the
  recovery replica's gate ``min(delta, gate - d_CM)`` (``contact.contact_gap``);
* ``EV_RATE``: ``delta_dot`` of an active contact crosses 0 downward (the
  peak deflection of the episode: located, not sampled);
* ``EV_ALTITUDE``: the CM altitude ``h = -Z`` crosses the crash level.

Roots are found on the dense output of the accepted step with the Illinois
variant of regula falsi, bracketing all along, to ``EVENT_TOL`` in time.
"""

import numpy as np
from numba import njit

from .contact import contact_gap
from .geometry import bumper_depth
from .integrator import dense_eval
from .layout import X_POS, X_QUAT
from .quaternion import rotation_matrix

EV_GAP = 0
EV_RATE = 1
EV_ALTITUDE = 2
NO_EVENT = 2.0  # "no event in this step" (fractions of a step are in [0, 1])
NEAR_GRAZE_SAMPLES = 3  # interior dense-output checks of near-grazing contacts


@njit(cache=True)
def event_value(
    kind: int,
    c: int,
    xs: np.ndarray,
    C: np.ndarray,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    level: float,
) -> float:
    """Value of event function ``kind`` for contact ``c = 4 s + j`` at state ``xs``."""
    if kind == EV_ALTITUDE:
        return -xs[X_POS + 2] - level
    rotation_matrix(xs[X_QUAT : X_QUAT + 4], C)
    d, dd = bumper_depth(xs, C, veh, c % 4, surf, c // 4)
    if kind == EV_GAP:
        return contact_gap(xs, d, surf, c // 4, opts)
    return dd


@njit(cache=True)
def locate(
    kind: int,
    c: int,
    x_old: np.ndarray,
    Q: np.ndarray,
    h: float,
    ga: float,
    gb: float,
    sb: float,
    tol: float,
    xs: np.ndarray,
    C: np.ndarray,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    level: float,
) -> float:
    """Root of an event function on ``[0, sb]`` (fractions of the step ``h``).

    ``ga`` is its value at 0 and ``gb`` at ``sb``, of opposite "sides"
    (``ga <= 0 < gb`` or ``ga > 0 >= gb``). Returns the fraction of the step at
    the root, on the side where the event has happened (the sign of ``gb``),
    within ``tol`` seconds.
    """
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
        dense_eval(x_old, Q, h, s, xs)
        fs = event_value(kind, c, xs, C, veh, surf, opts, level)
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


@njit(cache=True)
def contact_event(
    c: int,
    active: bool,
    ga: float,
    gb: float,
    gda: float,
    gdb: float,
    x_old: np.ndarray,
    Q: np.ndarray,
    h: float,
    tol: float,
    xs: np.ndarray,
    C: np.ndarray,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
) -> float:
    """Fraction of the step at which contact ``c`` begins or ends (``NO_EVENT``: neither).

    ``ga``/``gb`` are its gap at the step's start and end, ``gda``/``gdb``
    the penetration rates there. An inactive contact begins where ``delta`` rises through 0;
    if both ends are negative but within the distance the contact point can
    travel in the step, the dense output is also sampled inside the step so that
    a graze is not stepped over. An active contact ends where ``delta`` falls
    through 0 (at once if it never penetrated after its onset).
    """
    if not active:
        if gb > 0.0:
            return locate(EV_GAP, c, x_old, Q, h, ga, gb, 1.0, tol, xs, C, veh, surf, opts, 0.0)
        band = h * (abs(gda) + abs(gdb))
        if -ga < band or -gb < band:
            for m in range(1, NEAR_GRAZE_SAMPLES + 1):
                sm = m / (NEAR_GRAZE_SAMPLES + 1.0)
                dense_eval(x_old, Q, h, sm, xs)
                gm = event_value(EV_GAP, c, xs, C, veh, surf, opts, 0.0)
                if gm > 0.0:
                    return locate(
                        EV_GAP, c, x_old, Q, h, ga, gm, sm, tol, xs, C, veh, surf, opts, 0.0
                    )
        return NO_EVENT
    if gb > 0.0:
        return NO_EVENT
    if ga > 0.0:
        return locate(EV_GAP, c, x_old, Q, h, ga, gb, 1.0, tol, xs, C, veh, surf, opts, 0.0)
    return 0.0  # touched and left at once (a graze)
