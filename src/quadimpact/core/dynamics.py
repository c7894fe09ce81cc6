"""The right-hand side: gravity + rotors + contact, then the rigid body.

Forces and moments are summed piece by piece (body components), so that
further terms (aerodynamic drag, blade flapping) can be added as their own
functions without touching the others.
"""

import numpy as np
from numba import njit

from .contact import bumper_plane_contact, friction_force, normal_force
from .layout import (
    O_DOUBLE_BUMPER1_YAW,
    O_MU,
    O_V_REG,
    O_YAW_REACTION_PAPER,
    RIN_CMD,
    RIN_FF,
    RIN_FIRST_ORDER,
    RIN_RATE,
    S_NORMAL,
    V_GRAVITY,
    V_MASS,
    V_TAU_M,
    X_QUAT,
    X_ROTOR,
)
from .quaternion import rotation_matrix
from .rigid_body import rigid_body_derivative
from .rotors import rotor_wrench


@njit(cache=True)
def contact_wrench(
    x: np.ndarray,
    C: np.ndarray,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    c_active: np.ndarray,
    c_lam: np.ndarray,
) -> tuple[float, float, float, float, float, float]:
    """Sum of the contact forces and moments of all active bumper-surface contacts.

    ``c_active[4 s + j]`` says whether bumper ``j`` is in an episode with
    surface ``s`` (set at the located onset); ``c_lam`` holds its damping
    coefficient, fixed at that onset. Returns force and moment, body frame.
    """
    fx = 0.0
    fy = 0.0
    fz = 0.0
    mx = 0.0
    my = 0.0
    mz = 0.0
    mu = opts[O_MU]
    double_b1 = opts[O_DOUBLE_BUMPER1_YAW] > 0.5
    for s in range(surf.shape[0]):
        nx = surf[s, S_NORMAL]
        ny = surf[s, S_NORMAL + 1]
        nz = surf[s, S_NORMAL + 2]
        for j in range(4):
            k = 4 * s + j
            if c_active[k] < 0.5:
                continue
            d, dd, rx, ry, rz, vcx, vcy, vcz = bumper_plane_contact(x, C, veh, j, surf, s)
            fn = normal_force(veh, d, dd, c_lam[k])
            if fn <= 0.0:
                continue
            gx = fn * nx
            gy = fn * ny
            gz = fn * nz
            if mu > 0.0:
                tx, ty, tz = friction_force(fn, mu, opts[O_V_REG], vcx, vcy, vcz, nx, ny, nz)
                gx += tx
                gy += ty
                gz += tz
            # inertial -> body: C^T g
            bx = C[0, 0] * gx + C[1, 0] * gy + C[2, 0] * gz
            by = C[0, 1] * gx + C[1, 1] * gy + C[2, 1] * gz
            bz = C[0, 2] * gx + C[1, 2] * gy + C[2, 2] * gz
            fx += bx
            fy += by
            fz += bz
            mx += ry * bz - rz * by
            my += rz * bx - rx * bz
            mzj = rx * by - ry * bx
            mz += mzj
            if double_b1 and j == 0:
                mz += mzj  # paper replica: bumper 1's yaw moment counted twice
    return fx, fy, fz, mx, my, mz


@njit(cache=True)
def rotor_rates(x: np.ndarray, veh: np.ndarray, rin: np.ndarray, omega_dot: np.ndarray) -> None:
    """Rotor accelerations (rad/s^2) of the current rotor mode, into ``omega_dot``."""
    if rin[RIN_FIRST_ORDER] > 0.5:
        for j in range(4):
            omega_dot[j] = (rin[RIN_CMD + j] - x[X_ROTOR + j]) / veh[V_TAU_M]
    else:
        for j in range(4):
            omega_dot[j] = rin[RIN_RATE + j]


@njit(cache=True)
def state_derivative(
    x: np.ndarray,
    xdot: np.ndarray,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    rin: np.ndarray,
    c_active: np.ndarray,
    c_lam: np.ndarray,
    C: np.ndarray,
    omega_dot: np.ndarray,
) -> None:
    """Full state derivative ``xdot = f(x)`` (the system is autonomous).

    ``C`` (3x3) and ``omega_dot`` (4,) are work arrays.
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
    tz, mx, my, mz = rotor_wrench(x, omega_dot, veh, opts[O_YAW_REACTION_PAPER] > 0.5)
    fz += tz
    cfx, cfy, cfz, cmx, cmy, cmz = contact_wrench(x, C, veh, surf, opts, c_active, c_lam)
    rigid_body_derivative(
        x, xdot, C, veh, fx + cfx, fy + cfy, fz + cfz, mx + cmx, my + cmy, mz + cmz
    )
