"""A vehicle's allocation and trim: what its rotors' speeds give, and the speeds of a thrust.

The allocation matrix (docs/MODEL.md 6.1), its inverse, and the rotor speeds
that give a thrust without torque (the resolve step's trim,
``simulation/resolve.py``), each computed once per (frozen) vehicle object
(:func:`vehicle_memo_value`, which the packing of the vehicle's blocks uses too).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from quadimpact.inputs.vehicle import Vehicle
from quadimpact.linalg import inverse, lu_factor, lu_solve, matvec, pseudo_inverse

__all__ = [
    "allocation_inverse",
    "allocation_matrix",
    "trim_rotor_speeds",
    "vehicle_memo",
    "vehicle_memo_value",
]

_PACKED: dict[tuple[int, str], tuple[Vehicle, Any]] = {}

_PACKED_LIMIT = 128


def vehicle_memo(kind: str, v: Vehicle, make: Any) -> np.ndarray:
    """A copy of ``make()`` computed once per (frozen) vehicle object and kind."""
    return vehicle_memo_value(kind, v, make).copy()


def vehicle_memo_value(kind: str, v: Vehicle, make: Any) -> Any:
    """``make()`` computed once per (frozen) vehicle object and kind (not copied: immutable)."""
    key = (id(v), kind)
    hit = _PACKED.get(key)
    if hit is None or hit[0] is not v:
        if len(_PACKED) >= _PACKED_LIMIT:
            _PACKED.pop(next(iter(_PACKED)))
        hit = (v, make())  # holds v, so its id stays its own
        _PACKED[key] = hit
    return hit[1]


def allocation_matrix(v: Vehicle, yaw_paper: bool) -> np.ndarray:
    """``A`` (4 x n) with ``[T, tau_x, tau_y, tau_z] = A [Omega_1^2 .. Omega_n^2]``
    (docs/MODEL.md 6.1), the vehicle's effectiveness matrix.

    Column ``j`` is rotor ``j``'s: ``kt_j``, ``-kt_j y_j``, ``kt_j x_j`` and the
    yaw entry of the rotor-torque model in use: ``-s_j dt_j`` (physical) or
    ``+s_j dt_j`` (paper replica).
    """
    kt = v.thrust_coefficients
    r = v.rotor_positions
    yaw = v.drag_torque_coefficients * v.spins * (1.0 if yaw_paper else -1.0)
    return np.vstack([kt, -kt * r[:, 1], kt * r[:, 0], yaw])


def allocation_inverse(v: Vehicle, yaw_paper: bool) -> np.ndarray:
    """The allocation's inverse ``A^+`` (n x 4): ``Omega^2 = A^+ [T, tau_x, tau_y, tau_z]``.

    A quadrotor's square ``A`` has the exact inverse ``A^-1`` (``linalg.inverse``,
    the same bits as before rotor counts other than 4). Any other count has the
    Moore-Penrose pseudo-inverse ``A^T (A A^T)^-1`` (``linalg.pseudo_inverse``):
    of all ``Omega^2`` giving the wrench, the one of the smallest norm.
    """
    a = allocation_matrix(v, yaw_paper)
    return inverse(a) if a.shape[1] == 4 else pseudo_inverse(a)


def trim_rotor_speeds(v: Vehicle, thrust_n: float, yaw_paper: bool) -> np.ndarray:
    """Rotor speeds (rad/s) giving total thrust ``thrust_n`` (N) and zero torques.

    A quadrotor solves ``A Omega^2 = [T, 0, 0, 0]`` (LU, as always); a vehicle
    with another rotor count takes the smallest-norm solution ``A^+ [T, 0, 0, 0]``
    (the pseudo-inverse of the controllers' allocation). Negative squares are 0.
    """
    if v.rotor_count != 4:
        inv = vehicle_memo_value(
            f"alloc-inv-{yaw_paper}-trim", v, lambda: allocation_inverse(v, yaw_paper)
        )
        w2 = matvec(inv, np.array([float(thrust_n), 0.0, 0.0, 0.0]))
        return np.sqrt(np.maximum(w2, 0.0))
    lu = vehicle_memo_value(
        f"alloc-lu-{yaw_paper}", v, lambda: lu_factor(allocation_matrix(v, yaw_paper))
    )
    w2 = lu_solve(lu, [thrust_n, 0.0, 0.0, 0.0])  # = solve(A, b), A eliminated once per vehicle
    return np.sqrt(np.maximum(w2, 0.0))  # np.clip's bits (the -0.0 and NaN cases too), faster
