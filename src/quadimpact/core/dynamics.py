"""The right-hand side: gravity + rotors + contact, then the rigid body.

Forces and moments are summed piece by piece (body components), so that
further terms (aerodynamic drag, blade flapping) can be added as their own
functions without touching the others.
"""

import numpy as np
from numba import njit

from .actuators import rotor_rates
from .contact import contact_wrench
from .layout import (
    O_SPINUP_PAPER,
    O_YAW_REACTION_PAPER,
    RIN_FF,
    RIN_FIRST_ORDER,
    V_GRAVITY,
    V_MASS,
    X_QUAT,
    X_ROTOR,
)
from .quaternion import rotation_matrix
from .rigid_body import rigid_body_derivative
from .rotors import rotor_wrench


@njit(cache=True)
def state_derivative(
    x: np.ndarray,
    xdot: np.ndarray,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    rin: np.ndarray,
    cs: np.ndarray,
    C: np.ndarray,
    omega_dot: np.ndarray,
) -> None:
    """Full state derivative ``xdot = f(x)`` (the system is autonomous).

    ``rin`` holds the rotor inputs of the interval, ``cs`` the contact pairs
    (which are in an episode, with which damping). ``C`` (3x3) and
    ``omega_dot`` (4,) are work arrays; on return ``C`` is the rotation of ``x``.
    """
    rotation_matrix(x[X_QUAT : X_QUAT + 4], C)
    rotor_rates(x, veh, rin, omega_dot)
    for j in range(4):
        xdot[X_ROTOR + j] = omega_dot[j]
    if rin[RIN_FIRST_ORDER] < 0.5:
        # ideal / scheduled rotors: the reaction torque uses the prescribed rate
        for j in range(4):
            omega_dot[j] = rin[RIN_FF + j]
    mg = veh[V_MASS] * veh[V_GRAVITY]
    fx = mg * C[2, 0]
    fy = mg * C[2, 1]
    fz = mg * C[2, 2]
    tz, mx, my, mz = rotor_wrench(
        x, omega_dot, veh, opts[O_YAW_REACTION_PAPER] > 0.5, opts[O_SPINUP_PAPER] > 0.5
    )
    fz += tz
    cfx, cfy, cfz, cmx, cmy, cmz = contact_wrench(x, C, veh, surf, opts, cs)
    rigid_body_derivative(
        x, xdot, C, veh, fx + cfx, fy + cfy, fz + cfz, mx + cmx, my + cmy, mz + cmz
    )
