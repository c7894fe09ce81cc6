"""The estimators on synthetic IMU streams (docs/ESTIMATION.md 7).

Each stream is fed sample by sample through the loop's own estimator stage
(``tests/core/estimator_streams.py``): hover and constant rotation with an
ideal IMU, the EKF's bias estimate with a magnetometer, its consistency
(NEES) on long noisy hovers, the pose sensor, and the agreement with the
``ahrs`` package's Mahony filter and EKF where the formulations coincide.
"""

from __future__ import annotations

import numpy as np
import pytest
from estimator_streams import (
    Harness,
    angle_deg,
    constant_rotation,
    error_vector,
    expmap,
    qmul,
)

from quadimpact.core import estimator_slots as ESL
from quadimpact.rotations import quat_to_matrix

DT = 0.005
M_I = np.array([np.cos(np.radians(60.0)), 0.0, np.sin(np.radians(60.0))])  # dip 60 deg, NED


def _mag(q: np.ndarray, rng=None, sigma=0.0) -> np.ndarray:
    m = np.array([quat_to_matrix(qi).T @ M_I for qi in np.atleast_2d(q)])
    if rng is not None:
        m = m + sigma * rng.standard_normal(m.shape)
    return m


@pytest.mark.parametrize("estimator", ["ideal", "complementary", "ekf"])
@pytest.mark.parametrize("magnetometer", [False, True])
def test_hover_with_the_ideal_imu_stays_exact_for_10_s(estimator, magnetometer):
    q0 = expmap(np.radians([4.0, -3.0, 35.0]))
    s = constant_rotation(np.zeros(3), q0, 2001, DT)
    h = Harness(estimator, len(s.t), q0=q0, magnetometer={"noise": 0.0} if magnetometer else None)
    if magnetometer:
        s.mag = _mag(s.q)
    err = h.run(s)
    assert err.max() < 0.01
    assert s.t[-1] == pytest.approx(10.0)


@pytest.mark.parametrize("estimator", ["complementary", "ekf"])
def test_constant_rotation_is_tracked_to_integration_accuracy(estimator):
    """A constant body rate: the exponential of the held rate is exact, and the
    accelerometer (consistent with the truth) corrects nothing."""
    q0 = expmap(np.radians([10.0, 5.0, -20.0]))
    s = constant_rotation(np.array([0.4, -0.3, 0.7]), q0, 2001, DT)
    err = Harness(estimator, len(s.t), q0=q0).run(s)
    assert err.max() < 1e-6  # deg: rounding only, over 10 s and 400 deg of yaw


def _biased_hover(n, bias, rng, *, mag=True):
    q0 = expmap(np.radians([3.0, -2.0, 40.0]))
    s = constant_rotation(np.zeros(3), q0, n, DT)
    s.w = s.w + bias + 1.8e-3 * rng.standard_normal((n, 3))
    s.f = s.f + 1.0 * rng.standard_normal((n, 3))
    if mag:
        s.mag = _mag(s.q, rng, 7e-3)
    return q0, s


def test_ekf_bias_estimate_converges_with_the_magnetometer():
    rng = np.random.default_rng(1)
    bias = np.array([0.01, -0.02, 0.015])
    q0, s = _biased_hover(6000, bias, rng)
    h = Harness("ekf", len(s.t), q0=q0, imu="noisy", magnetometer={},
                params={"initial_bias_std_rad_s": 0.03, "maneuver_accel_m_s2": 0.0,
                        "gate_m_s2": 1e9})  # fmt: skip
    h.est[ESL.ES_BIAS : ESL.ES_BIAS + 3] = 0.0  # it starts knowing nothing of the bias
    err = h.run(s)
    assert np.abs(h.bias_hat() - bias).max() < 3e-4
    assert err[-1000:].max() < 0.4  # deg, with a noisy IMU


def test_without_the_magnetometer_yaw_drifts_with_the_bias():
    """Yaw is unobservable without a magnetometer: the z bias is never learnt and the
    heading error grows as ``b_z t``; the tilt stays corrected by the accelerometer."""
    rng = np.random.default_rng(2)
    bias = np.array([0.0, 0.0, 0.02])
    q0, s = _biased_hover(4000, bias, rng, mag=False)
    h = Harness("ekf", len(s.t), q0=q0, imu="noisy", params={"initial_bias_std_rad_s": 0.03})
    h.est[ESL.ES_BIAS : ESL.ES_BIAS + 3] = 0.0
    h.run(s)
    phi = np.degrees(error_vector(h.q_hat(), s.q[-1]))
    body_z = quat_to_matrix(h.q_hat()).T @ np.array([0.0, 0.0, 1.0])  # inertial Z in body axes
    yaw_err = abs(phi @ body_z)
    assert yaw_err == pytest.approx(np.degrees(0.02 * s.t[-1]), rel=0.1)
    assert abs(h.bias_hat()[2]) < 0.002


def test_ekf_is_consistent_on_long_noisy_hovers():
    """NEES of the attitude and bias (6 states) averaged over runs, within the chi-square
    95 % band at nearly every sample, when the filter's noise figures are the sensors'."""
    from scipy.stats import chi2

    dt, n, runs = DT, 3000, 12
    sg, sa, sw, sm = 2e-3, 0.5, 1e-3, 1e-2
    p0_att, p0_b = np.radians(2.0), 0.01
    nees = np.zeros((runs, n))
    for r in range(runs):
        rng = np.random.default_rng(100 + r)
        q0 = expmap(rng.normal(0.0, 0.2, 3))
        s = constant_rotation(np.zeros(3), q0, n, dt)
        steps = sw * np.sqrt(dt) * rng.standard_normal((n - 1, 3))
        b = np.cumsum(np.vstack([rng.normal(0.0, p0_b, (1, 3)), steps]), 0)
        w = b + sg * rng.standard_normal((n, 3))
        f = s.f + sa * rng.standard_normal((n, 3))
        mag = _mag(q0)[0] + sm * rng.standard_normal((n, 3))
        h = Harness("ekf", n, q0=q0, magnetometer={"noise": sm}, params={
            "gyro_noise_rad_s": sg, "accel_noise_m_s2": sa, "gravity_noise_m_s2": sa,
            "magnetometer_noise": sm, "gyro_bias_walk_rad_s_sqrt_s": sw,
            "initial_attitude_std_deg": 2.0, "initial_bias_std_rad_s": p0_b, "gate_m_s2": 1e9,
        })  # fmt: skip
        h.est[ESL.ES_Q : ESL.ES_Q + 4] = qmul(q0, expmap(rng.normal(0.0, p0_att, 3)))
        h.est[ESL.ES_BIAS : ESL.ES_BIAS + 3] = b[0] + rng.normal(0.0, p0_b, 3)
        for i in range(n):
            h.sample(s.t[i], f[i], w[i], q0, mag=mag[i])
            e = np.concatenate([error_vector(h.q_hat(), q0), b[i] - h.bias_hat()])
            nees[r, i] = e @ np.linalg.solve(h.P(), e)
    avg = nees.mean(axis=0)
    lo, hi = chi2.ppf(0.025, 6 * runs) / runs, chi2.ppf(0.975, 6 * runs) / runs
    inside = (avg >= lo) & (avg <= hi)
    assert inside.mean() > 0.9
    assert 0.8 * 6 < avg.mean() < 1.2 * 6


@pytest.mark.parametrize("estimator", ["complementary", "ekf"])
def test_the_pose_sensor_bounds_velocity_and_position(estimator):
    """Without a pose sensor velocity and position integrate the accelerometer's noise and
    drift; with one (100 Hz, 1 mm) the initial errors are corrected and stay small."""
    rng = np.random.default_rng(3)
    n = 2000
    q0 = expmap(np.radians([2.0, 1.0, 10.0]))
    s = constant_rotation(np.zeros(3), q0, n, DT)
    s.f = s.f + 0.5 * rng.standard_normal((n, 3))
    pos = np.array([0.0, 0.0, -5.0])
    s.pos = np.tile(pos, (n, 1))
    s.vel = np.zeros((n, 3))
    pose = np.full((n, 3), np.nan)
    pose[::2] = pos + 1e-3 * rng.standard_normal((n // 2, 3))
    errs = {}
    for with_pose in (False, True):
        h = Harness(estimator, n, q0=q0, pose_sensor={"attitude": False} if with_pose else None,
                    params={"initial_velocity_error_m_s": 0.0})  # fmt: skip
        h.est[ESL.ES_VEL : ESL.ES_VEL + 3] = (0.3, -0.2, 0.1)
        h.est[ESL.ES_POS : ESL.ES_POS + 3] = pos + (0.1, 0.05, -0.05)
        s.pose = pose if with_pose else None
        h.run(s)
        errs[with_pose] = (np.linalg.norm(h.est[ESL.ES_VEL : ESL.ES_VEL + 3]),
                           np.linalg.norm(h.est[ESL.ES_POS : ESL.ES_POS + 3] - pos))  # fmt: skip
    assert errs[True][0] < 0.05 and errs[True][1] < 0.01
    assert errs[False][0] > 0.2 and errs[False][1] > 1.0


# ----------------------------------------------------------------- ahrs
def _wobble(n, rng, f_noise=0.3, w_noise=2e-3, m_noise=5e-3):
    t = np.arange(n) * DT
    w_true = np.stack([0.8 * np.sin(2 * np.pi * 0.5 * t), 0.6 * np.cos(2 * np.pi * 0.3 * t),
                       0.4 * np.sin(2 * np.pi * 0.2 * t + 1.0)], 1)  # fmt: skip
    q = np.empty((n, 4))
    q[0] = expmap(np.radians([5.0, -3.0, 20.0]))
    for i in range(1, n):
        q[i] = qmul(q[i - 1], expmap(w_true[i] * DT))
        q[i] /= np.linalg.norm(q[i])
    f = np.array([-9.81 * quat_to_matrix(qi)[2] for qi in q]) + f_noise * rng.standard_normal(
        (n, 3)
    )
    w = w_true + w_noise * rng.standard_normal((n, 3))
    return t, q, f, w, _mag(q, rng, m_noise)


@pytest.mark.parametrize("marg", [False, True], ids=["imu", "marg"])
def test_complementary_agrees_with_ahrs_mahony(marg):
    """The same filter where the formulations coincide: equal accelerometer and
    magnetometer gains, no gate, the same order (bias update, then the corrected rate).
    They differ in two things: ``ahrs`` measures the errors at the prior attitude (one
    sample behind the measurement), ours at the predicted one; ``ahrs`` integrates to
    first order (``q += q (x) (0, w) dt / 2``, normalised), ours with the exponential.
    On a noisy hover (no rotation but the gyro noise: the prior is nearly the
    prediction) they agree to 1e-3 deg
    over 15 s; under rotation ``ahrs`` lags by about ``|w| dt`` where ours is exact.
    Frames: ``ahrs``'s Mahony reads the gravity reaction along +z of its reference (it
    gets ``-f``) and, with a magnetometer, puts magnetic north on +y (its reference is
    (west, north, down), a yaw of 90 deg from NED)."""
    ahrs = pytest.importorskip("ahrs", reason="ahrs (the dev extra) is not installed")
    rng = np.random.default_rng(2)
    n = 3000
    kp, ki = 1.0, 0.3
    params = {"k_acc_1_s": kp, "k_mag_1_s": kp, "k_bias_1_s2": ki, "gate_m_s2": 1e9}
    turn = np.array([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])  # NED -> (W, N, D)
    back = turn * np.array([1.0, -1.0, -1.0, -1.0])

    def run(q, f, w, mag):
        h = Harness("complementary", n, q0=q[0], params=params,
                    magnetometer={"noise": 5e-3} if marg else None)  # fmt: skip
        h.est[ESL.ES_BIAS : ESL.ES_BIAS + 3] = 0.0
        ref = ahrs.filters.Mahony(k_P=kp, k_I=ki, frequency=1.0 / DT)
        qr = qmul(turn, q[0]) if marg else q[0].copy()
        diff, err_mine, err_ref = (np.zeros(n) for _ in range(3))
        for i in range(n):
            h.sample(i * DT, f[i], w[i], q[i], mag=mag[i] if marg else None)
            if i > 0:
                if marg:
                    qr = ref.updateMARG(qr, w[i], -f[i], mag[i], dt=DT)
                else:
                    qr = ref.updateIMU(qr, w[i], -f[i], dt=DT)
            q_ref = qmul(back, qr) if marg else qr
            diff[i] = angle_deg(h.q_hat(), q_ref)
            err_mine[i], err_ref[i] = angle_deg(h.q_hat(), q[i]), angle_deg(q_ref, q[i])
        return diff, err_mine, err_ref

    # a noisy hover: the formulations coincide
    q0 = expmap(np.radians([5.0, -3.0, 20.0]))
    s = constant_rotation(np.zeros(3), q0, n, DT)
    w = 2e-3 * rng.standard_normal((n, 3))
    f = s.f + 0.3 * rng.standard_normal((n, 3))
    diff, _, _ = run(s.q, f, w, _mag(s.q, rng, 5e-3))
    assert diff.max() < 1e-3
    # a constant rotation, ideal IMU: ours exact, ahrs one sample behind (about |w| dt)
    rate = np.array([0.3, -0.2, 0.6])
    s = constant_rotation(rate, q0, n, DT)
    diff, err_mine, err_ref = run(s.q, s.f, s.w, _mag(s.q))
    assert err_mine.max() < 1e-6
    lag = np.degrees(np.linalg.norm(rate) * DT)
    assert 0.1 * lag < err_ref[-1] < 2.0 * lag


def test_ekf_agrees_with_ahrs_ekf():
    """Where the formulations coincide (attitude only: our bias state held at zero with a
    negligible prior; the noises matched, the accelerometer's divided by g since ``ahrs``
    normalises the vectors; no gate) the two EKFs give the same attitude to 0.1 deg after
    a 1-s transient (0.02 deg RMS). They differ in the state (``ahrs``: the quaternion,
    updated additively then normalised; ours: a rotation-vector error, multiplicative),
    the measurement (``ahrs``: the normalised accelerometer and magnetometer stacked;
    ours: the specific force as gravity, then the field, in sequence) and the bias (none in
    ``ahrs``)."""
    ahrs = pytest.importorskip("ahrs", reason="ahrs (the dev extra) is not installed")
    rng = np.random.default_rng(2)
    n = 3000
    t, q, f, w, mag = _wobble(n, rng)
    sg, sa, sm = 2e-3, 0.3, 5e-3
    h = Harness("ekf", n, q0=q[0], magnetometer={"noise": sm}, params={
        "gyro_noise_rad_s": sg, "accel_noise_m_s2": sa, "gravity_noise_m_s2": sa,
        "magnetometer_noise": sm, "gate_m_s2": 1e9, "initial_attitude_std_deg": 1.0,
        "initial_bias_std_rad_s": 1e-9, "gyro_bias_walk_rad_s_sqrt_s": 1e-12,
    })  # fmt: skip
    h.est[ESL.ES_BIAS : ESL.ES_BIAS + 3] = 0.0
    ref = ahrs.filters.EKF(mag=mag, frequency=1.0 / DT, frame="NED", magnetic_ref=M_I,
                           noises=[sg**2, (sa / 9.81) ** 2, sm**2], q0=q[0],
                           P=np.eye(4) * (np.radians(1.0) / 2) ** 2)  # fmt: skip
    qr = q[0].copy()
    diff, err_mine, err_ref = np.zeros(n), np.zeros(n), np.zeros(n)
    for i in range(n):
        h.sample(t[i], f[i], w[i], q[i], mag=mag[i])
        if i > 0:
            qr = ref.update(qr, w[i], -f[i], mag[i], dt=DT)
        diff[i] = angle_deg(h.q_hat(), qr)
        err_mine[i], err_ref[i] = angle_deg(h.q_hat(), q[i]), angle_deg(qr, q[i])
    settled = slice(200, None)
    assert diff[settled].max() < 0.1
    assert np.sqrt(np.mean(diff[settled] ** 2)) < 0.03
    assert np.sqrt(np.mean(err_mine**2)) < 0.2 and np.sqrt(np.mean(err_ref**2)) < 0.2


# ----------------------------------------------------------------- work space
@pytest.mark.parametrize("with_pose", [False, True])
def test_ekf_sample_reads_nothing_its_work_space_held_before(with_pose):
    """The ``ekf``'s work space is made once per run and never cleared: each sample writes
    every entry it reads, so garbage left in it (NaN) changes no bit of the estimate."""
    rng = np.random.default_rng(7)
    n = 200
    q0 = expmap(np.radians([3.0, -2.0, 15.0]))
    s = constant_rotation(np.array([0.2, -0.1, 0.3]), q0, n, DT)
    s.f = s.f + 0.3 * rng.standard_normal((n, 3))
    s.w = s.w + 2e-3 * rng.standard_normal((n, 3))
    s.mag = _mag(s.q, rng, 5e-3)
    pos = np.array([0.0, 0.0, -5.0])
    s.pos = np.tile(pos, (n, 1))
    s.vel = np.zeros((n, 3))
    pose = np.full((n, 3), np.nan)
    pose[::2] = pos + 1e-3 * rng.standard_normal((n // 2, 3))
    s.pose = pose if with_pose else None
    runs = []
    for garbage in (False, True):
        h = Harness("ekf", n, q0=q0, magnetometer={}, pose_sensor={} if with_pose else None)
        assert h.w.ekf.shape == (6, 12, 12)
        for i in range(n):
            if garbage:
                h.w.ekf[:] = np.nan
            h.sample(s.t[i], s.f[i], s.w[i], s.q[i], s.mag[i],
                     None if s.pose is None else s.pose[i], s.pos[i], s.vel[i])  # fmt: skip
        runs.append(np.concatenate([h.q_hat(), h.bias_hat(), h.P().ravel(),
                                    h.est[ESL.ES_VEL : ESL.ES_POS + 3]]))  # fmt: skip
    assert np.all(np.isfinite(runs[0]))
    assert np.array_equal(runs[0], runs[1])
