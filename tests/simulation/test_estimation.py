"""Estimation in the loop (docs/ESTIMATION.md): the sensors, the estimators, stage 5.

The estimators' own checks on synthetic streams are in tests/core/test_estimators.py;
here they run inside simulations: ``ideal`` changes nothing, stage 5 changes nothing
up to stage 4, the added sensors are recorded and drawn from the run's seed, the
controllers read the estimate, and through impacts with the IMU's disturbance the
complementary filter's crash-phase error exceeds the EKF's on the same trials.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from quadimpact import simulate
from quadimpact.inputs.scenarios import FlightScenario, ImpactTrial
from quadimpact.simulation.batch import simulate_batch
from quadimpact.simulation.recovery_metrics import RECOVERY_KEYS
from quadimpact.studies.recovery.recovery_study import sample_trials

TRIAL = {"roll_deg": 8.0, "pitch_deg": -25.0, "yaw_deg": 10.0, "speed_m_s": 1.6, "seed": 11}
UP_TO_STAGE4 = [k for k in RECOVERY_KEYS if k not in (
    "t_stage5_s", "time_to_hover_s", "min_altitude_m", "impacts_after_detection",
    "max_tilt_deg", "max_rate_rad_s", "final_speed_m_s", "held_hover", "time_to_held_hover_s",
    "held_hover_distance_m", "touched_after_hover")]  # fmt: skip


def test_ideal_is_the_default_and_changes_nothing():
    a = simulate(ImpactTrial(**TRIAL, imu="noisy"))
    b = simulate(ImpactTrial(**TRIAL, imu="noisy", estimator="ideal", sensors=None))
    assert a.summary["estimator"] == "ideal" and not a.summary["magnetometer"]
    pd.testing.assert_frame_equal(a.timeseries, b.timeseries)
    pd.testing.assert_frame_equal(a.imu, b.imu)
    # the ideal estimator's estimate is the truth, its rates the gyro as measured
    assert a.summary["est_attitude_max_crash_deg"] < 1e-9  # rounding only
    assert a.summary["est_velocity_max_post_m_s"] == 0.0


def test_stage5_changes_nothing_up_to_stage4():
    """Stage 5 starts the tick after stage 4's entry; everything before is bit for bit the
    run without it (and recovered trials no longer drift away)."""
    on = simulate(ImpactTrial(**TRIAL))
    off = simulate(ImpactTrial(**TRIAL, controller_params={"hover": False}))
    s_on, s_off = on.summary, off.summary
    assert s_off["recovered"] and s_off["t_stage5_s"] is None
    assert {k: s_on[k] for k in UP_TO_STAGE4} == {k: s_off[k] for k in UP_TO_STAGE4}
    assert s_on["t_stage5_s"] == pytest.approx(s_on["t_stage4_s"] + 0.005, abs=1e-12)
    t4 = s_on["t_stage4_s"]
    before_on = on.timeseries[on.timeseries["t_s"] <= t4 + 0.005]
    before_off = off.timeseries[off.timeseries["t_s"] <= t4 + 0.005]
    pd.testing.assert_frame_equal(before_on, before_off)
    # the default holds where the vehicle stops: it reaches hover
    assert s_on["time_to_hover_s"] is not None and s_on["final_speed_m_s"] < 0.2
    entry = simulate(ImpactTrial(**TRIAL, controller_params={"hover_hold": "entry"})).summary
    assert entry["final_speed_m_s"] < 0.5 * s_off["final_speed_m_s"]
    assert {k: entry[k] for k in UP_TO_STAGE4} == {k: s_off[k] for k in UP_TO_STAGE4}


def test_the_impact_disturbance_rings_after_each_onset():
    """An ideal IMU with the disturbance alone: exact before the first contact; after it,
    the deviation divided by ``a0 sqrt(sum over onsets of exp(-2 (t - t_c) / tau))`` is
    standard normal (accelerometer and gyro alike)."""
    tau, a0, g0 = 0.2, 14.0, 0.1
    r = simulate(ImpactTrial(**TRIAL, imu={"impact_disturbance": {"time_constant_s": tau}}))
    imu, onsets = r.imu, np.sort(r.episodes["t_start_s"].to_numpy())
    assert r.summary["impact_disturbance"] and len(onsets) >= 1
    t = imu["t_s"].to_numpy()
    factor = np.sqrt(np.array([np.exp(-2 * (ti - onsets[onsets < ti]) / tau).sum() for ti in t]))
    assert (factor[t <= onsets[0]] == 0.0).all()
    ring = factor > 0.05
    for axis, amp in (("fx_m_s2", a0), ("fy_m_s2", a0), ("p_rad_s", g0), ("r_rad_s", g0)):
        true = axis.replace("_m_s2", "_true_m_s2").replace("_rad_s", "_true_rad_s")
        dev = (imu[axis] - imu[true]).to_numpy()
        assert (dev[t <= onsets[0]] == 0.0).all()
        z = dev[ring] / (amp * factor[ring])
        assert abs(z.mean()) < 0.2 and 0.85 < z.std() < 1.15, axis


def test_added_sensors_are_recorded_and_leave_the_imu_draws_alone():
    base = simulate(ImpactTrial(**TRIAL, imu="noisy", final_time_s=1.0))
    r = simulate(ImpactTrial(**TRIAL, sensors="indoor", final_time_s=1.0,
                             pose_sensor={"latency_s": 0.01}))  # fmt: skip
    s = r.summary
    assert s["sensors"] == "indoor" and s["magnetometer"] and s["pose_sensor"]
    assert s["impact_disturbance"]
    imu = r.imu
    onset = s["first_contact_s"]
    before = imu["t_s"] <= onset
    # the IMU's own noise and bias are the same draws (the added sensors use another stream)
    for c in ("fx_m_s2", "fy_m_s2", "fz_m_s2"):
        np.testing.assert_array_equal(imu[c][before], base.imu[c][before])
    # the bias walks
    assert imu["bias_r_true_rad_s"].std() > 0.0
    # magnetometer: the unit field, with noise
    norm = np.linalg.norm(imu[["mx", "my", "mz"]].to_numpy(), axis=1)
    assert abs(norm.mean() - 1.0) < 0.01
    # pose: every other sample (100 Hz), 2 samples late (10 ms at 200 Hz)
    got = imu["pose_x_m"].notna().to_numpy()
    assert not got[:2].any() and got[2:12].tolist() == [True, False] * 5
    ts = r.timeseries.set_index("t_s")
    t_meas = imu["t_s"][got].to_numpy()[3]
    x_then = ts["x_m"].loc[round(t_meas - 0.01, 3)]
    assert abs(imu["pose_x_m"][got].to_numpy()[3] - x_then) < 5e-3
    # the same table on any machine: the run again
    again = simulate(ImpactTrial(**TRIAL, sensors="indoor", final_time_s=1.0,
                                 pose_sensor={"latency_s": 0.01}))  # fmt: skip
    pd.testing.assert_frame_equal(r.imu, again.imu)


@pytest.mark.parametrize("estimator", ["complementary", "ekf"])
def test_hover_in_flight_with_the_ideal_imu(estimator):
    """A 10-s hover flown by the cascade PID, the IMU at the CM: the estimate stays
    within 0.01 deg of the truth."""
    r = simulate(FlightScenario(controller="cascade-pid", final_time_s=10.0, estimator=estimator,
                                imu={"position": "cm"}, magnetometer={"noise": 0.0}))  # fmt: skip
    assert r.summary["est_attitude_max_pre_deg"] < 0.01


def test_the_controllers_read_the_estimate():
    """An initial attitude error of the estimate flies the vehicle off by that error: the
    controller holds the estimate level, not the truth."""
    kw = {"controller": "cascade-pid", "final_time_s": 0.5, "imu": {"position": "cm"}}
    truth = simulate(FlightScenario(**kw))
    error = {"initial_attitude_error_deg": 3.0}
    off = simulate(FlightScenario(**kw, estimator="complementary", seed=4, estimator_params=error))
    tilt = {}
    for name, r in (("truth", truth), ("off", off)):
        last = r.timeseries.iloc[-1]
        tilt[name] = math.degrees(math.acos(1.0 - 2.0 * (last["q1"] ** 2 + last["q2"] ** 2)))
    err = off.imu["attitude_error_deg"].iloc[-1]
    assert tilt["truth"] < 0.01 and err > 1.0
    assert tilt["off"] > 1.0  # the true vehicle tilts by (the roll-pitch part of) the error


def test_complementary_crash_error_exceeds_the_ekf_with_the_impact_disturbance():
    trials = sample_trials(40, 7)
    crash = {}
    for est in ("complementary", "ekf"):
        s = pd.DataFrame(simulate_batch(
            [ImpactTrial(**t, estimator=est, sensors="impact") for t in trials]))  # fmt: skip
        crash[est] = s["est_attitude_rms_crash_deg"].to_numpy(dtype=float)
    both = np.isfinite(crash["complementary"]) & np.isfinite(crash["ekf"])
    assert both.sum() >= 35
    assert np.mean(crash["complementary"][both]) > np.mean(crash["ekf"][both])
    assert np.median(crash["complementary"][both]) > np.median(crash["ekf"][both])
