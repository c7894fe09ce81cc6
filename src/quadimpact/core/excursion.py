"""The attitude excursion over a run's output samples, one sample at a time.

The summary's ``attitude_excursion`` (docs/STUDIES.md 2): the largest roll,
pitch and yaw departures from the references and the largest tilt of the
body z axis from the reference's, over every output sample. The loop adds
each sample as it writes it (``recording.write_sample``, from the rotation
matrix it has just computed), into the ``EX_*`` slots of the run's stats
(``ST_EXCURSION``; declared in ``core/excursion_slots.py``), so a run's
summary needs no pass over its samples and a sweep's runs need not keep them
at all. ``quadimpact.simulation.attitude``
runs the same update over a table's quaternions.

The angles follow :func:`quadimpact.rotations.quat_to_euler_zyx` (ZYX,
pitch by ``atan2``, the gimbal-lock rule), taken through degrees and back as
the time-series table reports them; roll and yaw departures are wrapped to
(-pi, pi]. Most samples cannot change a maximum: a sample's ``atan2`` is
taken only where a sign test says its angle may reach the largest so far
(:func:`may_reach`, with a slack far above the rounding of the angle), so
the result is that of evaluating every sample, bit for bit
(``tests/simulation/test_attitude.py``).
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.excursion_slots import EX_COS_TILT, EX_DEV, EX_DEV_TRIG, EX_REF_TRIG

GIMBAL_LOCK_COS = 1e-9
"""``cos(pitch)`` below which only the rotation about the vertical is defined (as
``quadimpact.rotations.GIMBAL_LOCK_COS``; tested equal)."""
DEG = 180.0 / math.pi
RAD = math.pi / 180.0
_TWO_PI = 2.0 * math.pi
SLACK = 1e-12
"""Relative slack of the pruning test: far above its rounding (a few 1e-16)."""
NEAR_LOCK_S2 = 1e-12
"""Below this ``cos(pitch)^2`` a sample is evaluated in full (the gimbal-lock rule)."""


@compiled
def wrap_pi(a: float) -> float:
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


@compiled
def may_reach(a: float, b: float, cu: float, su: float, cos_t: float, sin_t: float) -> bool:
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
    return not (g < -SLACK * (cross + abs(dot)))


@compiled
def new_max(d: float, dev: float, cos_d: float, sin_d: float) -> tuple[float, float, float]:
    """``max(d, dev)`` with its cosine and sine (computed again only when it changed)."""
    m = max(d, dev)
    if m != d:
        return m, math.cos(m), math.sin(m)
    return m, cos_d, sin_d


@compiled
def new_max_at(
    d: float, dev: float, cos_d: float, sin_d: float, a: float, b: float, cu: float, su: float
) -> tuple[float, float, float]:
    """:func:`new_max` for a departure ``dev`` that is the angle between ``(a, b)`` and the
    unit ``(cu, su)``: when it is the new largest, its cosine and sine from the vectors.

    They are those of ``dev`` within a few rounding errors (1e-15), far inside
    :func:`may_reach`'s slack of 1e-12, and cost a square root and two
    divisions instead of a cosine and a sine. Only the pruning reads them: the
    largest departure itself is ``dev`` (the same bits as :func:`new_max`).
    """
    m = max(d, dev)
    if m != d:
        r = math.sqrt(a * a + b * b)
        return m, (a * cu + b * su) / r, abs(b * cu - a * su) / r
    return m, cos_d, sin_d


@compiled
def euler_of(
    c00: float, c10: float, c20: float, c21: float, c22: float, c01: float, c11: float
) -> tuple[float, float, float]:
    """ZYX roll, pitch, yaw (rad) of a rotation matrix's entries ``cij``, through degrees
    and back (the gimbal-lock rule: roll 0, the rotation about the vertical as yaw)."""
    cos_pitch = math.hypot(c00, c10)
    pitch = math.atan2(-c20, cos_pitch)
    if cos_pitch < GIMBAL_LOCK_COS:
        roll = 0.0
        yaw = math.atan2(-c01, c11)
    else:
        roll = math.atan2(c21, c22)
        yaw = math.atan2(c10, c00)
    roll = wrap_pi(roll) * DEG * RAD
    yaw = wrap_pi(yaw) * DEG * RAD
    return roll, pitch * DEG * RAD, yaw


SETTLED_MARGIN = 1e-12
"""Added to :func:`settled`'s bounds: far above the rounding of a sample's values (1e-15)."""


@compiled(inline="always")
def _reach_g(a: float, b: float, cu: float, su: float, cos_t: float, sin_t: float) -> float:
    """:func:`may_reach`'s test as one number: it says False exactly where this is below 0."""
    dot = a * cu + b * su
    cross = abs(b * cu - a * su)
    return cross * cos_t - dot * sin_t + SLACK * (cross + abs(dot))


@compiled
def settled(C: np.ndarray, dc: float, pitch_ref: float, z_ref: np.ndarray, e: np.ndarray) -> bool:
    """Whether no sample within ``dc`` of the rotation ``C`` can change the excursion ``e``.

    ``dc`` bounds how far each entry of a sample's rotation lies from ``C``'s.
    True only where, for every such sample, :func:`excursion_add` would find
    the tilt's cosine at or above the lowest so far, no angle that
    :func:`may_reach` the largest so far, and no gimbal lock: it would leave
    ``e`` as it is, bit for bit. Each quantity moves by at most a multiple of
    ``dc`` (its Lipschitz constant: the tilt's cosine ``sqrt(3) |z_ref|``,
    :func:`may_reach`'s test 1.5 per unit of its vector, which moves by
    ``sqrt(2) dc``, the pitch's ``sqrt(3) dc``), plus :data:`SETTLED_MARGIN`.
    NaN: False.
    """
    if not abs(pitch_ref) <= 0.5 * math.pi:
        return False
    c00 = C[0, 0]
    c10 = C[1, 0]
    c20 = C[2, 0]
    c21 = C[2, 1]
    c22 = C[2, 2]
    zn = math.sqrt(z_ref[0] * z_ref[0] + z_ref[1] * z_ref[1] + z_ref[2] * z_ref[2])
    c = C[0, 2] * z_ref[0] + C[1, 2] * z_ref[1] + c22 * z_ref[2]
    if not c - 1.7321 * zn * dc - SETTLED_MARGIN >= e[EX_COS_TILT]:
        return False
    hs = math.sqrt(c00 * c00 + c10 * c10)
    if not hs - 1.4143 * dc - SETTLED_MARGIN > 2.0 * math.sqrt(NEAR_LOCK_S2):
        return False
    move = 1.5 * 1.4143 * dc + SETTLED_MARGIN
    g = _reach_g(c22, c21, e[EX_REF_TRIG], e[EX_REF_TRIG + 1], e[EX_DEV_TRIG], e[EX_DEV_TRIG + 1])
    if not g + move < 0.0:
        return False
    g = _reach_g(
        c00, c10, e[EX_REF_TRIG + 4], e[EX_REF_TRIG + 5], e[EX_DEV_TRIG + 4], e[EX_DEV_TRIG + 5]
    )
    if not g + move < 0.0:
        return False
    g = _reach_g(
        hs, -c20, e[EX_REF_TRIG + 2], e[EX_REF_TRIG + 3], e[EX_DEV_TRIG + 2], e[EX_DEV_TRIG + 3]
    )
    return g + 1.5 * 1.7321 * dc + SETTLED_MARGIN < 0.0


@compiled
def excursion_start(roll_ref: float, pitch_ref: float, yaw_ref: float, e: np.ndarray) -> None:
    """Start an excursion ``e`` (``EX_*``, NEX) against the references (rad): nothing yet."""
    for k in range(3):
        e[EX_DEV + k] = 0.0
        e[EX_DEV_TRIG + 2 * k] = 1.0
        e[EX_DEV_TRIG + 2 * k + 1] = 0.0
    e[EX_COS_TILT] = 1.0  # the largest tilt is acos of the lowest cosine
    e[EX_REF_TRIG] = math.cos(roll_ref)
    e[EX_REF_TRIG + 1] = math.sin(roll_ref)
    e[EX_REF_TRIG + 2] = math.cos(pitch_ref)
    e[EX_REF_TRIG + 3] = math.sin(pitch_ref)
    e[EX_REF_TRIG + 4] = math.cos(yaw_ref)
    e[EX_REF_TRIG + 5] = math.sin(yaw_ref)


@compiled
def excursion_add(
    C: np.ndarray,
    roll_ref: float,
    pitch_ref: float,
    yaw_ref: float,
    z_ref: np.ndarray,
    e: np.ndarray,
) -> None:
    """Add a sample of rotation ``C`` (body to inertial, from a unit quaternion) to ``e``.

    ``z_ref``: the reference attitude's body z axis, inertial. Each departure
    is the angle between two plane vectors: roll that of ``(C33, C32)`` from
    ``(cos, sin)`` of its reference, yaw that of ``(C11, C21)``, pitch that of
    ``(cos(pitch), -C31)`` (for a pitch reference within +-90 deg); a
    sample's angle is evaluated only where :func:`may_reach` says it may
    reach the largest so far. Samples within 1e-6 of gimbal lock are
    evaluated in full.
    """
    c00 = C[0, 0]
    c10 = C[1, 0]
    c20 = C[2, 0]
    c21 = C[2, 1]
    c22 = C[2, 2]
    c = C[0, 2] * z_ref[0] + C[1, 2] * z_ref[1] + c22 * z_ref[2]
    e[EX_COS_TILT] = min(e[EX_COS_TILT], max(-1.0, c))
    d_roll, d_pitch, d_yaw = e[EX_DEV], e[EX_DEV + 1], e[EX_DEV + 2]
    cos_r, sin_r = e[EX_DEV_TRIG], e[EX_DEV_TRIG + 1]
    cos_p, sin_p = e[EX_DEV_TRIG + 2], e[EX_DEV_TRIG + 3]
    cos_y, sin_y = e[EX_DEV_TRIG + 4], e[EX_DEV_TRIG + 5]
    s2 = c00 * c00 + c10 * c10
    if not s2 > NEAR_LOCK_S2:  # near gimbal lock (or NaN): every angle in full
        roll, pitch, yaw = euler_of(c00, c10, c20, c21, c22, C[0, 1], C[1, 1])
        d_roll, cos_r, sin_r = new_max(d_roll, abs(wrap_pi(roll - roll_ref)), cos_r, sin_r)
        d_pitch, cos_p, sin_p = new_max(d_pitch, abs(pitch - pitch_ref), cos_p, sin_p)
        d_yaw, cos_y, sin_y = new_max(d_yaw, abs(wrap_pi(yaw - yaw_ref)), cos_y, sin_y)
    else:  # away from gimbal lock: roll = atan2(C32, C33), yaw = atan2(C21, C11)
        # a new largest departure takes its cosine and sine from the sample's vectors
        # (new_max_at); the pitch's only where its vector's angle is the departure
        cu, su = e[EX_REF_TRIG], e[EX_REF_TRIG + 1]
        if may_reach(c22, c21, cu, su, cos_r, sin_r):
            roll = wrap_pi(math.atan2(c21, c22)) * DEG * RAD
            dev = abs(wrap_pi(roll - roll_ref))
            d_roll, cos_r, sin_r = new_max_at(d_roll, dev, cos_r, sin_r, c22, c21, cu, su)
        cu, su = e[EX_REF_TRIG + 2], e[EX_REF_TRIG + 3]
        if not abs(pitch_ref) <= 0.5 * math.pi:
            pitch = math.atan2(-c20, math.hypot(c00, c10)) * DEG * RAD
            d_pitch, cos_p, sin_p = new_max(d_pitch, abs(pitch - pitch_ref), cos_p, sin_p)
        elif may_reach(math.sqrt(s2), -c20, cu, su, cos_p, sin_p):
            pitch = math.atan2(-c20, math.hypot(c00, c10)) * DEG * RAD
            dev = abs(pitch - pitch_ref)
            d_pitch, cos_p, sin_p = new_max_at(
                d_pitch, dev, cos_p, sin_p, math.sqrt(s2), -c20, cu, su
            )
        cu, su = e[EX_REF_TRIG + 4], e[EX_REF_TRIG + 5]
        if may_reach(c00, c10, cu, su, cos_y, sin_y):
            yaw = wrap_pi(math.atan2(c10, c00)) * DEG * RAD
            dev = abs(wrap_pi(yaw - yaw_ref))
            d_yaw, cos_y, sin_y = new_max_at(d_yaw, dev, cos_y, sin_y, c00, c10, cu, su)
    e[EX_DEV], e[EX_DEV + 1], e[EX_DEV + 2] = d_roll, d_pitch, d_yaw
    e[EX_DEV_TRIG], e[EX_DEV_TRIG + 1] = cos_r, sin_r
    e[EX_DEV_TRIG + 2], e[EX_DEV_TRIG + 3] = cos_p, sin_p
    e[EX_DEV_TRIG + 4], e[EX_DEV_TRIG + 5] = cos_y, sin_y
