"""Small quaternion operations on rotation vectors, shared by the sensors and the estimators.

Quaternions are scalar first (Hamilton product), body to inertial; a
rotation vector ``phi`` (rad) in body axes rotates ``q`` into
``q (x) exp(phi)``, with ``exp(phi) = (cos |phi|/2, sin(|phi|/2) phi/|phi|)``.
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.quaternion import rotation_matrix


@compiled
def dcm(q: np.ndarray, C: np.ndarray) -> None:
    """Fill ``C`` (3x3) with the body-to-inertial rotation of ``q`` (normalised here).

    ``quaternion.rotation_matrix`` as a called function: it is inlined wherever it
    is used, and the estimators use it often (one compiled copy keeps the loop's
    compile time down).
    """
    rotation_matrix(q, C)


@compiled
def rotate_by(q: np.ndarray, px: float, py: float, pz: float) -> None:
    """``q <- q (x) exp(phi)`` in place (``phi`` in body axes, rad), normalised."""
    a = math.sqrt(px * px + py * py + pz * pz)
    if a == 0.0:
        return
    c = math.cos(0.5 * a)
    s = math.sin(0.5 * a) / a
    bw = c
    bx = s * px
    by = s * py
    bz = s * pz
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    r0 = q0 * bw - q1 * bx - q2 * by - q3 * bz
    r1 = q0 * bx + q1 * bw + q2 * bz - q3 * by
    r2 = q0 * by - q1 * bz + q2 * bw + q3 * bx
    r3 = q0 * bz + q1 * by - q2 * bx + q3 * bw
    n = math.sqrt(r0 * r0 + r1 * r1 + r2 * r2 + r3 * r3)
    q[0] = r0 / n
    q[1] = r1 / n
    q[2] = r2 / n
    q[3] = r3 / n


@compiled
def error_vector(q_hat: np.ndarray, q: np.ndarray) -> tuple[float, float, float]:
    """The rotation vector ``phi`` (rad, body axes of ``q_hat``) with ``q = q_hat (x) exp(phi)``.

    The shorter of the two rotations (the sign of ``q`` does not matter).
    """
    w = q_hat[0] * q[0] + q_hat[1] * q[1] + q_hat[2] * q[2] + q_hat[3] * q[3]
    x = q_hat[0] * q[1] - q_hat[1] * q[0] - q_hat[2] * q[3] + q_hat[3] * q[2]
    y = q_hat[0] * q[2] + q_hat[1] * q[3] - q_hat[2] * q[0] - q_hat[3] * q[1]
    z = q_hat[0] * q[3] - q_hat[1] * q[2] + q_hat[2] * q[1] - q_hat[3] * q[0]
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    v = math.sqrt(x * x + y * y + z * z)
    if v == 0.0:
        return 0.0, 0.0, 0.0
    angle = 2.0 * math.atan2(v, w)
    return angle * x / v, angle * y / v, angle * z / v


@compiled
def error_angle(q_hat: np.ndarray, q: np.ndarray) -> float:
    """The angle (rad) of ``q_hat (x) q^-1``: how far the estimate is from the truth."""
    n1 = math.sqrt(q_hat[0] ** 2 + q_hat[1] ** 2 + q_hat[2] ** 2 + q_hat[3] ** 2)
    n2 = math.sqrt(q[0] ** 2 + q[1] ** 2 + q[2] ** 2 + q[3] ** 2)
    w = (q_hat[0] * q[0] + q_hat[1] * q[1] + q_hat[2] * q[2] + q_hat[3] * q[3]) / (n1 * n2)
    x = q_hat[0] * q[1] - q_hat[1] * q[0] - q_hat[2] * q[3] + q_hat[3] * q[2]
    y = q_hat[0] * q[2] + q_hat[1] * q[3] - q_hat[2] * q[0] - q_hat[3] * q[1]
    z = q_hat[0] * q[3] - q_hat[1] * q[2] + q_hat[2] * q[1] - q_hat[3] * q[0]
    v = math.sqrt(x * x + y * y + z * z) / (n1 * n2)
    return 2.0 * math.atan2(v, abs(w))
