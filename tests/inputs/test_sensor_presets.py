"""A plug-in's preset of sensors is named like a built-in one: by a scenario, by
``quadimpact run``, ``recovery`` and ``pole`` (``--plugin FILE --sensors NAME``) and by the
benchmark as a sensor set of its own, never cached; bad presets fail in one line."""

from __future__ import annotations

import json
import textwrap

import numpy as np
import pandas as pd
import pytest

from quadimpact import simulate
from quadimpact.errors import InputError
from quadimpact.inputs import plugins
from quadimpact.inputs.scenarios import scenario_from_dict
from quadimpact.inputs.sensors import (
    BUILTIN_SENSOR_PRESETS,
    SENSOR_PRESETS,
    register_sensor_preset,
)

from helpers import cli_here

# a preset of the impact IMU and a coarse barometer (a built-in component): no new kernel
BARO = {"imu": "impact", "instruments": {"barometer": {"noise_m": 0.5, "rate_hz": 50}}}
PLUGIN = textwrap.dedent(
    """
    from quadimpact.inputs.sensors import register_sensor_preset

    register_sensor_preset(
        "test-baro",
        {"imu": "impact", "instruments": {"barometer": {"noise_m": 0.5, "rate_hz": 50}}},
    )
    """
)


@pytest.fixture
def preset(monkeypatch):
    """``test-baro`` registered for the test (and removed after it)."""
    monkeypatch.setitem(SENSOR_PRESETS, "test-baro", dict(BARO))
    return "test-baro"


@pytest.fixture
def plugin_file(tmp_path, monkeypatch):
    """A plug-in file registering ``test-baro``; this process forgets it afterwards."""
    path = tmp_path / "baro_preset.py"
    path.write_text(PLUGIN)
    monkeypatch.delenv(plugins.PLUGINS_ENV, raising=False)
    yield path
    SENSOR_PRESETS.pop("test-baro", None)
    plugins._LOADED.pop(plugins.plugin_ref(str(path)), None)


def test_a_registered_preset_fills_the_scenario_as_a_builtin_does(preset):
    base = {"kind": "flight", "final_time_s": 0.5, "controller": "cascade-pid", "seed": 3}
    s = scenario_from_dict({**base, "sensors": preset})
    assert s.imu.preset == "impact"
    assert s.instruments["barometer"].noise_m == 0.5
    # the same run as the scenario that writes the sensors out itself
    written = scenario_from_dict({**base, **BARO})
    a, b = simulate(s).imu, simulate(written).imu
    assert np.array_equal(a["barometer_altitude_m"], b["barometer_altitude_m"], equal_nan=True)
    # the barometer's noise is the preset's (0.5 m, not the default), at its 50 Hz
    err = (a["barometer_altitude_m"] - a["barometer_altitude_true_m"]).to_numpy()
    samples = err[np.isfinite(err)]
    assert 20 <= samples.size <= 30  # 0.5 s at 50 Hz (the IMU samples at 200 Hz)
    assert 0.3 < samples.std() < 0.8


def test_a_scenario_field_still_wins_over_the_preset(preset):
    s = scenario_from_dict(
        {"kind": "flight", "sensors": preset, "instruments": {"barometer": {"noise_m": 0.1}}}
    )
    assert s.instruments["barometer"].noise_m == 0.1


@pytest.mark.parametrize(
    ("name", "preset", "message"),
    [
        ("impact", {"imu": "ideal"}, "a built-in preset has that name"),
        ("", {"imu": "ideal"}, "the name must be a non-empty word"),
        ("x", {"gps": {}}, "gps: not a sensor field"),
        ("x", {"imu": "cheap"}, "sensor preset 'x': imu"),
        ("x", {"instruments": {"sonar": {}}}, "instruments: sonar: no such sensor component"),
        ("x", {"instruments": {"barometer": {"noise_m": -1}}}, "barometer"),
        ("x", {"magnetometer": {"noise": "loud"}}, "magnetometer"),
    ],
)
def test_a_bad_preset_is_refused_in_one_line(name, preset, message):
    with pytest.raises(InputError, match=message) as info:
        register_sensor_preset(name, preset)
    assert "\n" not in str(info.value)
    assert name not in SENSOR_PRESETS or name in BUILTIN_SENSOR_PRESETS


def test_an_unknown_preset_is_refused_naming_the_field():
    with pytest.raises(InputError, match="sensors: unknown preset of sensors 'nope'"):
        scenario_from_dict({"kind": "flight", "sensors": "nope"})


def test_the_recovery_study_takes_a_registered_preset(preset):
    from quadimpact.studies.recovery.recovery_spec import RecoveryStudy

    study = RecoveryStudy(n=2, sensors=preset, estimator="ekf")
    base = scenario_from_dict(study.sweep_spec().base)
    assert base.sensors == preset and base.instruments["barometer"].noise_m == 0.5
    with pytest.raises(InputError, match="sensors: must be one of"):
        RecoveryStudy(n=2, sensors="nope")


def test_run_loads_the_plugin_named_on_the_command_line(plugin_file, tmp_path, capsys):
    scenario = tmp_path / "s.toml"
    scenario.write_text('kind = "flight"\nfinal_time_s = 0.3\nsensors = "test-baro"\n')
    code, err = cli_here(capsys, "run", str(scenario), "--out", str(tmp_path / "r0"))
    assert code == 2 and "unknown preset of sensors 'test-baro'" in err
    assert len(err.strip().splitlines()) == 1
    out = tmp_path / "r1"
    code, err = cli_here(
        capsys, "run", str(scenario), "--plugin", str(plugin_file), "--out", str(out)
    )
    assert code == 0, err
    imu = pd.read_parquet(out / "imu.parquet")
    assert "barometer_altitude_m" in imu
    summary = json.loads((out / "summary.json").read_text())
    assert summary["sensors"] == "test-baro"  # the result says which preset made it
    code, err = cli_here(capsys, "run", str(scenario), "--plugin", str(tmp_path / "no.py"))
    assert code == 2 and "--plugin: no such file" in err


def test_the_recovery_command_flies_the_plugin_preset(plugin_file, tmp_path, capsys):
    out = tmp_path / "rec"
    args = ["recovery", "--plugin", str(plugin_file), "--sensors", "test-baro",
            "--estimator", "ekf", "--n", "2", "--workers", "1", "--no-example",
            "--no-progress", "--out", str(out)]  # fmt: skip
    code, err = cli_here(capsys, *args)
    assert code == 0, err
    trials = pd.read_parquet(out / "trials.parquet")
    assert len(trials) == 2
    code, err = cli_here(capsys, "recovery", "--sensors", "nope", "--out", str(tmp_path / "x"))
    assert code == 2 and "--sensors: must be one of" in err


def test_the_benchmark_flies_a_plugin_preset_as_a_set_and_never_caches_it(preset, tmp_path):
    from quadimpact.studies.benchmark.benchmark_study import BenchmarkStudy, run_benchmark
    from quadimpact.studies.benchmark.suite import parse_sensor_sets, sensor_set

    assert parse_sensor_sets(f"ideal,{preset}", "3") == ("ideal", preset)
    with pytest.raises(InputError, match="suite 1 flies"):
        parse_sensor_sets(preset, "1")  # suite 1 keeps its published criteria and sets
    flown = sensor_set(preset)
    assert flown.plugin and flown.sensors == preset and flown.estimator == "ekf"
    study = BenchmarkStudy(tasks=("wall",), sensors=(preset,), references=False, limit=2)
    assert study.identity()["plugin_sensor_presets"][preset]["instruments"]["barometer"]
    cache = tmp_path / "cache"
    result = run_benchmark(study, tmp_path / "b", workers=1, cache=cache)
    cells = [c for c in result.cells if c["sensors"] == preset]
    assert cells and {c["source"] for c in cells} == {"run"}
    assert not any(cache.glob("*.parquet")) if cache.exists() else True
    assert f"`{preset}`: the plug-in preset of sensors" in (result.report).read_text()
