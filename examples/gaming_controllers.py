"""Two controllers that game a survival criterion: suite 2 of the benchmark ranks them last.

Suite 1 of the benchmark counted "less than 2 m of height lost" on the pole
and edge tasks and a declared stage 4 on the wall (docs/BENCHMARK.md 8). A
law that levels and climbs away for ever met both. Suite 2 counts a held
hover instead (docs/BENCHMARK.md 1.2). These two plug-ins keep that honest;
the tests fly them (``tests/studies/benchmark/test_gaming.py``):

* ``climb-away``: until the detection it holds its rotor speeds; then it
  tilts 20 deg away from the detected wall normal, climbs at 1.5 m/s and
  never settles. It declares its recovery (stage 4) at once, as a law
  gaming suite 1's wall criterion would.
* ``do-nothing``: it holds the rotor speeds it has, before and after the
  detection.

Benchmark one: ``quadimpact benchmark --quick --plugin examples/gaming_controllers.py
--controller climb-away --out DIR``.
"""

from __future__ import annotations

import math

from numba import njit
from pydantic import BaseModel, ConfigDict

from quadimpact import register_controller
from quadimpact.core import named
from quadimpact.core.controllers.common import allocate, linearised_torques
from quadimpact.core.layout import MEM_STAGE
from quadimpact.core.quaternion import euler_zyx
from quadimpact.inputs.controllers import param_index


class ClimbAwayParams(BaseModel):
    """The parameters, with units in the names."""

    model_config = ConfigDict(extra="forbid", frozen=True)
    tilt_deg: float = 20.0  # lean away from the detected wall normal
    climb_m_s: float = 1.5  # climb rate held after the detection
    k_climb_1_s: float = 4.0  # climb-rate error -> vertical acceleration
    k_attitude_1_s2: float = 60.0  # roll and pitch error -> angular acceleration
    k_rate_1_s: float = 14.0  # roll and pitch rate -> angular acceleration


TILT = param_index(ClimbAwayParams, "tilt_deg")
CLIMB = param_index(ClimbAwayParams, "climb_m_s")
K_CLIMB = param_index(ClimbAwayParams, "k_climb_1_s")
K_ATT = param_index(ClimbAwayParams, "k_attitude_1_s2")
K_RATE = param_index(ClimbAwayParams, "k_rate_1_s")


@njit
def _hold_rotors(meas, cmd):
    speeds = named.rotor_speeds(meas)
    for j in range(cmd.shape[0]):
        cmd[j] = speeds[j]


@njit
def climb_away_step(t, meas, ctrl, mem, veh, dt, cmd):
    """One tick: hold until the detection, then lean away and climb for ever."""
    if not named.detected(meas):
        _hold_rotors(meas, cmd)
        return
    p = named.params(ctrl)
    q = named.attitude(meas)
    rates = named.body_rates(meas)
    v = named.velocity_body(meas)
    roll, pitch, yaw = euler_zyx(q)  # rad, Z-Y-X
    n = named.wall_normal(meas)  # inertial NED, out of the obstacle
    horizontal = math.hypot(n[0], n[1])
    nx, ny = (n[0] / horizontal, n[1] / horizontal) if horizontal > 1e-9 else (0.0, 0.0)
    ax = math.cos(yaw) * nx + math.sin(yaw) * ny  # the away direction in heading axes
    ay = -math.sin(yaw) * nx + math.cos(yaw) * ny
    lean = math.tan(math.radians(p[TILT]))
    pitch_ref = -math.atan(ax * lean)  # nose down to accelerate forward
    roll_ref = math.atan(ay * lean)
    c20 = 2.0 * (q[1] * q[3] - q[0] * q[2])
    c21 = 2.0 * (q[2] * q[3] + q[0] * q[1])
    c22 = 1.0 - 2.0 * (q[1] * q[1] + q[2] * q[2])
    climb = -(c20 * v[0] + c21 * v[1] + c22 * v[2])  # m/s, up positive
    thrust = (
        named.mass(veh) * (named.gravity(veh) + p[K_CLIMB] * (p[CLIMB] - climb)) / max(c22, 0.3)
    )
    tx, ty, tz = linearised_torques(
        rates, veh, -p[K_ATT] * (roll - roll_ref) - p[K_RATE] * rates[0],
        -p[K_ATT] * (pitch - pitch_ref) - p[K_RATE] * rates[1], -2.0 * rates[2],
    )  # fmt: skip
    allocate(ctrl, thrust, tx, ty, tz, cmd)
    mem[MEM_STAGE] = 4.0  # declares its recovery at once


class NoParams(BaseModel):
    """No parameters."""

    model_config = ConfigDict(extra="forbid", frozen=True)


@njit
def do_nothing_step(t, meas, ctrl, mem, veh, dt, cmd):
    """One tick: hold the rotor speeds it has, whatever happens."""
    _hold_rotors(meas, cmd)


register_controller(
    "climb-away",
    step=climb_away_step,
    params=ClimbAwayParams,
    description="games suite 1: lean away, climb for ever (examples/gaming_controllers.py)",
    replace=True,
)
register_controller(
    "do-nothing",
    step=do_nothing_step,
    params=NoParams,
    description="holds its rotor speeds whatever happens (examples/gaming_controllers.py)",
    replace=True,
)
