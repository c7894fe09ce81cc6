"""The paper's wall approach (docs/STUDIES.md section 1): attitude and the approach shooting.

The vehicle holds the attitude (heading psi, inclination iota) and the
altitude from the start. Without aerodynamic drag nothing in the dynamics
depends on X or V_X, so ``V_X(T_c) = v0 + A`` and the leading bumper's depth at
``T_c`` shifts one to one with X0: one free-flight run gives A and the depth,
a correction of v0 and a shift of X0 make the first contact happen at ``T_c``
with ``V_X = V_c`` (repeated until the residuals are below 1e-12). If that
needs ``v0 < 0``, the vehicle starts later, at rest, at the ``t0`` found by
the secant method on ``V_X(T_c; t0) = V_c`` (one free-flight run per trial;
Brent's method if the secant leaves ``[0, T_c)``).

The shooting runs in one compiled call (``core/approach.py``, the kernel's
``approach``); :func:`solve_approach` packs its inputs and reads what it found.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from quadimpact.core import feature_slots as FS
from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP
from quadimpact.core.approach import (
    AP_DV,
    AP_LATE,
    AP_LATE_RULE,
    AP_Q,
    AP_REASON,
    AP_ROTORS,
    AP_START,
    AP_STATUS,
    AP_T0,
    AP_TC,
    AP_V0,
    AP_VC,
    AP_X0,
    APPROACH_MAX_ITER,
    APPROACH_NO_BRACKET,
    APPROACH_RUN_FAILED,
    APPROACH_TOL_M_S,
    NAP,
)
from quadimpact.core.geometry import (
    NPAIR,
    PR_FEATURE,
    PR_SHAPE,
    pair_depths,
    pair_table,
)
from quadimpact.core.geometry.shapes import by_kind, plugin_shapes
from quadimpact.core.kernel import BUILTIN, Kernel
from quadimpact.core.records import Model, new_output
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.inputs.resolve import (  # defined with the rest of a run's start; names kept
    PAPER_FIT_OFFSET_RAD,
    PAPER_FIT_SCALE,
    initial_state,
    wall_attitude,
)
from quadimpact.results.costs import CpuClock
from quadimpact.rotations import inclination_deg, quat_to_matrix

__all__ = [
    "APPROACH_MAX_ITER",
    "APPROACH_TOL_M_S",
    "PAPER_FIT_OFFSET_RAD",
    "PAPER_FIT_SCALE",
    "feature_depths",
    "pair_depths_at",
    "inclination_deg_of",
    "initial_state",
    "shooting_record",
    "solve_approach",
    "wall_attitude",
]


def inclination_deg_of(q: np.ndarray) -> float:
    """Inclination (deg) of attitude ``q``: angle of body z projected on X-Z from Z, + toward +X."""
    return float(inclination_deg(quat_to_matrix(np.asarray(q, dtype=float))))


# ------------------------------------------------------------------ shooting
def feature_depths(x: np.ndarray, feat: np.ndarray, shapes: np.ndarray, s: int = 0) -> np.ndarray:
    """Penetration (m) of every contact feature into shape ``s`` at the state ``x``.

    The compiled contact geometry (``core.geometry``), called from Python.
    """
    return pair_depths_at(x, feat, shapes[s : s + 1], pair_table(feat, shapes[s : s + 1]))


def pair_depths_at(
    x: np.ndarray, feat: np.ndarray, shapes: np.ndarray, pairs: np.ndarray
) -> np.ndarray:
    """Penetration (m) of every pair of the table ``pairs`` (``c = shape * n_features +
    feature``, ``core.geometry.pair_table``) at the state ``x``, in one compiled call.

    The cached loop's geometry knows the built-in shapes only: a pair with a
    plug-in shape (``core.geometry.register_shape``) is measured by that
    shape's own contact function for the feature's kind (compiled alone).
    """
    xq = np.ascontiguousarray(x, dtype=float)
    C = np.ascontiguousarray(quat_to_matrix(xq[L.X_QUAT : L.X_QUAT + 4]))
    depths = np.empty(pairs.shape[0])
    pair_depths(xq, C, feat, shapes, pairs, depths)
    plugins = plugin_shapes()
    if plugins:
        for c in range(pairs.shape[0]):
            s = int(pairs[c, PR_SHAPE])
            comp = by_kind(int(shapes[s, SHP.SH_KIND]))
            if comp is None or comp not in plugins:
                continue
            f = int(pairs[c, PR_FEATURE])
            contact = comp.contacts.get(int(feat[f, FS.F_KIND]))
            if contact is not None:
                depths[c] = float(contact(xq, C, feat, f, shapes, s)[0])
    return depths


def solve_approach(
    *,
    run: Model,
    free_opts: np.ndarray,
    wall: np.ndarray,
    q: np.ndarray,
    rotors: np.ndarray,
    start: np.ndarray,
    impact_time_s: float,
    speed_m_s: float,
    late_start: bool,
    kernel: Kernel | None = None,
    clock: CpuClock | None = None,
) -> tuple[np.ndarray, float, dict[str, Any]]:
    """Initial state and time that bring the first contact at ``T_c`` with ``V_X = V_c``.

    Parameters
    ----------
    run : Model
        The packed run (its vehicle, features, controller and power-off schedule).
    free_opts : numpy.ndarray
        Its options without a crash, ``T_c`` as the duration.
    wall : numpy.ndarray, shape (1, NSHAPE)
        The packed wall alone.
    q, rotors : numpy.ndarray
        Attitude held and initial rotor speeds.
    start : numpy.ndarray, shape (3,)
        Initial position before the X shift, inertial NED, m.
    impact_time_s, speed_m_s : float
        ``T_c`` and ``V_c``.
    late_start : bool
        The ``late-start`` rule: start later at rest whenever ``v0 < 0`` would be
        needed; otherwise (the authors' rule) only when the start would lie
        beyond the wall.
    kernel : Kernel, optional
        The run loop of a plug-in controller (default: the built-in kernel).
    clock : CpuClock, optional
        Adds up the CPU time of the shooting runs (the summary's ``cost``).

    Returns
    -------
    x0 : numpy.ndarray
        The initial state.
    t0 : float
        The start time, s.
    approach : dict
        ``start_time_s``, ``start_x_m``, ``start_speed_m_s``, ``late_start``,
        ``speed_residual_m_s`` (the summary's ``approach``).
    """
    ap = shooting_record(
        run=run,
        free_opts=free_opts,
        wall=wall,
        q=q,
        rotors=rotors,
        start=start,
        impact_time_s=impact_time_s,
        speed_m_s=speed_m_s,
        late_start=late_start,
        kernel=kernel,
        clock=clock,
    )
    return _shooting_result(ap)


def shooting_record(
    *,
    run: Model,
    free_opts: np.ndarray,
    wall: np.ndarray,
    q: np.ndarray,
    rotors: np.ndarray,
    start: np.ndarray,
    impact_time_s: float,
    speed_m_s: float,
    late_start: bool,
    kernel: Kernel | None = None,
    clock: CpuClock | None = None,
) -> np.ndarray:
    """The compiled shooting's record (``AP_*``) after its call, unchecked.

    The arguments are :func:`solve_approach`'s. Besides what that function
    reads back, the record counts the free-flight runs flown (``AP_RUNS``).
    """
    free = run._replace(
        x0=np.zeros(L.NX),
        span=np.zeros(L.NSPAN),
        shapes=np.zeros((0, SHP.NSHAPE)),
        pairs=np.zeros((0, NPAIR), dtype=np.int64),
        opts=free_opts,
        scfg=np.zeros(IMS.NSCFG),
        noise=np.zeros((0, 6)),
        t_out=np.array([float(impact_time_s)]),
    )
    ap = _shooting_inputs(q, rotors, start, impact_time_s, speed_m_s, late_start)
    solve = (kernel or BUILTIN).approach
    args = (free, new_output(free, 0, 1), wall, pair_table(run.feat, wall), ap)
    if clock is None:
        solve(*args)
    else:
        with clock:
            solve(*args)
    return ap


def _shooting_inputs(
    q: np.ndarray, rotors: np.ndarray, start: np.ndarray, tc: float, vc: float, late: bool
) -> np.ndarray:
    """The shooting's record (``AP_*``) before the call: ``T_c`` (``tc``, s),
    ``V_c`` (``vc``, m/s), the late-start rule (``late``), the start position before the X
    shift (inertial NED, m), the attitude held ``q`` and the initial rotor speeds."""
    ap = np.zeros(NAP)
    ap[AP_TC] = tc
    ap[AP_VC] = vc
    ap[AP_LATE_RULE] = 1.0 if late else 0.0
    ap[AP_START : AP_START + 3] = start
    ap[AP_Q : AP_Q + 4] = q
    ap[AP_ROTORS : AP_ROTORS + len(rotors)] = rotors
    return ap


def _shooting_result(ap: np.ndarray) -> tuple[np.ndarray, float, dict[str, Any]]:
    """What the shooting found in its record ``ap`` (``AP_*``): the initial state,
    the start time (s) and the summary's ``approach`` (:func:`solve_approach`); a failed
    run (``RuntimeError``) or no late start reaching the speed (``ValueError``) raised."""
    status = int(ap[AP_STATUS])
    if status == APPROACH_RUN_FAILED:
        reason = L.REASON_TEXT.get(int(ap[AP_REASON]), "") or "no state sampled at T_c"
        raise RuntimeError("approach shooting run failed: " + reason)
    if status == APPROACH_NO_BRACKET:
        raise ValueError(
            "approach: no late start reaches the wall at the speed asked "
            "(the speed residual has one sign over [0, T_c))"
        )
    x0 = ap[AP_X0 : AP_X0 + L.NX].copy()
    approach = {
        "start_time_s": float(ap[AP_T0]),
        "start_x_m": float(x0[L.X_POS]),
        "start_speed_m_s": float(ap[AP_V0]),
        "late_start": bool(ap[AP_LATE]),
        "speed_residual_m_s": float(ap[AP_DV]),
    }
    return x0, float(ap[AP_T0]), approach
