"""Sensor components (``core/sensors/registry.py``), with the barometer as the example.

The barometer is one module and one registry line: these tests fly it from a
scenario (a dict and a file), read its record columns and sweep it, and
check its measurement against the true altitude by its noise model.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadimpact import simulate
from quadimpact.core.sensors import measurement_slots as MSS
from quadimpact.core.sensors import registry
from quadimpact.core.sensors.barometer import SENSOR
from quadimpact.errors import InputError
from quadimpact.inputs.scenarios import load_scenario_file, scenario_from_dict
from quadimpact.inputs.toml_files import apply_overrides

HOVER = {
    "kind": "flight",
    "final_time_s": 2.0,
    "controller": "cascade-pid",
    "imu": {"preset": "ideal", "rate_hz": 200},
}


def _run(**fields):
    return simulate(scenario_from_dict({**HOVER, **fields}))


def _baro(result):
    imu = result.imu
    rows = imu["barometer_altitude_m"].notna()
    return (
        imu["t_s"][rows].to_numpy(),
        imu["barometer_altitude_m"][rows].to_numpy(),
        imu["barometer_altitude_true_m"][rows].to_numpy(),
    )


def test_addresses_follow_declared_sizes():
    # MJX's sensor_adr from sensor_dim: each block starts where the one before ends
    where = registry.addresses()
    at = [0, 0, 0, 0, 0]
    for c in registry.components():
        a = where[c.name]
        spans = (a.config, a.state, a.measurement, a.noise, a.record)
        for k, (lo, hi) in enumerate(spans):
            if k == 3 and c.legacy_noise is not None:  # columns of snoise, not of cnoise
                assert (lo, hi) == (
                    c.legacy_noise.start,
                    c.legacy_noise.start + c.legacy_noise.width,
                )
                continue
            assert lo == at[k] and hi - lo == c.sizes()[k]
            at[k] = hi
    assert tuple(at) == registry.tail_sizes()
    assert (
        registry.measurement_address("barometer", "altitude_m")
        == MSS.NMEAS + where["barometer"].measurement[0]
    )


def test_noise_free_barometer_reads_the_true_altitude_at_its_rate():
    r = _run(instruments={"barometer": {"noise_m": 0.0, "bias_walk_m_sqrt_s": 0.0}})
    t, y, h = _baro(r)
    assert np.array_equal(y, h)  # no noise, no offset: the altitude itself
    # 50 Hz on a 200-Hz IMU: every fourth sample, from t0 to the end
    assert len(t) == int(2.0 * 50) + 1
    assert np.allclose(np.diff(t), 0.02, atol=1e-12)
    assert abs(h[0] - 2.0) < 1e-12  # the start altitude


def test_offset_is_a_constant_bias():
    r = _run(
        instruments={"barometer": {"noise_m": 0.0, "bias_walk_m_sqrt_s": 0.0, "offset_m": 1.5}}
    )
    _, y, h = _baro(r)
    assert np.allclose(y - h, 1.5, rtol=0, atol=1e-12)


def test_noise_statistics_match_the_model():
    # white noise alone: the errors are N(0, sigma^2); 101 samples per run, 4 seeds
    sigma = 0.3
    errors = []
    for seed in range(4):
        r = _run(
            seed=seed, instruments={"barometer": {"noise_m": sigma, "bias_walk_m_sqrt_s": 0.0}}
        )
        _, y, h = _baro(r)
        errors.append(y - h)
    e = np.concatenate(errors)
    n = e.size
    assert abs(e.mean()) < 4 * sigma / math.sqrt(n)
    # the sample variance's relative standard error is sqrt(2 / (n - 1))
    assert abs(e.var(ddof=1) / sigma**2 - 1.0) < 4 * math.sqrt(2.0 / (n - 1))


def test_bias_walk_grows_as_the_square_root_of_time():
    # no white noise: the error is the walk, whose variance at t is sigma_b^2 (t - t0)
    sb = 0.5
    finals = []
    for seed in range(40):
        r = _run(
            seed=seed,
            final_time_s=1.0,
            instruments={"barometer": {"noise_m": 0.0, "bias_walk_m_sqrt_s": sb}},
        )
        t, y, h = _baro(r)
        finals.append((y - h)[-1])
    var = np.var(finals, ddof=1)
    expected = sb**2 * 1.0
    assert abs(var / expected - 1.0) < 4 * math.sqrt(2.0 / 39)


def test_draws_are_seeded_and_independent_of_the_other_sensors():
    baro = {"barometer": {"noise_m": 0.2}}
    a = _run(seed=7, instruments=baro)
    b = _run(seed=7, instruments=baro)
    c = _run(seed=8, instruments=baro)
    d = _run(seed=7, instruments=baro, magnetometer={})
    assert np.array_equal(_baro(a)[1], _baro(b)[1])  # bit for bit
    assert not np.array_equal(_baro(a)[1], _baro(c)[1])
    assert np.array_equal(_baro(a)[1], _baro(d)[1])  # a magnetometer leaves it as it was


def test_a_barometer_changes_nothing_else():
    noisy = {"imu": {"preset": "impact", "rate_hz": 200}, "seed": 3, "magnetometer": {}}
    with_baro = _run(**noisy, instruments={"barometer": {}})
    without = _run(**noisy)
    assert "barometer_altitude_m" not in without.imu.columns
    for col in without.imu.columns:
        assert np.array_equal(
            with_baro.imu[col].to_numpy(), without.imu[col].to_numpy(), equal_nan=True
        ), col
    assert np.array_equal(
        with_baro.timeseries.to_numpy(), without.timeseries.to_numpy(), equal_nan=True
    )


def test_flown_from_a_scenario_file(tmp_path):
    path = tmp_path / "baro.toml"
    path.write_text(
        'kind = "flight"\nfinal_time_s = 0.5\ncontroller = "cascade-pid"\n'
        "[instruments.barometer]\nrate_hz = 25\nnoise_m = 0.0\nbias_walk_m_sqrt_s = 0.0\n"
    )
    r = simulate(load_scenario_file(path))
    t, y, h = _baro(r)
    assert len(t) == int(0.5 * 25) + 1 and np.array_equal(y, h)
    assert r.scenario.instruments["barometer"].rate_hz == 25


def test_swept_by_a_dotted_field(tmp_path):
    from quadimpact.sweep.runner import run_sweep

    base = {**HOVER, "final_time_s": 0.3, "instruments": {"barometer": {}}}
    table = run_sweep(
        {"base": base, "grid": {"instruments.barometer.rate_hz": [10, 50]}},
        tmp_path / "sweep",
        workers=1,
    )
    assert list(table["status"]) == ["completed", "completed"]
    assert sorted(table["instruments.barometer.rate_hz"]) == [10, 50]
    merged = apply_overrides(base, {"instruments.barometer.rate_hz": 10})
    assert merged["instruments"]["barometer"]["rate_hz"] == 10
    assert base["instruments"]["barometer"] == {}  # the base is not changed


@pytest.mark.parametrize(
    ("instruments", "fragment"),
    [
        ({"thermometer": {}}, "no such sensor component"),
        ({"barometer": {"rate_hz": -1}}, "rate_hz"),
        ({"barometer": {"noise": 1}}, "noise"),
        ({"barometer": 3}, "must be a table"),
    ],
)
def test_bad_instruments_are_refused_in_one_line(instruments, fragment):
    with pytest.raises((InputError, ValueError)) as err:
        scenario_from_dict({**HOVER, "instruments": instruments})
    assert fragment in str(err.value) and "\n" not in str(err.value)


def test_component_declares_units_for_every_record_column():
    for name, unit in SENSOR.record_columns():
        assert name.startswith("barometer_") and unit == "m"
