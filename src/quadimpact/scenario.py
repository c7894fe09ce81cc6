"""Scenarios to packed runs: attitude, trim, surfaces, and the wall-approach shooting.

``prepare(scenario)`` turns a validated :class:`~quadimpact.config.WallApproach`
or :class:`~quadimpact.config.FlightScenario` into a :class:`RunSetup`: the
flat arrays of the compiled core plus what the analysis needs to read the
result (surface names, references, the approach solution, warnings).

The wall approach (STUDIES.md section 1): the vehicle holds the attitude
(heading psi, inclination iota) and the altitude from the start. Without
aerodynamic drag nothing in the dynamics depends on X or V_X, so
``V_X(T_c) = v0 + A`` and the leading bumper's depth at ``T_c`` shifts one to
one with X0: one free-flight run gives A and the depth, a correction of v0
and a shift of X0 make the first contact happen at ``T_c`` with
``V_X = V_c`` (repeated until the residuals are below 1e-12). If that needs
``v0 < 0``, the vehicle starts later, at rest, at the ``t0`` found by
Brent's method on ``V_X(T_c; t0) = V_c`` (one free-flight run per trial).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import brentq

from .config import FlightScenario, ModelOptions, WallApproach, resolve_model_options
from .core import layout as L
from .core.geometry import bumper_contact
from .core.run import execute
from .frames import euler_zyx_to_quat, quat_to_matrix
from .packing import (
    RPM,
    Surface,
    pack_controller,
    pack_options,
    pack_surfaces,
    pack_vehicle,
    trim_rotor_speeds,
)
from .vehicle import Vehicle, load_vehicle

PAPER_FIT_OFFSET_RAD = 0.0042477  # the authors' fitted inclination mapping (MODEL.md 8.4)
PAPER_FIT_SCALE = 1.3836686
PAPER_CRASH_ALTITUDE_M = -0.3  # MODEL.md 8.5
APPROACH_TOL_M_S = 1e-12  # shooting residuals (speed m/s, depth m)
APPROACH_MAX_ITER = 4

CONTROLLER_KINDS = {"paper": L.CTRL_PAPER, "cascade-pid": L.CTRL_CASCADE_PID}


@dataclass
class RunSetup:
    """Everything the compiled loop takes, and what is needed to read its record."""

    x0: np.ndarray
    t0: float
    tf: float
    veh: np.ndarray
    surf: np.ndarray
    opts: np.ndarray
    ctrl: np.ndarray
    surface_names: tuple[str, ...]
    references: dict[str, float]
    vehicle: Vehicle
    options: ModelOptions
    output_rate_hz: float
    wall: Surface | None = None
    approach: dict[str, Any] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    sched_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    sched_rate: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))
    sched_stop: np.ndarray = field(default_factory=lambda: np.zeros(4))

    def schedule(self) -> dict[str, np.ndarray]:
        """The power-off schedule as keyword arguments of ``core.run.execute``."""
        return {
            "sched_t": self.sched_t,
            "sched_rate": self.sched_rate,
            "sched_stop": self.sched_stop,
        }

    def output_times(self) -> np.ndarray:
        """Output grid: ``t0``, the multiples of 1/rate inside (t0, tf), and ``tf`` (s)."""
        dt = 1.0 / self.output_rate_hz
        k0 = math.floor(self.t0 / dt) + 1
        k1 = math.ceil(self.tf / dt)
        inner = np.arange(k0, k1) * dt
        inner = inner[(inner > self.t0 + 1e-12) & (inner < self.tf - 1e-12)]
        return np.concatenate([[self.t0], inner, [self.tf]])


# ------------------------------------------------------------------ attitude
def wall_attitude(
    heading_deg: float, inclination_deg: float, mapping: str = "exact"
) -> tuple[float, float, float]:
    """Roll, pitch, yaw (rad, ZYX) for a heading and an inclination toward the wall.

    ``exact``: yaw = psi and the body z axis in the inertial X-Z plane at
    angle iota from Z, tilted so the thrust points toward +X (STUDIES.md 1):
    ``phi = -asin(sin psi sin iota)``, ``theta = asin(-cos psi sin iota / cos phi)``.
    ``paper-fit``: the authors' mapping (MODEL.md 8.4) at psi = 0 and +-45 deg,
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
    z = quat_to_matrix(np.asarray(q, dtype=float))[..., :, 2]
    return float(np.degrees(np.arctan2(-z[..., 0], z[..., 2])))


# ---------------------------------------------------------------- settings
def _resolve_vehicle(s: WallApproach | FlightScenario) -> Vehicle:
    v = load_vehicle(s.vehicle)
    if s.vehicle_overrides:
        v = v.with_overrides(**dict(s.vehicle_overrides))
    return v


def _initial_speeds(
    v: Vehicle, roll: float, pitch: float, rule: str, yaw_paper: bool
) -> np.ndarray:
    weight = v.mass_kg * v.gravity_m_s2
    if rule == "level-hover":
        return np.full(4, math.sqrt(weight / (4.0 * v.thrust_coefficient)))
    return trim_rotor_speeds(v, weight / (math.cos(roll) * math.cos(pitch)), yaw_paper)


def _packed_options(
    s: WallApproach | FlightScenario, o: ModelOptions, duration_s: float, *, free: bool = False
) -> np.ndarray:
    if free:
        crash_rule, level, stop = L.CRASH_NONE, 0.0, False
    elif s.ground == "contact":
        crash_rule, level, stop = L.CRASH_NONE, 0.0, False
    elif o.crash_rule == "paper-ticks":
        crash_rule, level, stop = L.CRASH_PAPER_TICKS, PAPER_CRASH_ALTITUDE_M, True
    else:
        crash_rule, level, stop = L.CRASH_CM_GROUND, 0.0, True
    limits = None
    if s.rotor_speed_limits_rpm is not None:
        lo, hi = s.rotor_speed_limits_rpm
        limits = (lo * RPM, hi * RPM)
    opts = pack_options(
        yaw_paper=o.yaw_reaction == "paper",
        bumper1_yaw_twice=bool(o.bumper1_yaw_twice),
        crash_rule=crash_rule,
        crash_altitude_m=level,
        stop_on_crash=stop,
        first_order_rotors=s.rotor_mode == "first-order",
        omega_limits_rad_s=limits,
        slew_limit_rad_s2=s.rotor_slew_limit_rad_s2,
        friction_coefficient=s.friction_coefficient,
        rtol=s.rtol,
        atol=s.atol,
        duration_s=duration_s,
    )
    if s.power_off is not None:
        trigger = s.power_off.trigger
        opts[L.O_POWER_OFF_T] = -1.0 if trigger == "first-contact" else float(trigger)
    return opts


def _schedule(s: WallApproach | FlightScenario) -> dict[str, np.ndarray]:
    """The power-off schedule as the kernel's arrays (s; rad/s^2; stall flags)."""
    if s.power_off is None:
        return {}
    stop = np.zeros(4)
    for m in s.power_off.stopped_motors:
        stop[m - 1] = 1.0
    return {
        "sched_t": np.asarray(s.power_off.segment_start_s, dtype=float),
        "sched_rate": np.asarray(s.power_off.rates_rpm_per_s, dtype=float) * RPM,
        "sched_stop": stop,
    }


def _ground(s: WallApproach | FlightScenario) -> list[Surface]:
    if s.ground == "contact":
        return [Surface("ground", (0.0, 0.0, 0.0), (0.0, 0.0, -1.0), is_ground=True)]
    return []


def _state(
    position: np.ndarray,
    v_inertial: np.ndarray,
    q: np.ndarray,
    omega: np.ndarray,
    rotors: np.ndarray,
) -> np.ndarray:
    x = np.zeros(L.NX)
    x[L.X_POS : L.X_POS + 3] = position
    x[L.X_VEL : L.X_VEL + 3] = quat_to_matrix(q).T @ v_inertial
    x[L.X_QUAT : L.X_QUAT + 4] = q
    x[L.X_OMEGA : L.X_OMEGA + 3] = omega
    x[L.X_ROTOR : L.X_ROTOR + 4] = rotors
    return x


# ------------------------------------------------------------- flight scenario
def prepare_flight(s: FlightScenario) -> RunSetup:
    """A general initial state set by the user (no shooting)."""
    v = _resolve_vehicle(s)
    o = resolve_model_options(s.model, s.model_options)
    yaw_paper = o.yaw_reaction == "paper"
    roll, pitch, yaw = (math.radians(a) for a in s.euler_deg)
    q = euler_zyx_to_quat(roll, pitch, yaw)
    rotors = (
        np.asarray(s.rotor_speeds_rad_s, dtype=float)
        if s.rotor_speeds_rad_s is not None
        else _initial_speeds(v, roll, pitch, o.initial_rotor_speeds, yaw_paper)
    )
    x0 = _state(
        np.asarray(s.position_m, float),
        np.asarray(s.velocity_m_s, float),
        q,
        np.asarray(s.angular_velocity_rad_s, float),
        rotors,
    )
    ref_att = s.attitude_ref_deg if s.attitude_ref_deg is not None else s.euler_deg
    refs = {
        "altitude_m": float(s.altitude_ref_m if s.altitude_ref_m is not None else -s.position_m[2]),
        "roll_rad": math.radians(ref_att[0]),
        "pitch_rad": math.radians(ref_att[1]),
        "yaw_rad": math.radians(ref_att[2]),
    }
    surfaces = [Surface(p.name, tuple(p.point_m), tuple(p.normal)) for p in s.surfaces]
    surfaces += _ground(s)
    duration = s.final_time_s - s.start_time_s
    return RunSetup(
        x0=x0,
        t0=float(s.start_time_s),
        tf=float(s.final_time_s),
        veh=pack_vehicle(v),
        surf=pack_surfaces(surfaces),
        opts=_packed_options(s, o, duration),
        ctrl=pack_controller(CONTROLLER_KINDS[s.controller], v, refs, yaw_paper),
        surface_names=tuple(x.name for x in surfaces),
        references=refs,
        vehicle=v,
        options=o,
        output_rate_hz=float(s.output_rate_hz),
        **_schedule(s),
    )


# --------------------------------------------------------------- wall approach
def _free_flight_end(
    setup: RunSetup, x0: np.ndarray, t0: float, t_end: float, free_opts
) -> np.ndarray:
    """State at ``t_end`` of a run from ``(t0, x0)`` with no surfaces and no crash."""
    out, _, stats = execute(
        x0,
        t0,
        t_end,
        setup.veh,
        np.zeros((0, L.NSURF)),
        free_opts,
        setup.ctrl,
        np.array([t_end]),
        max_episodes=1,
        **setup.schedule(),
    )
    if stats[L.ST_STATUS] == L.STATUS_FAILED or out.shape[0] != 1:
        raise RuntimeError(
            "approach shooting run failed: " + L.REASON_TEXT[int(stats[L.ST_REASON])]
        )
    return out[0, L.OUT_X : L.OUT_X + L.NX]


def _inertial_velocity(x: np.ndarray) -> np.ndarray:
    return quat_to_matrix(x[L.X_QUAT : L.X_QUAT + 4]) @ x[L.X_VEL : L.X_VEL + 3]


def bumper_depths(x: np.ndarray, veh: np.ndarray, surf: np.ndarray, s: int = 0) -> np.ndarray:
    """Penetration (m) of the four bumpers into surface ``s`` at state ``x``
    (the compiled contact geometry, called from Python)."""
    xq = np.ascontiguousarray(x, dtype=float)
    C = np.ascontiguousarray(quat_to_matrix(xq[L.X_QUAT : L.X_QUAT + 4]))
    return np.array([bumper_contact(xq, C, veh, j, surf, s)[0] for j in range(4)])


def prepare_wall_approach(s: WallApproach) -> RunSetup:
    """The paper's scenario, with the approach solved so that first contact is at T_c."""
    v = _resolve_vehicle(s)
    o = resolve_model_options(s.model, s.model_options)
    yaw_paper = o.yaw_reaction == "paper"
    if s.roll_deg is not None and s.pitch_deg is not None:
        roll, pitch, yaw = (math.radians(a) for a in (s.roll_deg, s.pitch_deg, s.heading_deg))
    else:
        roll, pitch, yaw = wall_attitude(s.heading_deg, s.inclination_deg, o.attitude_mapping)
    q = euler_zyx_to_quat(roll, pitch, yaw)
    rotors = _initial_speeds(v, roll, pitch, o.initial_rotor_speeds, yaw_paper)
    refs = {"altitude_m": float(s.altitude_m), "roll_rad": roll, "pitch_rad": pitch, "yaw_rad": yaw}
    wall = Surface("wall", (float(s.wall_distance_m), 0.0, 0.0), (-1.0, 0.0, 0.0))
    surfaces = [wall, *_ground(s)]
    tc = float(s.impact_time_s)
    vc = float(s.speed_m_s)
    setup = RunSetup(
        x0=np.zeros(L.NX),
        t0=0.0,
        tf=float(s.final_time_s),
        veh=pack_vehicle(v),
        surf=pack_surfaces(surfaces),
        opts=_packed_options(s, o, float(s.final_time_s)),
        ctrl=pack_controller(CONTROLLER_KINDS[s.controller], v, refs, yaw_paper),
        surface_names=tuple(x.name for x in surfaces),
        references=refs,
        vehicle=v,
        options=o,
        output_rate_hz=float(s.output_rate_hz),
        wall=wall,
        **_schedule(s),
    )
    free_opts = _packed_options(s, o, tc, free=True)
    wall_only = pack_surfaces([wall])
    h0 = s.start_altitude_m if s.start_altitude_m is not None else s.altitude_m
    start = np.array([0.0, 0.0, -float(h0)])

    def shoot(t0: float, v0: float, x_start: float) -> tuple[np.ndarray, np.ndarray]:
        pos = start + np.array([x_start, 0.0, 0.0])
        x0 = _state(pos, np.array([v0, 0.0, 0.0]), q, np.zeros(3), rotors)
        return x0, _free_flight_end(setup, x0, t0, tc, free_opts)

    def solve_from(t0: float, v0: float) -> tuple[float, float, float, np.ndarray]:
        """Correct v0 (unless at rest) and X0 until the residuals vanish."""
        x_start = 0.0
        for _ in range(APPROACH_MAX_ITER):
            x0, xe = shoot(t0, v0, x_start)
            dv = vc - _inertial_velocity(xe)[0]
            depth = bumper_depths(xe, setup.veh, wall_only).max()
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
        late = o.approach_start == "late-start"
        if not late:  # the authors' rule: start later only from beyond the wall
            late = bumper_depths(x0, setup.veh, wall_only).max() > 0.0
    if late:

        def residual(t_start: float) -> float:
            _, xe = shoot(t_start, 0.0, 0.0)
            return _inertial_velocity(xe)[0] - vc

        t0 = brentq(residual, 0.0, tc - 1e-9, xtol=1e-14, rtol=4 * np.finfo(float).eps)
        v0, x_start, dv, x0 = solve_from(t0, 0.0)
    setup.x0 = x0
    setup.t0 = t0
    setup.approach = {
        "start_time_s": t0,
        "start_x_m": float(x0[L.X_POS]),
        "start_speed_m_s": float(v0),
        "late_start": bool(late),
        "speed_residual_m_s": float(dv),
    }
    if late:
        setup.warnings.append(
            f"the approach needs v0 < 0: the vehicle starts at rest at t0 = {t0:.6f} s"
        )
    return setup


def prepare(scenario: WallApproach | FlightScenario) -> RunSetup:
    """Validated scenario -> packed run."""
    if isinstance(scenario, WallApproach):
        return prepare_wall_approach(scenario)
    return prepare_flight(scenario)
