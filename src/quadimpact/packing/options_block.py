"""The options' block: ``opts`` (``O_*``: model switches, crash rule, rotor limits,
integrator settings), and a power-off schedule's rates."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from quadimpact.core import layout as L
from quadimpact.inputs.resolved import ResolvedShared
from quadimpact.inputs.run_settings import RunSettings
from quadimpact.packing.constants import (
    EVENT_TOL_S,
    FRICTION_V_REG_M_S,
    MAX_STEPS_PER_S,
    MIN_STEP_BUDGET,
    RPM,
    V_MIN_M_S,
)
from quadimpact.packing.controller_block import refuse_nan

__all__ = [
    "PAPER_CRASH_ALTITUDE_M",
    "pack_options",
    "pack_run_options",
    "pack_schedule",
    "schedule_rates",
]

#: The crash altitude of the paper's crash rule (m): the centre of mass 0.3 m below
#: the ground plane, counted in control ticks (docs/VARIANTS.md 4.5).
PAPER_CRASH_ALTITUDE_M = -0.3


def pack_options(
    *,
    yaw_paper: bool,
    spinup_paper: bool,
    contact_gate_m: float,
    bumper1_yaw_twice: bool,
    crash_rule: int,
    crash_altitude_m: float,
    stop_on_crash: bool,
    first_order_rotors: bool,
    omega_limits_rad_s: tuple[float, float] | None,
    slew_limit_rad_s2: float | None,
    rtol: float,
    atol: float,
    control_rate_hz: float,
    duration_s: float,
    cut_step_motors: Sequence[int] = (),
) -> np.ndarray:
    """Model switches and integrator settings as the ``O_*`` vector.

    ``slew_limit_rad_s2``: ``None`` is no limit (0 in ``O_SLEW_MAX``).
    ``rtol``, ``atol``, ``control_rate_hz`` (Hz): as resolved
    (``simulation/resolve.py`` decides their defaults).
    ``cut_step_motors``: the motors (1-4) a power-off schedule cuts at the
    first control tick after its trigger (``O_CUT_STEP_MOTORS``, motor ``j``
    as bit ``j - 1``; docs/VARIANTS.md).
    """
    opts = np.zeros(L.NOPT)
    opts[L.O_YAW_REACTION_PAPER] = float(yaw_paper)
    opts[L.O_SPINUP_PAPER] = float(spinup_paper)
    opts[L.O_CONTACT_GATE] = float(contact_gate_m)
    opts[L.O_DOUBLE_BUMPER1_YAW] = float(bumper1_yaw_twice)
    opts[L.O_CRASH_RULE] = crash_rule
    opts[L.O_CRASH_ALTITUDE] = crash_altitude_m
    opts[L.O_STOP_ON_CRASH] = float(stop_on_crash)
    opts[L.O_ROTOR_MODE] = L.ROTOR_FIRST_ORDER if first_order_rotors else L.ROTOR_IDEAL
    if omega_limits_rad_s is not None:
        opts[L.O_OMEGA_MIN], opts[L.O_OMEGA_MAX] = omega_limits_rad_s
    opts[L.O_SLEW_MAX] = 0.0 if slew_limit_rad_s2 is None else slew_limit_rad_s2  # 0: none
    opts[L.O_V_REG] = FRICTION_V_REG_M_S
    opts[L.O_V_MIN] = V_MIN_M_S
    opts[L.O_DT_CONTROL] = 1.0 / control_rate_hz
    opts[L.O_RTOL] = rtol
    opts[L.O_ATOL] = atol
    opts[L.O_H_MAX] = 0.0
    opts[L.O_MAX_STEPS] = max(MIN_STEP_BUDGET, MAX_STEPS_PER_S * duration_s)
    opts[L.O_EVENT_TOL] = EVENT_TOL_S
    opts[L.O_POWER_OFF_T] = np.inf
    opts[L.O_CUT_STEP_MOTORS] = float(sum(1 << (m - 1) for m in set(cut_step_motors)))
    refuse_nan(opts, "the options")
    return opts


def schedule_rates(rates_rpm_per_s: Sequence[Sequence[float]], zero_rate: str) -> np.ndarray:
    """A power-off schedule's rates as the kernel takes them, rad/s^2.

    With ``zero_rate = "off"`` a rate of exactly 0 (or -0) is the motor
    switched off over the segment (``core.layout.MOTOR_OFF``: its speed 0
    from the segment's start); with ``"hold"`` it keeps its speed.
    """
    rpm = np.asarray(rates_rpm_per_s, dtype=float).reshape(-1, 4)
    rates = np.zeros((rpm.shape[0], L.MAX_ROTORS))  # a quadrotor's motors 1-4; 0 beyond
    rates[:, :4] = rpm * RPM
    if zero_rate == "off":
        rates[:, :4][rpm == 0.0] = L.MOTOR_OFF
    return rates


def pack_run_options(r: ResolvedShared, duration_s: float, *, free: bool = False) -> np.ndarray:
    """A run's ``opts`` vector from its resolved description (settings, options, rates).

    The crash rule from the ground setting and the model's ``crash_rule``
    (``free``: none, for the free flight before an impact trial's impact),
    rotor limits in rad/s, the power-off trigger (s, or -1: first contact),
    the recovery end time (s after the recovery's end). ``duration_s``: what
    the step budget is sized for, s.
    """
    s, o = r.settings, r.options
    if free:
        crash_rule, level, stop = L.CRASH_NONE, 0.0, False
    elif s.ground in ("contact", "none"):
        crash_rule, level, stop = L.CRASH_NONE, 0.0, False
    elif o.crash_rule == "paper-ticks":
        crash_rule, level, stop = L.CRASH_PAPER_TICKS, PAPER_CRASH_ALTITUDE_M, True
    elif o.crash_rule == "ground-ticks":
        crash_rule, level, stop = L.CRASH_PAPER_TICKS, 0.0, True
    else:
        crash_rule, level, stop = L.CRASH_CM_GROUND, 0.0, True
    limits = None
    if s.rotor_speed_limits_rpm is not None:
        lo, hi = s.rotor_speed_limits_rpm
        limits = (lo * RPM, hi * RPM)
    opts = pack_options(
        yaw_paper=o.yaw_reaction == "paper",
        spinup_paper=o.spinup_reaction == "paper",
        contact_gate_m=float(o.contact_gate_m),
        bumper1_yaw_twice=bool(o.bumper1_yaw_twice),
        crash_rule=crash_rule,
        crash_altitude_m=level,
        stop_on_crash=stop,
        first_order_rotors=s.rotor_mode == "first-order",
        omega_limits_rad_s=limits,
        slew_limit_rad_s2=r.slew_limit_rad_s2,
        rtol=r.rtol,
        atol=r.atol,
        control_rate_hz=r.control_rate_hz,
        duration_s=duration_s,
        cut_step_motors=o.cut_step_motors,
    )
    if s.power_off is not None:
        trigger = s.power_off.trigger
        opts[L.O_POWER_OFF_T] = -1.0 if trigger == "first-contact" else float(trigger)
    if s.end_after_recovery_s is not None:
        opts[L.O_END_AFTER_RECOVERY] = float(s.end_after_recovery_s)
    return opts


def pack_schedule(s: RunSettings) -> dict[str, np.ndarray]:
    """The power-off schedule as the kernel's arrays (s; rad/s^2; stall flags)."""
    if s.power_off is None:
        return {}
    stop = np.zeros(L.MAX_ROTORS)
    for m in s.power_off.stopped_motors:
        stop[m - 1] = 1.0
    return {
        "sched_t": np.asarray(s.power_off.segment_start_s, dtype=float),
        "sched_rate": schedule_rates(s.power_off.rates_rpm_per_s, s.power_off.zero_rate),
        "sched_stop": stop,
    }
