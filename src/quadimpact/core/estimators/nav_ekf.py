"""The navigation filter ``nav-ekf``: an error-state EKF fusing the IMU with the aiding sensors.

Nominal state: the attitude ``q_hat`` (body to inertial), the velocity
``v_hat`` and position ``p_hat`` (inertial NED), the gyro bias ``b_g``, the
accelerometer bias ``b_a`` (body) and the barometer's bias ``b_b`` (m). Error
state, 16 numbers (``N_NAV``; covariance ``est[ES_NAV_P]``, row-major)::

    dx = (dtheta [0:3], dv [3:6], dp [6:9], db_g [9:12], db_a [12:15], db_b [15])

with ``q = q_hat (x) exp(dtheta)`` (``dtheta`` in body axes).

Prediction at each IMU sample (``w_hat = w - b_g``, ``f_hat = f_cm - b_a``,
``dt`` since the last sample): strapdown, ``q_hat <- q_hat (x) exp(w_hat dt)``
and ``navigation.py``'s integration of ``C_hat f_hat + g e_Z``; the
covariance with::

    Phi = I + [[R(w_hat dt)^T - I, 0, 0, -I dt, 0,        0],
               [-C [f_hat x] dt,   0, 0, 0,     -C dt,    0],
               [0,                 I dt, 0, 0,  0,        0], 0 ...]
    Q   = diag(s_g^2 dt^2 I, s_a^2 dt^2 I, 0, s_wg^2 dt I, s_wa^2 dt I, s_wb^2 dt)

(the ``ekf``'s conventions: ``s_g``, ``s_a`` the noises per sample).

**The IMU's lever arm.** The accelerometer sits at ``r`` from the CM (body
axes, ``EC_NAV_LEVER``: the IMU's position, or 0 with ``imu_lever_arm =
"none"``) and reads the specific force of that point, ``f = f_cm + w_dot x r
+ w x (w x r)``. In a tumble at 15 rad/s with the Navi's 5-cm offset the
centripetal part alone is 11 m/s^2. The filter's velocity and position are
the CM's. Integrating ``f`` gives the IMU point's, ``v_s = v + C (w x r)``
and ``p_s = p + C r`` (since ``d/dt C (w x r) = C (w_dot x r + w x (w x
r))``, exactly), so each sample integrates ``f`` and then moves ``v`` by
``-(C (w x r))`` and ``p`` by ``-(C r)``, each less its value at the previous
sample (``w = w_gyro - b_g``). The sum telescopes: no angular acceleration is
needed and no discretisation error is added, however fast the tumble. The
covariance's Jacobian and the gravity update read ``f_cm = f - w_dot x r -
w x (w x r)`` (``w_dot`` from two consecutive samples); the impact and
clipping tests the sensor's own ``f``. The
IMU's impact disturbance grows ``s_g`` and ``s_a`` after each impact the
filter sees, as in the ``ekf`` (``ekf.impact_noise_factor``). While an axis
of the gyro reads at its range, the reading is clipped: that sample's ``s_g``
on that axis gets the range added in quadrature; an accelerometer axis at its
range adds its range to ``s_a`` on every axis (the velocity error is inertial).

Updates (each a Kalman update of 1 to 3 rows, ``P <- P - K S K^T``, then the
injection of the correction into the nominal state), at each IMU sample:

* accelerometer as gravity, as the ``ekf`` (``f - b_a = -g C^T e_Z``), with its
  gate on ``||f| - g|`` (skip or de-weight);
* magnetometer, as the ``ekf``, at each of its samples;
* barometer: ``altitude = -p_z + b_b``, at each new sample (its ``n`` grew);
* rangefinder: ``range = -p_z / C_22`` (the slant range to the plane
  ``z = 0`` along the body's down axis), at each new valid sample while the
  estimated tilt is within ``EC_NAV_MAX_TILT``; the sample's own noise
  (``noise_m``), at least ``EC_NAV_RANGE``;
* optical flow: the raw flow compensated with the gyro at the image's
  capture time (the history ``ES_NAV_RING``), ``c = flow + (p, q) =
  (v_By, -v_Bx) C_22 / h`` with ``v_B = C^T v`` and ``h = -p_z`` the
  estimated height, at each new sample of quality > 0 while the tilt is
  within ``EC_NAV_MAX_TILT`` and ``h > EC_NAV_MIN_HEIGHT``; the sample's own
  noise (``noise_rad_s``), at least ``EC_NAV_FLOW``. **Delay**: the image
  was taken ``delay`` before it arrives (20 ms by default). With
  ``EC_NAV_DELAYED`` the predicted flow, its Jacobian and the tilt test use
  the current estimate carried back to the capture time by the prediction
  alone: the history keeps each sample's prediction increments (velocity,
  attitude, height), and the increments since the capture are undone. So
  the innovation compares like with like (the vehicle's own motion over the
  delay is removed), and every correction made since the capture is kept
  (an estimate stored at the capture time would miss them and count the
  later samples twice). The correction goes to the current estimate; over
  20 ms the error state hardly moves, so the current covariance stands for
  the delayed one.

Gates: each aiding update (magnetometer, barometer, rangefinder, flow) is
refused when its normalised innovation squared ``y^T S^-1 y`` exceeds
``n^2 m`` (``n`` the source's gate in sigma, ``EC_NAV_GATES``; ``m`` its
rows; ``n <= 0``: no gate). Re-acquisition: a source none of whose samples has
been fused for ``EC_NAV_REACQUIRE`` seconds (a dropout while the vehicle
tumbles, or a run of refusals) is re-acquired at its next usable sample: the
variance of the states it measures is raised by the innovation's square in
those states' units (their cross-covariances cleared), and the sample fused
without the gate. So the gate can never lock a source out for longer than
``EC_NAV_REACQUIRE``, and after a dropout the estimate jumps to the source
instead of creeping towards it with the gain of a covariance that did not
see the impact.

Work space: the covariance's and the updates' scratch live in the state
(``ES_NAV_WORK``), so a sample allocates nothing.

The measurements are read from the sensor components' blocks of the
measurement record (``core.sensors.registry.measurement_address``); a
component not registered in this build is not fused.
"""

import math

import numpy as np

from quadimpact.core.compiled import allocating, compiled
from quadimpact.core.estimator_slots import (
    EC_INIT_BIAS_ZERO,
    EC_OWN,
    ES_BIAS,
    ES_OWN,
    ES_POS,
    ES_Q,
    ES_VEL,
    ES_W,
    N_OWN_ECFG,
    N_OWN_EST,
)
from quadimpact.core.estimators.ekf import (
    EC_IMPACT_F,
    EC_IMPACT_REPLACE,
    EC_IMPACT_W,
    EC_P0,
    EC_SIG_ACC,
    EC_SIG_GYRO,
    EC_SIG_MAG,
    EC_SIG_WALK,
    ES_SCRATCH,
    N_EKF_CFG,
    N_EKF_EST,
    _with_impact,
    gravity_variance,
    impact_noise_factor,
)
from quadimpact.core.estimators.navigation import integrate_navigation
from quadimpact.core.estimators.older_sensors import MAG, MAG_FIELD_I, MAG_T
from quadimpact.core.layout import Block
from quadimpact.core.records import Data, Model
from quadimpact.core.sensors.imu_slots import (
    SC_BIAS,
    SC_RANGE_F,
    SC_RANGE_W,
)
from quadimpact.core.sensors.measurement_slots import MS_IMU_F, MS_IMU_W
from quadimpact.core.sensors.registry import measurement_address
from quadimpact.core.sensors.rotvec import dcm, rotate_by
from quadimpact.core.vehicle_slots import V_GRAVITY

# ---- its blocks: after the EKF's (core/estimators/ekf.py), whose noises, gate, initial
# stds (EC_SIG_*, EC_P0), impact model (EC_IMPACT_*) and scratch state it uses
_cfg = Block("ecfg.nav-ekf", "EC_NAV_", start=N_EKF_CFG, capacity=EC_OWN + N_OWN_ECFG)
EC_NAV_ACC_WALK = _cfg.slot("EC_NAV_ACC_WALK")  # accelerometer bias random walk, m/s^2/sqrt(s)
EC_NAV_BARO = _cfg.slot("EC_NAV_BARO", 2)  # barometer: noise m, bias walk m/sqrt(s)
EC_NAV_RANGE = _cfg.slot("EC_NAV_RANGE")  # rangefinder noise floor, m
EC_NAV_FLOW = _cfg.slot("EC_NAV_FLOW")  # optical-flow noise floor, rad/s
EC_NAV_GATES = _cfg.slot("EC_NAV_GATES", 4)  # innovation gates (sigma): mag, baro, range, flow
EC_NAV_REACQUIRE = _cfg.slot("EC_NAV_REACQUIRE")  # s: a source unfused this long is re-acquired
EC_NAV_P0 = _cfg.slot("EC_NAV_P0", 2)  # initial std: accelerometer bias m/s^2, baro bias m
EC_NAV_MIN_HEIGHT = _cfg.slot("EC_NAV_MIN_HEIGHT")  # m: flow not fused below this height
EC_NAV_MAX_TILT = _cfg.slot("EC_NAV_MAX_TILT")  # cos of the largest tilt for range and flow
EC_NAV_LEVER = _cfg.slot("EC_NAV_LEVER", 3)  # IMU position from the CM the filter removes, m
EC_NAV_DELAYED = _cfg.slot("EC_NAV_DELAYED")  # 1: flow predicted from the state at its capture
EC_NAV_REACQ_EXCESS = _cfg.slot("EC_NAV_REACQ_EXCESS")  # 1: re-acquisition inflates by the excess
N_NAV_CFG = _cfg.end("N_NAV_CFG")

N_NAV = 16  # error state: attitude, velocity, position, gyro bias, accel. bias (3 each), baro bias
N_NAV_RING = 64  # IMU samples of history (the flow's capture time)
N_NAV_RING_W = 11  # a ring row: t, p, q (gyro minus bias), the prediction's dv, dtheta, dp_z
N_NAV_WORK = 2 * N_NAV * N_NAV + 14 * N_NAV + 6  # P, its scratch, the updates' work, f (CM, sensor)
_st = Block("est.nav-ekf", "ES_", start=N_EKF_EST, capacity=ES_OWN + N_OWN_EST)
ES_NAV_P = _st.slot("ES_NAV_P", N_NAV * N_NAV)  # its error covariance, row-major
ES_ACC_BIAS = _st.slot("ES_ACC_BIAS", 3)  # accelerometer bias estimate, body, m/s^2
ES_BARO_BIAS = _st.slot("ES_BARO_BIAS")  # barometer bias estimate, m
ES_NAV_SEEN = _st.slot("ES_NAV_SEEN", 3)  # samples seen so far: barometer, rangefinder, flow
ES_NAV_FUSED_T = _st.slot("ES_NAV_FUSED_T", 4)  # s, the latest fused sample of mag, baro,
#   range, flow (NaN: none yet)
ES_NAV_COUNT = _st.slot("ES_NAV_COUNT", 12)  # per source (mag, baro, range, flow):
#   fused, rejected by the gate, re-acquisitions
ES_NAV_NIS = _st.slot("ES_NAV_NIS", 4)  # the latest normalised innovation squared of each
ES_NAV_RING = _st.slot("ES_NAV_RING", N_NAV_RING_W * N_NAV_RING)  # the latest samples' rows
ES_NAV_RING_AT = _st.slot("ES_NAV_RING_AT")  # the ring's next row
ES_NAV_W_PREV = _st.slot("ES_NAV_W_PREV", 3)  # the previous sample's gyro minus bias (NaN: none)
ES_NAV_ARM_PREV = _st.slot("ES_NAV_ARM_PREV", 6)  # C (w x r), C r at the previous sample (NaN)
ES_NAV_WORK = _st.slot("ES_NAV_WORK", N_NAV_WORK)  # nav-ekf's work space (no allocation)
N_NAV_EST = _st.end("N_NAV_EST")

# the error state's parts
I_TH, I_V, I_P, I_BG, I_BA, I_BB = 0, 3, 6, 9, 12, 15
# the aiding sources (ES_NAV_COUNT, ES_NAV_NIS, ES_NAV_FUSED_T, EC_NAV_GATES; ES_NAV_SEEN
# from the barometer on)
SRC_MAG, SRC_BARO, SRC_RANGE, SRC_FLOW = 0, 1, 2, 3
# ES_NAV_COUNT: per source, fused, refused by the gate, re-acquired
CNT_FUSED, CNT_REFUSED, CNT_REACQUIRED = 0, 1, 2


def _address(name: str, slot: str) -> int:
    """A component's slot in ``meas``, or -1 when the component is not in this build."""
    try:
        return measurement_address(name, slot)
    except KeyError:
        return -1


BARO_ALT = _address("barometer", "altitude_m")
BARO_N = _address("barometer", "n")
RNG_RANGE = _address("rangefinder", "range_m")
RNG_VALID = _address("rangefinder", "valid")
RNG_NOISE = _address("rangefinder", "noise_m")
RNG_N = _address("rangefinder", "n")
FLOW_X = _address("optical_flow", "flow_x_rad_s")
FLOW_Y = _address("optical_flow", "flow_y_rad_s")
FLOW_QUALITY = _address("optical_flow", "quality")
FLOW_NOISE = _address("optical_flow", "noise_rad_s")
FLOW_CAPTURE = _address("optical_flow", "capture_t_s")
FLOW_N = _address("optical_flow", "n")


@compiled
def nav_init(m: Model, d: Data) -> None:
    """The initial covariance and the filter's own initial state.

    ``P0 = diag(s_att^2, s_vel^2, s_pos^2, s_bg^2, s_ba^2, s_bb^2)`` (``EC_P0``,
    ``EC_NAV_P0``); the accelerometer bias estimate starts at the IMU's drawn
    bias (as the gyro's does: the vehicle has flown before), or at 0 with
    ``EC_INIT_BIAS_ZERO``; the barometer's at 0.
    """
    est = d.est
    e = m.ecfg
    for k in range(N_NAV * N_NAV):
        est[ES_NAV_P + k] = 0.0
    stds = (e[EC_P0], e[EC_P0 + 2], e[EC_P0 + 3], e[EC_P0 + 1], e[EC_NAV_P0])
    for b in range(5):
        s = stds[b]
        for a in range(3):
            k = 3 * b + a
            est[ES_NAV_P + k * N_NAV + k] = s * s
    s = e[EC_NAV_P0 + 1]
    est[ES_NAV_P + N_NAV * N_NAV - 1] = s * s
    zero = e[EC_INIT_BIAS_ZERO] > 0.5
    for a in range(3):
        est[ES_ACC_BIAS + a] = 0.0 if zero else m.scfg[SC_BIAS + a]
    est[ES_BARO_BIAS] = 0.0
    for k in range(3):
        est[ES_NAV_SEEN + k] = 0.0
    for k in range(4):
        est[ES_NAV_FUSED_T + k] = np.nan
    for k in range(12):
        est[ES_NAV_COUNT + k] = 0.0
    for k in range(4):
        est[ES_NAV_NIS + k] = np.nan
    for k in range(N_NAV_RING_W * N_NAV_RING):
        est[ES_NAV_RING + k] = np.nan
    est[ES_NAV_RING_AT] = 0.0
    for k in range(3):
        est[ES_NAV_W_PREV + k] = np.nan
    for k in range(6):
        est[ES_NAV_ARM_PREV + k] = np.nan


@allocating
def nav_covariance(est: np.ndarray) -> np.ndarray:
    """A copy of the 16 x 16 error covariance (for tests and analysis)."""
    P = np.empty((N_NAV, N_NAV))
    for i in range(N_NAV):
        for j in range(N_NAV):
            P[i, j] = est[ES_NAV_P + i * N_NAV + j]
    return P


@compiled
def nav_predict(est: np.ndarray, P: np.ndarray, A: np.ndarray, ecfg: np.ndarray,
                scfg: np.ndarray, w: np.ndarray, f: np.ndarray, dt: float, C: np.ndarray,
                impact: float) -> None:  # fmt: skip
    """The covariance's prediction over ``dt`` (s) and the attitude's; ``A``: scratch 16 x 16.

    ``f``: the specific force at the CM (0:3, m/s^2) and as the sensor read it
    (3:6, for its range test); ``C``: the attitude estimate's rotation
    before; ``impact``: the impact disturbance's factor
    (``ekf.impact_noise_factor``). Velocity and position are advanced by the
    caller.
    """
    n = N_NAV
    wx = w[0] - est[ES_BIAS]
    wy = w[1] - est[ES_BIAS + 1]
    wz = w[2] - est[ES_BIAS + 2]
    fx = f[0] - est[ES_ACC_BIAS]
    fy = f[1] - est[ES_ACC_BIAS + 1]
    fz = f[2] - est[ES_ACC_BIAS + 2]
    # R(w dt)^T: the rotation of -w dt, into A's corner as scratch first
    q = est[ES_SCRATCH : ES_SCRATCH + 4]
    q[0] = 1.0
    q[1] = 0.0
    q[2] = 0.0
    q[3] = 0.0
    rotate_by(q, -wx * dt, -wy * dt, -wz * dt)
    R = A[13:16, 13:16]  # scratch (a view), read out before A is filled
    dcm(q, R)
    r00, r01, r02 = R[0, 0], R[0, 1], R[0, 2]
    r10, r11, r12 = R[1, 0], R[1, 1], R[1, 2]
    r20, r21, r22 = R[2, 0], R[2, 1], R[2, 2]
    # M = -C [f x] dt (velocity from attitude), N = -C dt (velocity from accel. bias)
    m00 = -(C[0, 1] * fz - C[0, 2] * fy) * dt
    m01 = -(C[0, 2] * fx - C[0, 0] * fz) * dt
    m02 = -(C[0, 0] * fy - C[0, 1] * fx) * dt
    m10 = -(C[1, 1] * fz - C[1, 2] * fy) * dt
    m11 = -(C[1, 2] * fx - C[1, 0] * fz) * dt
    m12 = -(C[1, 0] * fy - C[1, 1] * fx) * dt
    m20 = -(C[2, 1] * fz - C[2, 2] * fy) * dt
    m21 = -(C[2, 2] * fx - C[2, 0] * fz) * dt
    m22 = -(C[2, 0] * fy - C[2, 1] * fx) * dt
    # A = Phi P, row block by row block
    for j in range(n):
        t0, t1, t2 = P[0, j], P[1, j], P[2, j]
        A[0, j] = r00 * t0 + r01 * t1 + r02 * t2 - dt * P[9, j]
        A[1, j] = r10 * t0 + r11 * t1 + r12 * t2 - dt * P[10, j]
        A[2, j] = r20 * t0 + r21 * t1 + r22 * t2 - dt * P[11, j]
        a0, a1, a2 = P[12, j], P[13, j], P[14, j]
        A[3, j] = (P[3, j] + m00 * t0 + m01 * t1 + m02 * t2
                   - dt * (C[0, 0] * a0 + C[0, 1] * a1 + C[0, 2] * a2))  # fmt: skip
        A[4, j] = (P[4, j] + m10 * t0 + m11 * t1 + m12 * t2
                   - dt * (C[1, 0] * a0 + C[1, 1] * a1 + C[1, 2] * a2))  # fmt: skip
        A[5, j] = (P[5, j] + m20 * t0 + m21 * t1 + m22 * t2
                   - dt * (C[2, 0] * a0 + C[2, 1] * a1 + C[2, 2] * a2))  # fmt: skip
        for k in range(3):
            A[6 + k, j] = P[6 + k, j] + dt * P[3 + k, j]
        for k in range(9, n):
            A[k, j] = P[k, j]
    # P = A Phi^T, column block by column block
    for i in range(n):
        t0, t1, t2 = A[i, 0], A[i, 1], A[i, 2]
        a0, a1, a2 = A[i, 12], A[i, 13], A[i, 14]
        P[i, 0] = r00 * t0 + r01 * t1 + r02 * t2 - dt * A[i, 9]
        P[i, 1] = r10 * t0 + r11 * t1 + r12 * t2 - dt * A[i, 10]
        P[i, 2] = r20 * t0 + r21 * t1 + r22 * t2 - dt * A[i, 11]
        P[i, 3] = (A[i, 3] + m00 * t0 + m01 * t1 + m02 * t2
                   - dt * (C[0, 0] * a0 + C[0, 1] * a1 + C[0, 2] * a2))  # fmt: skip
        P[i, 4] = (A[i, 4] + m10 * t0 + m11 * t1 + m12 * t2
                   - dt * (C[1, 0] * a0 + C[1, 1] * a1 + C[1, 2] * a2))  # fmt: skip
        P[i, 5] = (A[i, 5] + m20 * t0 + m21 * t1 + m22 * t2
                   - dt * (C[2, 0] * a0 + C[2, 1] * a1 + C[2, 2] * a2))  # fmt: skip
        for k in range(3):
            P[i, 6 + k] = A[i, 6 + k] + dt * A[i, 3 + k]
        for k in range(9, n):
            P[i, k] = A[i, k]
    # process noise
    replace = ecfg[EC_IMPACT_REPLACE] > 0.5
    sg = ecfg[EC_SIG_GYRO]
    sa = ecfg[EC_SIG_ACC]
    if impact > 0.0:
        sg = _with_impact(sg, ecfg[EC_IMPACT_W], impact, replace)
        sa = _with_impact(sa, ecfg[EC_IMPACT_F], impact, replace)
    range_w = scfg[SC_RANGE_W]
    range_f = scfg[SC_RANGE_F]
    # a clipped accelerometer axis: its range in quadrature, on every inertial axis (the
    # velocity error is inertial; a body axis's noise lands on all three)
    va = sa * sa
    for k in range(3):
        if range_f > 0.0 and abs(f[3 + k]) >= range_f:
            va += range_f * range_f
    sw = ecfg[EC_SIG_WALK]
    swa = ecfg[EC_NAV_ACC_WALK]
    for k in range(3):
        vg = sg * sg
        if range_w > 0.0 and abs(w[k]) >= range_w:
            vg += range_w * range_w  # the attitude error is in body axes: this axis only
        P[k, k] += vg * dt * dt
        P[3 + k, 3 + k] += va * dt * dt
        P[9 + k, 9 + k] += sw * sw * dt
        P[12 + k, 12 + k] += swa * swa * dt
    sb = ecfg[EC_NAV_BARO + 1]
    P[15, 15] += sb * sb * dt
    rotate_by(est[ES_Q : ES_Q + 4], wx * dt, wy * dt, wz * dt)


@compiled
def _project(P: np.ndarray, W: np.ndarray, rows: int) -> None:
    """``(P H^T)^T`` into ``W[8:8+rows]`` and ``S = H P H^T + R`` into ``W[5:8, 0:3]``.

    ``W`` as :func:`nav_update`. A row of ``(P H^T)^T`` is kept in sixteen
    local sums (in registers) while ``H``'s row is scanned once: each entry is
    the sum over the columns in increasing order, the zeros of ``H`` skipped,
    as in a loop over the entries.
    """
    n = N_NAV
    H = W[0:4]
    r = W[4, 3:6]
    S = W[5:8, 0:6]
    Q = W[8:14]
    for a in range(rows):
        s0 = s1 = s2 = s3 = s4 = s5 = s6 = s7 = 0.0
        s8 = s9 = s10 = s11 = s12 = s13 = s14 = s15 = 0.0
        for k in range(n):
            h = H[a, k]
            if h != 0.0:
                s0 += P[0, k] * h
                s1 += P[1, k] * h
                s2 += P[2, k] * h
                s3 += P[3, k] * h
                s4 += P[4, k] * h
                s5 += P[5, k] * h
                s6 += P[6, k] * h
                s7 += P[7, k] * h
                s8 += P[8, k] * h
                s9 += P[9, k] * h
                s10 += P[10, k] * h
                s11 += P[11, k] * h
                s12 += P[12, k] * h
                s13 += P[13, k] * h
                s14 += P[14, k] * h
                s15 += P[15, k] * h
        Q[a, 0] = s0
        Q[a, 1] = s1
        Q[a, 2] = s2
        Q[a, 3] = s3
        Q[a, 4] = s4
        Q[a, 5] = s5
        Q[a, 6] = s6
        Q[a, 7] = s7
        Q[a, 8] = s8
        Q[a, 9] = s9
        Q[a, 10] = s10
        Q[a, 11] = s11
        Q[a, 12] = s12
        Q[a, 13] = s13
        Q[a, 14] = s14
        Q[a, 15] = s15
    for a in range(rows):
        for b in range(rows):
            s = 0.0
            for k in range(n):
                h = H[a, k]
                if h != 0.0:
                    s += h * Q[b, k]
            S[a, b] = s
        S[a, a] += r[a]


@compiled
def nav_update(est: np.ndarray, P: np.ndarray, W: np.ndarray, rows: int, gate: float) -> float:
    """A Kalman update with ``rows`` (1-3) rows of ``H`` (16 columns), innovation ``y`` and
    noise variances ``r``, unless refused by the gate; its correction injected.

    ``W`` (14 x 16, as :func:`nav_ekf_sample` makes it) holds ``H`` (rows 0-2), ``y`` and ``r``
    (row 4) and the scratch. ``gate``: refuse when ``y^T S^-1 y > gate^2 rows``
    (``<= 0``: no gate). Returns the normalised innovation squared, negated
    when refused.
    """
    n = N_NAV
    H = W[0:4]
    y = W[4, 0:3]
    S = W[5:8, 0:6]
    Q = W[8:14]  # (P H^T)^T in rows 0-2, K^T in rows 3-5
    _project(P, W, rows)
    # S^-1 into S[:, 3:6] (Gauss-Jordan, S symmetric positive definite)
    for a in range(rows):
        for b in range(rows):
            S[a, 3 + b] = 1.0 if a == b else 0.0
    for c in range(rows):
        piv = S[c, c]
        for b in range(rows):
            S[c, b] /= piv
            S[c, 3 + b] /= piv
        for a in range(rows):
            if a != c:
                fac = S[a, c]
                for b in range(rows):
                    S[a, b] -= fac * S[c, b]
                    S[a, 3 + b] -= fac * S[c, 3 + b]
    nis = 0.0
    for a in range(rows):
        for b in range(rows):
            nis += y[a] * S[a, 3 + b] * y[b]
    if gate > 0.0 and nis > gate * gate * rows:
        return -nis
    # K = P H^T S^-1, transposed, into Q's rows 3-5; the correction dx into H's row 3
    dx = H[3]
    for i in range(n):
        for a in range(rows):
            s = 0.0
            for b in range(rows):
                s += Q[b, i] * S[b, 3 + a]
            Q[3 + a, i] = s
        s = 0.0
        for a in range(rows):
            s += Q[3 + a, i] * y[a]
        dx[i] = s
    # P <- P - K (P H^T)^T, then symmetric; the sums over the rows written out (row i's
    # factors hoisted), the same operations in the same order as loops over them
    for i in range(n):
        k0, q0 = Q[3, i], Q[0, i]
        k1 = q1 = k2 = q2 = 0.0
        if rows > 1:
            k1, q1 = Q[4, i], Q[1, i]
        if rows > 2:
            k2, q2 = Q[5, i], Q[2, i]
        for j in range(i, n):
            s = 0.0
            s += k0 * Q[0, j]
            if rows > 1:
                s += k1 * Q[1, j]
            if rows > 2:
                s += k2 * Q[2, j]
            s2 = 0.0
            s2 += Q[3, j] * q0
            if rows > 1:
                s2 += Q[4, j] * q1
            if rows > 2:
                s2 += Q[5, j] * q2
            v = 0.5 * (P[i, j] + P[j, i]) - 0.5 * (s + s2)
            P[i, j] = v
            P[j, i] = v
    rotate_by(est[ES_Q : ES_Q + 4], dx[0], dx[1], dx[2])
    for a in range(3):
        est[ES_VEL + a] += dx[I_V + a]
        est[ES_POS + a] += dx[I_P + a]
        est[ES_BIAS + a] += dx[I_BG + a]
        est[ES_ACC_BIAS + a] += dx[I_BA + a]
    est[ES_BARO_BIAS] += dx[I_BB]
    return nis


@compiled
def _inflate(P: np.ndarray, lo: int, hi: int, extra: float) -> None:
    """Clear the cross-covariances of the states ``lo..hi-1`` and add ``extra`` to their
    variances (the re-acquisition)."""
    for i in range(lo, hi):
        for j in range(N_NAV):
            if j < lo or j >= hi:
                P[i, j] = 0.0
                P[j, i] = 0.0
            elif j != i:
                P[i, j] = 0.0
        P[i, i] += extra


@compiled
def _spread(P: np.ndarray, W: np.ndarray, rows: int) -> float:
    """The innovation's predicted spread, ``trace(H P H^T + R)`` (``W`` as :func:`nav_update`)."""
    s = 0.0
    for a in range(rows):
        s += W[4, 3 + a]
        for i in range(N_NAV):
            hi = W[a, i]
            if hi != 0.0:
                for j in range(N_NAV):
                    s += hi * P[i, j] * W[a, j]
    return s


@compiled
def _fuse(t: float, src: int, est: np.ndarray, P: np.ndarray, W: np.ndarray, rows: int,
          ecfg: np.ndarray, lo: int, hi: int, scale: float) -> bool:  # fmt: skip
    """One aiding source's update through its gate, with the re-acquisition rule.

    A source none of whose samples was fused for ``EC_NAV_REACQUIRE`` s is
    re-acquired: the states ``lo..hi-1`` lose their cross-covariances and
    their variances grow by the innovation's norm squared times ``scale^2``
    (the innovation in those states' units); with ``EC_NAV_REACQ_EXCESS``
    only by its excess over the predicted spread ``trace(H P H^T + R)``
    (nothing, and the covariance kept, when the innovation is within it);
    the sample is then fused without the gate. Returns whether the sample
    was fused.
    """
    c = ES_NAV_COUNT + 3 * src
    if t - est[ES_NAV_FUSED_T + src] > ecfg[EC_NAV_REACQUIRE]:
        y = W[4, 0:3]
        e2 = 0.0
        for a in range(rows):
            e2 += y[a] * y[a]
        if ecfg[EC_NAV_REACQ_EXCESS] > 0.5:
            e2 -= _spread(P, W, rows)
        if e2 > 0.0:
            _inflate(P, lo, hi, e2 * scale * scale)
        est[ES_NAV_NIS + src] = nav_update(est, P, W, rows, 0.0)
        est[c + CNT_REACQUIRED] += 1.0
        est[ES_NAV_FUSED_T + src] = t
        return True
    nis = nav_update(est, P, W, rows, ecfg[EC_NAV_GATES + src])
    est[ES_NAV_NIS + src] = abs(nis)
    if nis < 0.0:
        est[c + CNT_REFUSED] += 1.0
        return False
    est[c + CNT_FUSED] += 1.0
    est[ES_NAV_FUSED_T + src] = t
    return True


@compiled
def _new_sample(est: np.ndarray, meas: np.ndarray, at: int, k: int) -> bool:
    """Whether the component's sample count ``meas[at]`` grew since last seen (then noted)."""
    if at < 0 or meas.shape[0] <= at:
        return False
    n = meas[at]
    if n > est[ES_NAV_SEEN + k]:
        est[ES_NAV_SEEN + k] = n
        return True
    return False


@compiled
def _ring_row(est: np.ndarray, t: float) -> int:
    """The offset in ``est`` of the history's row nearest ``t`` (s), or -1 when it is empty.

    A row: ``t``, the bias-corrected rates ``(p, q)`` (rad/s), then the
    increments the sample's prediction made: velocity (3, m/s), the attitude's
    rotation vector ``w_hat dt`` (3, rad, body) and ``p_z`` (m).
    """
    best = -1
    gap = math.inf
    for k in range(N_NAV_RING):
        at = ES_NAV_RING + N_NAV_RING_W * k
        tk = est[at]
        if not np.isnan(tk) and abs(tk - t) < gap:
            gap = abs(tk - t)
            best = at
    return best


@compiled
def _clear(H: np.ndarray) -> None:
    for a in range(3):
        for k in range(N_NAV):
            H[a, k] = 0.0


@compiled
def _gravity(est: np.ndarray, P: np.ndarray, W: np.ndarray, ecfg: np.ndarray, f: np.ndarray,
             g: float, C: np.ndarray, impact: float) -> None:  # fmt: skip
    """The accelerometer as gravity, ``f - b_a = -g C^T e_Z``, behind the ``ekf``'s gate.

    ``H_theta = -g [u x]`` (``u = C^T e_Z``), ``H_ba = I``.
    """
    use, rg = gravity_variance(f, g, ecfg, est, impact)
    if not use:
        return
    H, y, r = W[0:4], W[4, 0:3], W[4, 3:6]
    _clear(H)
    _skew(H, -g, C[2, 0], C[2, 1], C[2, 2])
    for a in range(3):
        y[a] = f[a] - est[ES_ACC_BIAS + a] + g * C[2, a]
        H[a, I_BA + a] = 1.0
        r[a] = rg
    nav_update(est, P, W, 3, 0.0)


@compiled
def _flow(t: float, est: np.ndarray, P: np.ndarray, W: np.ndarray, ecfg: np.ndarray,
          meas: np.ndarray, C: np.ndarray) -> None:  # fmt: skip
    """The optical flow compensated with the gyro, ``flow + (p, q) = (v_By, -v_Bx) C_22 / h``.

    Fused when the sample is new, of quality > 0, the tilt within
    ``EC_NAV_MAX_TILT`` and the estimated height above ``EC_NAV_MIN_HEIGHT``.
    With ``EC_NAV_DELAYED`` the prediction uses the estimate at the capture
    time (the history's row; ``C`` is then overwritten with its rotation);
    the correction goes to the current estimate.
    """
    if not _new_sample(est, meas, FLOW_N, 2):
        return
    if not meas[FLOW_QUALITY] > 0.0:
        return
    row = _ring_row(est, meas[FLOW_CAPTURE])
    p_cap, q_cap = 0.0, 0.0
    h = -est[ES_POS + 2]
    v0, v1, v2 = est[ES_VEL], est[ES_VEL + 1], est[ES_VEL + 2]
    if row >= 0:
        p_cap, q_cap = est[row + 1], est[row + 2]
        if ecfg[EC_NAV_DELAYED] > 0.5:
            # undo the prediction's increments of the samples after the capture
            qc = est[ES_SCRATCH : ES_SCRATCH + 4]
            for a in range(4):
                qc[a] = est[ES_Q + a]
            k = (int(est[ES_NAV_RING_AT]) - 1) % N_NAV_RING
            for _ in range(N_NAV_RING):
                at = ES_NAV_RING + N_NAV_RING_W * k
                if at == row:
                    break
                v0 -= est[at + 3]
                v1 -= est[at + 4]
                v2 -= est[at + 5]
                h += est[at + 10]
                rotate_by(qc, -est[at + 6], -est[at + 7], -est[at + 8])
                k = (k - 1) % N_NAV_RING
            dcm(qc, C)
    c22 = C[2, 2]
    if not (c22 >= ecfg[EC_NAV_MAX_TILT] and h > ecfg[EC_NAV_MIN_HEIGHT]):
        return
    bx = C[0, 0] * v0 + C[1, 0] * v1 + C[2, 0] * v2
    by = C[0, 1] * v0 + C[1, 1] * v1 + C[2, 1] * v2
    bz = C[0, 2] * v0 + C[1, 2] * v1 + C[2, 2] * v2
    k = c22 / h
    u0, u1 = C[2, 0], C[2, 1]
    H, y, r = W[0:4], W[4, 0:3], W[4, 3:6]
    _clear(H)
    # d v_B / d theta = [v_B x]; d C_22 / d theta = (-u_1, u_0, 0); d k / d p_z = C_22 / h^2
    H[0, 0] = k * bz - by / h * u1
    H[0, 1] = by / h * u0
    H[0, 2] = -k * bx
    H[1, 0] = bx / h * u1
    H[1, 1] = k * bz - bx / h * u0
    H[1, 2] = -k * by
    for a in range(3):
        H[0, I_V + a] = k * C[a, 1]
        H[1, I_V + a] = -k * C[a, 0]
    H[0, I_P + 2] = by * c22 / (h * h)
    H[1, I_P + 2] = -bx * c22 / (h * h)
    y[0] = meas[FLOW_X] + p_cap - k * by
    y[1] = meas[FLOW_Y] + q_cap + k * bx
    s = max(meas[FLOW_NOISE], ecfg[EC_NAV_FLOW])
    r[0] = s * s
    r[1] = s * s
    _fuse(t, SRC_FLOW, est, P, W, 2, ecfg, I_V, I_V + 2, h / c22)


@compiled
def _at_cm(est: np.ndarray, ecfg: np.ndarray, w: np.ndarray, f: np.ndarray, dt: float,
           out: np.ndarray) -> None:  # fmt: skip
    """The specific force at the CM, ``f - w_dot x r - w x (w x r)``, into ``out[0:3]``.

    ``w``, ``f``: the gyro (rad/s) and accelerometer (m/s^2) samples, body;
    ``r = EC_NAV_LEVER`` (m, body); ``w_dot`` (rad/s^2) from the previous
    sample's bias-corrected rate (0 at the first sample or ``dt = 0``). The
    sensor's own ``f`` into ``out[3:6]``. Notes this sample's rate for the next.
    """
    r0, r1, r2 = ecfg[EC_NAV_LEVER], ecfg[EC_NAV_LEVER + 1], ecfg[EC_NAV_LEVER + 2]
    w0 = w[0] - est[ES_BIAS]
    w1 = w[1] - est[ES_BIAS + 1]
    w2 = w[2] - est[ES_BIAS + 2]
    a0 = a1 = a2 = 0.0
    if dt > 0.0 and not np.isnan(est[ES_NAV_W_PREV]):
        a0 = (w0 - est[ES_NAV_W_PREV]) / dt
        a1 = (w1 - est[ES_NAV_W_PREV + 1]) / dt
        a2 = (w2 - est[ES_NAV_W_PREV + 2]) / dt
    est[ES_NAV_W_PREV] = w0
    est[ES_NAV_W_PREV + 1] = w1
    est[ES_NAV_W_PREV + 2] = w2
    c0 = w1 * r2 - w2 * r1  # w x r
    c1 = w2 * r0 - w0 * r2
    c2 = w0 * r1 - w1 * r0
    out[0] = f[0] - (a1 * r2 - a2 * r1) - (w1 * c2 - w2 * c1)
    out[1] = f[1] - (a2 * r0 - a0 * r2) - (w2 * c0 - w0 * c2)
    out[2] = f[2] - (a0 * r1 - a1 * r0) - (w0 * c1 - w1 * c0)
    for k in range(3):
        out[3 + k] = f[k]


@compiled
def _lever_offset(est: np.ndarray, ecfg: np.ndarray, C: np.ndarray) -> None:
    """The IMU point's velocity and position made the CM's (module docstring).

    ``v -= C (w x r) - (its previous value)``, ``p -= C r - (its previous
    value)``, with ``w`` this sample's bias-corrected rate (``ES_NAV_W_PREV``,
    written by :func:`_at_cm`) and ``C`` the attitude estimate's rotation
    the integration used. Nothing moves at the first sample.
    """
    r0, r1, r2 = ecfg[EC_NAV_LEVER], ecfg[EC_NAV_LEVER + 1], ecfg[EC_NAV_LEVER + 2]
    w0, w1, w2 = est[ES_NAV_W_PREV], est[ES_NAV_W_PREV + 1], est[ES_NAV_W_PREV + 2]
    c0 = w1 * r2 - w2 * r1  # w x r
    c1 = w2 * r0 - w0 * r2
    c2 = w0 * r1 - w1 * r0
    first = np.isnan(est[ES_NAV_ARM_PREV])
    for a in range(3):
        u = C[a, 0] * c0 + C[a, 1] * c1 + C[a, 2] * c2
        s = C[a, 0] * r0 + C[a, 1] * r1 + C[a, 2] * r2
        if not first:
            est[ES_VEL + a] -= u - est[ES_NAV_ARM_PREV + a]
            est[ES_POS + a] -= s - est[ES_NAV_ARM_PREV + 3 + a]
        est[ES_NAV_ARM_PREV + a] = u
        est[ES_NAV_ARM_PREV + 3 + a] = s


@compiled
def nav_ekf_sample(t: float, dt: float, m: Model, d: Data, C: np.ndarray) -> None:
    """Predict over ``dt`` (s) and correct with the measurements of the sample at ``t`` (s).

    ``C``: scratch 3x3 (the estimate's rotation on return). Allocates nothing:
    its work space is ``est[ES_NAV_WORK]``.
    """
    ecfg = m.ecfg
    est = d.est
    meas = d.meas
    g = m.veh[V_GRAVITY]
    n = N_NAV
    nn = 2 * n * n
    W = est[ES_NAV_WORK : ES_NAV_WORK + nn].reshape((2, n, n))
    P, A = W[0], W[1]
    Wu = est[ES_NAV_WORK + nn : ES_NAV_WORK + nn + 14 * n].reshape((14, n))
    for i in range(14):  # the updates' work: H, y and r, scratch (nav_update)
        for j in range(n):
            Wu[i, j] = 0.0
    fc = est[ES_NAV_WORK + nn + 14 * n : ES_NAV_WORK + nn + 14 * n + 6]
    H, y, r = Wu[0:4], Wu[4, 0:3], Wu[4, 3:6]
    for i in range(n):
        for j in range(n):
            P[i, j] = est[ES_NAV_P + i * n + j]
    for k in range(4):
        if np.isnan(est[ES_NAV_FUSED_T + k]):
            est[ES_NAV_FUSED_T + k] = t  # the initial estimate counts as fused
    f = meas[MS_IMU_F : MS_IMU_F + 3]
    w = meas[MS_IMU_W : MS_IMU_W + 3]
    # the history (the flow's capture time): this sample's rates, its prediction's increments
    at = int(est[ES_NAV_RING_AT])
    row = ES_NAV_RING + N_NAV_RING_W * at
    est[row] = t
    est[row + 1] = w[0] - est[ES_BIAS]
    est[row + 2] = w[1] - est[ES_BIAS + 1]
    for k in range(3, 6):
        est[row + k] = est[ES_VEL + k - 3]  # the velocity before (made an increment below)
    est[row + 10] = est[ES_POS + 2]
    est[ES_NAV_RING_AT] = (at + 1) % N_NAV_RING
    _at_cm(est, ecfg, w, f, dt, fc)
    q = est[ES_Q : ES_Q + 4]
    dcm(q, C)
    impact = impact_noise_factor(t, f, ecfg, est)
    if dt > 0.0:
        for a in range(3):
            y[a] = f[a] - est[ES_ACC_BIAS + a]  # f - b_a before the prediction (IMU point)
        nav_predict(est, P, A, ecfg, m.scfg, w, fc, dt, C, impact)
        dcm(q, C)
        integrate_navigation(est, C, y, g, dt)
    dcm(q, C)
    _lever_offset(est, ecfg, C)
    for a in range(3):
        est[row + 3 + a] = est[ES_VEL + a] - est[row + 3 + a]
        est[row + 6 + a] = est[ES_NAV_W_PREV + a] * dt
    est[row + 10] = est[ES_POS + 2] - est[row + 10]
    _gravity(est, P, Wu, ecfg, fc, g, C, impact)
    dcm(q, C)
    # magnetometer: m = C^T m_I (H_theta = [u_m x], u_m = C^T m_I)
    if meas[MAG_T] == t:
        mi = m.scfg[MAG_FIELD_I : MAG_FIELD_I + 3]
        u0 = C[0, 0] * mi[0] + C[1, 0] * mi[1] + C[2, 0] * mi[2]
        u1 = C[0, 1] * mi[0] + C[1, 1] * mi[1] + C[2, 1] * mi[2]
        u2 = C[0, 2] * mi[0] + C[1, 2] * mi[1] + C[2, 2] * mi[2]
        _clear(H)
        _skew(H, 1.0, u0, u1, u2)
        y[0] = meas[MAG] - u0
        y[1] = meas[MAG + 1] - u1
        y[2] = meas[MAG + 2] - u2
        r[0] = r[1] = r[2] = ecfg[EC_SIG_MAG] ** 2
        norm = math.sqrt(mi[0] * mi[0] + mi[1] * mi[1] + mi[2] * mi[2])
        _fuse(t, SRC_MAG, est, P, Wu, 3, ecfg, I_TH, I_TH + 3, 1.0 / norm)
        dcm(q, C)
    # barometer: altitude = -p_z + b_b
    if _new_sample(est, meas, BARO_N, 0):
        _clear(H)
        H[0, I_P + 2] = -1.0
        H[0, I_BB] = 1.0
        y[0] = meas[BARO_ALT] - (-est[ES_POS + 2] + est[ES_BARO_BIAS])
        r[0] = ecfg[EC_NAV_BARO] ** 2
        _fuse(t, SRC_BARO, est, P, Wu, 1, ecfg, I_P + 2, I_P + 3, 1.0)
        dcm(q, C)
    # rangefinder: range = h / C_22, h = -p_z; dC_22/dtheta = (-u_1, u_0, 0), u = C^T e_Z
    c22 = C[2, 2]
    if _new_sample(est, meas, RNG_N, 1) and meas[RNG_VALID] > 0.5 and c22 >= ecfg[EC_NAV_MAX_TILT]:
        h = -est[ES_POS + 2]
        _clear(H)
        H[0, I_TH] = h / (c22 * c22) * C[2, 1]
        H[0, I_TH + 1] = -h / (c22 * c22) * C[2, 0]
        H[0, I_P + 2] = -1.0 / c22
        y[0] = meas[RNG_RANGE] - h / c22
        r[0] = max(meas[RNG_NOISE], ecfg[EC_NAV_RANGE]) ** 2
        _fuse(t, SRC_RANGE, est, P, Wu, 1, ecfg, I_P + 2, I_P + 3, c22)
        dcm(q, C)
    _flow(t, est, P, Wu, ecfg, meas, C)
    dcm(q, C)
    for i in range(n):
        for j in range(n):
            est[ES_NAV_P + i * n + j] = 0.5 * (P[i, j] + P[j, i])
    for a in range(3):
        est[ES_W + a] = w[a] - est[ES_BIAS + a]


@compiled
def _skew(H: np.ndarray, s: float, u0: float, u1: float, u2: float) -> None:
    """``H[:3, 0:3] = s [u x]``: a measurement of the attitude error."""
    H[0, 0] = 0.0
    H[0, 1] = -s * u2
    H[0, 2] = s * u1
    H[1, 0] = s * u2
    H[1, 1] = 0.0
    H[1, 2] = -s * u0
    H[2, 0] = -s * u1
    H[2, 1] = s * u0
    H[2, 2] = 0.0
