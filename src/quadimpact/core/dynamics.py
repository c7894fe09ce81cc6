"""The right-hand side: gravity + rotors + contact, then the rigid body.

Forces and moments are summed piece by piece (body components), so that
further terms (aerodynamic drag, blade flapping) can be added as their own
functions without touching the others.
"""

import numpy as np

from quadimpact.core.actuators import rotor_rates
from quadimpact.core.compiled import compiled
from quadimpact.core.contact import contact_wrench
from quadimpact.core.layout import O_SPINUP_PAPER, O_YAW_REACTION_PAPER, X_QUAT, X_ROTOR
from quadimpact.core.quaternion import rotation_matrix
from quadimpact.core.records import Data, Model, Work
from quadimpact.core.rigid_body import rigid_body_derivative
from quadimpact.core.rotors import (
    RIN_FF,
    RIN_FIRST_ORDER,
    rotor_wrench,
)
from quadimpact.core.vehicle_slots import V_GRAVITY, V_MASS, V_N_ROTORS


@compiled(inline="always")
def _rotor_states(
    x: np.ndarray, xdot: np.ndarray, veh: np.ndarray, rin: np.ndarray, omega_dot: np.ndarray, n: int
) -> None:
    """The ``n`` rotor speeds' derivatives into ``xdot``; ``omega_dot``: the rates of the
    reaction torque (the prescribed ones in the ideal and scheduled modes)."""
    rotor_rates(x, veh, rin, omega_dot, n)
    for j in range(n):
        xdot[X_ROTOR + j] = omega_dot[j]
    if rin[RIN_FIRST_ORDER] < 0.5:
        # ideal / scheduled rotors: the reaction torque uses the prescribed rate
        for j in range(n):
            omega_dot[j] = rin[RIN_FF + j]


@compiled(inline="always")
def state_derivative(x: np.ndarray, xdot: np.ndarray, m: Model, d: Data, w: Work) -> None:
    """Full state derivative ``xdot = f(x)`` (the system is autonomous).

    ``m`` is the run (vehicle, features, shapes, options), ``d.rin`` the rotor
    inputs of the interval, ``d.cs`` the contact pairs (which are in an
    episode, with which damping). Uses ``w.C`` and ``w.wdot`` as work space; on
    return ``w.C`` is the rotation of ``x`` and ``w.wdot`` the rotor rates used
    in the reaction torque.
    """
    C = w.C
    omega_dot = w.wdot
    veh = m.veh
    rin = d.rin
    rotation_matrix(x[X_QUAT : X_QUAT + 4], C)
    n = int(veh[V_N_ROTORS])
    if n == 4:  # a quadrotor: the loops' count known to the compiler (unrolled, as before)
        _rotor_states(x, xdot, veh, rin, omega_dot, 4)
    else:
        _rotor_states(x, xdot, veh, rin, omega_dot, n)
    mg = veh[V_MASS] * veh[V_GRAVITY]
    fx = mg * C[2, 0]
    fy = mg * C[2, 1]
    fz = mg * C[2, 2]
    opts = m.opts
    tz, mx, my, mz = rotor_wrench(
        x, omega_dot, veh, opts[O_YAW_REACTION_PAPER] > 0.5, opts[O_SPINUP_PAPER] > 0.5
    )
    fz += tz
    cfx, cfy, cfz, cmx, cmy, cmz = contact_wrench(x, C, m, d.cs)
    rigid_body_derivative(
        x, xdot, C, veh, fx + cfx, fy + cfy, fz + cfz, mx + cmx, my + cmy, mz + cmz
    )
