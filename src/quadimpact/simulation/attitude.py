"""Attitude excursion of a table's samples, compiled: one pass over their quaternions.

The summary's ``attitude_excursion`` (largest roll, pitch and yaw departures
from the references and the largest tilt of the body z axis from the
reference's): a run's loop adds each output sample as it writes it
(``quadimpact.core.excursion``); :func:`excursion_from_quaternions` runs the
same update over the quaternions of a time-series table
(``metrics.attitude_excursion_deg``), and :func:`excursion_full`, which
evaluates every row, is its definition (bit for bit,
``tests/simulation/test_attitude.py``). The formulas are those of
:func:`quadimpact.rotations.quat_to_euler_zyx` and
:func:`quadimpact.rotations.quat_to_matrix`; results agree with the NumPy
computation to a few units in the last place (the elementary functions are
the platform's, not NumPy's).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadimpact.core.excursion import DEG, euler_of, excursion_add, excursion_start, wrap_pi
from quadimpact.core.excursion_slots import EX_COS_TILT, EX_DEV, NEX
from quadimpact.core.quaternion import rotation_matrix

__all__ = ["excursion_from_quaternions", "excursion_full"]


@njit(cache=True)
def _unit(quat: np.ndarray, i: int) -> tuple[float, float, float, float]:
    """Row ``i`` of ``quat`` divided by its norm (as ``core.quaternion.rotation_matrix``)."""
    n = math.sqrt(
        quat[i, 0] * quat[i, 0]
        + quat[i, 1] * quat[i, 1]
        + quat[i, 2] * quat[i, 2]
        + quat[i, 3] * quat[i, 3]
    )
    return quat[i, 0] / n, quat[i, 1] / n, quat[i, 2] / n, quat[i, 3] / n


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
    degrees and back, as the time-series table reports them. Each row is
    added as the run's loop adds its samples (``core.excursion.excursion_add``,
    which evaluates a row's angles only where they may reach the largest so
    far); the value is that of :func:`excursion_full`, bit for bit.
    """
    e = np.zeros(NEX)
    C = np.empty((3, 3))
    excursion_start(roll_ref, pitch_ref, yaw_ref, e)
    for i in range(quat.shape[0]):
        rotation_matrix(quat[i], C)
        excursion_add(C, roll_ref, pitch_ref, yaw_ref, z_ref, e)
    return (
        e[EX_DEV] * DEG,
        e[EX_DEV + 1] * DEG,
        e[EX_DEV + 2] * DEG,
        math.acos(e[EX_COS_TILT]) * DEG,
    )


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
        c01 = 2.0 * (q1 * q2 - q0 * q3)
        c11 = 1.0 - 2.0 * (q1 * q1 + q3 * q3)
        roll, pitch, yaw = euler_of(c00, c10, c20, c21, c22, c01, c11)
        d_roll = max(d_roll, abs(wrap_pi(roll - roll_ref)))
        d_pitch = max(d_pitch, abs(pitch - pitch_ref))
        d_yaw = max(d_yaw, abs(wrap_pi(yaw - yaw_ref)))
        c = c02 * z_ref[0] + c12 * z_ref[1] + c22 * z_ref[2]
        c_min = min(c_min, max(-1.0, c))
    return d_roll * DEG, d_pitch * DEG, d_yaw * DEG, math.acos(c_min) * DEG
