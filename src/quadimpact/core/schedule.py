"""Motor power-off schedules (MODEL.md 5, the experiments of the paper's section V).

From a trigger time ``t_p`` (the first contact, or a given time) each motor's
speed follows a prescribed piecewise-linear schedule, whatever the controller
commands: over segment ``k``, ``[t_p + start_k, t_p + start_{k+1})``, motor
``j`` changes at ``rate[k, j]`` (rad/s^2), and never goes below zero (a motor
that reaches zero stays there until a later segment's rate is positive).
Motors marked as stalling stop at the trigger (their speed jumps to zero; the
spin-down torque of that jump is not modelled).

The rotor speeds are states whose derivative is the current rate, so the
integrator reproduces the schedule exactly (a linear function); the run loop
cuts its steps at every segment start and at every instant a motor reaches
zero, which ``next_boundary`` gives in closed form.
"""

import math

import numpy as np
from numba import njit

from .layout import RIN_FF, RIN_FIRST_ORDER, RIN_RATE, X_ROTOR

ZERO_SPEED = 1e-9  # rad/s: a motor at or below this is stopped


@njit(cache=True)
def apply_segment(x: np.ndarray, sched_rate: np.ndarray, seg: int, rin: np.ndarray) -> None:
    """Rotor inputs for segment ``seg``: prescribed rates, floored at zero speed."""
    rin[RIN_FIRST_ORDER] = 0.0
    for j in range(4):
        if x[X_ROTOR + j] <= ZERO_SPEED:
            x[X_ROTOR + j] = 0.0
        r = sched_rate[seg, j]
        if x[X_ROTOR + j] <= 0.0 and r < 0.0:
            r = 0.0
        rin[RIN_RATE + j] = r
        rin[RIN_FF + j] = r


@njit(cache=True)
def next_boundary(
    t: float, x: np.ndarray, t_p: float, sched_t: np.ndarray, seg: int, rin: np.ndarray
) -> float:
    """Next instant (s) where the rotor inputs change: a segment start or a motor stopping."""
    t_b = t_p + sched_t[seg + 1] if seg + 1 < sched_t.shape[0] else math.inf
    for j in range(4):
        r = rin[RIN_RATE + j]
        if r < 0.0 and x[X_ROTOR + j] > 0.0:
            t_b = min(t_b, t + x[X_ROTOR + j] / -r)
    return t_b


@njit(cache=True)
def segment_at(t: float, t_p: float, sched_t: np.ndarray) -> int:
    """Index of the segment in force at time ``t`` (0 before the second start)."""
    seg = 0
    while seg + 1 < sched_t.shape[0] and t_p + sched_t[seg + 1] <= t:
        seg += 1
    return seg
