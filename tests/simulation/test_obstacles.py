"""Runs against cylinders and boxes, checked by physics (docs/OBSTACLES.md 5).

* a box face far from its edges gives the run of the plane through that face
  (to rounding); a cylinder of very large radius approaches the plane;
* a head-on pole hit at zero offset, roll 0, yaw 0, of a mirror-symmetric
  vehicle: no sideways motion, roll or yaw; offsets +y and -y: mirrored runs;
* an elastic contact (e = 1, no friction, no thrust) against a pole and a
  box edge conserves the energy (kinetic, gravity and elastic) to the
  integrator's tolerance;
* a sphere feature dropped on a plane rebounds with the restitution of the
  1-DOF Hunt-Crossley contact (integrated independently here).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from quadimpact import simulate
from quadimpact.core import controller_slots as CTL
from quadimpact.core import feature_slots as FS
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.kernel import BUILTIN
from quadimpact.core.recording_slots import E_OPEN, E_T_END, E_T_START, OUT_T, OUT_X
from quadimpact.core.records import new_output
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.inputs.scenarios import FlightScenario, ImpactTrial, scenario_from_dict
from quadimpact.inputs.world import Box, Cylinder
from quadimpact.simulation.setup import prepare

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
POLE = Cylinder(name="pole", point_m=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0), radius_m=0.1)


def _columns(result, names):
    ts = result.timeseries
    return np.column_stack([ts[n].to_numpy() for n in names])


def test_a_box_face_is_the_wall_plane():
    """The wall trial and a large box whose face is the wall: the same run, to rounding."""
    trial = ImpactTrial(pitch_deg=-20.0, roll_deg=5.0, yaw_deg=10.0, final_time_s=1.0)
    wall = simulate(trial)
    box = Box(name="box", centre_m=(5.0, 0.0, -5.0), half_extents_m=(5.0, 5.0, 5.0))
    faced = simulate(trial.model_copy(update={"obstacles": (box,)}))
    assert len(wall.episodes) == len(faced.episodes) > 0
    for col in ("t_start_s", "t_end_s", "peak_delta_m", "peak_force_n"):
        np.testing.assert_allclose(faced.episodes[col], wall.episodes[col], rtol=1e-7, atol=1e-9)
    names = ["x_m", "y_m", "z_m", "q0", "q1", "q2", "q3", "p_rad_s", "q_rad_s", "r_rad_s"]
    np.testing.assert_allclose(_columns(faced, names), _columns(wall, names), atol=1e-7)


def test_a_cylinder_of_large_radius_approaches_the_wall():
    trial = ImpactTrial(pitch_deg=-15.0, yaw_deg=20.0, final_time_s=0.3)
    plane = simulate(trial).summary["delta_init_m"]
    gaps = []
    for radius in (3.0, 30.0, 300.0):
        big = Cylinder(name="drum", point_m=(radius, 0.0, 0.0), axis=(0, 0, 1), radius_m=radius)
        got = simulate(trial.model_copy(update={"obstacles": (big,)})).summary["delta_init_m"]
        gaps.append(abs(got - plane))
    assert gaps[0] > gaps[1] > gaps[2]
    assert gaps[2] < 1e-4 * plane


def _symmetric_navi_trial(offset: float, **kw) -> dict:
    """The Navi made mirror-symmetric about its x-z plane (rotors, bumpers, inertia, IMU)."""
    x, y, z = 0.1265, 0.1265, -0.02455
    bx, by, bz = 0.1356, 0.1356, -0.02755
    return {
        "kind": "impact-trial",
        "vehicle": "navi",
        "vehicle_overrides": {
            "rotor_positions_m": [[x, y, z], [-x, y, z], [-x, -y, z], [x, -y, z]],
            "bumper_centres_m": [[bx, by, bz], [-bx, by, bz], [-bx, -by, bz], [bx, -by, bz]],
            "inertia_kg_m2": [[0.0112, 0, 0], [0, 0.0113, 0], [0, 0, 0.0211]],
            "imu_position_m": [0.0, 0.0, 0.0],
        },
        "obstacles": [POLE.model_dump()],
        "start_distance_m": 0.3,
        "altitude_m": 2.0,
        "speed_m_s": 2.0,
        "pitch_deg": -20.0,
        "lateral_offset_m": offset,
        "controller": "paper",
        "final_time_s": 0.6,
        **kw,
    }


def test_a_head_on_pole_hit_has_no_sideways_force_and_no_yaw():
    result = simulate(scenario_from_dict(_symmetric_navi_trial(0.0)))
    assert result.summary["first_contact_s"] is not None
    lateral = _columns(result, ["y_m", "vy_m_s", "roll_deg", "yaw_deg", "p_rad_s", "r_rad_s"])
    assert np.abs(lateral).max() < 1e-9
    # the leading bumpers 1 and 4 touch together, with the same peaks
    eps = result.episodes
    first = eps[eps["t_start_s"] == eps["t_start_s"].min()]
    assert sorted(first["bumper"]) == [1, 4]
    assert first["peak_delta_m"].iloc[0] == pytest.approx(first["peak_delta_m"].iloc[1], rel=1e-9)


@pytest.mark.parametrize("controller", ["paper", "recovery"])
def test_offsets_plus_and_minus_y_give_mirrored_runs(controller):
    extra = {"pre_impact": "nominal"} if controller == "recovery" else {}
    runs = [
        simulate(scenario_from_dict(_symmetric_navi_trial(o, controller=controller, **extra)))
        for o in (0.08, -0.08)
    ]
    # to the rounding of the step-size control, which sees mirrored numbers: 1e-6 m and
    # deg, 1e-5 rad/s
    same = ["t_s", "x_m", "z_m", "pitch_deg", "altitude_m"]
    flipped = ["y_m", "vy_m_s", "roll_deg", "yaw_deg"]
    np.testing.assert_allclose(_columns(runs[1], same), _columns(runs[0], same), atol=1e-6)
    np.testing.assert_allclose(_columns(runs[1], flipped), -_columns(runs[0], flipped), atol=1e-6)
    rates = ["q_rad_s"], ["p_rad_s", "r_rad_s"]
    np.testing.assert_allclose(_columns(runs[1], rates[0]), _columns(runs[0], rates[0]), atol=1e-5)
    np.testing.assert_allclose(_columns(runs[1], rates[1]), -_columns(runs[0], rates[1]), atol=1e-5)
    # bumper 1 (starboard) on one side is bumper 4 (port) on the other
    a = runs[0].episodes.sort_values("t_start_s").reset_index(drop=True)
    b = runs[1].episodes.sort_values("t_start_s").reset_index(drop=True)
    mirror = {1: 4, 4: 1, 2: 3, 3: 2}
    assert [mirror[j] for j in a["bumper"]] == list(b["bumper"])


def _energy(x: np.ndarray, veh: np.ndarray) -> float:
    m = veh[VS.V_MASS]
    inertia = veh[VS.V_INERTIA : VS.V_INERTIA + 9].reshape(3, 3)
    v = x[L.X_VEL : L.X_VEL + 3]
    w = x[L.X_OMEGA : L.X_OMEGA + 3]
    return 0.5 * m * v @ v + 0.5 * w @ inertia @ w - m * veh[VS.V_GRAVITY] * x[L.X_POS + 2]


def _elastic_run(obstacle, position, velocity, euler=(0.0, 0.0, 0.0)):
    """No thrust, e = 1, no friction: a rigid body bouncing off ``obstacle`` under gravity."""
    scenario = FlightScenario(
        vehicle="navi",
        position_m=position,
        velocity_m_s=velocity,
        euler_deg=euler,
        angular_velocity_rad_s=(0.3, -0.2, 0.5),
        obstacles=(obstacle,),
        ground="none",
        final_time_s=0.6,
        rtol=1e-11,
        atol=1e-13,
    )
    setup = prepare(scenario)
    feat = setup.feat.copy()
    feat[:, FS.F_E] = 1.0
    feat[:, FS.F_MU] = 0.0
    ctrl = np.zeros(CTL.NCTRL)
    ctrl[CTL.C_KIND] = L.CTRL_NONE
    x0 = setup.x0.copy()
    x0[L.X_ROTOR : L.X_ROTOR + 4] = 0.0
    m = setup.model(x0=x0, feat=feat, ctrl=ctrl, scfg=np.zeros(IMS.NSCFG))
    o = new_output(m, 0, 64)
    BUILTIN.run(m, o)
    n_out = int(o.stats[L.ST_N_OUT])
    states = o.out[:n_out, OUT_X : OUT_X + L.NX]
    episodes = o.episodes[: int(o.stats[L.ST_N_EPISODES])]
    return setup, states, episodes, o.out[:n_out, OUT_T]


@pytest.mark.parametrize(
    "where",
    ["pole", "box edge"],
)
def test_an_elastic_contact_conserves_energy(where):
    if where == "pole":
        obstacle, pos, vel = POLE, (-0.40, 0.03, -2.0), (2.0, 0.0, 0.0)
    else:  # a vertical edge of a box turned 45 deg, toward the vehicle
        obstacle = Box(
            name="box", centre_m=(0.2, 0.0, -2.0), half_extents_m=(0.2, 0.2, 1.0),
            euler_deg=(0.0, 0.0, 45.0),
        )  # fmt: skip
        pos, vel = (-0.5, 0.02, -2.0), (2.0, 0.0, 0.0)
    setup, states, episodes, t = _elastic_run(obstacle, pos, vel)
    assert len(episodes) >= 1 and not episodes[:, E_OPEN].any()
    energy = np.array([_energy(x, setup.veh) for x in states])
    after = t > episodes[:, E_T_END].max() + 1e-3
    assert after.any()
    e0 = energy[0]
    assert np.abs(energy[after] - e0).max() < 1e-7 * e0


def _restitution_1dof(k: float, n: float, e: float, m: float, v_in: float) -> float:
    lam = 6.0 * (1.0 - e) * k / (((2.0 * e - 1.0) ** 2 + 3.0) * v_in)

    def rhs(_t, y):
        delta, rate = y
        f = max(0.0, k * max(delta, 0.0) ** n * (1.0 + lam / k * rate))
        return [rate, -f / m]

    def leave(_t, y):
        return y[0]

    leave.terminal, leave.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 10.0), [0.0, v_in], events=leave, rtol=1e-12, atol=1e-14)
    return -sol.y_events[0][0][1] / v_in


def test_a_dropped_sphere_rebounds_with_the_1dof_restitution(tmp_path):
    from quadimpact.inputs.scenarios import load_scenario_file

    caged = tmp_path / "ball.toml"
    text = (EXAMPLES / "vehicles" / "navi_cage.toml").read_text()
    caged.write_text(text.replace("restitution = 0.6", "restitution = 0.75"))
    scenario = FlightScenario(
        vehicle=str(caged),
        position_m=(0.0, 0.0, -0.5),
        velocity_m_s=(0.0, 0.0, 1.0),
        obstacles=(load_scenario_file(EXAMPLES / "landing.toml").obstacles[0],),
        ground="none",
        final_time_s=0.4,
        rtol=1e-11,
        atol=1e-13,
    )
    setup = prepare(scenario)
    veh = setup.veh.copy()
    veh[VS.V_GRAVITY] = 0.0  # the 1-DOF law alone
    ctrl = np.zeros(CTL.NCTRL)
    ctrl[CTL.C_KIND] = L.CTRL_NONE
    x0 = setup.x0.copy()
    x0[L.X_ROTOR : L.X_ROTOR + 4] = 0.0
    m = setup.model(x0=x0, veh=veh, ctrl=ctrl, scfg=np.zeros(IMS.NSCFG))
    o = new_output(m, 0, 16)
    BUILTIN.run(m, o)
    assert int(o.stats[L.ST_N_EPISODES]) == 1
    ep = o.episodes[0]
    assert ep[E_T_START] == pytest.approx((0.5 - 0.33) / 1.0, abs=1e-9)
    x_end = o.out[int(o.stats[L.ST_N_OUT]) - 1, OUT_X : OUT_X + L.NX]
    f = setup.feat[0]
    expected = _restitution_1dof(f[FS.F_K], f[FS.F_N], f[FS.F_E], veh[VS.V_MASS], 1.0)
    assert -x_end[L.X_VEL + 2] == pytest.approx(expected, rel=1e-6)
    assert np.abs(x_end[L.X_OMEGA : L.X_OMEGA + 3]).max() < 1e-12
    assert not math.isnan(expected)
