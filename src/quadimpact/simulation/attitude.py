"""Attitude excursion of a run, compiled: one pass over the sampled quaternions.

The summary's ``attitude_excursion`` (largest roll, pitch and yaw departures
from the references and the largest tilt of the body z axis from the
reference's) over every output sample, without building the time-series
table. The formulas are those of :func:`quadimpact.rotations.quat_to_euler_zyx`
(ZYX Euler angles, pitch by ``atan2``, the gimbal-lock rule) and
:func:`quadimpact.rotations.quat_to_matrix`; results agree with the NumPy
computation to a few units in the last place (the elementary functions are
the platform's, not NumPy's).

Most rows cannot change a maximum: :func:`excursion_from_quaternions` takes a
row's ``atan2`` only where a cheap sign test says it may (half the cost of a
summary's pass), with the result of :func:`excursion_full`, which evaluates
every row, bit for bit (``tests/simulation/test_attitude.py``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadimpact.rotations import GIMBAL_LOCK_COS

__all__ = ["excursion_from_quaternions", "excursion_full"]

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
def _unit(quat: np.ndarray, i: int) -> tuple[float, float, float, float]:
    """Row ``i`` of ``quat`` divided by its norm."""
    n = math.sqrt(
        quat[i, 0] * quat[i, 0]
        + quat[i, 1] * quat[i, 1]
        + quat[i, 2] * quat[i, 2]
        + quat[i, 3] * quat[i, 3]
    )
    return quat[i, 0] / n, quat[i, 1] / n, quat[i, 2] / n, quat[i, 3] / n


_SLACK = 1e-12
"""Relative slack of the pruning test: far above its rounding (a few 1e-16)."""
_NEAR_LOCK_S2 = 1e-12
"""Below this ``cos(pitch)^2`` a row is evaluated in full (the gimbal-lock rule)."""


@njit(cache=True)
def _may_reach(a: float, b: float, cu: float, su: float, cos_t: float, sin_t: float) -> bool:
    """Whether the angle between ``(a, b)`` and the unit ``(cu, su)`` may be ``>= t``.

    ``(cos_t, sin_t)`` are those of ``t`` in [0, pi]. With ``theta`` the angle
    (in [0, pi]), ``|cross| cos t - dot sin t = |(a, b)| sin(theta - t)``, which
    is negative only where ``theta < t``; False is returned only where it is
    below ``-1e-12 |(a, b)|``, so that ``theta < t - 1e-12`` for sure (NaN:
    True).
    """
    dot = a * cu + b * su
    cross = abs(b * cu - a * su)
    g = cross * cos_t - dot * sin_t
    return not (g < -_SLACK * (cross + abs(dot)))


@njit(cache=True)
def _new_max(d: float, dev: float, cos_d: float, sin_d: float) -> tuple[float, float, float]:
    """``max(d, dev)`` with its cosine and sine (computed again only when it changed)."""
    m = max(d, dev)
    if m != d:
        return m, math.cos(m), math.sin(m)
    return m, cos_d, sin_d


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

    The value is that of :func:`excursion_full` bit for bit; a row's angle is
    evaluated (``atan2``...) only where it may reach the largest departure so
    far. Each departure is the angle between two plane vectors: roll that of
    ``(C33, C32)`` from ``(cos, sin)`` of its reference, yaw that of
    ``(C11, C21)``, pitch that of ``(cos(pitch), -C31)`` (for a pitch
    reference within +-90 deg), so a sign test of their cross and dot
    products (:func:`_may_reach`, with a slack far above the rounding of the
    evaluated angle) tells which rows cannot change the maximum. Rows within
    1e-6 of gimbal lock are evaluated in full.
    """
    d_roll = 0.0
    d_pitch = 0.0
    d_yaw = 0.0
    c_min = 1.0  # the largest tilt is acos of the smallest cosine (acos decreases)
    cr, sr = math.cos(roll_ref), math.sin(roll_ref)
    cp_ref, sp_ref = math.cos(pitch_ref), math.sin(pitch_ref)
    cy, sy = math.cos(yaw_ref), math.sin(yaw_ref)
    prune_pitch = abs(pitch_ref) <= 0.5 * math.pi
    cos_r, sin_r = 1.0, 0.0  # cos and sin of the largest departures so far
    cos_p, sin_p = 1.0, 0.0
    cos_y, sin_y = 1.0, 0.0
    for i in range(quat.shape[0]):
        q0, q1, q2, q3 = _unit(quat, i)
        c00 = 1.0 - 2.0 * (q2 * q2 + q3 * q3)  # the direction cosines used (quat_to_matrix)
        c10 = 2.0 * (q1 * q2 + q0 * q3)
        c02 = 2.0 * (q1 * q3 + q0 * q2)
        c12 = 2.0 * (q2 * q3 - q0 * q1)
        c20 = 2.0 * (q1 * q3 - q0 * q2)
        c21 = 2.0 * (q2 * q3 + q0 * q1)
        c22 = 1.0 - 2.0 * (q1 * q1 + q2 * q2)
        c = c02 * z_ref[0] + c12 * z_ref[1] + c22 * z_ref[2]
        c_min = min(c_min, max(-1.0, c))
        s2 = c00 * c00 + c10 * c10
        if not s2 > _NEAR_LOCK_S2:  # near gimbal lock (or NaN): every angle in full
            roll, pitch, yaw = _euler(q0, q1, q2, q3, c00, c10, c20, c21, c22)
            d_roll, cos_r, sin_r = _new_max(d_roll, abs(_wrap_pi(roll - roll_ref)), cos_r, sin_r)
            d_pitch, cos_p, sin_p = _new_max(d_pitch, abs(pitch - pitch_ref), cos_p, sin_p)
            d_yaw, cos_y, sin_y = _new_max(d_yaw, abs(_wrap_pi(yaw - yaw_ref)), cos_y, sin_y)
            continue
        # away from gimbal lock: roll = atan2(C32, C33), yaw = atan2(C21, C11)
        if _may_reach(c22, c21, cr, sr, cos_r, sin_r):
            roll = _wrap_pi(math.atan2(c21, c22)) * _DEG * _RAD
            d_roll, cos_r, sin_r = _new_max(d_roll, abs(_wrap_pi(roll - roll_ref)), cos_r, sin_r)
        if not prune_pitch or _may_reach(math.sqrt(s2), -c20, cp_ref, sp_ref, cos_p, sin_p):
            pitch = math.atan2(-c20, math.hypot(c00, c10)) * _DEG * _RAD
            d_pitch, cos_p, sin_p = _new_max(d_pitch, abs(pitch - pitch_ref), cos_p, sin_p)
        if _may_reach(c00, c10, cy, sy, cos_y, sin_y):
            yaw = _wrap_pi(math.atan2(c10, c00)) * _DEG * _RAD
            d_yaw, cos_y, sin_y = _new_max(d_yaw, abs(_wrap_pi(yaw - yaw_ref)), cos_y, sin_y)
    return d_roll * _DEG, d_pitch * _DEG, d_yaw * _DEG, math.acos(c_min) * _DEG


@njit(cache=True)
def _euler(
    q0: float, q1: float, q2: float, q3: float,
    c00: float, c10: float, c20: float, c21: float, c22: float,
) -> tuple[float, float, float]:  # fmt: skip
    """ZYX roll, pitch, yaw (rad) of one row, through degrees and back (the gimbal-lock rule)."""
    cos_pitch = math.hypot(c00, c10)
    pitch = math.atan2(-c20, cos_pitch)
    if cos_pitch < GIMBAL_LOCK_COS:
        roll = 0.0
        c01 = 2.0 * (q1 * q2 - q0 * q3)
        c11 = 1.0 - 2.0 * (q1 * q1 + q3 * q3)
        yaw = math.atan2(-c01, c11)
    else:
        roll = math.atan2(c21, c22)
        yaw = math.atan2(c10, c00)
    roll = _wrap_pi(roll) * _DEG * _RAD
    yaw = _wrap_pi(yaw) * _DEG * _RAD
    return roll, pitch * _DEG * _RAD, yaw


@njit(cache=True)
def excursion_full(
    quat: np.ndarray,
    roll_ref: float,
    pitch_ref: float,
    yaw_ref: float,
    z_ref: np.ndarray,
) -> tuple[float, float, float, float]:
    """:func:`excursion_from_quaternions` with every row's angles evaluated (its definition)."""
    d_roll = 0.0
    d_pitch = 0.0
    d_yaw = 0.0
    c_min = 1.0
    for i in range(quat.shape[0]):
        q0, q1, q2, q3 = _unit(quat, i)
        c00 = 1.0 - 2.0 * (q2 * q2 + q3 * q3)  # the direction cosines used (quat_to_matrix)
        c10 = 2.0 * (q1 * q2 + q0 * q3)
        c02 = 2.0 * (q1 * q3 + q0 * q2)
        c12 = 2.0 * (q2 * q3 - q0 * q1)
        c20 = 2.0 * (q1 * q3 - q0 * q2)
        c21 = 2.0 * (q2 * q3 + q0 * q1)
        c22 = 1.0 - 2.0 * (q1 * q1 + q2 * q2)
        roll, pitch, yaw = _euler(q0, q1, q2, q3, c00, c10, c20, c21, c22)
        d_roll = max(d_roll, abs(_wrap_pi(roll - roll_ref)))
        d_pitch = max(d_pitch, abs(pitch - pitch_ref))
        d_yaw = max(d_yaw, abs(_wrap_pi(yaw - yaw_ref)))
        c = c02 * z_ref[0] + c12 * z_ref[1] + c22 * z_ref[2]
        c_min = min(c_min, max(-1.0, c))
    return d_roll * _DEG, d_pitch * _DEG, d_yaw * _DEG, math.acos(c_min) * _DEG
