"""The authors' 2016 estimator study's parts in simulations (docs/ESTIMATION.md 8).

The waypoint flight, the end after recovery, observers out of the loop, the
impact noise that replaces the nominal noise, the magnetometer's bias, and
quadimpact's EKF through the replica's impacts with its dip-72 magnetometer.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from quadimpact import simulate
from quadimpact.inputs.scenarios import FlightScenario, ImpactTrial, scenario_from_dict
from quadimpact.studies.estimators.estimator_study import EstimatorStudy

TRIAL = {"roll_deg": 8.0, "pitch_deg": -25.0, "yaw_deg": 10.0, "speed_m_s": 1.6, "seed": 11}


def _qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    a0, av, b0, bv = a[0], a[1:], b[0], b[1:]
    return np.r_[a0 * b0 - av @ bv, a0 * bv + b0 * av + np.cross(av, bv)]


def test_the_waypoint_flight_holds_then_flies_to_the_waypoint():
    """Hover at the start until time_s, then to the waypoint 3 m ahead at 30 deg of
    heading; altitude held, tilt within its limit, and the speed limit kept."""
    s = FlightScenario(
        controller="cascade-pid", vehicle="navi", position_m=(0.0, 0.0, -5.0),
        euler_deg=(0.0, 0.0, 30.0), ground="none", final_time_s=12.0, output_rate_hz=100.0,
        waypoint={"x_m": 3.0, "y_m": 0.0, "time_s": 2.0, "tilt_max_deg": 25.0},
    )  # fmt: skip
    ts = simulate(s).timeseries
    hover = ts[ts["t_s"] <= 2.0]
    assert hover["x_m"].abs().max() < 1e-6 and hover["y_m"].abs().max() < 1e-6
    end = ts.iloc[-1]
    assert math.hypot(end["x_m"] - 3.0, end["y_m"]) < 0.05
    assert (ts["altitude_m"] - 5.0).abs().max() < 0.15
    tilt = np.degrees(
        np.arccos(np.cos(np.radians(ts["roll_deg"])) * np.cos(np.radians(ts["pitch_deg"])))
    )
    assert tilt.max() < 25.0 + 3.0  # the attitude loop's overshoot on the tilt limit
    speed = np.hypot(np.gradient(ts["x_m"], ts["t_s"]), np.gradient(ts["y_m"], ts["t_s"]))
    assert speed.max() < 2.5 * 1.1
    assert abs(ts["yaw_deg"] - 30.0).max() < 2.0


def test_a_waypoint_needs_the_cascade_pid_position_loop():
    with pytest.raises(ValueError, match="waypoint: needs controller"):
        FlightScenario(controller="paper", waypoint={"x_m": 1.0})


def test_the_run_ends_after_recovery():
    s = simulate(ImpactTrial(**TRIAL, final_time_s=10.0, end_after_recovery_s=1.5)).summary
    assert s["recovered"]
    full = simulate(ImpactTrial(**TRIAL, final_time_s=10.0)).summary
    assert s["t_stage4_s"] == full["t_stage4_s"]
    assert s["t_final_s"] == pytest.approx(s["t_stage4_s"] + 1.5, abs=1e-9)
    assert full["t_final_s"] == pytest.approx(10.0)


def test_an_observer_leaves_the_loop_as_the_ideal_estimator_has_it():
    """Out of the loop the controller and the detector read the truth: the trajectory is
    the ideal estimator's bit for bit, while the estimate is computed and scored."""
    base = dict(TRIAL, sensors="authors-2016")
    ideal = simulate(ImpactTrial(**base))
    obs = simulate(ImpactTrial(**base, estimator="ekf", estimate_in_loop=False))
    pd.testing.assert_frame_equal(ideal.timeseries, obs.timeseries)
    assert obs.summary["est_attitude_rms_crash_deg"] > 0.01
    inloop = simulate(ImpactTrial(**base, estimator="ekf"))
    assert not inloop.timeseries.equals(ideal.timeseries)


def test_the_replacing_impact_noise_restarts_at_each_onset():
    """An ideal IMU with the disturbance replacing its nominal noise (1 m/s^2, 0.1 rad/s
    here): after each onset the deviation over ``max(sigma, a0 exp(-(t - t_c)/tau))``
    (the latest onset ``t_c``) is standard normal, where the disturbance dominates and
    where it has decayed below the nominal noise."""
    tau, a0, g0, sf, sw = 0.2, 14.0, 0.1, 1.0, 0.02
    imu = {"accel_noise_m_s2": sf, "gyro_noise_rad_s": sw,
           "impact_disturbance": {"time_constant_s": tau, "mode": "replace"}}  # fmt: skip
    r = simulate(ImpactTrial(**TRIAL, imu=imu))
    data, onsets = r.imu, np.sort(r.episodes["t_start_s"].to_numpy())
    t = data["t_s"].to_numpy()
    latest = np.array([onsets[onsets <= ti].max() if (onsets <= ti).any() else np.nan for ti in t])
    decay = np.where(np.isfinite(latest), np.exp(-(t - np.nan_to_num(latest)) / tau), 0.0)
    for axis, amp, sigma in (("fx_m_s2", a0, sf), ("fz_m_s2", a0, sf), ("q_rad_s", g0, sw)):
        true = axis.replace("_m_s2", "_true_m_s2").replace("_rad_s", "_true_rad_s")
        dev = (data[axis] - data[true]).to_numpy()
        std = np.maximum(sigma, amp * decay)
        for part in (decay * amp > 2 * sigma, decay * amp < 0.5 * sigma):
            z = dev[part] / std[part]
            assert part.sum() > 20 and abs(z.mean()) < 0.25 and 0.8 < z.std() < 1.2, axis


def test_the_magnetometer_bias_is_drawn_per_run():
    mag = {"dip_deg": 71.9, "norm": 0.99, "noise": 0.0, "bias": 1e-3}
    runs = [simulate(FlightScenario(magnetometer=mag, final_time_s=0.1, seed=k)) for k in (1, 2)]
    field = 0.99 * np.array([math.cos(math.radians(71.9)), 0.0, math.sin(math.radians(71.9))])
    biases = []
    for r in runs:
        m = r.imu[["mx", "my", "mz"]].to_numpy()
        assert np.ptp(m, axis=0).max() < 1e-12  # level hover, no noise: a constant reading
        biases.append(m[0] - field)
    assert 1e-5 < np.abs(biases[0]).max() < 5e-3
    assert not np.allclose(biases[0], biases[1])
    again = simulate(FlightScenario(magnetometer=mag, final_time_s=0.1, seed=1))
    np.testing.assert_array_equal(again.imu[["mx", "my", "mz"]].to_numpy()[0] - field, biases[0])


def test_the_authors_initial_error_is_in_euler_angles_with_a_zero_bias_estimate():
    params = {"initial_euler_error_deg": [2.0, 2.0, 5.0], "initial_bias": "zero"}
    errs, biases = [], []
    for seed in range(40):
        s = ImpactTrial(**{**TRIAL, "seed": seed}, sensors="authors-2016", estimator="ekf",
                        estimator_params=params, final_time_s=0.01)  # fmt: skip
        imu = simulate(s).imu
        errs.append(imu["attitude_error_deg"].iloc[0])
        hat = imu[["bias_p_hat_rad_s", "bias_q_hat_rad_s", "bias_r_hat_rad_s"]].iloc[0]
        true = imu[["bias_p_true_rad_s", "bias_q_true_rad_s", "bias_r_true_rad_s"]].iloc[0]
        biases.append((hat.abs().max(), true.abs().max()))
    # the bias estimate starts from 0 (one update away from it), not from the truth
    hat, true = np.array(biases).T
    assert hat.max() < 2e-3 and np.median(true) > 5e-3
    # the error angle of ZYX errors N(0, (2, 2, 5) deg): RMS sqrt(4 + 4 + 25) deg
    assert np.sqrt(np.mean(np.square(errs))) == pytest.approx(math.sqrt(33.0), rel=0.25)


def test_ekf_through_the_replica_impacts_with_a_dip_72_magnetometer():
    """quadimpact's EKF as an observer in the authors' study. Unaware of the impact's gyro
    noise (``impact_noise = "none"``) it explains the attitude increments that its precise
    magnetometer sees as a gyro bias; the bias error's part along the field, which the
    magnetometer cannot see, turns the estimate about the field's axis, and only the
    de-weighted accelerometer can undo that: a lasting error after stage 4, about that
    axis. With the disturbance in its noise (the default) the error stays small."""
    study = EstimatorStudy(scenario="authors-2016", n=12)
    field = np.array([math.cos(math.radians(71.9)), 0.0, math.sin(math.radians(71.9))])
    post = {}
    for mode in ("none", "sensor"):
        post[mode] = []
        for i in range(12):
            d = {**study.scenario_dict(i), "estimator": "ekf",
                 "estimator_params": {"impact_noise": mode}}  # fmt: skip
            r = simulate(scenario_from_dict(d))
            post[mode].append(r.summary["est_attitude_rms_post_deg"])
            if mode == "none" and post[mode][-1] > 3.0:
                imu, ts = r.imu.iloc[-1], r.timeseries.iloc[-1]
                q_hat = imu[["q0_hat", "q1_hat", "q2_hat", "q3_hat"]].to_numpy(float)
                q = ts[["q0", "q1", "q2", "q3"]].to_numpy(float)
                e = _qmul(q_hat, np.r_[q[0], -q[1:]])
                phi = 2.0 * np.sign(e[0]) * e[1:]
                assert abs(phi @ field) / np.linalg.norm(phi) > 0.95
    assert np.mean(post["none"]) > 2.5, post["none"]
    assert np.mean(post["sensor"]) < 1.0 and max(post["sensor"]) < 1.5, post["sensor"]
