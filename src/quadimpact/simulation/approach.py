"""The paper's wall approach (docs/STUDIES.md section 1): attitude and the approach shooting.

The vehicle holds the attitude (heading psi, inclination iota) and the
altitude from the start. Without aerodynamic drag nothing in the dynamics
depends on X or V_X, so ``V_X(T_c) = v0 + A`` and the leading bumper's depth at
``T_c`` shifts one to one with X0: one free-flight run gives A and the depth,
a correction of v0 and a shift of X0 make the first contact happen at ``T_c``
with ``V_X = V_c`` (repeated until the residuals are below 1e-12). If that
needs ``v0 < 0``, the vehicle starts later, at rest, at the ``t0`` found by
Brent's method on ``V_X(T_c; t0) = V_c`` (one free-flight run per trial).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from quadimpact.core import layout as L
from quadimpact.core.geometry import contact_record
from quadimpact.core.records import Model
from quadimpact.core.run import Kernel, execute
from quadimpact.linalg import matvec, matvec_t
from quadimpact.results.costs import CpuClock
from quadimpact.rotations import inclination_deg, quat_to_matrix
from quadimpact.simulation.roots import brentq

__all__ = [
    "APPROACH_MAX_ITER",
    "APPROACH_TOL_M_S",
    "PAPER_FIT_OFFSET_RAD",
    "PAPER_FIT_SCALE",
    "feature_depths",
    "inclination_deg_of",
    "initial_state",
    "solve_approach",
    "wall_attitude",
]

PAPER_FIT_OFFSET_RAD = 0.0042477  # the authors' fitted inclination mapping (docs/VARIANTS.md 4.4)
PAPER_FIT_SCALE = 1.3836686
APPROACH_TOL_M_S = 1e-12  # shooting residuals (speed m/s, depth m)
APPROACH_MAX_ITER = 4


# ------------------------------------------------------------------ attitude
def wall_attitude(
    heading_deg: float, inclination_deg: float, mapping: str = "exact"
) -> tuple[float, float, float]:
    """Roll, pitch, yaw (rad, ZYX) for a heading and an inclination toward the wall.

    ``exact``: yaw = psi and the body z axis in the inertial X-Z plane at
    angle iota from Z, tilted so the thrust points toward +X (docs/STUDIES.md 1):
    ``phi = -asin(sin psi sin iota)``, ``theta = asin(-cos psi sin iota / cos phi)``.
    ``paper-fit``: the authors' mapping (docs/VARIANTS.md 4.4) at psi = 0 and +-45 deg,
    ``exact`` elsewhere.
    """
    psi = math.radians(heading_deg)
    iota = math.radians(inclination_deg)
    if mapping == "paper-fit":
        if heading_deg == 0.0:
            return 0.0, -iota, psi
        if abs(heading_deg) == 45.0:
            a = -(iota - PAPER_FIT_OFFSET_RAD) / PAPER_FIT_SCALE
            return a, a, psi
    phi = -math.asin(math.sin(psi) * math.sin(iota))
    theta = math.asin(-math.cos(psi) * math.sin(iota) / math.cos(phi))
    return phi, theta, psi


def inclination_deg_of(q: np.ndarray) -> float:
    """Inclination (deg) of attitude ``q``: angle of body z projected on X-Z from Z, + toward +X."""
    return float(inclination_deg(quat_to_matrix(np.asarray(q, dtype=float))))


def initial_state(
    position: np.ndarray,
    v_inertial: np.ndarray,
    q: np.ndarray,
    omega: np.ndarray,
    rotors: np.ndarray,
) -> np.ndarray:
    """The kernel's state vector (layout ``X_*``) from inertial position and velocity."""
    x = np.zeros(L.NX)
    x[L.X_POS : L.X_POS + 3] = position
    x[L.X_VEL : L.X_VEL + 3] = matvec_t(quat_to_matrix(q), v_inertial)
    x[L.X_QUAT : L.X_QUAT + 4] = q
    x[L.X_OMEGA : L.X_OMEGA + 3] = omega
    x[L.X_ROTOR : L.X_ROTOR + 4] = rotors
    return x


# ------------------------------------------------------------------ shooting
def _free_flight_end(
    run: Model,
    x0: np.ndarray,
    t0: float,
    t_end: float,
    free_opts: np.ndarray,
    kernel: Kernel | None = None,
    clock: CpuClock | None = None,
) -> np.ndarray:
    """State at ``t_end`` of the run ``run`` from ``(t0, x0)`` with no shapes, no IMU, no crash."""
    span = np.zeros(L.NSPAN)
    span[L.SPAN_T0] = t0
    span[L.SPAN_TF] = t_end
    m = run._replace(
        x0=np.ascontiguousarray(x0, dtype=np.float64),
        span=span,
        shapes=np.zeros((0, L.NSHAPE)),
        pairs=np.zeros((0, L.NPAIR), dtype=np.int64),
        opts=free_opts,
        scfg=np.zeros(L.NSCFG),
        noise=np.zeros((0, 6)),
        t_out=np.array([t_end]),
    )
    if clock is None:
        rec = execute(m, max_episodes=1, kernel=kernel)
    else:
        with clock:
            rec = execute(m, max_episodes=1, kernel=kernel)
    if rec.stats[L.ST_STATUS] == L.STATUS_FAILED or rec.out.shape[0] != 1:
        raise RuntimeError(
            "approach shooting run failed: " + L.REASON_TEXT[int(rec.stats[L.ST_REASON])]
        )
    return rec.out[0, L.OUT_X : L.OUT_X + L.NX]


def _inertial_velocity(x: np.ndarray) -> np.ndarray:
    return matvec(quat_to_matrix(x[L.X_QUAT : L.X_QUAT + 4]), x[L.X_VEL : L.X_VEL + 3])


def feature_depths(x: np.ndarray, feat: np.ndarray, shapes: np.ndarray, s: int = 0) -> np.ndarray:
    """Penetration (m) of every contact feature into shape ``s`` at the state ``x``.

    The compiled contact geometry (``core.geometry``), called from Python.
    """
    xq = np.ascontiguousarray(x, dtype=float)
    C = np.ascontiguousarray(quat_to_matrix(xq[L.X_QUAT : L.X_QUAT + 4]))
    return np.array([contact_record(xq, C, feat, shapes, f, s)[0] for f in range(feat.shape[0])])


def solve_approach(
    *,
    run: Model,
    free_opts: np.ndarray,
    wall: np.ndarray,
    q: np.ndarray,
    rotors: np.ndarray,
    start: np.ndarray,
    impact_time_s: float,
    speed_m_s: float,
    late_start: bool,
    kernel: Kernel | None = None,
    clock: CpuClock | None = None,
) -> tuple[np.ndarray, float, dict[str, Any]]:
    """Initial state and time that bring the first contact at ``T_c`` with ``V_X = V_c``.

    Parameters
    ----------
    run : Model
        The packed run (its vehicle, features, controller and power-off schedule).
    free_opts : numpy.ndarray
        Its options without a crash, ``T_c`` as the duration.
    wall : numpy.ndarray, shape (1, NSHAPE)
        The packed wall alone.
    q, rotors : numpy.ndarray
        Attitude held and initial rotor speeds.
    start : numpy.ndarray, shape (3,)
        Initial position before the X shift, inertial NED, m.
    impact_time_s, speed_m_s : float
        ``T_c`` and ``V_c``.
    late_start : bool
        The ``late-start`` rule: start later at rest whenever ``v0 < 0`` would be
        needed; otherwise (the authors' rule) only when the start would lie
        beyond the wall.
    kernel : Kernel, optional
        The run loop of a plug-in controller (default: the built-in kernel).
    clock : CpuClock, optional
        Adds up the CPU time of the shooting runs (the summary's ``cost``).

    Returns
    -------
    x0 : numpy.ndarray
        The initial state.
    t0 : float
        The start time, s.
    approach : dict
        ``start_time_s``, ``start_x_m``, ``start_speed_m_s``, ``late_start``,
        ``speed_residual_m_s`` (the summary's ``approach``).
    """
    tc = float(impact_time_s)
    vc = float(speed_m_s)

    def shoot(t0: float, v0: float, x_start: float) -> tuple[np.ndarray, np.ndarray]:
        pos = start + np.array([x_start, 0.0, 0.0])
        x0 = initial_state(pos, np.array([v0, 0.0, 0.0]), q, np.zeros(3), rotors)
        return x0, _free_flight_end(run, x0, t0, tc, free_opts, kernel, clock)

    def solve_from(t0: float, v0: float) -> tuple[float, float, float, np.ndarray]:
        """Correct v0 (unless at rest) and X0 until the residuals vanish."""
        x_start = 0.0
        for _ in range(APPROACH_MAX_ITER):
            x0, xe = shoot(t0, v0, x_start)
            dv = vc - _inertial_velocity(xe)[0]
            depth = feature_depths(xe, run.feat, wall).max()
            if abs(dv) <= APPROACH_TOL_M_S and abs(depth) <= APPROACH_TOL_M_S:
                break
            if t0 == 0.0 or v0 != 0.0:
                v0 += dv
                x_start -= depth + dv * (tc - t0)
            else:
                x_start -= depth
        return v0, x_start, dv, x0

    late = False
    t0 = 0.0
    v0, x_start, dv, x0 = solve_from(0.0, vc)
    if v0 < 0.0:
        late = late_start
        if not late:  # the authors' rule: start later only from beyond the wall
            late = feature_depths(x0, run.feat, wall).max() > 0.0
    if late:

        def residual(t_start: float) -> float:
            _, xe = shoot(t_start, 0.0, 0.0)
            return _inertial_velocity(xe)[0] - vc

        t0 = brentq(residual, 0.0, tc - 1e-9, xtol=1e-14, rtol=4 * np.finfo(float).eps)
        v0, x_start, dv, x0 = solve_from(t0, 0.0)
    approach = {
        "start_time_s": t0,
        "start_x_m": float(x0[L.X_POS]),
        "start_speed_m_s": float(v0),
        "late_start": bool(late),
        "speed_residual_m_s": float(dv),
    }
    return x0, t0, approach
