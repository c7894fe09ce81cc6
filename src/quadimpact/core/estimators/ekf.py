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

The IMU's impact disturbance (when the sensors have one and ``EC_IMPACT_TAU >
0``): from each sample whose body-horizontal specific force reaches
``EC_IMPACT_THRESHOLD`` (an impact, by the detector's rule; each such sample
restarts it), the gyro's noise in the prediction and the accelerometer's in the
gravity measurement grow by the disturbance, ``g0 exp(-(t - t_i)/tau)`` and
``a0 exp(-(t - t_i)/tau)`` (their variances added, or the larger taken when the
disturbance replaces the nominal noise). Without it the filter believes its
gyro through the impact and explains the disturbance's attitude increments,
which a precise magnetometer sees, as a gyro bias; the bias error's part
along the field, which the magnetometer cannot see, then turns the estimate
about the field's direction, an error only the (de-weighted) accelerometer
can remove (docs/ESTIMATION.md 8.4).

The reset's second-order term (``P <- G P G^T``, ``G = I - [dtheta/2 x]``) is
neglected. All noise figures are parameters (``ecfg``); by default they are
the sensors' own (with floors, so an ideal IMU does not make ``P`` singular).
"""

import math

import numpy as np

from quadimpact.core.compiled import allocating, compiled
from quadimpact.core.estimator_slots import (
    EC_OWN,
    ES_BIAS,
    ES_GATED,
    ES_OWN,
    ES_POS,
    ES_Q,
    ES_VEL,
    ES_W,
    N_OWN_ECFG,
    N_OWN_EST,
)
from quadimpact.core.estimators.navigation import integrate_navigation
from quadimpact.core.estimators.older_sensors import MAG, MAG_FIELD_I, MAG_T, POSE, POSE_ATT, POSE_T
from quadimpact.core.layout import Block
from quadimpact.core.records import Data, Model
from quadimpact.core.sensors.measurement_slots import MS_IMU_F, MS_IMU_W
from quadimpact.core.sensors.rotvec import dcm, error_vector, rotate_by
from quadimpact.core.vehicle_slots import V_GRAVITY

# ---- its blocks at ecfg[EC_OWN:] and est[ES_OWN:] (core/estimator_slots.py); the additive EKF
# and nav-ekf continue them (they share the gate, the noises and the covariance slots)
_cfg = Block("ecfg.ekf", "EC_", start=EC_OWN, capacity=EC_OWN + N_OWN_ECFG)
EC_GATE = _cfg.slot("EC_GATE")  # m/s^2: accelerometer correction gated while ||f| - g| > this
EC_GATE_MODE = _cfg.slot("EC_GATE_MODE")  # GATE_SKIP or GATE_DEWEIGHT
EC_DEWEIGHT = _cfg.slot("EC_DEWEIGHT")  # de-weighting: R times this (excess / gate)^2
EC_SIG_GYRO = _cfg.slot("EC_SIG_GYRO")  # gyro white noise per sample, rad/s
EC_SIG_WALK = _cfg.slot("EC_SIG_WALK")  # gyro bias random walk, rad/s/sqrt(s)
EC_SIG_ACC = _cfg.slot("EC_SIG_ACC")  # accelerometer white noise per sample, m/s^2
EC_SIG_GRAV = _cfg.slot("EC_SIG_GRAV")  # std of the gravity measurement, m/s^2
EC_SIG_MAG = _cfg.slot("EC_SIG_MAG")  # magnetometer noise (unit field)
EC_SIG_POS = _cfg.slot("EC_SIG_POS")  # pose position noise, m
EC_SIG_ATT = _cfg.slot("EC_SIG_ATT")  # pose attitude noise, rad
EC_P0 = _cfg.slot("EC_P0", 4)  # initial std: attitude rad, bias rad/s, velocity m/s, position m
EC_NAV = _cfg.slot("EC_NAV")  # 1: velocity and position are filter states (pose sensor)
EC_IMPACT_W = _cfg.slot("EC_IMPACT_W")  # the IMU's impact disturbance: gyro g0, rad/s
EC_IMPACT_F = _cfg.slot("EC_IMPACT_F")  # ... accelerometer a0, m/s^2
EC_IMPACT_TAU = _cfg.slot("EC_IMPACT_TAU")  # ... time constant, s (<= 0: not modelled)
EC_IMPACT_REPLACE = _cfg.slot("EC_IMPACT_REPLACE")  # 1: it replaces the nominal noise
EC_IMPACT_THRESHOLD = _cfg.slot("EC_IMPACT_THRESHOLD")  # |(f_x, f_y)| marking an impact, m/s^2
N_EKF_CFG = _cfg.end("N_EKF_CFG")
GATE_SKIP = 0
GATE_DEWEIGHT = 1

N_EKF = 12  # error state: attitude (3), gyro bias (3), velocity (3), position (3)
_st = Block("est.ekf", "ES_", start=ES_OWN, capacity=ES_OWN + N_OWN_EST)
ES_P = _st.slot("ES_P", N_EKF * N_EKF)  # error covariance, row-major
ES_SCRATCH = _st.slot("ES_SCRATCH", 4)  # a quaternion's worth of scratch (the prediction)
ES_T_IMPACT = _st.slot("ES_T_IMPACT")  # s, the latest impact sample (NaN: none)
N_EKF_EST = _st.end("N_EKF_EST")


@compiled
def ekf_dimension(ecfg: np.ndarray) -> int:
    """Error-state dimension: 12 with the navigation states (a pose sensor), else 6."""
    return N_EKF if ecfg[EC_NAV] > 0.5 else 6


@compiled
def ekf_init(m: Model, d: Data) -> None:
    """The initial covariance: ``diag(s_att^2, s_bias^2, s_vel^2, s_pos^2)`` (``EC_P0``)."""
    est = d.est
    for k in range(N_EKF * N_EKF):
        est[ES_P + k] = 0.0
    for k in range(N_EKF):
        s = m.ecfg[EC_P0 + k // 3]
        est[ES_P + k * N_EKF + k] = s * s


@allocating
def covariance(est: np.ndarray, n: int) -> np.ndarray:
    """A copy of the covariance's first ``n`` rows and columns (for tests and analysis)."""
    P = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            P[i, j] = est[ES_P + i * N_EKF + j]
    return P


@compiled
def _mul12(W: np.ndarray, a: int, b: int, o: int, n: int, k: int) -> None:
    """``_mul(W, a, b, o, n, k, 12, False)``: each output row in twelve local sums."""
    for i in range(n):
        s0 = s1 = s2 = s3 = s4 = s5 = s6 = s7 = s8 = s9 = s10 = s11 = 0.0
        for r in range(k):
            x = W[a, i, r]
            if x != 0.0:
                s0 += x * W[b, r, 0]
                s1 += x * W[b, r, 1]
                s2 += x * W[b, r, 2]
                s3 += x * W[b, r, 3]
                s4 += x * W[b, r, 4]
                s5 += x * W[b, r, 5]
                s6 += x * W[b, r, 6]
                s7 += x * W[b, r, 7]
                s8 += x * W[b, r, 8]
                s9 += x * W[b, r, 9]
                s10 += x * W[b, r, 10]
                s11 += x * W[b, r, 11]
        W[o, i, 0] = s0
        W[o, i, 1] = s1
        W[o, i, 2] = s2
        W[o, i, 3] = s3
        W[o, i, 4] = s4
        W[o, i, 5] = s5
        W[o, i, 6] = s6
        W[o, i, 7] = s7
        W[o, i, 8] = s8
        W[o, i, 9] = s9
        W[o, i, 10] = s10
        W[o, i, 11] = s11


@compiled
def _mul_bt12(W: np.ndarray, a: int, b: int, o: int, k: int, m: int) -> None:
    """``_mul(W, a, b, o, 12, k, m, True)``: each output column in twelve local sums."""
    for j in range(m):
        s0 = s1 = s2 = s3 = s4 = s5 = s6 = s7 = s8 = s9 = s10 = s11 = 0.0
        for r in range(k):
            y = W[b, j, r]
            if y != 0.0:
                s0 += W[a, 0, r] * y
                s1 += W[a, 1, r] * y
                s2 += W[a, 2, r] * y
                s3 += W[a, 3, r] * y
                s4 += W[a, 4, r] * y
                s5 += W[a, 5, r] * y
                s6 += W[a, 6, r] * y
                s7 += W[a, 7, r] * y
                s8 += W[a, 8, r] * y
                s9 += W[a, 9, r] * y
                s10 += W[a, 10, r] * y
                s11 += W[a, 11, r] * y
        W[o, 0, j] = s0
        W[o, 1, j] = s1
        W[o, 2, j] = s2
        W[o, 3, j] = s3
        W[o, 4, j] = s4
        W[o, 5, j] = s5
        W[o, 6, j] = s6
        W[o, 7, j] = s7
        W[o, 8, j] = s8
        W[o, 9, j] = s9
        W[o, 10, j] = s10
        W[o, 11, j] = s11


@compiled
def _mul(W: np.ndarray, a: int, b: int, o: int, n: int, k: int, m: int, bt: bool) -> None:
    """``W[o, :n, :m] = W[a, :n, :k] W[b, :k, :m]`` (``W[b]^T`` when ``bt``), in a fixed
    order of operations (no BLAS: the same bits on every CPU).

    Each entry is the sum over ``r = 0, 1, ...`` in that order, from ``+0.0``. The
    terms whose structural factor is exactly zero are skipped: ``W[a]``'s, or
    ``W[b]``'s when ``bt`` (``Phi``, ``H`` and ``I - K H`` are mostly zeros).
    Adding a zero product never changes a sum that starts at ``+0.0``, so the
    bits are the same for finite inputs. ``o`` differs from ``a`` and ``b``.

    The 12-wide products (``m = 12``, or ``n = 12`` when ``bt``) keep an output
    row (column) in twelve local sums, in registers, instead of adding into
    ``W[o]`` term by term: the same operations in the same order.
    """
    if bt and n == N_EKF:
        _mul_bt12(W, a, b, o, k, m)
    elif not bt and m == N_EKF:
        _mul12(W, a, b, o, n, k)
    elif bt:
        for j in range(m):
            for i in range(n):
                W[o, i, j] = 0.0
            for r in range(k):
                y = W[b, j, r]
                if y != 0.0:
                    for i in range(n):
                        W[o, i, j] += W[a, i, r] * y
    else:
        for i in range(n):
            for j in range(m):
                W[o, i, j] = 0.0
            for r in range(k):
                x = W[a, i, r]
                if x != 0.0:
                    for j in range(m):
                        W[o, i, j] += x * W[b, r, j]


@compiled
def kalman_update(est: np.ndarray, W: np.ndarray, n: int, y: np.ndarray, r: float) -> None:
    """One 3-row update (Joseph form) of the covariance ``W[0]`` (``n`` states) with the
    rows ``W[4, :3]`` of ``H``, innovation ``y`` and noise variance ``r``; the correction
    injected into the nominal state ``est``. ``W[1..3]``, ``W[5]`` and ``W[4]``'s rows
    6-8: scratch."""
    P, T2, T3, K = W[0], W[2], W[3], W[5]
    _mul(W, 0, 4, 1, n, n, 3, True)  # P H^T (n x 3)
    _mul(W, 4, 1, 2, 3, n, 3, False)  # S = H P H^T (3 x 3)
    for k in range(3):
        T2[k, k] += r
    a, b, c = T2[0, 0], T2[0, 1], T2[0, 2]
    d, e, f = T2[1, 0], T2[1, 1], T2[1, 2]
    g, h, i = T2[2, 0], T2[2, 1], T2[2, 2]
    det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    T3[0, 0] = (e * i - f * h) / det
    T3[0, 1] = -(b * i - c * h) / det
    T3[0, 2] = (b * f - c * e) / det
    T3[1, 0] = -(d * i - f * g) / det
    T3[1, 1] = (a * i - c * g) / det
    T3[1, 2] = -(a * f - c * d) / det
    T3[2, 0] = (d * h - e * g) / det
    T3[2, 1] = -(a * h - b * g) / det
    T3[2, 2] = (a * e - b * d) / det
    _mul(W, 1, 3, 5, n, 3, 3, False)  # K = P H^T S^-1 (n x 3)
    dx = K[:, 3]  # the correction, in K's fourth column
    dx[:] = 0.0
    for j in range(n):
        dx[j] = K[j, 0] * y[0] + K[j, 1] * y[1] + K[j, 2] * y[2]
    _mul(W, 5, 4, 3, n, 3, n, False)  # K H
    for j in range(n):
        for k in range(n):
            T3[j, k] = (1.0 if j == k else 0.0) - T3[j, k]  # I - K H
    Kt = W[4, 6:9]  # K^T, contiguous for the last loop (H's rows 6-8: scratch)
    for k in range(n):
        for a3 in range(3):
            Kt[a3, k] = K[k, a3]
    _mul(W, 3, 0, 1, n, n, n, False)
    _mul(W, 1, 3, 2, n, n, n, True)  # (I - K H) P (I - K H)^T
    for j in range(n):
        k0, k1, k2 = K[j, 0], K[j, 1], K[j, 2]
        for k in range(n):
            P[j, k] = T2[j, k] + r * (k0 * Kt[0, k] + k1 * Kt[1, k] + k2 * Kt[2, k])
    rotate_by(est[ES_Q : ES_Q + 4], dx[0], dx[1], dx[2])
    for a3 in range(3):
        est[ES_BIAS + a3] += dx[3 + a3]
        est[ES_VEL + a3] += dx[6 + a3]
        est[ES_POS + a3] += dx[9 + a3]


@compiled
def _with_impact(sigma: float, amplitude: float, factor: float, replace: bool) -> float:
    """A noise's standard deviation with the impact disturbance ``amplitude * factor``."""
    extra = amplitude * factor
    if replace:
        return max(sigma, extra)
    return math.sqrt(sigma * sigma + extra * extra)


@compiled
def gravity_variance(
    f: np.ndarray, g: float, ecfg: np.ndarray, est: np.ndarray, impact: float
) -> tuple[bool, float]:
    """Whether to fuse the specific force ``f`` (m/s^2) as gravity, and its noise variance.

    The variance is ``EC_SIG_GRAV^2``, plus the impact disturbance's share at
    ``impact`` (per unit amplitude). While ``||f| - g| > EC_GATE`` the sample
    is skipped (``GATE_SKIP``) or its variance multiplied by
    ``EC_DEWEIGHT (excess / gate)^2`` (``GATE_DEWEIGHT``); ``est[ES_GATED]``
    records whether the gate was crossed. The ``ekf`` and ``nav-ekf`` share it.
    """
    fn = math.sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2])
    excess = abs(fn - g)
    gate = ecfg[EC_GATE]
    r = ecfg[EC_SIG_GRAV] ** 2
    if impact > 0.0:
        sa = ecfg[EC_SIG_ACC]
        extra = _with_impact(sa, ecfg[EC_IMPACT_F], impact, ecfg[EC_IMPACT_REPLACE] > 0.5)
        r += extra * extra - sa * sa
    use = excess <= gate
    if not use and int(ecfg[EC_GATE_MODE]) == GATE_DEWEIGHT and gate > 0.0:
        use = True
        r *= max(1.0, ecfg[EC_DEWEIGHT] * (excess / gate) ** 2)
    est[ES_GATED] = 0.0 if excess <= gate else 1.0
    return use, r


@compiled
def impact_noise_factor(t: float, f: np.ndarray, ecfg: np.ndarray, est: np.ndarray) -> float:
    """The IMU's impact disturbance at the sample ``t`` (s) per unit amplitude, as the
    filter sees it: 0 unless modelled (``EC_IMPACT_TAU``) and an impact seen, else
    ``exp(-(t - t_i)/tau)`` from the latest sample ``t_i`` whose ``|(f_x, f_y)|``
    reached ``EC_IMPACT_THRESHOLD`` (this one included)."""
    tau = ecfg[EC_IMPACT_TAU]
    if not tau > 0.0:
        return 0.0
    if math.sqrt(f[0] * f[0] + f[1] * f[1]) >= ecfg[EC_IMPACT_THRESHOLD]:
        est[ES_T_IMPACT] = t
    if np.isnan(est[ES_T_IMPACT]):
        return 0.0
    return math.exp(-(t - est[ES_T_IMPACT]) / tau)


@compiled
def ekf_predict(est: np.ndarray, W: np.ndarray, n: int, ecfg: np.ndarray, w: np.ndarray,
                f: np.ndarray, dt: float, C: np.ndarray, impact: float) -> None:  # fmt: skip
    """The prediction over ``dt`` (s): the attitude and the covariance ``W[0]``.

    ``C``: the estimate's rotation before; ``W[1..3]``: scratch; ``impact``: the
    impact disturbance's factor (:func:`impact_noise_factor`).
    """
    P, T1, Phi = W[0], W[1], W[3]
    wx = w[0] - est[ES_BIAS]
    wy = w[1] - est[ES_BIAS + 1]
    wz = w[2] - est[ES_BIAS + 2]
    for i in range(n):
        for j in range(n):
            Phi[i, j] = 1.0 if i == j else 0.0
    # R(w dt)^T: the rotation of the rotation vector -w dt (into T1's corner)
    q = est[ES_SCRATCH : ES_SCRATCH + 4]
    q[0] = 1.0
    q[1] = 0.0
    q[2] = 0.0
    q[3] = 0.0
    rotate_by(q, -wx * dt, -wy * dt, -wz * dt)
    dcm(q, T1)
    for i in range(3):
        for j in range(3):
            Phi[i, j] = T1[i, j]
        Phi[i, 3 + i] = -dt
    if n == N_EKF:
        # -C [f x] dt
        for i in range(3):
            c0, c1, c2 = C[i, 0], C[i, 1], C[i, 2]
            Phi[6 + i, 0] = -(c1 * f[2] - c2 * f[1]) * dt
            Phi[6 + i, 1] = -(c2 * f[0] - c0 * f[2]) * dt
            Phi[6 + i, 2] = -(c0 * f[1] - c1 * f[0]) * dt
            Phi[9 + i, 6 + i] = dt
    _mul(W, 3, 0, 1, n, n, n, False)
    _mul(W, 1, 3, 0, n, n, n, True)
    replace = ecfg[EC_IMPACT_REPLACE] > 0.5
    sg = ecfg[EC_SIG_GYRO] * dt
    if impact > 0.0:
        sg = _with_impact(ecfg[EC_SIG_GYRO], ecfg[EC_IMPACT_W], impact, replace) * dt
    sb = ecfg[EC_SIG_WALK]
    for k in range(3):
        P[k, k] += sg * sg
        P[3 + k, 3 + k] += sb * sb * dt
    if n == N_EKF:
        sa = ecfg[EC_SIG_ACC] * dt
        if impact > 0.0:
            sa = _with_impact(ecfg[EC_SIG_ACC], ecfg[EC_IMPACT_F], impact, replace) * dt
        for k in range(3):
            P[6 + k, 6 + k] += sa * sa
    rotate_by(est[ES_Q : ES_Q + 4], wx * dt, wy * dt, wz * dt)


@compiled
def ekf_sample(t: float, dt: float, m: Model, d: Data, C: np.ndarray, W: np.ndarray) -> None:
    """Predict over ``dt`` (s) and correct with the measurements of the sample at ``t`` (s).

    ``C``: scratch 3x3 (the estimate's rotation on return). ``W``: the work
    space, ``(6, 12, 12)`` (``records.Work.ekf``, made once per run): the
    covariance, scratch, ``H`` (rows 0-2; the innovation in row 3) and ``K``
    (columns 0-2; the correction in column 3). Every entry is written before
    it is read, so the work space needs no clearing between samples.
    """
    ecfg = m.ecfg
    est = d.est
    meas = d.meas
    g = m.veh[V_GRAVITY]
    n = ekf_dimension(ecfg)
    P = W[0]
    for i in range(n):
        for j in range(n):
            P[i, j] = est[ES_P + i * N_EKF + j]
    f = meas[MS_IMU_F : MS_IMU_F + 3]
    w = meas[MS_IMU_W : MS_IMU_W + 3]
    q = est[ES_Q : ES_Q + 4]
    dcm(q, C)
    impact = impact_noise_factor(t, f, ecfg, est)
    if dt > 0.0:
        ekf_predict(est, W, n, ecfg, w, f, dt, C, impact)
        dcm(q, C)
        integrate_navigation(est, C, f, g, dt)
    H = W[4]
    y = H[3, :3]  # the innovation, in H's fourth row
    # accelerometer: gravity
    use, r = gravity_variance(f, g, ecfg, est, impact)
    if use:
        for k in range(3):
            y[k] = f[k] + g * C[2, k]
        # H_theta = -g [u x], u = C^T e_Z
        _skew(H, -g, C[2, 0], C[2, 1], C[2, 2])
        kalman_update(est, W, n, y, r)
        dcm(q, C)
    # magnetometer: H_theta = [u_m x], u_m = C^T m_I
    if meas[MAG_T] == t:
        mi = m.scfg[MAG_FIELD_I : MAG_FIELD_I + 3]
        u0 = C[0, 0] * mi[0] + C[1, 0] * mi[1] + C[2, 0] * mi[2]
        u1 = C[0, 1] * mi[0] + C[1, 1] * mi[1] + C[2, 1] * mi[2]
        u2 = C[0, 2] * mi[0] + C[1, 2] * mi[1] + C[2, 2] * mi[2]
        y[0] = meas[MAG] - u0
        y[1] = meas[MAG + 1] - u1
        y[2] = meas[MAG + 2] - u2
        _skew(H, 1.0, u0, u1, u2)
        kalman_update(est, W, n, y, ecfg[EC_SIG_MAG] ** 2)
        dcm(q, C)
    # pose sensor: position (H_p = I), attitude (H_theta = I)
    if meas[POSE_T] == t:
        if n == N_EKF:
            _unit(H, 9)
            for k in range(3):
                y[k] = meas[POSE + k] - est[ES_POS + k]
            kalman_update(est, W, n, y, ecfg[EC_SIG_POS] ** 2)
        if m.scfg[POSE_ATT] > 0.5:
            _unit(H, 0)
            y[0], y[1], y[2] = error_vector(q, meas[POSE + 3 : POSE + 7])
            kalman_update(est, W, n, y, ecfg[EC_SIG_ATT] ** 2)
        dcm(q, C)
    for i in range(n):
        for j in range(n):
            est[ES_P + i * N_EKF + j] = 0.5 * (P[i, j] + P[j, i])
    for a in range(3):
        est[ES_W + a] = w[a] - est[ES_BIAS + a]


@compiled
def _skew(H: np.ndarray, s: float, u0: float, u1: float, u2: float) -> None:
    """``H[:3, :] = [s [u x], 0]``: a measurement of the attitude error alone."""
    H[:3, :] = 0.0
    H[0, 1] = -s * u2
    H[0, 2] = s * u1
    H[1, 0] = s * u2
    H[1, 2] = -s * u0
    H[2, 0] = -s * u1
    H[2, 1] = s * u0


@compiled
def _unit(H: np.ndarray, col: int) -> None:
    """``H[:3, :]`` selecting the three states from ``col``."""
    H[:3, :] = 0.0
    for k in range(3):
        H[k, col + k] = 1.0
