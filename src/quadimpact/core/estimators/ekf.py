"""A multiplicative (error-state) extended Kalman filter.

Nominal state: the attitude ``q_hat`` (body to inertial), the gyro bias
``b_hat`` and, integrated from the accelerometer, the velocity ``v_hat`` and
position ``p_hat`` (inertial). Error state: ``dtheta`` (rotation vector, body
axes, ``q = q_hat (x) exp(dtheta)``), ``db = b - b_hat``, and, when the run has
a pose sensor (``EC_NAV``), ``dv``, ``dp``: 6 or 12 states, covariance ``P``
(``est[ES_P]``, 12 x 12 row-major, the first ``n`` rows and columns used).

Prediction at each IMU sample (gyro ``w``, specific force ``f``, ``dt`` since
the last sample), ``w_hat = w - b_hat``::

    q_hat <- q_hat (x) exp(w_hat dt)
    Phi   = [[R(w_hat dt)^T, -I dt, 0, 0],
             [0,              I,    0, 0],
             [-C_hat [f x] dt, 0,   I, 0],
             [0,              0,  I dt, I]]
    P     <- Phi P Phi^T + diag(s_g^2 dt^2 I, s_b^2 dt I, s_a^2 dt^2 I, 0)

(``s_g``: the gyro's white noise per sample, rad/s; ``s_b``: its bias random
walk, rad/s/sqrt(s); ``s_a``: the accelerometer's noise per sample, m/s^2),
then velocity and position by ``navigation.py``.

Updates, each a 3-row Kalman update in Joseph form followed by the injection
``q_hat <- q_hat (x) exp(dtheta)``, ``b_hat += db``, ``v_hat += dv``, ``p_hat += dp``:

* accelerometer as a measurement of gravity, ``f = -g C^T e_Z``:
  ``H_theta = -g [u x]`` with ``u = C_hat^T e_Z``, noise ``s_grav`` (m/s^2);
  while ``||f| - g| > gate`` it is skipped (``GATE_SKIP``) or its noise
  variance multiplied by ``k (||f| - g| / gate)^2`` (``GATE_DEWEIGHT``);
* magnetometer, ``m = C^T m_I``: ``H_theta = [u_m x]``, ``u_m = C_hat^T m_I``;
* pose position, ``p_m = p``: ``H_p = I``; pose attitude, the rotation vector
  from the estimate to the measured attitude: ``H_theta = I``.

The reset's second-order term (``P <- G P G^T``, ``G = I - [dtheta/2 x]``) is
neglected. All noise figures are parameters (``ecfg``); by default they are
the sensors' own (with floors, so an ideal IMU does not make ``P`` singular).
"""

import math

import numpy as np
from numba import njit

from ..layout import (
    EC_DEWEIGHT,
    EC_GATE,
    EC_GATE_MODE,
    EC_NAV,
    EC_P0,
    EC_SIG_ACC,
    EC_SIG_ATT,
    EC_SIG_GRAV,
    EC_SIG_GYRO,
    EC_SIG_MAG,
    EC_SIG_POS,
    EC_SIG_WALK,
    ES_BIAS,
    ES_GATED,
    ES_P,
    ES_POS,
    ES_Q,
    ES_VEL,
    ES_W,
    GATE_DEWEIGHT,
    MS_IMU_F,
    MS_IMU_W,
    MS_MAG,
    MS_MAG_T,
    MS_POSE,
    MS_POSE_T,
    N_EKF,
    SC_MAG_FIELD,
    SC_POSE_ATT,
    V_GRAVITY,
)
from ..quaternion import rotation_matrix
from ..records import Data, Model
from ..sensors.rotvec import error_vector, rotate_by
from .navigation import integrate_navigation


@njit(cache=True)
def ekf_dimension(ecfg: np.ndarray) -> int:
    """Error-state dimension: 12 with the navigation states (a pose sensor), else 6."""
    return N_EKF if ecfg[EC_NAV] > 0.5 else 6


@njit(cache=True)
def ekf_init(m: Model, d: Data) -> None:
    """The initial covariance: ``diag(s_att^2, s_bias^2, s_vel^2, s_pos^2)`` (``EC_P0``)."""
    est = d.est
    for k in range(N_EKF * N_EKF):
        est[ES_P + k] = 0.0
    for k in range(N_EKF):
        s = m.ecfg[EC_P0 + k // 3]
        est[ES_P + k * N_EKF + k] = s * s


@njit(cache=True)
def covariance(est: np.ndarray, n: int) -> np.ndarray:
    """A copy of the covariance's first ``n`` rows and columns."""
    P = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            P[i, j] = est[ES_P + i * N_EKF + j]
    return P


@njit(cache=True)
def _store(est: np.ndarray, P: np.ndarray) -> None:
    n = P.shape[0]
    for i in range(n):
        for j in range(n):
            est[ES_P + i * N_EKF + j] = 0.5 * (P[i, j] + P[j, i])


@njit(cache=True)
def _skew(H: np.ndarray, col: int, s: float, u0: float, u1: float, u2: float) -> None:
    """``H[:, col:col+3] = s [u x]``."""
    H[0, col] = 0.0
    H[0, col + 1] = -s * u2
    H[0, col + 2] = s * u1
    H[1, col] = s * u2
    H[1, col + 1] = 0.0
    H[1, col + 2] = -s * u0
    H[2, col] = -s * u1
    H[2, col + 1] = s * u0
    H[2, col + 2] = 0.0


@njit(cache=True)
def _mm(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """``A B`` in a fixed order of operations (no BLAS: the same bits on every CPU)."""
    n, k = A.shape
    m = B.shape[1]
    out = np.zeros((n, m))
    for i in range(n):
        for j in range(m):
            s = 0.0
            for r in range(k):
                s += A[i, r] * B[r, j]
            out[i, j] = s
    return out


@njit(cache=True)
def _mmt(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """``A B^T`` in a fixed order of operations."""
    n, k = A.shape
    m = B.shape[0]
    out = np.zeros((n, m))
    for i in range(n):
        for j in range(m):
            s = 0.0
            for r in range(k):
                s += A[i, r] * B[j, r]
            out[i, j] = s
    return out


@njit(cache=True)
def _inverse3(S: np.ndarray) -> np.ndarray:
    """The inverse of a 3 x 3 matrix (adjugate over determinant)."""
    a, b, c = S[0, 0], S[0, 1], S[0, 2]
    d, e, f = S[1, 0], S[1, 1], S[1, 2]
    g, h, i = S[2, 0], S[2, 1], S[2, 2]
    A = e * i - f * h
    B = -(d * i - f * g)
    Cc = d * h - e * g
    det = a * A + b * B + c * Cc
    out = np.empty((3, 3))
    out[0, 0] = A / det
    out[1, 0] = B / det
    out[2, 0] = Cc / det
    out[0, 1] = -(b * i - c * h) / det
    out[1, 1] = (a * i - c * g) / det
    out[2, 1] = -(a * h - b * g) / det
    out[0, 2] = (b * f - c * e) / det
    out[1, 2] = -(a * f - c * d) / det
    out[2, 2] = (a * e - b * d) / det
    return out


@njit(cache=True)
def kalman_update(est: np.ndarray, P: np.ndarray, H: np.ndarray, y: np.ndarray, r: float) -> None:
    """One 3-row update of ``P`` (in place) with innovation ``y`` and noise variance ``r``;
    the correction injected into the nominal state ``est``."""
    n = P.shape[0]
    PHt = _mmt(P, H)
    S = _mm(H, PHt)
    for k in range(3):
        S[k, k] += r
    K = _mm(PHt, _inverse3(S))
    dx = np.zeros(n)
    for i in range(n):
        dx[i] = K[i, 0] * y[0] + K[i, 1] * y[1] + K[i, 2] * y[2]
    IKH = np.eye(n) - _mm(K, H)
    Pn = _mmt(_mm(IKH, P), IKH)
    KKt = _mmt(K, K)
    for i in range(n):
        for j in range(n):
            P[i, j] = Pn[i, j] + r * KKt[i, j]
    rotate_by(est[ES_Q : ES_Q + 4], dx[0], dx[1], dx[2])
    for a in range(3):
        est[ES_BIAS + a] += dx[3 + a]
    if n == N_EKF:
        for a in range(3):
            est[ES_VEL + a] += dx[6 + a]
            est[ES_POS + a] += dx[9 + a]


@njit(cache=True)
def ekf_predict(est: np.ndarray, P: np.ndarray, ecfg: np.ndarray, w: np.ndarray,
                f: np.ndarray, dt: float, C: np.ndarray) -> None:  # fmt: skip
    """The prediction over ``dt`` (s): attitude and covariance (``C``: the rotation before)."""
    n = P.shape[0]
    wx = w[0] - est[ES_BIAS]
    wy = w[1] - est[ES_BIAS + 1]
    wz = w[2] - est[ES_BIAS + 2]
    Phi = np.eye(n)
    # R(w dt)^T: the rotation of the rotation vector -w dt
    R = np.empty((3, 3))
    q = np.array([1.0, 0.0, 0.0, 0.0])
    rotate_by(q, -wx * dt, -wy * dt, -wz * dt)
    rotation_matrix(q, R)
    for i in range(3):
        for j in range(3):
            Phi[i, j] = R[i, j]
        Phi[i, 3 + i] = -dt
    if n == N_EKF:
        # -C [f x] dt
        Fx = np.zeros((3, 3))
        Fx[0, 1] = -f[2]
        Fx[0, 2] = f[1]
        Fx[1, 0] = f[2]
        Fx[1, 2] = -f[0]
        Fx[2, 0] = -f[1]
        Fx[2, 1] = f[0]
        CF = _mm(C, Fx)
        for i in range(3):
            for j in range(3):
                Phi[6 + i, j] = -CF[i, j] * dt
            Phi[9 + i, 6 + i] = dt
    Pn = _mmt(_mm(Phi, P), Phi)
    sg = ecfg[EC_SIG_GYRO] * dt
    sb = ecfg[EC_SIG_WALK]
    for k in range(3):
        Pn[k, k] += sg * sg
        Pn[3 + k, 3 + k] += sb * sb * dt
    if n == N_EKF:
        sa = ecfg[EC_SIG_ACC] * dt
        for k in range(3):
            Pn[6 + k, 6 + k] += sa * sa
    P[:, :] = Pn
    rotate_by(est[ES_Q : ES_Q + 4], wx * dt, wy * dt, wz * dt)


@njit(cache=True)
def ekf_sample(t: float, dt: float, m: Model, d: Data, C: np.ndarray) -> None:
    """Predict over ``dt`` (s) and correct with the measurements of the sample at ``t`` (s).

    ``C``: scratch 3x3 (the estimate's rotation on return).
    """
    ecfg = m.ecfg
    est = d.est
    meas = d.meas
    g = m.veh[V_GRAVITY]
    n = ekf_dimension(ecfg)
    P = covariance(est, n)
    f = meas[MS_IMU_F : MS_IMU_F + 3]
    w = meas[MS_IMU_W : MS_IMU_W + 3]
    q = est[ES_Q : ES_Q + 4]
    rotation_matrix(q, C)
    if dt > 0.0:
        ekf_predict(est, P, ecfg, w, f, dt, C)
        rotation_matrix(q, C)
        integrate_navigation(est, C, f, g, dt)
    H = np.zeros((3, n))
    y = np.empty(3)
    # accelerometer: gravity
    fn = math.sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2])
    excess = abs(fn - g)
    gate = ecfg[EC_GATE]
    r = ecfg[EC_SIG_GRAV] ** 2
    use = excess <= gate
    if not use and int(ecfg[EC_GATE_MODE]) == GATE_DEWEIGHT and gate > 0.0:
        use = True
        r *= max(1.0, ecfg[EC_DEWEIGHT] * (excess / gate) ** 2)
    est[ES_GATED] = 0.0 if excess <= gate else 1.0
    if use:
        u0 = C[2, 0]
        u1 = C[2, 1]
        u2 = C[2, 2]
        for k in range(3):
            y[k] = f[k] + g * (C[2, k])
        _skew(H, 0, -g, u0, u1, u2)
        kalman_update(est, P, H, y, r)
        rotation_matrix(q, C)
    # magnetometer
    if meas[MS_MAG_T] == t:
        mi = m.scfg[SC_MAG_FIELD : SC_MAG_FIELD + 3]
        u = np.empty(3)
        for k in range(3):
            u[k] = C[0, k] * mi[0] + C[1, k] * mi[1] + C[2, k] * mi[2]
            y[k] = meas[MS_MAG + k] - u[k]
        H[:, :] = 0.0
        _skew(H, 0, 1.0, u[0], u[1], u[2])
        kalman_update(est, P, H, y, ecfg[EC_SIG_MAG] ** 2)
        rotation_matrix(q, C)
    # pose sensor
    if meas[MS_POSE_T] == t:
        if n == N_EKF:
            H[:, :] = 0.0
            for k in range(3):
                H[k, 9 + k] = 1.0
                y[k] = meas[MS_POSE + k] - est[ES_POS + k]
            kalman_update(est, P, H, y, ecfg[EC_SIG_POS] ** 2)
        if m.scfg[SC_POSE_ATT] > 0.5:
            H[:, :] = 0.0
            for k in range(3):
                H[k, k] = 1.0
            y[0], y[1], y[2] = error_vector(q, meas[MS_POSE + 3 : MS_POSE + 7])
            kalman_update(est, P, H, y, ecfg[EC_SIG_ATT] ** 2)
        rotation_matrix(q, C)
    _store(est, P)
    for a in range(3):
        est[ES_W + a] = w[a] - est[ES_BIAS + a]
