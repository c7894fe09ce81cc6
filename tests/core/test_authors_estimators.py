"""The authors' 2016 filters and the EKF's impact noise on synthetic IMU streams.

The raw-vector complementary filter (its normalised gain) and the 7-state
additive-quaternion EKF (its Jacobians, its transition matrix as written and
correct) (docs/ESTIMATION.md 8). quadimpact's EKF through impacts with a
magnetometer of dip 72 deg: tests/simulation/test_authors_2016.py.
"""

from __future__ import annotations

import numpy as np
import pytest
from estimator_streams import Harness, constant_rotation, expmap, qmul

from quadimpact.core import estimator_slots as ESL
from quadimpact.core.estimators import ekf as EKF
from quadimpact.core.estimators import older_sensors as OS
from quadimpact.core.estimators.ekf_additive import _rotate_t, _transition
from quadimpact.rotations import quat_to_matrix

G = 9.81
DT = 0.01  # the authors' 100 Hz
MAG_2016 = {"dip_deg": 71.9, "norm": 0.99, "noise": 0.0}


def _field(h: Harness) -> np.ndarray:
    return h.m.scfg[OS.MAG_FIELD_I : OS.MAG_FIELD_I + 3].copy()


def _mag(q: np.ndarray, field: np.ndarray) -> np.ndarray:
    return np.array([quat_to_matrix(qi).T @ field for qi in np.atleast_2d(q)])


def test_the_magnetometer_field_has_its_dip_and_norm():
    h = Harness("ekf", 10, magnetometer=MAG_2016)
    m = _field(h)
    assert np.linalg.norm(m) == pytest.approx(0.99, rel=1e-12)
    assert np.degrees(np.arctan2(m[2], m[0])) == pytest.approx(71.9, rel=1e-12)
    assert m[1] == 0.0


@pytest.mark.parametrize(
    ("estimator", "params"),
    [
        ("complementary", {"form": "raw"}),
        ("ekf-additive", {"transition": "correct"}),
        ("ekf-additive", {"transition": "as-written"}),
    ],
)
def test_the_authors_filters_hold_a_hover_exactly(estimator, params):
    """Readings consistent with the truth (ideal IMU, the magnetometer): nothing to correct."""
    q0 = expmap(np.radians([4.0, -3.0, 35.0]))
    s = constant_rotation(np.zeros(3), q0, 1001, DT)
    h = Harness(estimator, len(s.t), params=params, q0=q0, magnetometer=MAG_2016, dt=DT)
    s.mag = _mag(s.q, _field(h))
    err = h.run(s)
    assert err.max() < 0.01


@pytest.mark.parametrize("transition", ["correct", "as-written"])
def test_the_additive_ekf_tracks_a_constant_rotation(transition):
    """First-order integration of q (x) (0, w) dt/2, normalised: a rotation error of order
    (|w| dt)^3 per step; the consistent readings then correct nothing visible."""
    q0 = expmap(np.radians([10.0, 5.0, -20.0]))
    s = constant_rotation(np.array([0.4, -0.3, 0.7]), q0, 1001, DT)
    h = Harness("ekf-additive", len(s.t), params={"transition": transition}, q0=q0, dt=DT,
                magnetometer=MAG_2016)  # fmt: skip
    s.mag = _mag(s.q, _field(h))
    err = h.run(s)
    assert err.max() < 0.01  # deg, over 10 s and 400 deg of yaw


def test_the_raw_complementary_filter_corrects_a_tilt_at_k_p_w_a_g2_over_2():
    """The authors' explicit filter on raw vectors: a small tilt error decays at
    ``k_p w_a g^2 / 2`` (2.4 1/s with their gains) before the bias loop acts."""
    q_true = np.array([1.0, 0.0, 0.0, 0.0])
    n = 6
    s = constant_rotation(np.zeros(3), q_true, n, DT)
    h = Harness("complementary", n, params={"form": "raw"}, q0=q_true, dt=DT)
    delta = np.radians(1.0)
    h.d.est[ESL.ES_Q : ESL.ES_Q + 4] = expmap(np.array([delta, 0.0, 0.0]))
    err = np.radians(h.run(s))
    k_p, w_a = 0.1, 0.5
    rate = k_p * w_a * G * G / 2.0
    assert rate == pytest.approx(2.4, abs=0.01)  # the spec's normalised gain
    # per sample the error shrinks by exp(-rate dt) (first order), the bias loop adding
    # O(k_I dt^2): measured over five samples
    measured = -np.log(err[5] / err[0]) / (5 * DT)
    assert measured == pytest.approx(rate, rel=0.03)


def test_the_additive_ekf_measurement_jacobian():
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = rng.standard_normal(4)
        q /= np.linalg.norm(q)
        v = tuple(rng.standard_normal(3))
        J = np.zeros((6, 7))
        h = np.array(_rotate_t(q, v, J, 0))
        np.testing.assert_allclose(h, quat_to_matrix(q).T @ np.array(v), atol=1e-14)
        eps = 1e-7
        for k in range(4):
            dq = q.copy()
            dq[k] += eps
            num = (np.array(_rotate_t(dq, v, np.zeros((6, 7)), 0)) - h) / eps
            np.testing.assert_allclose(J[:3, k], num, atol=1e-5)


def test_the_additive_ekf_transition_matches_its_propagation():
    """The correct form is the Jacobian of q + dt/2 q (x) (0, w - b) in (q, b)."""
    q = expmap(np.array([0.3, -0.2, 0.9]))
    w = np.array([0.3, -0.5, 0.2])
    F = np.zeros((7, 7))
    _transition(F, q, tuple(w), DT, False)

    def prop(x):
        return np.concatenate([x[:4] + 0.5 * DT * qmul(x[:4], np.r_[0.0, w - x[4:]]), x[4:]])

    x = np.r_[q, 0.0, 0.0, 0.0]
    num = np.array([(prop(x + 1e-7 * e) - prop(x)) / 1e-7 for e in np.eye(7)]).T
    np.testing.assert_allclose(F, num, atol=1e-6)
    _transition(F, q, tuple(w), DT, True)
    expected = -0.5 * DT * (np.eye(4) + (num[:4, :4] - np.eye(4)) / (0.5 * DT))
    np.testing.assert_allclose(F[:4, :4], expected, atol=1e-9)


def test_the_transition_as_written_resets_the_quaternion_covariance_to_q():
    """Predictions alone (free fall, no magnetometer: no update): as written, P's
    quaternion block is the process noise of one step, whatever it was; the correct form
    accumulates it."""
    n = 50
    s = constant_rotation(np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]), n, DT)
    s.f[:] = 0.0  # free fall: ||f| - g| beyond the gate
    out = {}
    for transition in ("as-written", "correct"):
        h = Harness("ekf-additive", n, params={"transition": transition}, dt=DT)
        h.run(s)
        p = h.d.est[EKF.ES_P : EKF.ES_P + 7 * EKF.N_EKF]
        out[transition] = np.diag(p.reshape(7, EKF.N_EKF))
    q_step = 1.8e-3 * DT
    np.testing.assert_allclose(out["as-written"][:4], q_step, rtol=1e-3)
    np.testing.assert_allclose(out["correct"][:4], 0.1 + (n - 1) * q_step, rtol=1e-3)
