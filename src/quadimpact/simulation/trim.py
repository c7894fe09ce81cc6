"""Trimmed rotor speeds: the ones that give a thrust and no torque (the resolve step)."""

from __future__ import annotations

import numpy as np

from quadimpact.inputs.vehicle import Vehicle
from quadimpact.linalg import lu_factor, lu_solve, matvec
from quadimpact.packing.vehicle_block import (
    allocation_inverse,
    allocation_matrix,
    vehicle_memo_value,
)

__all__ = ["trim_rotor_speeds"]


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
