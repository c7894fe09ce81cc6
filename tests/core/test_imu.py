"""The IMU reads the specific force at its position: hover, free fall, pure spin, wall contact."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadimpact import FlightScenario
from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.kernel import execute
from quadimpact.core.recording_slots import OUT_DELTA, OUT_T, OUT_X
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.rotations import quat_to_matrix
from quadimpact.simulation.setup import prepare

G = 9.81


def _scfg(rate_hz: float = 200.0, position=(0.0, 0.0, 0.0)) -> np.ndarray:
    scfg = np.zeros(IMS.NSCFG)
    scfg[IMS.SC_RATE] = rate_hz
    scfg[IMS.SC_POS : IMS.SC_POS + 3] = position
    return scfg


def _run(setup, scfg, *, veh=None, ctrl=None, noise=None):
    n_imu = int((setup.tf - setup.t0) * scfg[IMS.SC_RATE]) + 2
    changes = {"veh": veh, "ctrl": ctrl}
    m = setup.model(
        **{k: v for k, v in changes.items() if v is not None},
        scfg=scfg, noise=noise, sched_t=None, sched_rate=None, sched_stop=None,
    )  # fmt: skip
    return execute(m, n_imu=n_imu)


def test_level_hover_reads_minus_g_along_body_z():
    setup = prepare(FlightScenario(position_m=(0, 0, -2), final_time_s=1.0))
    imu = _run(setup, _scfg(position=(0.02, 0.01, -0.05))).imu
    assert imu.shape[0] == 201  # t0 and every tick to 1 s
    f = imu[:, IMS.I_F : IMS.I_F + 3]
    np.testing.assert_allclose(f, np.tile([0.0, 0.0, -G], (imu.shape[0], 1)), atol=1e-12, rtol=0)
    np.testing.assert_allclose(imu[:, IMS.I_W : IMS.I_W + 3], 0.0, atol=1e-12)


def test_free_fall_reads_zero():
    setup = prepare(FlightScenario(position_m=(0, 0, -50), euler_deg=(20, -10, 30),
                                   rotor_speeds_rad_s=(0, 0, 0, 0), final_time_s=1.0))  # fmt: skip
    ctrl = setup.ctrl.copy()
    ctrl[CTL.C_KIND] = L.CTRL_NONE  # rotors stay stopped
    imu = _run(setup, _scfg(position=(0.1, -0.05, 0.02)), ctrl=ctrl).imu
    np.testing.assert_allclose(imu[:, IMS.I_F : IMS.I_F + 3], 0.0, atol=1e-12)


def test_constant_spin_off_the_cm_reads_the_centripetal_term():
    """Torque-free spin about a principal axis, no gravity: f = w x (w x r)."""
    omega = np.array([0.0, 0.0, 7.0])
    r = np.array([0.05, -0.03, 0.02])
    setup = prepare(FlightScenario(position_m=(0, 0, -5), angular_velocity_rad_s=tuple(omega),
                                   rotor_speeds_rad_s=(0, 0, 0, 0), final_time_s=0.5))  # fmt: skip
    veh = setup.veh.copy()
    veh[VS.V_GRAVITY] = 0.0
    inertia = np.diag(np.diag(veh[VS.V_INERTIA : VS.V_INERTIA + 9].reshape(3, 3)))
    veh[VS.V_INERTIA : VS.V_INERTIA + 9] = inertia.ravel()
    veh[VS.V_INERTIA_INV : VS.V_INERTIA_INV + 9] = np.linalg.inv(inertia).ravel()
    ctrl = setup.ctrl.copy()
    ctrl[CTL.C_KIND] = L.CTRL_NONE
    imu = _run(setup, _scfg(1000.0, r), veh=veh, ctrl=ctrl).imu
    expected = np.cross(omega, np.cross(omega, r))
    np.testing.assert_allclose(imu[:, IMS.I_F : IMS.I_F + 3], np.tile(expected, (len(imu), 1)),
                               atol=1e-9)  # fmt: skip
    np.testing.assert_allclose(
        imu[:, IMS.I_W : IMS.I_W + 3], np.tile(omega, (len(imu), 1)), atol=1e-9
    )


def test_wall_contact_body_x_reading_is_the_contact_force_over_mass():
    """Level vehicle, no gravity, no rotors, flying into a wall: f_x = -sum F_n / m at the CM."""
    wall = {"name": "wall", "point_m": (0.3, 0.0, 0.0), "normal": (-1.0, 0.0, 0.0)}
    setup = prepare(FlightScenario(position_m=(0, 0, -5), velocity_m_s=(1.0, 0, 0),
                                   rotor_speeds_rad_s=(0, 0, 0, 0), surfaces=(wall,),
                                   final_time_s=0.5))  # fmt: skip
    veh = setup.veh.copy()
    veh[VS.V_GRAVITY] = 0.0
    ctrl = setup.ctrl.copy()
    ctrl[CTL.C_KIND] = L.CTRL_NONE
    rec = _run(setup, _scfg(1000.0), veh=veh, ctrl=ctrl)
    out, imu = rec.out, rec.imu
    assert len(rec.episodes) >= 2  # bumpers 1 and 4 (the contact really happened)
    # the output grid (1 kHz) and the IMU samples (1 kHz) coincide
    np.testing.assert_allclose(out[:, OUT_T], imu[:, IMS.I_T], atol=1e-12)
    nf = setup.feat.shape[0]
    force = out[:, OUT_DELTA + nf : OUT_DELTA + 2 * nf].sum(axis=1)
    assert force.max() > 1.0
    quat = out[:, OUT_X + L.X_QUAT : OUT_X + L.X_QUAT + 4]
    # contact force along -X (inertial) in body axes, over the mass
    f_body = np.einsum("nji,j->ni", quat_to_matrix(quat), np.array([-1.0, 0.0, 0.0]))
    expected = f_body * (force / veh[VS.V_MASS])[:, None]
    np.testing.assert_allclose(imu[:, IMS.I_F : IMS.I_F + 3], expected, atol=1e-9)


def test_noise_and_bias_statistics_and_saturation():
    setup = prepare(FlightScenario(position_m=(0, 0, -2), final_time_s=10.0))
    n = 10_000  # samples at 1 kHz from 0 to 10 s: n + 1
    rng = np.random.default_rng(7)
    noise = rng.standard_normal((n + 1, 6))
    scfg = _scfg(1000.0)
    scfg[IMS.SC_NOISE_F] = 1.0
    scfg[IMS.SC_NOISE_W] = 1.8e-3
    bias = np.array([0.05, -0.04, 0.03, 0.01, -0.02, 0.015])
    scfg[IMS.SC_BIAS : IMS.SC_BIAS + 6] = bias
    imu = _run(setup, scfg, noise=noise).imu
    assert imu.shape[0] == n + 1
    f_err = imu[:, IMS.I_F : IMS.I_F + 3] - imu[:, IMS.I_F_TRUE : IMS.I_F_TRUE + 3]
    w_err = imu[:, IMS.I_W : IMS.I_W + 3] - imu[:, IMS.I_W_TRUE : IMS.I_W_TRUE + 3]
    err = np.hstack([f_err, w_err])
    sigma = np.array([1.0, 1.0, 1.0, 1.8e-3, 1.8e-3, 1.8e-3])
    m = len(err)
    # mean within 4 standard errors of the bias, std within 4 standard errors of sigma
    assert np.all(np.abs(err.mean(axis=0) - bias) < 4 * sigma / math.sqrt(m))
    assert np.all(np.abs(err.std(axis=0) - sigma) < 4 * sigma / math.sqrt(2 * m))
    # the noise is exactly the draws the caller made, scaled
    np.testing.assert_allclose(err - bias, noise[: len(err)] * sigma, atol=1e-12)
    # saturation clips at the range
    scfg[IMS.SC_RANGE_F] = 2.0
    imu = _run(setup, scfg, noise=noise).imu
    f = imu[:, IMS.I_F : IMS.I_F + 3]
    assert f.min() == -2.0 and f.max() == 2.0
    assert np.all(np.abs(f) <= 2.0)


@pytest.mark.parametrize("kind", [L.FILTER_FIRST_ORDER, L.FILTER_MOVING_AVERAGE])
def test_low_pass_filters(kind):
    setup = prepare(FlightScenario(position_m=(0, 0, -2), final_time_s=1.0))
    rng = np.random.default_rng(3)
    noise = rng.standard_normal((1002, 6))
    scfg = _scfg(1000.0)
    scfg[IMS.SC_NOISE_F] = 1.0
    raw = _run(setup, scfg, noise=noise).imu[:, IMS.I_F]
    scfg[IMS.SC_FILTER] = kind
    scfg[IMS.SC_FILTER_PARAM] = 0.01 if kind == L.FILTER_FIRST_ORDER else 8
    filt = _run(setup, scfg, noise=noise).imu[:, IMS.I_F]
    if kind == L.FILTER_MOVING_AVERAGE:
        expected = np.array([raw[max(0, i - 7) : i + 1].mean() for i in range(len(raw))])
    else:
        a = 1.0 - math.exp(-0.001 / 0.01)
        expected = np.empty_like(raw)
        expected[0] = raw[0]
        for i in range(1, len(raw)):
            expected[i] = expected[i - 1] + a * (raw[i] - expected[i - 1])
    np.testing.assert_allclose(filt, expected, atol=1e-12)
    assert filt.std() < 0.5 * raw.std()
