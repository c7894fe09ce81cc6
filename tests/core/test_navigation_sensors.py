"""The on-board navigation sensors (sensor components): the rangefinder's slant range and
the optical flow's image rate, against the state they are computed from."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadimpact import simulate
from quadimpact.inputs.scenarios import scenario_from_dict

EXACT_RANGE = {"preset": "lidar", "noise_m": 0.0, "noise_per_m": 0.0}
EXACT_FLOW = {"noise_min_rad_s": 0.0, "noise_max_rad_s": 0.0, "delay_s": 0.0}


def _flight(**fields):
    base = {
        "kind": "flight",
        "final_time_s": 0.5,
        "controller": "cascade-pid",
        "output_rate_hz": 100.0,
        "imu": {"preset": "ideal", "rate_hz": 100.0},
    }
    return simulate(scenario_from_dict({**base, **fields}))


def _at_imu_times(r):
    """The time series and the IMU table joined on their common times (100 Hz both)."""
    ts = r.timeseries.assign(key=np.round(r.timeseries["t_s"], 9))
    imu = r.imu.assign(key=np.round(r.imu["t_s"], 9))
    return ts.merge(imu, on="key", suffixes=("", "_imu"))


@pytest.mark.parametrize("roll_deg", [0.0, 20.0, -35.0])
def test_range_is_height_over_the_cosine_of_the_tilt(roll_deg):
    r = _flight(euler_deg=(roll_deg, 10.0, 30.0), instruments={"rangefinder": EXACT_RANGE})
    j = _at_imu_times(r)
    tilt_cos = np.cos(np.radians(j["roll_deg"])) * np.cos(np.radians(j["pitch_deg"]))
    expected = j["altitude_m"] / tilt_cos
    assert np.allclose(j["rangefinder_range_true_m"], expected, rtol=1e-12, atol=1e-12)
    assert np.array_equal(j["rangefinder_range_m"], j["rangefinder_range_true_m"])


def test_range_is_invalid_beyond_its_tilt_and_window():
    tilted = _flight(euler_deg=(50.0, 0.0, 0.0), final_time_s=0.05,
                     instruments={"rangefinder": EXACT_RANGE})  # fmt: skip
    assert tilted.imu["rangefinder_range_m"].isna().all()
    assert tilted.imu["rangefinder_range_true_m"].notna().any()
    far = _flight(position_m=(0.0, 0.0, -5.0), instruments={"rangefinder": {"preset": "tof"}})
    assert far.imu["rangefinder_range_m"].isna().all()  # 5 m: beyond the ToF's 4 m


def test_range_noise_follows_its_law():
    # the lidar's 0.05 m + 1 % at 2 m: 0.07 m
    errs = []
    for seed in range(3):
        r = _flight(seed=seed, final_time_s=1.0, instruments={"rangefinder": {"preset": "lidar"}})
        imu = r.imu.dropna(subset=["rangefinder_range_m"])
        errs.append(imu["rangefinder_range_m"] - imu["rangefinder_range_true_m"])
    e = np.concatenate(errs)
    sigma = 0.05 + 0.01 * 2.0
    assert abs(e.std(ddof=1) / sigma - 1.0) < 4 / math.sqrt(2 * e.size)


def test_compensated_flow_is_velocity_over_distance():
    r = _flight(
        velocity_m_s=(0.6, -0.4, 0.1),
        euler_deg=(8.0, -5.0, 40.0),
        angular_velocity_rad_s=(0.3, -0.2, 0.1),
        instruments={"optical_flow": EXACT_FLOW},
    )
    j = _at_imu_times(r).dropna(subset=["optical_flow_flow_x_rad_s"])
    assert len(j) > 40
    tilt_cos = np.cos(np.radians(j["roll_deg"])) * np.cos(np.radians(j["pitch_deg"]))
    d = j["altitude_m"] / tilt_cos
    assert np.allclose((j["optical_flow_flow_x_rad_s"] + j["p_rad_s"]) * d, j["v_m_s"], atol=1e-12)
    assert np.allclose((j["optical_flow_flow_y_rad_s"] + j["q_rad_s"]) * d, -j["u_m_s"], atol=1e-12)


def test_flow_is_delivered_after_its_delay():
    args = {"velocity_m_s": (0.5, 0.0, 0.0), "angular_velocity_rad_s": (0.0, 0.5, 0.0)}
    now = _flight(**args, instruments={"optical_flow": EXACT_FLOW})
    late = _flight(**args, instruments={"optical_flow": {**EXACT_FLOW, "delay_s": 0.02}})
    a = now.imu["optical_flow_flow_y_rad_s"].to_numpy()
    b = late.imu["optical_flow_flow_y_rad_s"].to_numpy()
    assert np.isnan(b[:2]).all()  # nothing before the first image's delay
    assert np.array_equal(b[2:], a[:-2])  # two samples of 100 Hz


def test_flow_quality_falls_to_zero_when_tilted():
    r = _flight(euler_deg=(50.0, 0.0, 0.0), final_time_s=0.05,
                instruments={"optical_flow": EXACT_FLOW})  # fmt: skip
    assert (r.imu["optical_flow_quality"].dropna() == 0.0).all()
    assert r.imu["optical_flow_flow_x_rad_s"].isna().all()


def test_flow_noise_grows_as_quality_falls():
    # a fast image (|flow| about 5 rad/s of 7.4): quality about 0.55, noise between the ends
    r = _flight(seed=1, final_time_s=0.3, position_m=(0.0, 0.0, -0.3), velocity_m_s=(1.5, 0.0, 0.0),
                instruments={"optical_flow": {"delay_s": 0.0}})  # fmt: skip
    imu = r.imu.dropna(subset=["optical_flow_flow_x_rad_s"])
    q = imu["optical_flow_quality"].to_numpy()
    assert 0.2 < q.mean() < 0.9
    e = (imu["optical_flow_flow_y_rad_s"] - imu["optical_flow_flow_y_true_rad_s"]).to_numpy()
    sigma = 0.5 - 0.35 * q
    z = e / sigma
    assert abs(z.std(ddof=1) - 1.0) < 4 / math.sqrt(2 * z.size)


def test_onboard_preset_carries_the_navigation_sensors():
    s = scenario_from_dict({"kind": "flight", "sensors": "onboard"})
    assert set(s.instruments) == {"barometer", "rangefinder", "optical_flow"}
    assert s.instruments["rangefinder"].max_m == 12.0  # the lidar
    assert s.magnetometer is not None and s.imu.preset == "impact"
    own = scenario_from_dict(
        {"kind": "flight", "sensors": "onboard", "instruments": {"barometer": {"noise_m": 0.5}}}
    )
    assert set(own.instruments) == {"barometer"}  # a scenario's own table wins, whole
