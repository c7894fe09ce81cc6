"""The impact trial: its initial state, hand-checked contact and detection, separate outcomes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadimpact import ImpactTrial, load_scenario_file, simulate
from quadimpact.core import feature_slots as FS
from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP
from quadimpact.inputs.vehicle import load_vehicle
from quadimpact.packing.vehicle_block import allocation_matrix
from quadimpact.rotations import quat_to_matrix
from quadimpact.simulation.setup import prepare


@pytest.mark.parametrize(("roll", "pitch", "yaw"), [(0, 0, 0), (5, -30, 20), (-15, 45, -45)])
@pytest.mark.parametrize("model", ["default", "recovery-replica"])
def test_initial_state(roll, pitch, yaw, model):
    s = ImpactTrial(roll_deg=roll, pitch_deg=pitch, yaw_deg=yaw, speed_m_s=1.2, model=model)
    setup = prepare(s)
    x = setup.x0
    v = load_vehicle("navi")
    phi, theta = math.radians(roll), math.radians(pitch)
    # rotor speeds: the allocation of m g cos(phi) cos(theta) with zero torques
    A = allocation_matrix(v, setup.options.yaw_reaction == "paper")
    w2 = x[L.X_ROTOR : L.X_ROTOR + 4] ** 2
    thrust = v.mass_kg * 9.81 * math.cos(phi) * math.cos(theta)
    np.testing.assert_allclose(A @ w2, [thrust, 0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(x[L.X_POS : L.X_POS + 3], (-0.32, 0.0, -5.0))
    vel = quat_to_matrix(x[L.X_QUAT : L.X_QUAT + 4]) @ x[L.X_VEL : L.X_VEL + 3]
    np.testing.assert_allclose(vel, (1.2, 0.0, 0.0), atol=1e-15)
    np.testing.assert_array_equal(x[L.X_OMEGA : L.X_OMEGA + 3], 0.0)
    # the wall X = 0, normal -X, no ground; the vehicle's slew limit; friction 0.3; 3 s
    wall = setup.shapes[:, SHP.SH_POINT : SHP.SH_NORMAL + 3]
    np.testing.assert_array_equal(wall, [[0, 0, 0, -1, 0, 0]])
    assert setup.opts[L.O_CRASH_RULE] == L.CRASH_NONE
    assert setup.opts[L.O_SLEW_MAX] == pytest.approx(70_000 * math.pi / 30)
    np.testing.assert_array_equal(setup.feat[:, FS.F_MU], [0.3] * len(setup.feature_names))
    assert setup.tf == 3.0
    assert s.resolved_pre_impact() == "spin-down"


def _leading_gap(v) -> float:
    """Distance (m) from the CM to the front of the bumpers of a level vehicle, along +X."""
    centres, _u, n = v.bumper_frames()
    return float(np.max(centres[:, 0] + v.bumper_radius_m * np.sqrt(1 - n[:, 0] ** 2)))


@pytest.mark.parametrize("speed", [0.5, 1.0, 2.5])
def test_level_trial_by_hand(speed):
    """Level, yaw 0, rotors held at trim: no force and no rotation before the contact, so the
    rim reaches X = 0 at gap / V exactly; with the spin-down, within a millisecond."""
    t_contact = (0.32 - _leading_gap(load_vehicle("navi"))) / speed
    held = simulate(ImpactTrial(speed_m_s=speed, pre_impact="hold")).summary
    assert held["first_contact_s"] == pytest.approx(t_contact, abs=1e-9)
    r = simulate(ImpactTrial(speed_m_s=speed))
    s = r.summary
    assert s["first_contact_s"] == pytest.approx(t_contact, abs=1e-3)
    t_contact = s["first_contact_s"]
    assert r.summary["leading_bumpers"] == [1, 4]
    # detection: the first IMU sample (a control tick) at or over 0.5 g, after the contact
    imu = r.imu
    over = imu["f_horizontal_m_s2"].to_numpy() >= 0.5 * 9.81
    first = int(np.argmax(over))
    assert over.any() and s["t_detect_s"] == imu["t_s"].iloc[first]
    assert not over[:first].any() and s["t_detect_s"] >= t_contact
    assert s["t_detect_s"] == pytest.approx(round(s["t_detect_s"] / 0.005) * 0.005, abs=1e-12)
    assert s["detection_latency_s"] == pytest.approx(s["t_detect_s"] - t_contact, abs=1e-9)
    assert s["normal_error_deg"] < 30.0
    # stage entries are control ticks, in order, and the time series' stage column agrees
    ts = r.timeseries
    assert s["t_stage1_s"] == s["t_detect_s"]  # 200 Hz IMU: detection at a tick, law at once
    for k in (1, 2, 3, 4):
        tk = s[f"t_stage{k}_s"]
        assert tk is not None
        after = ts[ts["t_s"] > tk + 1e-9]["stage"].iloc[0]
        before = ts[ts["t_s"] <= tk + 1e-9]["stage"].iloc[-1]
        assert after >= k and before < k  # the stage in force after the tick of entry
    assert s["recovered"] and not s["not_detected"] and not s["false_detection"]
    assert s["time_to_recover_s"] == pytest.approx(s["t_stage4_s"] - s["t_detect_s"])


def test_recovered_and_not_detected_are_separate():
    undetected = simulate(ImpactTrial(speed_m_s=1.0, detection={"enabled": False})).summary
    assert undetected["first_contact_s"] is not None
    assert undetected["not_detected"] and not undetected["detected"]
    assert not undetected["recovered"] and undetected["t_stage1_s"] is None
    nothing = simulate(ImpactTrial(speed_m_s=0.5, start_distance_m=5.0, final_time_s=1.0)).summary
    assert nothing["first_contact_s"] is None
    assert not nothing["not_detected"] and not nothing["detected"] and not nothing["recovered"]
    assert simulate(ImpactTrial(speed_m_s=1.0)).summary["recovered"]


def test_seeds_make_the_noise():
    def imu(seed):
        return simulate(ImpactTrial(speed_m_s=1.0, imu="noisy", seed=seed)).imu

    a, b, c = imu(1), imu(1), imu(2)
    assert a.equals(b)
    assert not np.allclose(a["fx_m_s2"], c["fx_m_s2"])
    ideal = simulate(ImpactTrial(speed_m_s=1.0, seed=1)).imu
    assert ideal["fx_m_s2"].equals(ideal["fx_true_m_s2"])  # the ideal IMU draws nothing


def test_scenario_file(tmp_path):
    path = tmp_path / "trial.toml"
    path.write_text(
        'kind = "impact-trial"\nvehicle = "navi"\nroll_deg = 5\npitch_deg = -30\nyaw_deg = 20\n'
        'speed_m_s = 1.5\nmodel = "recovery-replica"\npre_impact = "hold"\nseed = 3\n'
        '[imu]\npreset = "noisy"\nrate_hz = 1000\n'
    )
    s = load_scenario_file(path)
    assert isinstance(s, ImpactTrial) and s.imu.rate_hz == 1000 and s.seed == 3
    assert s.resolved_pre_impact() == "spin-down"  # the replica forces it
    assert s.start_distance_m == 0.32 and s.altitude_m == 5 and s.friction_coefficient == 0.3
