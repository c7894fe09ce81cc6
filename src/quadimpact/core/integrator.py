"""Dormand-Prince 5(4) (MATLAB's ode45) with its continuous extension.

One step of the 7-stage FSAL pair, the scaled max-norm error estimate of
ode45 (each component against ``atol + rtol max(|y|, |y_new|)``), the
step-size update, and the 4th-order dense output of Shampine (1986), as also
used by SciPy's ``RK45``. The problem (the right-hand side) is passed in by
the run loop; nothing here knows about quadrotors.

The vectors have the length of the arrays passed in: the run loop passes the
state's first ``N_RIGID + n`` components (``core.rotors.active_states``), the
rigid body and the vehicle's ``n`` rotors. The rotor slots beyond them are
constant zeros, so the error norm and the dense output are those of the
vehicle's own state.
"""

import numpy as np

from quadimpact.core.compiled import compiled

# Butcher tableau
C2, C3, C4, C5 = 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0
A21 = 1.0 / 5.0
A31, A32 = 3.0 / 40.0, 9.0 / 40.0
A41, A42, A43 = 44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0
A51, A52, A53, A54 = 19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0
A61, A62, A63, A64, A65 = (
    9017.0 / 3168.0,
    -355.0 / 33.0,
    46732.0 / 5247.0,
    49.0 / 176.0,
    -5103.0 / 18656.0,
)
B1, B3, B4, B5, B6 = 35.0 / 384.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0
# error weights: b - b_hat
E1 = 71.0 / 57600.0
E3 = -71.0 / 16695.0
E4 = 71.0 / 1920.0
E5 = -17253.0 / 339200.0
E6 = 22.0 / 525.0
E7 = -1.0 / 40.0

# dense output: y(t + s h) = y + h sum_i K_i sum_k P[i][k] s^(k+1)  (Shampine 1986).
# Scalars, not a global array: Numba cannot cache functions using global arrays.
P00, P01, P02, P03 = (
    1.0,
    -8048581381.0 / 2820520608.0,
    8663915743.0 / 2820520608.0,
    -12715105075.0 / 11282082432.0,
)
P21, P22, P23 = (
    131558114200.0 / 32700410799.0,
    -68118460800.0 / 10900136933.0,
    87487479700.0 / 32700410799.0,
)
P31, P32, P33 = (
    -1754552775.0 / 470086768.0,
    14199869525.0 / 1410260304.0,
    -10690763975.0 / 1880347072.0,
)
P41, P42, P43 = (
    127303824393.0 / 49829197408.0,
    -318862633887.0 / 49829197408.0,
    701980252875.0 / 199316789632.0,
)
P51, P52, P53 = (
    -282668133.0 / 205662961.0,
    2019193451.0 / 616988883.0,
    -1453857185.0 / 822651844.0,
)
P61, P62, P63 = (
    40617522.0 / 29380423.0,
    -110615467.0 / 29380423.0,
    69997945.0 / 29380423.0,
)

SAFETY = 0.9
FAC_MIN = 0.2
FAC_MAX = 10.0
ORDER_EXP = 1.0 / 5.0


@compiled
def stage_state(x: np.ndarray, K: np.ndarray, h: float, stage: int, out: np.ndarray) -> None:
    """State at which stage ``stage`` (1..6) is evaluated; ``K[0..stage-1]`` known."""
    n = x.shape[0]
    for i in range(n):
        if stage == 1:
            acc = A21 * K[0, i]
        elif stage == 2:
            acc = A31 * K[0, i] + A32 * K[1, i]
        elif stage == 3:
            acc = A41 * K[0, i] + A42 * K[1, i] + A43 * K[2, i]
        elif stage == 4:
            acc = A51 * K[0, i] + A52 * K[1, i] + A53 * K[2, i] + A54 * K[3, i]
        elif stage == 5:
            acc = A61 * K[0, i] + A62 * K[1, i] + A63 * K[2, i] + A64 * K[3, i] + A65 * K[4, i]
        else:
            acc = B1 * K[0, i] + B3 * K[2, i] + B4 * K[3, i] + B5 * K[4, i] + B6 * K[5, i]
        out[i] = x[i] + h * acc


@compiled
def error_norm(
    x: np.ndarray, x_new: np.ndarray, K: np.ndarray, h: float, rtol: float, atol: float
) -> float:
    """Max over components of |local error| / (atol + rtol max(|x|, |x_new|))."""
    err = 0.0
    for i in range(x.shape[0]):
        e = h * (
            E1 * K[0, i] + E3 * K[2, i] + E4 * K[3, i] + E5 * K[4, i] + E6 * K[5, i] + E7 * K[6, i]
        )
        sc = atol + rtol * max(abs(x[i]), abs(x_new[i]))
        r = abs(e) / sc
        if r > err:
            err = r
    return err


@compiled
def step_factor(err: float, accepted_before: bool) -> float:
    """Step-size multiplier after a trial with scaled error ``err``."""
    if err == 0.0:
        return FAC_MAX
    fac = SAFETY * err ** (-ORDER_EXP)
    if err > 1.0:
        return max(FAC_MIN, min(1.0, fac))
    if not accepted_before:
        return max(1.0, min(FAC_MAX, fac))
    return max(FAC_MIN, min(FAC_MAX, fac))


@compiled
def dense_coefficients(K: np.ndarray, Q: np.ndarray, n: int) -> None:
    """``Q = K^T P`` (n x 4), the dense-output polynomial coefficients of the last step,
    for the first ``n`` components."""
    for i in range(n):
        k0 = K[0, i]
        k2 = K[2, i]
        k3 = K[3, i]
        k4 = K[4, i]
        k5 = K[5, i]
        k6 = K[6, i]
        Q[i, 0] = P00 * k0
        Q[i, 1] = P01 * k0 + P21 * k2 + P31 * k3 + P41 * k4 + P51 * k5 + P61 * k6
        Q[i, 2] = P02 * k0 + P22 * k2 + P32 * k3 + P42 * k4 + P52 * k5 + P62 * k6
        Q[i, 3] = P03 * k0 + P23 * k2 + P33 * k3 + P43 * k4 + P53 * k5 + P63 * k6


@compiled
def dense_eval(x_old: np.ndarray, Q: np.ndarray, h: float, sigma: float, out: np.ndarray) -> None:
    """Interpolated state at ``t_old + sigma h`` (0 <= sigma <= 1), into ``out``."""
    s1 = sigma
    s2 = s1 * sigma
    s3 = s2 * sigma
    s4 = s3 * sigma
    for i in range(x_old.shape[0]):
        out[i] = x_old[i] + h * (Q[i, 0] * s1 + Q[i, 1] * s2 + Q[i, 2] * s3 + Q[i, 3] * s4)


@compiled(inline="always")
def dense_eval_part(
    x_old: np.ndarray, Q: np.ndarray, h: float, sigma: float, out: np.ndarray, lo: int, hi: int
) -> None:
    """:func:`dense_eval` of the components ``lo`` to ``hi - 1`` only (the same bits for them)."""
    s1 = sigma
    s2 = s1 * sigma
    s3 = s2 * sigma
    s4 = s3 * sigma
    for i in range(lo, hi):
        out[i] = x_old[i] + h * (Q[i, 0] * s1 + Q[i, 1] * s2 + Q[i, 2] * s3 + Q[i, 3] * s4)


@compiled
def copy_into(dst: np.ndarray, src: np.ndarray) -> None:
    """``dst[:] = src`` element by element (no temporary: the arrays never overlap here)."""
    for i in range(src.shape[0]):
        dst[i] = src[i]


@compiled
def all_finite(x: np.ndarray) -> bool:
    """Every component of ``x`` finite (no temporary array)."""
    for i in range(x.shape[0]):
        if not np.isfinite(x[i]):
            return False
    return True
