"""A controller plug-in, from its template: copy this file, change ``step``, register, fly.

A controller is three things (docs/CONTROLLERS.md, "Plugging in a controller"):

1. its **parameters**: a pydantic model, validated, with defaults and units in
   the names; scenario files set them under ``[controller_params]``;
2. its **step**: a compiled function called at every control tick (200 Hz)
   with the records of the loop, which it reads by name
   (``quadimpact.core.named``), and which writes the four rotor-speed commands;
3. a **name**, under which ``register_controller`` makes it a controller like
   the built-ins: in scenario files, sweeps, studies and ``quadimpact run``.

This one holds the scenario's altitude and attitude references: a PD law on
the altitude (with an integral it keeps in its memory) and on the Z-Y-X Euler
angles, torques scaled by the inertia, then the vehicle's allocation. It reads
the estimate of the state (the true state with the ``ideal`` estimator), as an
on-board controller would.

Run it: ``python examples/controller_template.py`` (the first run of a process
compiles the step alone, a second or two; the loop is the cached one, which
calls the step by its address).
"""

from __future__ import annotations

import math

from numba import njit
from pydantic import BaseModel, ConfigDict

from quadimpact import FlightScenario, register_controller, simulate
from quadimpact.core import named
from quadimpact.inputs.controllers import param_index


class HoldParams(BaseModel):
    """The parameters (``[controller_params]``), with units in the names."""

    model_config = ConfigDict(extra="forbid", frozen=True)
    k_altitude_1_s2: float = 4.0  # altitude error -> vertical acceleration
    k_climb_1_s: float = 3.0  # climb-rate error -> vertical acceleration
    k_integral_1_s3: float = 1.0  # altitude error integral -> vertical acceleration
    k_attitude_1_s2: float = 50.0  # roll and pitch error -> angular acceleration
    k_rate_1_s: float = 12.0  # roll and pitch rate -> angular acceleration
    k_yaw_1_s2: float = 2.0  # yaw error -> yaw acceleration (the rotors' drag is weak, and
    k_yaw_rate_1_s: float = 2.0  # their spin-up reaction opposes it: low yaw gains)


# Where each parameter is in the packed block: constants the compiled step reads by name.
K_ALT = param_index(HoldParams, "k_altitude_1_s2")
K_CLIMB = param_index(HoldParams, "k_climb_1_s")
K_INT = param_index(HoldParams, "k_integral_1_s3")
K_ATT = param_index(HoldParams, "k_attitude_1_s2")
K_RATE = param_index(HoldParams, "k_rate_1_s")
K_YAW = param_index(HoldParams, "k_yaw_1_s2")
K_YAW_RATE = param_index(HoldParams, "k_yaw_rate_1_s")
# Its own memory (``mem``, kept between ticks; its last slot, ``MEM_STAGE``, is reported
# as its stage).
MEM_INTEGRAL = 1  # the altitude error's integral, m s


@njit
def hold_step(t, meas, ctrl, mem, veh, dt, cmd):
    """One control tick: read the estimate, compute thrust and torques, write ``cmd`` (rad/s)."""
    p = named.params(ctrl)
    q0, q1, q2, q3 = named.attitude(meas)  # body -> inertial, scalar first
    rates = named.body_rates(meas)  # rad/s, body FRD
    v_body = named.velocity_body(meas)  # m/s, body FRD
    altitude = -named.position(meas)[2]  # NED: z points down
    h_ref, roll_ref, pitch_ref, yaw_ref = named.references(ctrl)
    mass, g = named.mass(veh), named.gravity(veh)
    inertia = named.inertia(veh)

    # the attitude matrix's last row gives the climb rate and the Z-Y-X angles
    c20 = 2.0 * (q1 * q3 - q0 * q2)
    c21 = 2.0 * (q2 * q3 + q0 * q1)
    c22 = 1.0 - 2.0 * (q1 * q1 + q2 * q2)
    climb = -(c20 * v_body[0] + c21 * v_body[1] + c22 * v_body[2])
    roll = math.atan2(c21, c22)
    pitch = -math.asin(max(-1.0, min(1.0, c20)))
    yaw = math.atan2(2.0 * (q1 * q2 + q0 * q3), 1.0 - 2.0 * (q2 * q2 + q3 * q3))

    # altitude: PD with an integral kept in the controller's memory
    error = h_ref - altitude
    mem[MEM_INTEGRAL] += error * dt
    a_up = p[K_ALT] * error - p[K_CLIMB] * climb + p[K_INT] * mem[MEM_INTEGRAL]
    thrust = mass * (g + a_up) / max(c22, 0.5)  # N, along -z body

    # attitude: PD on the angles (yaw error wrapped), torques = inertia x acceleration
    yaw_error = (yaw_ref - yaw + math.pi) % (2.0 * math.pi) - math.pi
    accel = (
        p[K_ATT] * (roll_ref - roll) - p[K_RATE] * rates[0],
        p[K_ATT] * (pitch_ref - pitch) - p[K_RATE] * rates[1],
        p[K_YAW] * yaw_error - p[K_YAW_RATE] * rates[2],
    )
    torque = [0.0, 0.0, 0.0]
    for i in range(3):
        for k in range(3):
            torque[i] += inertia[i, k] * accel[k]

    # the vehicle's allocation: squared rotor speeds of thrust and torques, never negative
    a_inv = named.allocation_inverse(ctrl)
    for j in range(4):
        square = a_inv[j, 0] * thrust
        for i in range(3):
            square += a_inv[j, 1 + i] * torque[i]
        cmd[j] = math.sqrt(max(square, 0.0))


register_controller(
    "template-hold",
    step=hold_step,
    params=HoldParams,
    description="the plug-in template: PD altitude and attitude hold (examples/)",
    replace=True,
)


if __name__ == "__main__":
    # a hover started 0.3 m low with 5 deg of roll: the plug-in brings it back
    scenario = FlightScenario(
        controller="template-hold", position_m=(0.0, 0.0, -1.7), euler_deg=(5.0, 0.0, 0.0),
        altitude_ref_m=2.0, attitude_ref_deg=(0.0, 0.0, 0.0), final_time_s=4.0,
    )  # fmt: skip
    result = simulate(scenario)
    end = result.timeseries.iloc[-1]
    print(result.summary["outcome"])
    print(
        f"altitude at the end {-end['z_m']:.4f} m (reference 2 m), roll {end['roll_deg']:.4f} deg"
    )
