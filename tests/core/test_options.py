"""Model options: crash rules, ground contact, friction, rotor modes and limits."""

import math

import numpy as np
import pytest

from quadimpact import FlightScenario, simulate
from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.kernel import execute
from quadimpact.core.recording_slots import E_FEATURE, E_T_END, E_T_START, OUT_CMD, OUT_T, OUT_X
from quadimpact.rotations import quat_to_matrix
from quadimpact.simulation.setup import prepare
from quadimpact.simulation.simulate import run_setup

from helpers import run_packed, states

G = 9.81
HEAVY = {"inertia_kg_m2": [[1e6, 0, 0], [0, 1e6, 0], [0, 0, 1e6]]}


def rotors_off(setup, gravity=True):
    veh = setup.veh.copy()
    if not gravity:
        veh[VS.V_GRAVITY] = 0.0
    ctrl = setup.ctrl.copy()
    ctrl[CTL.C_KIND] = L.CTRL_NONE
    return run_packed(setup, veh=veh, ctrl=ctrl)


def falling(**kw):
    return prepare(FlightScenario(rotor_speeds_rad_s=(0, 0, 0, 0), final_time_s=2.0, **kw))


def test_crash_when_the_cm_reaches_the_ground_is_located():
    _, _, st = rotors_off(falling())
    assert st[L.ST_STATUS] == L.STATUS_CRASHED
    assert st[L.ST_CRASH_T] == pytest.approx(math.sqrt(2 * 2.0 / G), abs=1e-9)
    assert st[L.ST_CRASH_X + 2] == pytest.approx(0.0, abs=1e-9)


def test_paper_crash_rule_tests_altitude_at_control_ticks():
    _, _, st = rotors_off(falling(model="paper-replica", rotor_mode="ideal"))
    t_cross = math.sqrt(2 * 2.3 / G)  # CM 0.3 m below the ground
    assert st[L.ST_CRASH_T] == pytest.approx(math.ceil(t_cross * 200) / 200, abs=1e-12)


def test_ground_as_contact_surface_bounces_and_records_the_crash():
    setup = falling(ground="contact", vehicle_overrides=HEAVY)
    out, ep, st = rotors_off(setup)
    assert st[L.ST_STATUS] == L.STATUS_CRASHED and st[L.ST_T_END] == 2.0  # goes on
    assert setup.shape_names == ("ground",)
    # level vehicle: the four bumpers touch the ground together, then it bounces up
    first = ep[ep[:, E_T_START] < ep[0, E_T_START] + 1e-6]
    assert sorted(first[:, E_FEATURE].astype(int)) == [0, 1, 2, 3]
    assert st[L.ST_CRASH_T] == pytest.approx(ep[0, E_T_START])
    h = -states(out)[:, L.X_POS + 2]
    after = h[out[:, OUT_T] > ep[0, E_T_END] + 0.05]
    assert after.max() > 0.5  # bounced well up (restitution 0.9 of a 2 m drop)


def test_ground_episodes_are_not_impacts():
    scenario = FlightScenario(rotor_speeds_rad_s=(0, 0, 0, 0), ground="contact", final_time_s=1.0)
    setup = prepare(scenario)
    setup.ctrl[CTL.C_KIND] = L.CTRL_NONE  # the rotors held at their speeds: off, as they start
    r = run_setup(setup, scenario)
    assert r.summary["crash_time_s"] is not None
    assert (r.episodes["surface"] == "ground").any()
    assert r.summary["n_episodes"] == 0 and r.summary["delta_init_m"] is None


@pytest.mark.parametrize("mu", [0.0, 0.3])
def test_friction_impulse_is_mu_times_normal_impulse(mu):
    """A point mass hitting the wall obliquely: tangential change = mu x normal change."""
    setup = prepare(
        FlightScenario(
            position_m=(0.6, 0.0, -2.0),
            velocity_m_s=(1.0, 0.8, 0.0),
            euler_deg=(0, 0, 45),
            rotor_speeds_rad_s=(0, 0, 0, 0),
            vehicle_overrides=HEAVY,
            friction_coefficient=mu,
            surfaces=[{"name": "wall", "point_m": (1.0, 0, 0), "normal": (-1, 0, 0)}],
            final_time_s=0.8,
        )
    )
    out, ep, _ = rotors_off(setup, gravity=False)
    assert ep.shape[0] == 1
    x = states(out)
    v = np.einsum("nij,nj->ni", quat_to_matrix(x[:, 6:10]), x[:, 3:6])
    dvn = 1.0 - v[-1, 0]
    dvt = 0.8 - v[-1, 1]
    assert dvn > 1.8
    # sliding throughout (|v_t| >> v_reg): the regularisation costs well under 1 %
    assert dvt == pytest.approx(mu * dvn, rel=1e-2, abs=1e-12)


def test_first_order_rotors_follow_their_time_constant():
    """A step of the command from 500 to 600 rad/s at t = 0: the built-in hold controller
    commands the rotors' own speeds, which the command floor of 600 rad/s lifts to 600."""
    setup = prepare(
        FlightScenario(
            rotor_speeds_rad_s=(500, 500, 500, 500), final_time_s=0.2, rotor_mode="first-order"
        )
    )
    veh = setup.veh.copy()
    veh[VS.V_GRAVITY] = 0.0
    setup.ctrl[CTL.C_KIND] = L.CTRL_NONE
    opts = setup.opts.copy()
    opts[L.O_OMEGA_MIN], opts[L.O_OMEGA_MAX], opts[L.O_SLEW_MAX] = 600.0, 0.0, 0.0
    out = execute(setup.model(veh=veh, opts=opts)).out
    assert np.all(out[1:, OUT_CMD : OUT_CMD + 4] == 600.0)
    t = out[:, OUT_T]
    tau = setup.vehicle.motor_time_constant_s
    expected = 600.0 - 100.0 * np.exp(-t / tau)
    np.testing.assert_allclose(out[:, OUT_X + L.X_ROTOR], expected, atol=1e-6)


def test_speed_and_slew_limits_bound_the_commands():
    r = simulate(
        FlightScenario(
            position_m=(0, 0, -1.0),
            altitude_ref_m=2.0,
            euler_deg=(20, 0, 0),
            attitude_ref_deg=(0, 0, 0),
            final_time_s=2.0,
            rotor_speed_limits_rpm=(5600, 6300),
            rotor_slew_limit_rad_s2=2e3,
        )
    )
    cmd = r.timeseries[[f"omega_cmd{j}_rad_s" for j in range(1, 5)]].to_numpy()
    rpm = 60 / (2 * np.pi)
    assert cmd.min() * rpm >= 5600 - 1e-6 and cmd.max() * rpm <= 6300 + 1e-6
    assert np.isclose(cmd.max() * rpm, 6300) and np.isclose(cmd.min() * rpm, 5600)
    steps = np.abs(np.diff(cmd[::5], axis=0))  # output at 1 kHz, commands at 200 Hz
    assert steps.max() <= 2e3 / 200 + 1e-6
    assert steps.max() == pytest.approx(2e3 / 200)  # the slew limit is reached
