"""Benchmark your own recovery controller: register it, then run ``quadimpact benchmark --quick``.

A plug-in controller (docs/CONTROLLERS.md, "Plugging in a controller") flies
every trial of the suite from its start (docs/BENCHMARK.md 2). This one is a
deliberately plain law, to show the interface, not to win:

* before the impact is detected it holds the rotor speeds it has;
* from the detection on it levels the vehicle (PD on the Z-Y-X roll and
  pitch, torques scaled by the inertia) with a thrust that holds the climb
  rate at zero, and
* **declares its recovery**, as the wall task's criterion needs: it writes
  its stage into ``mem[MEM_STAGE]`` (1 from the detection, 4 once level
  within 0.2 rad, turning slower than 1 rad/s and not descending faster
  than 0.3 m/s). The grids' criterion (height lost) and the hover columns do
  not read it.

Run it: ``python examples/benchmark_controller.py [--out DIR]``. Measured on
the project's 2-core machine, shared with other jobs (1-minute load average
3.6 to 7.2), the workers at their default: 260 s (4.3 min) with the
reference rows in the benchmark cache (its 6 cells of ``level-first`` run);
1,087 s (18 min) and 993 s (16.5 min) when the code is new to the cache, as
on a first run, which computes the five reference controllers' 30 cells too.
These times were measured when each worker process compiled the loop around
the plug-in (30 s of CPU each, as measured then); a worker now compiles the step alone, a
second or two. The registration is at the top level of this file, so the sweeps'
worker processes, which import it again, register it too.
"""

from __future__ import annotations

import argparse

from numba import njit
from pydantic import BaseModel, ConfigDict

from quadimpact import register_controller
from quadimpact.core import named
from quadimpact.core.controllers.common import allocate, linearised_torques
from quadimpact.core.layout import MEM_STAGE
from quadimpact.core.quaternion import euler_zyx
from quadimpact.inputs.controllers import param_index


class LevelParams(BaseModel):
    """The parameters (``--param NAME=VALUE``), with units in the names."""

    model_config = ConfigDict(extra="forbid", frozen=True)
    k_attitude_1_s2: float = 60.0  # roll and pitch error -> angular acceleration
    k_rate_1_s: float = 14.0  # roll and pitch rate -> angular acceleration
    k_climb_1_s: float = 4.0  # climb-rate error -> vertical acceleration
    level_rad: float = 0.2  # declared recovered within this roll and pitch
    rate_rad_s: float = 1.0  # ... turning slower than this
    sink_m_s: float = 0.3  # ... and not descending faster than this


K_ATT = param_index(LevelParams, "k_attitude_1_s2")
K_RATE = param_index(LevelParams, "k_rate_1_s")
K_CLIMB = param_index(LevelParams, "k_climb_1_s")
LEVEL = param_index(LevelParams, "level_rad")
RATE = param_index(LevelParams, "rate_rad_s")
SINK = param_index(LevelParams, "sink_m_s")


@njit
def level_step(t, meas, ctrl, mem, veh, dt, cmd):
    """One tick: hold the rotors until the detection, then level and declare the recovery."""
    if not named.detected(meas):
        speeds = named.rotor_speeds(meas)
        for j in range(4):
            cmd[j] = speeds[j]
        return
    p = named.params(ctrl)
    q = named.attitude(meas)
    rates = named.body_rates(meas)
    v = named.velocity_body(meas)
    roll, pitch, _ = euler_zyx(q)  # rad, Z-Y-X
    # the vertical: the third row of the attitude matrix (body to inertial)
    c20 = 2.0 * (q[1] * q[3] - q[0] * q[2])
    c21 = 2.0 * (q[2] * q[3] + q[0] * q[1])
    c22 = 1.0 - 2.0 * (q[1] * q[1] + q[2] * q[2])
    climb = -(c20 * v[0] + c21 * v[1] + c22 * v[2])  # m/s, up positive
    thrust = named.mass(veh) * (named.gravity(veh) - p[K_CLIMB] * climb) / max(c22, 0.3)
    # angular accelerations (rad/s^2) to torques, then the vehicle's allocation: the
    # built-in controllers' own compiled helpers (quadimpact.core.controllers.common)
    tx, ty, tz = linearised_torques(
        rates, veh, -p[K_ATT] * roll - p[K_RATE] * rates[0],
        -p[K_ATT] * pitch - p[K_RATE] * rates[1], -2.0 * rates[2],
    )  # fmt: skip
    allocate(ctrl, thrust, tx, ty, tz, cmd)
    # the stage: 1 from the detection, 4 (recovered) once level, slow and not sinking
    level = abs(roll) < p[LEVEL] and abs(pitch) < p[LEVEL]
    slow = abs(rates[0]) < p[RATE] and abs(rates[1]) < p[RATE]
    if mem[MEM_STAGE] < 4.0:
        mem[MEM_STAGE] = 4.0 if level and slow and climb > -p[SINK] else 1.0


register_controller(
    "level-first",
    step=level_step,
    params=LevelParams,
    description="the benchmark example: hold, then level (examples/benchmark_controller.py)",
    replace=True,
)


if __name__ == "__main__":
    from quadimpact.cli import main

    parser = argparse.ArgumentParser(description="Benchmark the level-first plug-in (--quick).")
    parser.add_argument("--out", default="results/benchmark-level-first", help="Folder.")
    args = parser.parse_args()
    main(["benchmark", "--quick", "--controller", "level-first", "--out", args.out])
