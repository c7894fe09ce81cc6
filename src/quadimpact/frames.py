"""Attitude and frame conversions (vectorised NumPy).

Conventions (MODEL.md section 1):

- Inertial frame I: NED (X toward the default wall, Y right, Z down).
- Body frame B: FRD (x forward, y starboard, z down), origin at the CM.
- Quaternion ``q = [q0, q1, q2, q3]``: scalar first, Hamilton product. Its
  rotation matrix ``C(q)`` maps body components to inertial components,
  ``a_I = C a_B``.
- Euler angles: aerospace ZYX, ``C = Rz(yaw) Ry(pitch) Rx(roll)``; angles in
  radians here (the time-series table carries degrees).

Every function accepts a single quaternion of shape ``(4,)`` or a stack of
shape ``(..., 4)`` and broadcasts over the leading dimensions.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "GIMBAL_LOCK_COS",
    "body_to_inertial",
    "euler_zyx_to_quat",
    "quat_to_euler_zyx",
    "quat_to_matrix",
    "wrap_angle_rad",
]

#: Below this value of ``cos(pitch)`` the attitude is treated as gimbal-locked:
#: roll is set to 0 and the whole rotation about the vertical goes to yaw.
GIMBAL_LOCK_COS = 1e-9


def _as_quat(q: ArrayLike) -> NDArray[np.float64]:
    """Return ``q`` as a float array of shape ``(..., 4)``, normalised.

    The integrated quaternion drifts slowly from unit norm; normalising here
    makes every conversion a proper rotation.
    """
    a = np.asarray(q, dtype=np.float64)
    if a.shape[-1:] != (4,):
        raise ValueError(f"quaternion array must have a last axis of length 4 (got {a.shape})")
    norm = np.linalg.norm(a, axis=-1, keepdims=True)
    if np.any(norm == 0.0):
        raise ValueError("quaternion of zero norm cannot represent a rotation")
    return a / norm


def quat_to_matrix(q: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrix ``C(q)`` mapping body (FRD) to inertial (NED) components.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Attitude quaternion(s), scalar first, Hamilton convention,
        body -> inertial. Normalised before use.

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        ``C`` such that ``a_I = C @ a_B``. Column ``k`` of ``C`` is the body
        axis ``k`` expressed in the inertial frame.
    """
    a = _as_quat(q)
    q0, q1, q2, q3 = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    c = np.empty(a.shape[:-1] + (3, 3), dtype=np.float64)
    c[..., 0, 0] = 1.0 - 2.0 * (q2 * q2 + q3 * q3)
    c[..., 0, 1] = 2.0 * (q1 * q2 - q0 * q3)
    c[..., 0, 2] = 2.0 * (q1 * q3 + q0 * q2)
    c[..., 1, 0] = 2.0 * (q1 * q2 + q0 * q3)
    c[..., 1, 1] = 1.0 - 2.0 * (q1 * q1 + q3 * q3)
    c[..., 1, 2] = 2.0 * (q2 * q3 - q0 * q1)
    c[..., 2, 0] = 2.0 * (q1 * q3 - q0 * q2)
    c[..., 2, 1] = 2.0 * (q2 * q3 + q0 * q1)
    c[..., 2, 2] = 1.0 - 2.0 * (q1 * q1 + q2 * q2)
    return c


def wrap_angle_rad(angle: ArrayLike) -> NDArray[np.float64]:
    """Wrap angle(s) to the interval (-pi, pi] (radians)."""
    a = np.asarray(angle, dtype=np.float64)
    w = np.mod(a + np.pi, 2.0 * np.pi) - np.pi  # [-pi, pi)
    return np.where(w <= -np.pi, w + 2.0 * np.pi, w)


def quat_to_euler_zyx(
    q: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Aerospace ZYX Euler angles of the attitude ``q``.

    ``C(q) = Rz(yaw) Ry(pitch) Rx(roll)`` with ``C`` body (FRD) -> inertial (NED).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Attitude quaternion(s), scalar first, body -> inertial.

    Returns
    -------
    roll, pitch, yaw : numpy.ndarray, shape (...)
        Radians. ``roll`` and ``yaw`` in (-pi, pi], ``pitch`` in [-pi/2, pi/2].

    Notes
    -----
    Pitch is computed as ``atan2(-C31, hypot(C11, C21))`` rather than
    ``asin(-C31)``: the two agree, but the ``atan2`` form stays accurate near
    +-90 deg and never leaves the domain (no clipping needed). At gimbal lock
    (``cos(pitch) < GIMBAL_LOCK_COS``) only ``yaw - roll`` (pitch +90 deg) or
    ``yaw + roll`` (pitch -90 deg) is defined; roll is then reported as 0 and
    the rotation about the vertical as yaw, ``atan2(-C12, C22)``.
    """
    c = quat_to_matrix(q)
    c00, c10, c20 = c[..., 0, 0], c[..., 1, 0], c[..., 2, 0]
    c21, c22 = c[..., 2, 1], c[..., 2, 2]
    c01, c11 = c[..., 0, 1], c[..., 1, 1]
    cos_pitch = np.hypot(c00, c10)
    pitch = np.arctan2(-c20, cos_pitch)
    locked = cos_pitch < GIMBAL_LOCK_COS
    roll = np.where(locked, 0.0, np.arctan2(c21, c22))
    yaw = np.where(locked, np.arctan2(-c01, c11), np.arctan2(c10, c00))
    return wrap_angle_rad(roll), pitch, wrap_angle_rad(yaw)


def euler_zyx_to_quat(roll: ArrayLike, pitch: ArrayLike, yaw: ArrayLike) -> NDArray[np.float64]:
    """Quaternion of the ZYX Euler attitude ``C = Rz(yaw) Ry(pitch) Rx(roll)``.

    Parameters
    ----------
    roll, pitch, yaw : array_like
        Radians; broadcast against each other.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit quaternion(s), scalar first, body (FRD) -> inertial (NED), with
        ``q0 >= 0`` whenever all angles lie in (-pi, pi].
    """
    r, p, y = np.broadcast_arrays(
        np.asarray(roll, dtype=np.float64),
        np.asarray(pitch, dtype=np.float64),
        np.asarray(yaw, dtype=np.float64),
    )
    cr, sr = np.cos(0.5 * r), np.sin(0.5 * r)
    cp, sp = np.cos(0.5 * p), np.sin(0.5 * p)
    cy, sy = np.cos(0.5 * y), np.sin(0.5 * y)
    q = np.empty(r.shape + (4,), dtype=np.float64)
    q[..., 0] = cr * cp * cy + sr * sp * sy
    q[..., 1] = sr * cp * cy - cr * sp * sy
    q[..., 2] = cr * sp * cy + sr * cp * sy
    q[..., 3] = cr * cp * sy - sr * sp * cy
    return q


def body_to_inertial(q: ArrayLike, v_body: ArrayLike) -> NDArray[np.float64]:
    """Express body-frame (FRD) vector(s) in the inertial frame (NED).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Attitude quaternion(s), scalar first, body -> inertial.
    v_body : array_like, shape (..., 3)
        Vector(s) in body components, e.g. the CM velocity ``[u, v, w]`` in m/s.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        ``C(q) @ v_body``: the same vector(s) in inertial components, same units.
    """
    v = np.asarray(v_body, dtype=np.float64)
    if v.shape[-1:] != (3,):
        raise ValueError(f"vector array must have a last axis of length 3 (got {v.shape})")
    c = quat_to_matrix(q)
    return np.einsum("...ij,...j->...i", c, v)
