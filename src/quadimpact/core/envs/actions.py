"""The learning environments' action maps: a normalised action to rotor commands.

``a`` clipped to [-1, 1]. Rotors: ``omega_j = lo + (a_j + 1) h``, ``h = (hi - lo)/2``,
with ``[lo, hi]`` the vehicle's rotor range (or ``[0, hi]``), evaluated by
:func:`affine_map` (and inverted exactly by :func:`affine_inverse`); ctbr:
collective thrust ``T = T_max (a_0 + 1)/2`` (``T_max = 4 kt hi^2``), body rate
references ``a_1..3 * rate_max`` (rad/s), then the staged controller's inner
loop ``recovery.rate_loop``. Rotor speeds in rad/s.
"""

import numpy as np

from quadimpact.core.compiled import allocating, compiled
from quadimpact.core.controller_slots import C_OMEGA_MAX, C_OMEGA_MIN
from quadimpact.core.controllers.recovery import (
    rate_loop,
)
from quadimpact.core.envs.episode_layout import (
    ACT_CTBR,
    ENV_ROTORS,
    EP_ACTION,
    EP_RATE_MAX,
    EP_ZERO_LOW,
)
from quadimpact.core.sensors.measurement_slots import MS_W_HAT
from quadimpact.core.vehicle_slots import V_KT


# ---------------------------------------------------------------- action maps
@compiled
def affine_map(a: float, lo: float, hi: float) -> float:
    """``lo + (a + 1) (hi - lo)/2`` for ``a`` in [-1, 1], rounded as finely as floats allow.

    Evaluated from the nearer end (``lo + (1 + a) h`` for ``a < -1/2``,
    ``hi - (1 - a) h`` for ``a > 1/2``) or from the middle (``m + a h``), so that
    ``1 + a`` and ``1 - a`` are exact: every float command from
    ``lo + (hi - lo)/4`` to ``hi`` is the map of some float ``a``. Below, only a
    part is (near ``a = -1`` floats are ``2^-53`` apart, which the map spreads
    over more commands than there are floats ``a``). ``a = -1`` gives ``lo`` and
    ``a = 1`` gives ``hi`` exactly.
    """
    h = 0.5 * (hi - lo)
    if a < -0.5:
        return lo + (1.0 + a) * h
    if a > 0.5:
        return hi - (1.0 - a) * h
    return (lo + h) + a * h


@compiled
def affine_inverse(w: float, lo: float, hi: float) -> tuple[float, bool]:
    """The ``a`` in [-1, 1] whose :func:`affine_map` is ``w``; False if none (the nearest then).

    Newton steps on the map, then a walk with ``nextafter`` to the exact value.
    """
    h = 0.5 * (hi - lo)
    if w <= lo:
        return -1.0, w == lo
    if w >= hi:
        return 1.0, w == hi
    a = min(max((w - lo) / h - 1.0, -1.0), 1.0)
    for _ in range(3):
        a = min(max(a + (w - affine_map(a, lo, hi)) / h, -1.0), 1.0)
    best = a
    best_err = abs(affine_map(a, lo, hi) - w)
    for _ in range(64):
        m = affine_map(a, lo, hi)
        if m == w:
            return a, True
        err = abs(m - w)
        if err < best_err:
            best = a
            best_err = err
        a = np.nextafter(a, 2.0) if m < w else np.nextafter(a, -2.0)
        if a < -1.0 or a > 1.0:
            break
    return best, False


@compiled
def rotor_range(ctrl: np.ndarray, par: np.ndarray) -> tuple[float, float]:
    """The rotor-speed range (rad/s) that rotor actions map onto."""
    lo = 0.0 if par[EP_ZERO_LOW] > 0.5 else ctrl[C_OMEGA_MIN]
    return lo, ctrl[C_OMEGA_MAX]


@compiled
def max_thrust(veh: np.ndarray, ctrl: np.ndarray) -> float:
    """``4 kt hi^2`` (N): all rotors at the top of the range."""
    hi = ctrl[C_OMEGA_MAX]
    return 4.0 * veh[V_KT] * hi * hi


@allocating
def action_command(
    action: np.ndarray,
    meas: np.ndarray,
    veh: np.ndarray,
    ctrl: np.ndarray,
    par: np.ndarray,
    cmd: np.ndarray,
) -> None:
    """Rotor speed commands (rad/s) of a normalised action, into ``cmd``.

    ``meas``: the tick's measurement record (the gyro for the ctbr rate loop).
    """
    a = np.empty(4)
    for j in range(ENV_ROTORS):
        v = action[j]
        a[j] = -1.0 if not v >= -1.0 else (1.0 if v > 1.0 else v)  # NaN -> -1
    if int(par[EP_ACTION]) == ACT_CTBR:
        thrust = affine_map(a[0], 0.0, max_thrust(veh, ctrl))
        rates = (a[1] * par[EP_RATE_MAX], a[2] * par[EP_RATE_MAX + 1], a[3] * par[EP_RATE_MAX + 2])
        rate_loop(
            thrust, rates[0], rates[1], rates[2], meas[MS_W_HAT : MS_W_HAT + 3], ctrl, veh, cmd
        )
    else:
        lo, hi = rotor_range(ctrl, par)
        for j in range(ENV_ROTORS):
            cmd[j] = affine_map(a[j], lo, hi)
