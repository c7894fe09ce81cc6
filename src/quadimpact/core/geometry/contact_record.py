"""The contact record every geometry function returns, as in Drake's contact queries.

A contact pair is one feature of the vehicle against one shape of the world.
Its geometry returns, at a state ``x``, the record (a tuple of floats, so
that it costs no allocation)::

    (delta, delta_dot, rcx, rcy, rcz, vcx, vcy, vcz, nx, ny, nz)

* ``delta``: penetration along the normal, m (> 0 in contact);
* ``delta_dot``: its rate, m/s (``-v_C . n``);
* ``rc``: the contact point (the feature's deepest point) from the CM, body
  frame, m (the inertial point is ``p + C rc``);
* ``vc``: the velocity of the vehicle's material point there, inertial, m/s
  (gives ``delta_dot`` and the sliding velocity);
* ``n``: unit normal of the shape at the contact, inertial, pointing from the
  shape toward the vehicle (a ring on a crease of a box or a finite cylinder:
  the blend of the two faces' normals that is the depth's gradient, of length
  a little under 1; ``ring.py``).

The force law (``core/contact.py``) consumes this record and never reads a
shape or a feature's geometry itself.
"""

import numpy as np
from numba import njit

from quadimpact.core.feature_slots import (
    F_CENTRE,
)
from quadimpact.core.layout import (
    X_OMEGA,
    X_VEL,
)

ContactRecord = tuple[float, float, float, float, float, float, float, float, float, float, float]
"""(delta, delta_dot, rcx, rcy, rcz, vcx, vcy, vcz, nx, ny, nz)."""

NO_CONTACT_DEPTH = -1e300  # m: the depth of a pair whose geometry is unknown (never touches)


@njit(cache=True, inline="always")
def feature_offset(C: np.ndarray, feat: np.ndarray, f: int) -> tuple[float, float, float]:
    """Feature ``f``'s centre ``F_CENTRE`` (body) from the CM in inertial axes, ``C c_b``, m."""
    cb0 = feat[f, F_CENTRE]
    cb1 = feat[f, F_CENTRE + 1]
    cb2 = feat[f, F_CENTRE + 2]
    return (
        C[0, 0] * cb0 + C[0, 1] * cb1 + C[0, 2] * cb2,
        C[1, 0] * cb0 + C[1, 1] * cb1 + C[1, 2] * cb2,
        C[2, 0] * cb0 + C[2, 1] * cb1 + C[2, 2] * cb2,
    )


@njit(cache=True, inline="always")
def material_record(
    x: np.ndarray,
    C: np.ndarray,
    delta: float,
    dx: float,
    dy: float,
    dz: float,
    nx: float,
    ny: float,
    nz: float,
) -> ContactRecord:
    """The record of a contact point at inertial offset ``d`` from the CM, depth ``delta``.

    ``C`` is the body-to-inertial rotation of ``x``; ``n`` the unit normal
    (inertial, toward the vehicle). Computes the point in body axes
    ``r_C = C^T d``, its material velocity ``C (v + omega x r_C)`` and
    ``delta_dot = -(v_C . n)``.
    """
    rcx = C[0, 0] * dx + C[1, 0] * dy + C[2, 0] * dz
    rcy = C[0, 1] * dx + C[1, 1] * dy + C[2, 1] * dz
    rcz = C[0, 2] * dx + C[1, 2] * dy + C[2, 2] * dz
    p = x[X_OMEGA]
    q = x[X_OMEGA + 1]
    r = x[X_OMEGA + 2]
    ub = x[X_VEL] + q * rcz - r * rcy
    vb = x[X_VEL + 1] + r * rcx - p * rcz
    wb = x[X_VEL + 2] + p * rcy - q * rcx
    vcx = C[0, 0] * ub + C[0, 1] * vb + C[0, 2] * wb
    vcy = C[1, 0] * ub + C[1, 1] * vb + C[1, 2] * wb
    vcz = C[2, 0] * ub + C[2, 1] * vb + C[2, 2] * wb
    delta_dot = -(vcx * nx + vcy * ny + vcz * nz)
    return delta, delta_dot, rcx, rcy, rcz, vcx, vcy, vcz, nx, ny, nz


@njit(cache=True, inline="always")
def no_contact() -> ContactRecord:
    """The record of a pair that cannot touch (an unknown geometry)."""
    return NO_CONTACT_DEPTH, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0
