"""Quaternion and rotation helpers for the compiled core.

Quaternions are scalar first, Hamilton product, and ``C(q)`` maps body
components to inertial components (``a_I = C a_B``), as in docs/MODEL.md section 1.
Euler angles are aerospace ZYX: ``C = Rz(psi) Ry(theta) Rx(phi)``.
"""

import math

import numpy as np
from numba import njit

from quadimpact.core.compiled import compiled


@njit(cache=True, inline="always")
def rotation_matrix(q: np.ndarray, C: np.ndarray) -> None:
    """Fill ``C`` (3x3) with the body-to-inertial rotation of ``q`` (normalised here)."""
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    q0 = q[0] / n
    q1 = q[1] / n
    q2 = q[2] / n
    q3 = q[3] / n
    C[0, 0] = 1.0 - 2.0 * (q2 * q2 + q3 * q3)
    C[0, 1] = 2.0 * (q1 * q2 - q0 * q3)
    C[0, 2] = 2.0 * (q1 * q3 + q0 * q2)
    C[1, 0] = 2.0 * (q1 * q2 + q0 * q3)
    C[1, 1] = 1.0 - 2.0 * (q1 * q1 + q3 * q3)
    C[1, 2] = 2.0 * (q2 * q3 - q0 * q1)
    C[2, 0] = 2.0 * (q1 * q3 - q0 * q2)
    C[2, 1] = 2.0 * (q2 * q3 + q0 * q1)
    C[2, 2] = 1.0 - 2.0 * (q1 * q1 + q2 * q2)


@compiled
def euler_zyx(q: np.ndarray) -> tuple[float, float, float]:
    """Roll, pitch, yaw (rad) of the attitude ``q`` (ZYX; pitch in [-pi/2, pi/2])."""
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    q0 = q[0] / n
    q1 = q[1] / n
    q2 = q[2] / n
    q3 = q[3] / n
    roll = math.atan2(2.0 * (q0 * q1 + q2 * q3), 1.0 - 2.0 * (q1 * q1 + q2 * q2))
    s = 2.0 * (q0 * q2 - q3 * q1)
    s = min(1.0, max(-1.0, s))
    pitch = math.asin(s)
    yaw = math.atan2(2.0 * (q0 * q3 + q1 * q2), 1.0 - 2.0 * (q2 * q2 + q3 * q3))
    return roll, pitch, yaw


@compiled
def wrap_pi(a: float) -> float:
    """Wrap an angle (rad) to (-pi, pi]."""
    w = a - 2.0 * math.pi * math.floor((a + math.pi) / (2.0 * math.pi))
    if w <= -math.pi:
        w += 2.0 * math.pi
    return w


@compiled
def normalise_quaternion(x: np.ndarray, offset: int) -> None:
    """Scale ``x[offset:offset+4]`` to unit norm in place."""
    n = math.sqrt(x[offset] ** 2 + x[offset + 1] ** 2 + x[offset + 2] ** 2 + x[offset + 3] ** 2)
    for i in range(4):
        x[offset + i] /= n
