"""The authors' EKF (their 2016 estimator study): 7 states, an additive quaternion.

State ``x = (q, b)``: the attitude quaternion (body to inertial, scalar
first) treated as a plain 4-vector, and the gyro bias; covariance ``P``
(7 x 7, in ``est[ES_P]`` with the row stride ``N_EKF``).

Prediction at each IMU sample, the first too (with ``dt = 0``; the update
follows it, as in a loop of predict-then-update from the start), with the
gyro ``w``, ``dt`` since the last sample, ``w_hat = w - b_hat``::

    q_hat <- q_hat + dt/2 Omega(w_hat) q_hat,  normalised     (q (x) (0, w_hat) dt/2)
    F     = [[F_qq, -dt/2 Xi(q_hat)], [0, I]]
    P     <- F P F^T + dt diag(q_quat I4, q_bias I3)

with ``Omega(w) q = q (x) (0, w)`` and ``Xi(q) v = q (x) (0, v)``. The correct
quaternion block is ``F_qq = I + dt/2 Omega(w_hat)``; the authors' code had
``F_qq = -dt/2 (I + Omega(w_hat))`` (``EC_AS_WRITTEN``), which is of order
``dt``: ``F P F^T`` all but vanishes, and the quaternion's covariance is in
effect reset to the process noise at every step (at the first sample, where
``dt = 0``, to nothing: ``P0``'s quaternion part never reaches an update).

Update with the raw accelerometer and magnetometer readings, stacked as
``z = (f, m)`` against ``h(q) = (C(q)^T (0, 0, -g), C(q)^T m_I)``
(``C(q)^T v = (q0^2 - |q_v|^2) v + 2 (q_v . v) q_v - 2 q0 q_v x v``), with the
noise ``diag(r_acc I3, r_mag I3)``; the accelerometer's rows only while
``||f| - g| <= gate``, the magnetometer's whenever it has a sample. The rows
are applied one at a time (exactly the stacked update for a diagonal noise,
with every row linearised at the prediction), then ``q_hat`` is normalised.
"""

import math

import numpy as np

from quadimpact.core.compiled import allocating, compiled
from quadimpact.core.estimator_slots import EC_OWN, ES_BIAS, ES_GATED, ES_Q, ES_W, N_OWN_ECFG
from quadimpact.core.estimators.ekf import EC_GATE, ES_P, N_EKF, N_EKF_CFG
from quadimpact.core.estimators.navigation import integrate_navigation
from quadimpact.core.estimators.older_sensors import MAG, MAG_FIELD_I, MAG_T
from quadimpact.core.layout import Block
from quadimpact.core.records import Data, Model
from quadimpact.core.sensors.measurement_slots import MS_IMU_F, MS_IMU_W
from quadimpact.core.sensors.rotvec import dcm
from quadimpact.core.vehicle_slots import V_GRAVITY

# ---- its block: after the EKF's (core/estimators/ekf.py), whose gate (EC_GATE) and
# covariance slots (ES_P, 7 x 7 with the row stride N_EKF) it uses
_cfg = Block("ecfg.ekf-additive", "EC_", start=N_EKF_CFG, capacity=EC_OWN + N_OWN_ECFG)
EC_AS_WRITTEN = _cfg.slot("EC_AS_WRITTEN")  # 1: the transition -dt/2 (I + Omega)
EC_R_ACC = _cfg.slot("EC_R_ACC")  # accelerometer noise variance, (m/s^2)^2
EC_R_MAG = _cfg.slot("EC_R_MAG")  # magnetometer noise variance (field units^2)
EC_Q_QUAT = _cfg.slot("EC_Q_QUAT")  # quaternion process noise per second
EC_Q_BIAS = _cfg.slot("EC_Q_BIAS")  # bias process noise per second, (rad/s)^2
EC_P0_QUAT = _cfg.slot("EC_P0_QUAT")  # initial quaternion variance
EC_P0_BIAS = _cfg.slot("EC_P0_BIAS")  # initial bias variance, (rad/s)^2
N_ADDITIVE_CFG = _cfg.end("N_ADDITIVE_CFG")

N_ADDITIVE = 7  # quaternion (4), gyro bias (3)


@compiled
def additive_init(m: Model, d: Data) -> None:
    """The initial covariance ``diag(p0_quat I4, p0_bias I3)`` (variances)."""
    est = d.est
    for k in range(N_EKF * N_EKF):
        est[ES_P + k] = 0.0
    for k in range(N_ADDITIVE):
        est[ES_P + k * N_EKF + k] = m.ecfg[EC_P0_QUAT] if k < 4 else m.ecfg[EC_P0_BIAS]


@compiled
def _normalise(q: np.ndarray) -> None:
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    for a in range(4):
        q[a] /= n


@compiled
def _transition(F: np.ndarray, q: np.ndarray, w: tuple, dt: float, as_written: bool) -> None:
    """The transition matrix ``F`` (7 x 7) at ``q`` with the rates ``w`` (rad/s) over ``dt``."""
    wx, wy, wz = w
    h = 0.5 * dt
    # Omega(w): q (x) (0, w) = Omega(w) q
    om = (
        (0.0, -wx, -wy, -wz),
        (wx, 0.0, wz, -wy),
        (wy, -wz, 0.0, wx),
        (wz, wy, -wx, 0.0),
    )
    for i in range(N_ADDITIVE):
        for j in range(N_ADDITIVE):
            F[i, j] = 1.0 if i == j else 0.0
    for i in range(4):
        for j in range(4):
            if as_written:
                F[i, j] = -h * ((1.0 if i == j else 0.0) + om[i][j])
            else:
                F[i, j] += h * om[i][j]
    # d/db of q (x) (0, w - b) dt/2: -dt/2 Xi(q)
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    xi = ((-q1, -q2, -q3), (q0, -q3, q2), (q3, q0, -q1), (-q2, q1, q0))
    for i in range(4):
        for j in range(3):
            F[i, 4 + j] = -h * xi[i][j]


@compiled
def _rotate_t(q: np.ndarray, v: tuple, J: np.ndarray, row: int) -> tuple[float, float, float]:
    """``C(q)^T v`` and its Jacobian in ``q`` into ``J[row : row + 3, :4]``."""
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    v0, v1, v2 = v
    s = q0 * q0 - (q1 * q1 + q2 * q2 + q3 * q3)
    d = q1 * v0 + q2 * v1 + q3 * v2
    cx = q2 * v2 - q3 * v1  # q_v x v
    cy = q3 * v0 - q1 * v2
    cz = q1 * v1 - q2 * v0
    h = (s * v0 + 2.0 * d * q1 - 2.0 * q0 * cx,
         s * v1 + 2.0 * d * q2 - 2.0 * q0 * cy,
         s * v2 + 2.0 * d * q3 - 2.0 * q0 * cz)  # fmt: skip
    qv = (q1, q2, q3)
    vv = (v0, v1, v2)
    c = (cx, cy, cz)
    # [v x] (the cross product with v from the left)
    vx = ((0.0, -v2, v1), (v2, 0.0, -v0), (-v1, v0, 0.0))
    for i in range(3):
        J[row + i, 0] = 2.0 * q0 * vv[i] - 2.0 * c[i]
        for j in range(3):
            J[row + i, 1 + j] = (
                -2.0 * vv[i] * qv[j]
                + (2.0 * d if i == j else 0.0)
                + 2.0 * qv[i] * vv[j]
                + 2.0 * q0 * vx[i][j]
            )
    return h


@compiled
def _scalar_update(P: np.ndarray, J: np.ndarray, row: int, y: float, r: float, dx: np.ndarray,
                   T: np.ndarray) -> None:  # fmt: skip
    """One scalar row ``J[row]`` of the update: innovation ``y`` (less ``J[row] dx``), noise
    variance ``r``; the correction accumulates in ``dx``, ``P`` is updated. ``T``: scratch."""
    n = N_ADDITIVE
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += P[i, j] * J[row, j]
        T[0, i] = s  # P h^T
    s = r
    for i in range(n):
        s += J[row, i] * T[0, i]
    inn = y
    for i in range(n):
        inn -= J[row, i] * dx[i]
    for i in range(n):
        dx[i] += T[0, i] / s * inn
    for i in range(n):
        for j in range(n):
            P[i, j] -= T[0, i] * T[0, j] / s


@allocating
def additive_sample(t: float, dt: float, m: Model, d: Data, C: np.ndarray) -> None:
    """Predict over ``dt`` (s) and correct with the sample at ``t`` (s).

    ``C``: scratch 3x3 (the estimate's rotation on return).
    """
    ecfg = m.ecfg
    est = d.est
    meas = d.meas
    g = m.veh[V_GRAVITY]
    n = N_ADDITIVE
    W = np.zeros((4, n, n))  # P, F, scratch, the Jacobian (rows 0-5)
    P, F, T, J = W[0], W[1], W[2], W[3]
    for i in range(n):
        for j in range(n):
            P[i, j] = est[ES_P + i * N_EKF + j]
    q = est[ES_Q : ES_Q + 4]
    w = meas[MS_IMU_W : MS_IMU_W + 3]
    f = meas[MS_IMU_F : MS_IMU_F + 3]
    wh = (w[0] - est[ES_BIAS], w[1] - est[ES_BIAS + 1], w[2] - est[ES_BIAS + 2])
    # every sample, the first (dt = 0) too: predict, then update
    _transition(F, q, wh, dt, ecfg[EC_AS_WRITTEN] > 0.5)
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    hdt = 0.5 * dt
    q[0] = q0 + hdt * (-q1 * wh[0] - q2 * wh[1] - q3 * wh[2])
    q[1] = q1 + hdt * (q0 * wh[0] + q2 * wh[2] - q3 * wh[1])
    q[2] = q2 + hdt * (q0 * wh[1] - q1 * wh[2] + q3 * wh[0])
    q[3] = q3 + hdt * (q0 * wh[2] + q1 * wh[1] - q2 * wh[0])
    _normalise(q)
    for i in range(n):  # T = F P
        for j in range(n):
            s = 0.0
            for k in range(n):
                s += F[i, k] * P[k, j]
            T[i, j] = s
    for i in range(n):  # P = T F^T + Q
        for j in range(n):
            s = 0.0
            for k in range(n):
                s += T[i, k] * F[j, k]
            P[i, j] = s
    for k in range(n):
        P[k, k] += dt * (ecfg[EC_Q_QUAT] if k < 4 else ecfg[EC_Q_BIAS])
    dx = T[6]  # the correction (T's last row; T[0] is the update's scratch)
    dx[:] = 0.0
    fn = math.sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2])
    use_acc = abs(fn - g) <= ecfg[EC_GATE]
    est[ES_GATED] = 0.0 if use_acc else 1.0
    for i in range(6):
        for j in range(n):
            J[i, j] = 0.0
    if use_acc:
        h = _rotate_t(q, (0.0, 0.0, -g), J, 0)
        for i in range(3):
            _scalar_update(P, J, i, f[i] - h[i], ecfg[EC_R_ACC], dx, T)
    if meas[MAG_T] == t:
        mi = m.scfg[MAG_FIELD_I : MAG_FIELD_I + 3]
        h = _rotate_t(q, (mi[0], mi[1], mi[2]), J, 3)
        for i in range(3):
            _scalar_update(P, J, 3 + i, meas[MAG + i] - h[i], ecfg[EC_R_MAG], dx, T)
    for a in range(4):
        q[a] += dx[a]
    _normalise(q)
    for a in range(3):
        est[ES_BIAS + a] += dx[4 + a]
    for i in range(n):
        for j in range(n):
            est[ES_P + i * N_EKF + j] = 0.5 * (P[i, j] + P[j, i])
    for a in range(3):
        est[ES_W + a] = w[a] - est[ES_BIAS + a]
    dcm(q, C)
    integrate_navigation(est, C, f, g, dt)
