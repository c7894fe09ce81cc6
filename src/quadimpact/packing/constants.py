"""The run settings every packing uses: the control rate, units, integrator defaults."""

from __future__ import annotations

import numpy as np

__all__ = [
    "CONTROL_RATE_HZ",
    "DEFAULT_ATOL",
    "DEFAULT_RTOL",
    "EVENT_TOL_S",
    "FRICTION_V_REG_M_S",
    "MAX_STEPS_PER_S",
    "RPM",
    "V_MIN_M_S",
]

CONTROL_RATE_HZ = 200.0

RPM = 2.0 * np.pi / 60.0  # rad/s per rpm

# Integrator defaults, chosen by measurement (docs/NUMERICS.md,
# benchmarks/bench_tolerance.py): tightening both tenfold changes delta_init
# of the paper example by far less than 1e-4 relative.
DEFAULT_RTOL = 1e-8

DEFAULT_ATOL = 1e-10

EVENT_TOL_S = 1e-12

V_MIN_M_S = 1e-3  # floor of v_i in the damping coefficient (docs/MODEL.md 4)

FRICTION_V_REG_M_S = 1e-2  # friction regularisation velocity

MAX_STEPS_PER_S = 2_000_000
