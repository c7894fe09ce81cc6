"""Newton-Euler equations in body axes with quaternion kinematics (paper eqs. 1-4).

``m (v_dot + omega x v) = F``, ``I omega_dot + omega x (I omega) = M``,
``p_dot = C v``, ``q_dot = 1/2 q (x) [0, omega]``.
"""

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import X_OMEGA, X_POS, X_QUAT, X_VEL
from quadimpact.core.vehicle_slots import V_INERTIA, V_INERTIA_INV, V_MASS


@compiled
def rigid_body_derivative(
    x: np.ndarray,
    xdot: np.ndarray,
    C: np.ndarray,
    veh: np.ndarray,
    fx: float,
    fy: float,
    fz: float,
    mx: float,
    my: float,
    mz: float,
) -> None:
    """Write the derivative of the 13 rigid-body states into ``xdot``.

    ``(fx, fy, fz)`` is the total force and ``(mx, my, mz)`` the total moment
    about the CM, both in body components (N, N m); ``C`` is the
    body-to-inertial rotation of ``x``'s quaternion.
    """
    m = veh[V_MASS]
    u = x[X_VEL]
    v = x[X_VEL + 1]
    w = x[X_VEL + 2]
    p = x[X_OMEGA]
    q = x[X_OMEGA + 1]
    r = x[X_OMEGA + 2]
    # position: p_dot = C v
    xdot[X_POS] = C[0, 0] * u + C[0, 1] * v + C[0, 2] * w
    xdot[X_POS + 1] = C[1, 0] * u + C[1, 1] * v + C[1, 2] * w
    xdot[X_POS + 2] = C[2, 0] * u + C[2, 1] * v + C[2, 2] * w
    # translation: v_dot = F/m - omega x v
    xdot[X_VEL] = fx / m - (q * w - r * v)
    xdot[X_VEL + 1] = fy / m - (r * u - p * w)
    xdot[X_VEL + 2] = fz / m - (p * v - q * u)
    # quaternion: q_dot = 1/2 q (x) [0, omega]
    q0 = x[X_QUAT]
    q1 = x[X_QUAT + 1]
    q2 = x[X_QUAT + 2]
    q3 = x[X_QUAT + 3]
    xdot[X_QUAT] = 0.5 * (-q1 * p - q2 * q - q3 * r)
    xdot[X_QUAT + 1] = 0.5 * (q0 * p + q2 * r - q3 * q)
    xdot[X_QUAT + 2] = 0.5 * (q0 * q + q3 * p - q1 * r)
    xdot[X_QUAT + 3] = 0.5 * (q0 * r + q1 * q - q2 * p)
    # rotation: I omega_dot = M - omega x (I omega)
    I = veh[V_INERTIA : V_INERTIA + 9]
    hx = I[0] * p + I[1] * q + I[2] * r
    hy = I[3] * p + I[4] * q + I[5] * r
    hz = I[6] * p + I[7] * q + I[8] * r
    ax = mx - (q * hz - r * hy)
    ay = my - (r * hx - p * hz)
    az = mz - (p * hy - q * hx)
    J = veh[V_INERTIA_INV : V_INERTIA_INV + 9]
    xdot[X_OMEGA] = J[0] * ax + J[1] * ay + J[2] * az
    xdot[X_OMEGA + 1] = J[3] * ax + J[4] * ay + J[5] * az
    xdot[X_OMEGA + 2] = J[6] * ax + J[7] * ay + J[8] * az
