"""The recovery controller's stage machine and staged law on hand-made inputs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.controllers import recovery as CL
from quadimpact.core.controllers import recovery as R

TOL = dict(q_tol=0.3, rate_tol=0.5, w_tol=0.3)


@pytest.mark.parametrize(
    ("stage", "qe", "rates", "w", "expected"),
    [
        (1, (0.5, 0.0), (0.0, 0.0), 0.0, 1),  # tilt error too large
        (1, (0.29, -0.29), (0.49, -0.49), 5.0, 2),  # converged (w does not matter)
        (1, (0.1, 0.1), (0.6, 0.0), 0.0, 1),  # rolling too fast
        (1, (0.1, 0.1), (0.0, -0.6), 0.0, 1),  # pitching too fast
        (2, (0.0, 0.31), (0.0, 0.0), 0.0, 2),
        (2, (0.0, 0.0), (0.0, 0.0), 2.0, 3),  # level: on to stage 3
        (3, (0.9, 0.9), (3.0, 3.0), 0.31, 3),  # still descending too fast
        (3, (0.9, 0.9), (3.0, 3.0), 0.29, 4),  # stage 3 only looks at w
        (3, (0.0, 0.0), (0.0, 0.0), -1.0, 4),  # climbing
        (4, (0.9, 0.9), (9.0, 9.0), 9.0, 4),  # stays
        (0, (0.0, 0.0), (0.0, 0.0), 0.0, 0),  # before detection nothing moves
    ],
)
def test_stage_machine_transitions(stage, qe, rates, w, expected):
    got = R.next_stage(stage, qe[0], qe[1], rates[0], rates[1], w, **TOL)
    assert got == expected


def test_at_most_one_stage_per_tick():
    # inputs that satisfy every test at once still move one stage
    for stage in (1, 2, 3):
        assert R.next_stage(stage, 0.0, 0.0, 0.0, 0.0, -5.0, **TOL) == stage + 1


def _packed(mass=1.0, g=9.81):
    veh = np.zeros(VS.NVEH)
    veh[VS.V_MASS] = mass
    veh[VS.V_GRAVITY] = g
    veh[VS.V_INERTIA : VS.V_INERTIA + 9] = np.diag([0.01, 0.01, 0.02]).ravel()
    ctrl = np.zeros(CTL.NCTRL)
    # an identity "allocation" so cmd^2 = (T, tau_x, tau_y, tau_z) can be read back
    ctrl[CTL.C_ALLOC_INV : CTL.C_ALLOC_INV + 16] = np.eye(4).ravel()
    ctrl[CTL.C_N_ROTORS] = veh[VS.V_N_ROTORS] = 4  # a quadrotor
    ctrl[CTL.C_OMEGA_MIN] = 0.0
    ctrl[CTL.C_OMEGA_MAX] = 1e9
    p = CTL.C_PARAMS
    ctrl[p + CL.R_K_ATT] = 20.0
    ctrl[p + CL.R_K_RATE : p + CL.R_K_RATE + 3] = (20.0, 20.0, 2.0)
    ctrl[p + CL.R_A_MAG] = g
    ctrl[p + CL.R_K_Z : p + CL.R_K_Z + 4] = (0.0, 0.0, 10.0, 10.0)
    return veh, ctrl


def _state(roll=0.0, pitch=0.0, yaw=0.0, w_body=0.0):
    from quadimpact.rotations import euler_zyx_to_quat

    x = np.zeros(L.NX)
    x[L.X_QUAT : L.X_QUAT + 4] = euler_zyx_to_quat(roll, pitch, yaw)
    x[L.X_VEL + 2] = w_body
    return x


def test_level_hover_target_gives_weight_and_no_torque():
    veh, ctrl = _packed()
    cmd = np.zeros(4)
    qe = R.staged_law(2, True, _state(), np.zeros(3), np.zeros(3), ctrl, veh, cmd)
    assert qe == (0.0, 0.0)
    np.testing.assert_allclose(cmd**2, [9.81, 0.0, 0.0, 0.0], atol=1e-12)


def test_stage1_tilts_away_from_the_wall_by_45_degrees():
    """a_ref = g n with n = -X: f_des points up and away, 45 deg from vertical."""
    veh, ctrl = _packed()
    cmd = np.zeros(4)
    normal = np.array([-1.0, 0.0, 0.0])
    qex, qey = R.staged_law(1, True, _state(), np.zeros(3), normal, ctrl, veh, cmd)
    # u = (0, 0, -1), f_des = (-g, 0, -g): axis u x f_des along +Y (body = inertial when
    # level), angle 45 deg, so q_e = (cos 22.5, 0, sin 22.5, 0): pitch up, thrust tilted to -X
    assert qex == pytest.approx(0.0, abs=1e-15)
    assert qey == pytest.approx(math.sin(math.radians(22.5)), rel=1e-12)
    # thrust along the level up axis: m (f_des . u) = g
    assert cmd[0] ** 2 == pytest.approx(9.81, rel=1e-12)
    # pitch-rate command K_rate * K_att * q_e,y, times Iyy
    assert math.sqrt(cmd[2] ** 2) == pytest.approx(math.sqrt(0.01 * 20 * 20 * qey), rel=1e-12)
    # the level target at the detection tick (recovery replica): no tilt command
    cmd2 = np.zeros(4)
    assert R.staged_law(1, False, _state(), np.zeros(3), normal, ctrl, veh, cmd2) == (0.0, 0.0)


def test_vertical_velocity_feedback_in_stages_3_and_4():
    veh, ctrl = _packed()
    for stage, k_z in ((2, 0.0), (3, 10.0), (4, 10.0)):
        cmd = np.zeros(4)
        R.staged_law(stage, True, _state(w_body=0.5), np.zeros(3), np.zeros(3), ctrl, veh, cmd)
        assert cmd[0] ** 2 == pytest.approx(9.81 + k_z * 0.5, rel=1e-12)


def test_tilted_vehicle_gets_a_rate_command_back_to_level():
    veh, ctrl = _packed()
    cmd = np.zeros(4)
    roll = math.radians(30.0)
    qex, qey = R.staged_law(2, True, _state(roll=roll), np.zeros(3), np.zeros(3), ctrl, veh, cmd)
    assert qex == pytest.approx(-math.sin(roll / 2), rel=1e-12)  # roll back
    assert qey == pytest.approx(0.0, abs=1e-15)
    # thrust: m g cos(roll) (f_des . u)
    assert cmd[0] ** 2 == pytest.approx(9.81 * math.cos(roll), rel=1e-12)


# ------------------------------------------------- the pole replica's switches
def _tilt_inputs(level_test, q_tol=0.15, euler_tol=0.2, qe=(0.0, 0.0)):
    """ctrl with the stage tests' switches, and mem with the previous tick's q_e."""
    _, ctrl = _packed()
    p = CTL.C_PARAMS
    ctrl[p + CL.R_Q_TOL] = q_tol
    ctrl[p + CL.R_LEVEL_TEST] = level_test
    ctrl[p + CL.R_EULER_TOL] = euler_tol
    mem = np.zeros(L.NMEM)
    mem[CL.RM_QE_X], mem[CL.RM_QE_Y] = qe
    return ctrl, mem


def _step(stage, x, ctrl, mem, rates=(0.0, 0.0), w=0.0, rate_tol=2.0, w_tol=0.2):
    """The stage after one tick's test, as recovery_step makes it."""
    a, b, tol = R.stage_tilt(stage, x, ctrl, mem)
    return R.next_stage(stage, a, b, rates[0], rates[1], w, tol, rate_tol, w_tol)


@pytest.mark.parametrize(
    ("roll", "pitch", "expected"),
    [
        (0.199, 0.0, 3),
        (0.201, 0.0, 2),
        (-0.199, 0.0, 3),
        (-0.201, 0.0, 2),
        (0.0, 0.199, 3),
        (0.0, 0.201, 2),
        (0.0, -0.199, 3),
        (0.0, -0.201, 2),
        (0.19, -0.19, 3),
    ],
)
def test_euler_stage2_test_fires_at_its_threshold(roll, pitch, expected):
    # a yaw of 2 rad changes nothing: the test reads the ZYX roll and pitch
    ctrl, mem = _tilt_inputs(CL.LEVEL_EULER, qe=(0.9, 0.9))  # q_e would fail the old test
    assert _step(2, _state(roll=roll, pitch=pitch, yaw=2.0), ctrl, mem) == expected


def test_euler_stage2_test_reads_the_state_now_not_the_previous_tilt_error():
    level = _state()
    # the previous tick's tilt error passes, the attitude now does not: stays in stage 2
    ctrl, mem = _tilt_inputs(CL.LEVEL_EULER, qe=(0.0, 0.0))
    assert _step(2, _state(pitch=0.3), ctrl, mem) == 2
    # and the other way round: moves on
    ctrl, mem = _tilt_inputs(CL.LEVEL_EULER, qe=(0.5, 0.5))
    assert _step(2, level, ctrl, mem) == 3
    # the default test reads the previous tick's tilt error, whatever the attitude now
    ctrl, mem = _tilt_inputs(CL.LEVEL_TILT_ERROR, qe=(0.5, 0.5))
    assert _step(2, level, ctrl, mem) == 2
    ctrl, mem = _tilt_inputs(CL.LEVEL_TILT_ERROR, qe=(0.1, -0.1))
    assert _step(2, _state(pitch=0.3), ctrl, mem) == 3


@pytest.mark.parametrize(
    ("p", "q", "expected"), [(1.99, -1.99, 3), (2.01, 0.0, 2), (0.0, -2.01, 2)]
)
def test_euler_stage2_test_checks_the_rates(p, q, expected):
    ctrl, mem = _tilt_inputs(CL.LEVEL_EULER)
    assert _step(2, _state(roll=0.1), ctrl, mem, rates=(p, q)) == expected


@pytest.mark.parametrize(
    ("qe", "rates", "expected"),
    [
        ((0.149, -0.149), (1.99, -1.99), 2),
        ((0.151, 0.0), (0.0, 0.0), 1),
        ((0.0, -0.151), (0.0, 0.0), 1),
        ((0.1, 0.1), (2.01, 0.0), 1),
        ((0.1, 0.1), (0.0, -2.01), 1),
    ],
)
def test_stage1_test_with_the_pole_tolerances(qe, rates, expected):
    # stage 1 reads the previous tick's tilt error even with the Euler test on (stage 2 only),
    # here against 0.15 and 2 rad/s; the attitude now does not matter
    ctrl, mem = _tilt_inputs(CL.LEVEL_EULER, qe=qe)
    assert _step(1, _state(roll=1.0, pitch=1.0), ctrl, mem, rates=rates) == expected


@pytest.mark.parametrize(("w", "expected"), [(0.199, 4), (0.201, 3), (-1.0, 4)])
def test_stage3_ends_below_the_pole_replicas_w(w, expected):
    ctrl, mem = _tilt_inputs(CL.LEVEL_EULER)
    assert _step(3, _state(), ctrl, mem, w=w) == expected


def test_stage1_reference_a_mag_sets_the_tilt_away():
    """a_ref = a_mag n: the target leans atan(a_mag / g) away from the wall (4.8: ~26 deg)."""
    veh, ctrl = _packed()
    ctrl[CTL.C_PARAMS + CL.R_A_MAG] = 4.8
    normal = np.array([-1.0, 0.0, 0.0])
    qex, qey = R.staged_law(1, True, _state(), np.zeros(3), normal, ctrl, veh, np.zeros(4))
    tilt = math.atan2(4.8, 9.81)
    assert math.degrees(tilt) == pytest.approx(26.07, abs=0.01)
    assert qex == pytest.approx(0.0, abs=1e-15)
    assert qey == pytest.approx(math.sin(tilt / 2), rel=1e-12)
