"""Attitude excursion of a run, compiled: one pass over the sampled quaternions.

The summary's ``attitude_excursion`` (largest roll, pitch and yaw departures
from the references and the largest tilt of the body z axis from the
reference's) over every output sample, without building the time-series
table. The formulas are those of :func:`quadimpact.rotations.quat_to_euler_zyx`
(ZYX Euler angles, pitch by ``atan2``, the gimbal-lock rule) and
:func:`quadimpact.rotations.quat_to_matrix`; results agree with the NumPy
computation to a few units in the last place (the elementary functions are
the platform's, not NumPy's).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadimpact.rotations import GIMBAL_LOCK_COS

__all__ = ["excursion_from_quaternions"]

_DEG = 180.0 / math.pi
_RAD = math.pi / 180.0


_TWO_PI = 2.0 * math.pi


@njit(cache=True)
def _wrap_pi(a: float) -> float:
    """``a`` wrapped to (-pi, pi], as ``rotations.wrap_angle_rad``.

    ``(a + pi) % 2 pi - pi``; the modulo of a number already in [0, 2 pi) is
    the number itself, so it is taken only outside (the same bits, without
    the division in the common case).
    """
    x = a + math.pi
    if not (0.0 <= x < _TWO_PI):
        x = x % _TWO_PI
    w = x - math.pi
    if w <= -math.pi:
        w += _TWO_PI
    return w


@njit(cache=True)
def excursion_from_quaternions(
    quat: np.ndarray,
    roll_ref: float,
    pitch_ref: float,
    yaw_ref: float,
    z_ref: np.ndarray,
) -> tuple[float, float, float, float]:
    """Largest roll, pitch, yaw departures and tilt (deg) over rows of ``quat`` (n, 4).

    ``z_ref`` is the reference attitude's body z axis in inertial axes. Roll and
    yaw differences are wrapped to (-180, 180]; the angles are taken through
    degrees and back, as the time-series table reports them.
    """
    d_roll = 0.0
    d_pitch = 0.0
    d_yaw = 0.0
    c_min = 1.0  # the largest tilt is acos of the smallest cosine (acos decreases)
    for i in range(quat.shape[0]):
        n = math.sqrt(
            quat[i, 0] * quat[i, 0]
            + quat[i, 1] * quat[i, 1]
            + quat[i, 2] * quat[i, 2]
            + quat[i, 3] * quat[i, 3]
        )
        q0 = quat[i, 0] / n
        q1 = quat[i, 1] / n
        q2 = quat[i, 2] / n
        q3 = quat[i, 3] / n
        c00 = 1.0 - 2.0 * (q2 * q2 + q3 * q3)
        c01 = 2.0 * (q1 * q2 - q0 * q3)
        c10 = 2.0 * (q1 * q2 + q0 * q3)
        c11 = 1.0 - 2.0 * (q1 * q1 + q3 * q3)
        c02 = 2.0 * (q1 * q3 + q0 * q2)
        c12 = 2.0 * (q2 * q3 - q0 * q1)
        c20 = 2.0 * (q1 * q3 - q0 * q2)
        c21 = 2.0 * (q2 * q3 + q0 * q1)
        c22 = 1.0 - 2.0 * (q1 * q1 + q2 * q2)
        cos_pitch = math.hypot(c00, c10)
        pitch = math.atan2(-c20, cos_pitch)
        if cos_pitch < GIMBAL_LOCK_COS:
            roll = 0.0
            yaw = math.atan2(-c01, c11)
        else:
            roll = math.atan2(c21, c22)
            yaw = math.atan2(c10, c00)
        roll = _wrap_pi(roll) * _DEG * _RAD
        yaw = _wrap_pi(yaw) * _DEG * _RAD
        pitch = pitch * _DEG * _RAD
        d_roll = max(d_roll, abs(_wrap_pi(roll - roll_ref)))
        d_pitch = max(d_pitch, abs(pitch - pitch_ref))
        d_yaw = max(d_yaw, abs(_wrap_pi(yaw - yaw_ref)))
        c = c02 * z_ref[0] + c12 * z_ref[1] + c22 * z_ref[2]
        c_min = min(c_min, max(-1.0, c))
    return d_roll * _DEG, d_pitch * _DEG, d_yaw * _DEG, math.acos(c_min) * _DEG
