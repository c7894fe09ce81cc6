"""The run settings every packing uses: the control rate, units, integrator defaults."""

from __future__ import annotations

# The defaults of the control rate and of the integrator's tolerances are the resolve
# step's (inputs/resolve.py), and so is the unit; their names stay here for the code
# that reads them from here.
from quadimpact.inputs.resolve import CONTROL_RATE_HZ, DEFAULT_ATOL, DEFAULT_RTOL, RPM

__all__ = [
    "CONTROL_RATE_HZ",
    "DEFAULT_ATOL",
    "DEFAULT_RTOL",
    "EVENT_TOL_S",
    "FRICTION_V_REG_M_S",
    "MAX_STEPS_PER_S",
    "MIN_STEP_BUDGET",
    "RPM",
    "V_MIN_M_S",
]


EVENT_TOL_S = 1e-12

V_MIN_M_S = 1e-3  # floor of v_i in the damping coefficient (docs/MODEL.md 4)

FRICTION_V_REG_M_S = 1e-2  # friction regularisation velocity

# The step budget of a run, accepted plus rejected steps (docs/NUMERICS.md, "Step
# budget"): 20,000 per simulated second, at least 20,000: 60,000 for a 3-s trial, 53 x
# the median of the benchmark's slowest task (1,130) and 8 x its slowest trial (7,932).
# A run that would exceed it fails: status "failed", reason "step budget exhausted".
MAX_STEPS_PER_S = 20_000
MIN_STEP_BUDGET = 20_000
