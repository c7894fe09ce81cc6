"""Attitude and frame conversions (vectorised NumPy), for every layer above the core.

Conventions (docs/MODEL.md section 1):

- Inertial frame I: NED (X toward the default wall, Y right, Z down).
- Body frame B: FRD (x forward, y starboard, z down), origin at the CM.
- Quaternion ``q = [q0, q1, q2, q3]``: scalar first, Hamilton product. Its
  rotation matrix ``C(q)`` maps body components to inertial components,
  ``a_I = C a_B``.
- Euler angles: aerospace ZYX, ``C = Rz(yaw) Ry(pitch) Rx(roll)``; angles in
  radians here (the time-series table carries degrees).

Every function accepts a single quaternion of shape ``(4,)`` (or matrix of
shape ``(3, 3)``) or a stack of shape ``(..., 4)`` (``(..., 3, 3)``) and
broadcasts over the leading dimensions. The flight logs' helpers
(:func:`quat_xyzw_to_matrix`, :func:`matrix_to_quat`,
:func:`matrix_to_euler_zyx_deg`, :func:`matrix_to_rotvec`) work on rotation
matrices in the same convention.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from quadimpact import libm
from quadimpact.linalg import dot, matvec, norm

__all__ = [
    "GIMBAL_LOCK_COS",
    "body_to_inertial",
    "euler_zyx_to_quat",
    "inclination_deg",
    "matrix_to_euler_zyx",
    "matrix_to_euler_zyx_deg",
    "matrix_to_quat",
    "matrix_to_rotvec",
    "quat_to_euler_zyx",
    "quat_to_matrix",
    "quat_xyzw_to_matrix",
    "unwrap_deg",
    "wrap_angle_deg",
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
    # = np.linalg.norm(a, axis=-1, keepdims=True), without its argument handling
    norm = np.sqrt(np.add.reduce(a * a, axis=-1, keepdims=True))
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
    if type(q) is np.ndarray and q.shape == (4,) and q.dtype == np.float64:
        return _single_quat_matrix(q)
    a = _as_quat(q)
    return _unit_quat_matrix(a[..., 0], a[..., 1], a[..., 2], a[..., 3])


def _single_quat_matrix(q: NDArray[np.float64]) -> NDArray[np.float64]:
    """:func:`quat_to_matrix` of one quaternion with Python floats (about 10x faster).

    The same operations in the same order as the array path (the norm summed
    first to last, as NumPy's reduction of four elements does), so the result
    is the same bit for bit (tested).
    """
    a0, a1, a2, a3 = q.tolist()
    norm = math.sqrt(((a0 * a0 + a1 * a1) + a2 * a2) + a3 * a3)
    if norm == 0.0:
        raise ValueError("quaternion of zero norm cannot represent a rotation")
    q0, q1, q2, q3 = a0 / norm, a1 / norm, a2 / norm, a3 / norm
    return np.array(
        [
            [1.0 - 2.0 * (q2 * q2 + q3 * q3), 2.0 * (q1 * q2 - q0 * q3), 2.0 * (q1 * q3 + q0 * q2)],
            [2.0 * (q1 * q2 + q0 * q3), 1.0 - 2.0 * (q1 * q1 + q3 * q3), 2.0 * (q2 * q3 - q0 * q1)],
            [2.0 * (q1 * q3 - q0 * q2), 2.0 * (q2 * q3 + q0 * q1), 1.0 - 2.0 * (q1 * q1 + q2 * q2)],
        ]
    )


def quat_xyzw_to_matrix(q: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices of ``(x, y, z, w)`` quaternions (ROS order, scalar last).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternion(s) ``[x, y, z, w]``; normalised before use.

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        The same matrices as :func:`quat_to_matrix` of ``[w, x, y, z]``.
    """
    a = np.asarray(q, dtype=np.float64)
    a = a / norm(a)[..., None]
    return _unit_quat_matrix(a[..., 3], a[..., 0], a[..., 1], a[..., 2])


def _unit_quat_matrix(
    q0: ArrayLike, q1: ArrayLike, q2: ArrayLike, q3: ArrayLike
) -> NDArray[np.float64]:
    """``C`` of the unit quaternion with components ``q0`` (scalar) .. ``q3``."""
    c = np.empty(np.shape(q0) + (3, 3), dtype=np.float64)
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


def _wrap(angle: ArrayLike, half_turn: float) -> NDArray[np.float64]:
    a = np.asarray(angle, dtype=np.float64)
    w = np.mod(a + half_turn, 2.0 * half_turn) - half_turn  # [-half, half)
    return np.where(w <= -half_turn, w + 2.0 * half_turn, w)


def wrap_angle_rad(angle: ArrayLike) -> NDArray[np.float64]:
    """Wrap angle(s) to the interval (-pi, pi] (radians)."""
    return _wrap(angle, np.pi)


def unwrap_deg(angle_deg: ArrayLike) -> NDArray[np.float64]:
    """An angle made continuous through +-180 deg (whole turns added), NaN samples kept.

    How roll and yaw are drawn and compared: a yaw going from 179 to -179 deg
    becomes 179 to 181, not a jump of a turn.
    """
    y = np.array(angle_deg, dtype=np.float64)
    ok = np.isfinite(y)
    if ok.any():
        y[ok] = np.degrees(np.unwrap(np.radians(y[ok])))
    return y


def wrap_angle_deg(angle: ArrayLike) -> NDArray[np.float64]:
    """Wrap angle(s) to the interval (-180, 180] (degrees)."""
    return _wrap(angle, 180.0)


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
    if type(q) is np.ndarray and q.shape == (4,) and q.dtype == np.float64:
        return _single_euler_zyx(q)
    c = quat_to_matrix(q)
    c00, c10, c20 = c[..., 0, 0], c[..., 1, 0], c[..., 2, 0]
    c21, c22 = c[..., 2, 1], c[..., 2, 2]
    c01, c11 = c[..., 0, 1], c[..., 1, 1]
    cos_pitch = np.hypot(c00, c10)
    pitch = libm.arctan2(-c20, cos_pitch)
    locked = cos_pitch < GIMBAL_LOCK_COS
    roll = np.where(locked, 0.0, libm.arctan2(c21, c22))
    yaw = np.where(locked, libm.arctan2(-c01, c11), libm.arctan2(c10, c00))
    return wrap_angle_rad(roll), pitch, wrap_angle_rad(yaw)


def _single_euler_zyx(
    q: NDArray[np.float64],
) -> tuple[NDArray[np.float64], np.float64, NDArray[np.float64]]:
    """:func:`quat_to_euler_zyx` of one quaternion with Python floats (about 4x faster).

    The same ufuncs on the same values as the array path, one at a time, and the
    same types out (roll and yaw 0-d arrays, pitch a NumPy float): the same bits
    (tested).
    """
    return matrix_to_euler_zyx(_single_quat_matrix(q))


def matrix_to_euler_zyx(
    C: NDArray[np.float64],
) -> tuple[NDArray[np.float64], np.float64, NDArray[np.float64]]:
    """:func:`quat_to_euler_zyx` of one rotation matrix ``C`` (3, 3), rad.

    The same rule (``atan2`` pitch, the gimbal-lock rule) and types as
    :func:`quat_to_euler_zyx` (roll and yaw 0-d arrays, pitch a NumPy float):
    of ``C = quat_to_matrix(q)``, the same bits as ``quat_to_euler_zyx(q)``.
    """
    (c00, c01, _), (c10, c11, _), (c20, c21, c22) = C.tolist()
    cos_pitch = np.hypot(c00, c10)
    pitch = libm.arctan2(-c20, cos_pitch)
    if cos_pitch < GIMBAL_LOCK_COS:
        roll, yaw = 0.0, float(libm.arctan2(-c01, c11))
    else:
        roll, yaw = float(libm.arctan2(c21, c22)), float(libm.arctan2(c10, c00))
    return np.asarray(_wrap_one(roll)), pitch, np.asarray(_wrap_one(yaw))


def _wrap_one(angle: float) -> float:
    """:func:`wrap_angle_rad` of one angle (rad): the same operations on a Python float."""
    w = float(np.mod(angle + np.pi, 2.0 * np.pi)) - np.pi
    return w + 2.0 * np.pi if w <= -np.pi else w


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
    if type(roll) in _FLOATS and type(pitch) in _FLOATS and type(yaw) in _FLOATS:
        return _single_euler_quat(roll, pitch, yaw)
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


_FLOATS = (float, np.float64)


def _single_euler_quat(roll: float, pitch: float, yaw: float) -> NDArray[np.float64]:
    """:func:`euler_zyx_to_quat` of one attitude (about 4x faster).

    One ``cos`` and one ``sin`` call on the three half angles (the same
    element-wise functions as the array path), then the products with Python
    floats in the same order: the same bits (tested).
    """
    half = np.array([0.5 * roll, 0.5 * pitch, 0.5 * yaw])
    cr, cp, cy = np.cos(half).tolist()
    sr, sp, sy = np.sin(half).tolist()
    return np.array(
        [
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        ]
    )


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
    return matvec(c, v)


# ----------------------------------------------------------- rotation matrices
def matrix_to_quat(C: ArrayLike) -> NDArray[np.float64]:
    """Scalar-first unit quaternions of rotation matrices, sign-continuous along the stack.

    Parameters
    ----------
    C : array_like, shape (n, 3, 3)
        Rotation matrices, body -> inertial.

    Returns
    -------
    numpy.ndarray, shape (n, 4)
        ``q`` with ``quat_to_matrix(q) == C``; the first has ``q0 >= 0`` and each
        next one the sign closer to its predecessor (``q`` and ``-q`` are the
        same attitude).
    """
    C = np.asarray(C, dtype=np.float64)
    n = len(C)
    q = np.empty((n, 4))
    tr = np.trace(C, axis1=1, axis2=2)
    for i in range(n):
        m = C[i]
        if tr[i] > 0:
            s = 2.0 * math.sqrt(1.0 + tr[i])
            q[i] = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s,
                    (m[1, 0] - m[0, 1]) / s]  # fmt: skip
        elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
            s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
            q[i] = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s,
                    (m[0, 2] + m[2, 0]) / s]  # fmt: skip
        elif m[1, 1] > m[2, 2]:
            s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
            q[i] = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s,
                    (m[1, 2] + m[2, 1]) / s]  # fmt: skip
        else:
            s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
            q[i] = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s,
                    0.25 * s]  # fmt: skip
    q /= norm(q)[:, None]
    if n:
        if q[0, 0] < 0:
            q[0] = -q[0]
        for i in range(1, n):  # continuity: q and -q are the same attitude
            if dot(q[i], q[i - 1]) < 0:
                q[i] = -q[i]
    return q


def matrix_to_euler_zyx_deg(
    C: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Roll, pitch, yaw (deg, ZYX) of rotation matrices, straight from ``atan2``.

    Unlike :func:`quat_to_euler_zyx`: degrees, no gimbal-lock rule, roll and
    yaw in [-180, 180] as ``atan2`` gives them.
    """
    C = np.asarray(C, dtype=np.float64)
    roll = np.degrees(libm.arctan2(C[..., 2, 1], C[..., 2, 2]))
    pitch = np.degrees(libm.arctan2(-C[..., 2, 0], np.hypot(C[..., 0, 0], C[..., 1, 0])))
    yaw = np.degrees(libm.arctan2(C[..., 1, 0], C[..., 0, 0]))
    return roll, pitch, yaw


def inclination_deg(C: ArrayLike) -> NDArray[np.float64]:
    """Inclination (deg) of attitude matrices (docs/STUDIES.md section 1).

    The angle of the body z axis, projected on the inertial X-Z plane, from
    the inertial Z axis; positive when the vehicle leans toward +X (the wall).
    """
    C = np.asarray(C, dtype=np.float64)
    return np.degrees(libm.arctan2(-C[..., 0, 2], C[..., 2, 2]))


def matrix_to_rotvec(R: ArrayLike) -> NDArray[np.float64]:
    """Rotation vectors (axis times angle, rad) of rotation matrices, shape (..., 3)."""
    R = np.asarray(R, dtype=np.float64)
    cos = np.clip((np.trace(R, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    ang = libm.arccos(cos)
    v = np.stack(
        [R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]],
        -1,
    )
    s = np.sin(ang)
    k = np.where(s > 1e-9, ang / (2.0 * np.where(s > 1e-9, s, 1.0)), 0.5)
    return v * k[..., None]
