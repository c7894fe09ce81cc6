"""The magnetometer and the pose sensor as sensor components (docs/ARCHITECTURE.md 10).

They predate components, so three things stay as they were: their draws are
columns of the frozen ``snoise`` matrix (a legacy stream), their IMU table
columns keep their names (``mx``..., ``pose_x_m``...), and a scenario names
them as ``[magnetometer]`` and ``[pose_sensor]``, not in ``[instruments]``.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from quadimpact import simulate
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.core.sensors import registry
from quadimpact.core.sensors.component import LegacyColumns
from quadimpact.errors import InputError
from quadimpact.inputs.scenarios import FlightScenario, scenario_from_dict
from quadimpact.packing.estimator_block import SENSOR_STREAM
from quadimpact.results.schema import IMU_COLUMNS

IDEAL_200 = {"preset": "ideal", "rate_hz": 200}


def test_their_draws_are_the_frozen_snoise_columns_and_their_columns_keep_their_names():
    mag, pose = registry.component("magnetometer"), registry.component("pose_sensor")
    assert mag.legacy_noise == LegacyColumns(start=IMS.SN_MAG, width=3)
    assert pose.legacy_noise == LegacyColumns(start=IMS.SN_POSE, width=6)
    assert registry.addresses()["pose_sensor"].noise == (IMS.SN_POSE, IMS.SN_POSE + 6)
    # no block of cnoise for them: the components' draws are the others' only
    others = [c for c in registry.components() if c.legacy_noise is None]
    assert registry.tail_sizes()[3] == sum(c.sizes()[3] for c in others)
    names = [n for c in (mag, pose) for n, _ in c.record_columns()]
    assert names == ["mx", "my", "mz", "pose_x_m", "pose_y_m", "pose_z_m"] + [
        f"pose_q{k}" for k in range(4)
    ]
    assert set(names) <= set(IMU_COLUMNS)


def test_the_magnetometer_reads_the_field_plus_sigma_times_its_snoise_columns():
    # level hover with the ideal IMU: a noise-free reading is the field itself, and the
    # noisy one adds sigma times columns 9-11 of the added sensors' stream, row by row
    sigma, dip = 0.01, 60.0
    runs = [
        simulate(FlightScenario(imu=IDEAL_200, magnetometer={"noise": s}, final_time_s=0.2, seed=3))
        .imu[["mx", "my", "mz"]]
        .to_numpy()
        for s in (0.0, sigma)
    ]
    field = np.array([math.cos(math.radians(dip)), 0.0, math.sin(math.radians(dip))])
    np.testing.assert_allclose(runs[0], np.tile(field, (len(runs[0]), 1)), rtol=0, atol=1e-12)
    n = len(runs[1])
    seq = np.random.SeedSequence(3, spawn_key=(SENSOR_STREAM,))
    draws = np.random.Generator(np.random.PCG64(seq)).standard_normal((n, IMS.NSN))
    z = (runs[1] - runs[0]) / sigma
    np.testing.assert_allclose(z, draws[:, IMS.SN_MAG : IMS.SN_MAG + 3], rtol=0, atol=1e-9)


def test_the_pose_sensor_arrives_at_its_rate_after_its_latency():
    # 50 Hz on a 200-Hz IMU, 15 ms late: 3 IMU samples after each of its times
    pose = {"rate_hz": 50, "latency_s": 0.015, "position_noise_m": 0.0, "attitude": False}
    imu = simulate(FlightScenario(imu=IDEAL_200, pose_sensor=pose, final_time_s=0.5)).imu
    t = imu["t_s"][imu["pose_x_m"].notna()].to_numpy()
    assert t[0] == pytest.approx(0.015, abs=1e-12)
    np.testing.assert_allclose(np.diff(t), 0.02, rtol=0, atol=1e-9)
    assert len(t) == 25  # 0.015 + 0.02 k <= 0.5
    # noise-free and level: the start position and the unit quaternion
    rows = imu[imu["pose_x_m"].notna()]
    assert np.ptp(rows["pose_z_m"].to_numpy()) < 1e-9
    assert np.allclose(rows[[f"pose_q{k}" for k in range(4)]].to_numpy(), [1, 0, 0, 0])


def test_without_them_their_columns_are_nan():
    imu = simulate(FlightScenario(imu=IDEAL_200, final_time_s=0.05)).imu
    assert imu[["mx", "pose_x_m", "pose_q3"]].isna().all().all()


def test_instruments_refuses_them_in_one_line_naming_their_table():
    with pytest.raises(InputError, match=r"set it as the scenario's \[magnetometer\] table"):
        scenario_from_dict({"kind": "flight", "instruments": {"magnetometer": {}}})


def test_a_plugin_may_not_declare_a_legacy_stream():
    baro = registry.component("barometer")
    twin = dataclasses.replace(baro, name="baro_twin", legacy_noise=LegacyColumns(0, 2))
    with pytest.raises(ValueError, match="legacy_noise"):
        registry.register_sensor(twin)
    assert "baro_twin" not in [c.name for c in registry.components()]
