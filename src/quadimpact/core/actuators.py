"""Actuators: rotor command limits and slew, rotor modes, and motor power-off schedules.

Per control tick, :func:`apply_command` turns the controller's four speed
commands into the rotor inputs of the interval (``rin``, slots ``RIN_*`` of ``core/rotors.py``):
the generic slew limit, speed range and zero floor (options ``O_SLEW_MAX``,
``O_OMEGA_MIN``, ``O_OMEGA_MAX``), then

* ideal rotors (the paper): the rotor states jump to the command and are
  held (zero-order hold); the reaction torque uses the finite difference
  ``(cmd_k - cmd_{k-1}) / dt`` as ``Omega_dot``;
* first-order rotors: ``Omega_dot = (cmd - Omega) / tau_m`` (:func:`rotor_rates`).

Motor power-off (the experiments of the paper's section V): from a trigger
time ``t_p`` (the first contact, or a given time) each motor's speed follows
a prescribed piecewise-linear schedule, whatever the controller commands:
over segment ``k``, ``[t_p + start_k, t_p + start_{k+1})``, motor ``j``
changes at ``rate[k, j]`` (rad/s^2), and never goes below zero (a motor that
reaches zero stays there until a later segment's rate is positive).
A rate of :data:`MOTOR_OFF` (the packing's value for a scheduled rate of
exactly 0: the crash data's powered-off motor) stops the motor at the
segment's start: its speed jumps to zero and stays there until a later
segment's rate is positive. Motors marked as stalling stop at the trigger.
The reaction torque of these jumps is not modelled, with one exception: the
motors of the option ``O_CUT_STEP_MOTORS`` (the authors' crash runs: motor 2)
keep their speed from the trigger to the first control tick after it and are
cut there as a one-tick command step, ``Omega_dot = -Omega / dt`` over that
tick's interval in the spin-up reaction (:func:`cut_step`, a stage of the tick
after the actuators); they stay off for the rest of the run, whatever the
schedule says.

The rotor speeds are states whose derivative is the current rate, so the
integrator reproduces the schedule exactly (a linear function); the run loop
cuts its steps at every segment start and at every instant a motor reaches
zero, which ``next_boundary`` gives in closed form.
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import (
    LS_K,
    LS_PO_ACTIVE,
    LS_PO_T,
    LS_T0,
    MOTOR_OFF,
    O_CUT_STEP_MOTORS,
    O_DT_CONTROL,
    O_OMEGA_MAX,
    O_OMEGA_MIN,
    O_SLEW_MAX,
    X_ROTOR,
)
from quadimpact.core.records import Data, Model
from quadimpact.core.rotors import (
    RIN_CMD,
    RIN_FF,
    RIN_FIRST_ORDER,
    RIN_PREV_CMD,
    RIN_RATE,
)
from quadimpact.core.vehicle_slots import V_N_ROTORS, V_TAU_M

ZERO_SPEED = 1e-9  # rad/s: a motor at or below this is stopped


@compiled
def apply_segment(
    x: np.ndarray, sched_rate: np.ndarray, seg: int, rin: np.ndarray, cut: int, n: int
) -> None:
    """Rotor inputs of the ``n`` rotors for segment ``seg``: prescribed rates, floored at zero.

    A rate of :data:`MOTOR_OFF` stops the motor. The motors of the bit mask
    ``cut`` (``opts[O_CUT_STEP_MOTORS]``) are left alone: :func:`cut_step`
    drives them.
    """
    rin[RIN_FIRST_ORDER] = 0.0
    for j in range(n):
        if (cut >> j) & 1:
            continue
        r = sched_rate[seg, j]
        if x[X_ROTOR + j] <= ZERO_SPEED or r == MOTOR_OFF:
            x[X_ROTOR + j] = 0.0
        if x[X_ROTOR + j] <= 0.0 and r < 0.0:
            r = 0.0
        rin[RIN_RATE + j] = r
        rin[RIN_FF + j] = r


@compiled
def next_boundary(
    t: float, x: np.ndarray, t_p: float, sched_t: np.ndarray, seg: int, rin: np.ndarray, n: int
) -> float:
    """Next instant (s) where the rotor inputs change: a segment start or one of the ``n``
    motors stopping."""
    t_b = t_p + sched_t[seg + 1] if seg + 1 < sched_t.shape[0] else math.inf
    for j in range(n):
        r = rin[RIN_RATE + j]
        if r < 0.0 and x[X_ROTOR + j] > 0.0:
            t_b = min(t_b, t + x[X_ROTOR + j] / -r)
    return t_b


@compiled
def cut_step(m: Model, d: Data) -> None:
    """The authors' motor cut at the tick ``d.ls[LS_K]``, once the power-off schedule is on.

    Each motor of ``opts[O_CUT_STEP_MOTORS]`` (bit ``j``: motor ``j + 1``)
    keeps its speed from the trigger to the first control tick after it and
    is commanded there from that speed to 0 in one step: over that tick's
    interval the spin-up reaction sees the finite difference ``-Omega / dt``
    (as an ideal rotor's command step), from the next tick on nothing; its
    speed is 0 from the cut on. Nothing happens without such motors or before
    the trigger.
    """
    cut = int(m.opts[O_CUT_STEP_MOTORS])
    ls = d.ls
    if cut == 0 or ls[LS_PO_ACTIVE] < 0.5:
        return
    dt = m.opts[O_DT_CONTROL]
    k = int(ls[LS_K])
    first = ls[LS_PO_T] >= ls[LS_T0] + (k - 1) * dt  # the trigger fell in the last interval
    x = d.x
    rin = d.rin
    for j in range(int(m.veh[V_N_ROTORS])):
        if (cut >> j) & 1:
            rin[RIN_FF + j] = -x[X_ROTOR + j] / dt if first else 0.0
            rin[RIN_RATE + j] = 0.0
            x[X_ROTOR + j] = 0.0


@compiled
def segment_at(t: float, t_p: float, sched_t: np.ndarray) -> int:
    """Index of the segment in force at time ``t`` (0 before the second start)."""
    seg = 0
    while seg + 1 < sched_t.shape[0] and t_p + sched_t[seg + 1] <= t:
        seg += 1
    return seg


@compiled
def apply_command(
    cmd: np.ndarray,
    x: np.ndarray,
    rin: np.ndarray,
    opts: np.ndarray,
    dt: float,
    scheduled: bool,
    n: int,
) -> None:
    """Limit the tick's speed commands of the ``n`` rotors (rad/s); set the interval's inputs.

    ``scheduled``: a power-off schedule is in force, so only the recorded command
    changes (the schedule keeps driving the rotor states).
    """
    w_lo = opts[O_OMEGA_MIN]
    w_hi = opts[O_OMEGA_MAX]
    slew = opts[O_SLEW_MAX]
    first_order = rin[RIN_FIRST_ORDER] > 0.5
    for j in range(n):
        prev = rin[RIN_PREV_CMD + j]
        w = cmd[j]
        if slew > 0.0:
            w = min(max(w, prev - slew * dt), prev + slew * dt)
        if w_lo > 0.0 and w < w_lo:
            w = w_lo
        if w_hi > 0.0 and w > w_hi:
            w = w_hi
        if w < 0.0:
            w = 0.0
        rin[RIN_CMD + j] = w
        if scheduled:  # the schedule overrides the controller
            pass
        elif first_order:
            rin[RIN_RATE + j] = 0.0
            rin[RIN_FF + j] = 0.0
        else:
            rin[RIN_RATE + j] = 0.0
            rin[RIN_FF + j] = (w - prev) / dt
            x[X_ROTOR + j] = w
        rin[RIN_PREV_CMD + j] = w


@compiled(inline="always")
def rotor_rates(
    x: np.ndarray, veh: np.ndarray, rin: np.ndarray, omega_dot: np.ndarray, n: int
) -> None:
    """Accelerations (rad/s^2) of the ``n`` rotors in the current rotor mode, into ``omega_dot``."""
    if rin[RIN_FIRST_ORDER] > 0.5:
        for j in range(n):
            omega_dot[j] = (rin[RIN_CMD + j] - x[X_ROTOR + j]) / veh[V_TAU_M]
    else:
        for j in range(n):
            omega_dot[j] = rin[RIN_RATE + j]
