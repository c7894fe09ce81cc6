"""A plug-in sensor component (``examples/sensor_template.py``, a variometer) flown as a
built-in is: named in a scenario, its noise from the run's seed, its columns recorded."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadimpact import simulate
from quadimpact.inputs.scenarios import scenario_from_dict

from helpers import load_example

pytestmark = pytest.mark.slow  # compiles a loop around the plug-in (about a minute)


def _load():
    return load_example("sensor_template.py")


def test_plugin_variometer_measures_the_climb_rate():
    _load()
    base = {
        "kind": "flight",
        "final_time_s": 1.0,
        "controller": "cascade-pid",
        "velocity_m_s": (0.0, 0.0, -0.5),  # climbing at 0.5 m/s at the start
        "imu": {"preset": "ideal", "rate_hz": 200},
    }
    exact = simulate(scenario_from_dict({**base, "instruments": {"variometer": {"noise_m_s": 0}}}))
    imu = exact.imu
    assert imu["variometer_climb_m_s"].iloc[0] == pytest.approx(0.5, abs=1e-12)
    assert np.array_equal(imu["variometer_climb_m_s"], imu["variometer_climb_true_m_s"])
    sigma = 0.2
    noisy = simulate(
        scenario_from_dict({**base, "seed": 5, "instruments": {"variometer": {"noise_m_s": sigma}}})
    )
    e = (noisy.imu["variometer_climb_m_s"] - noisy.imu["variometer_climb_true_m_s"]).to_numpy()
    n = e.size
    assert abs(e.var(ddof=1) / sigma**2 - 1.0) < 4 * math.sqrt(2.0 / (n - 1))
    again = simulate(
        scenario_from_dict({**base, "seed": 5, "instruments": {"variometer": {"noise_m_s": sigma}}})
    )
    assert np.array_equal(noisy.imu["variometer_climb_m_s"], again.imu["variometer_climb_m_s"])


def test_plugin_preset_of_the_variometer_flies_in_a_study_and_the_benchmark(tmp_path):
    """The template's preset (impact IMU + variometer) names the plug-in in a study."""
    from quadimpact.studies.benchmark.benchmark_study import BenchmarkStudy, run_benchmark
    from quadimpact.studies.recovery.recovery_spec import RecoveryStudy

    _load()
    spec = RecoveryStudy(n=2, sensors="variometer-impact", estimator="ekf").sweep_spec()
    assert spec.base["sensors"] == "variometer-impact"  # the preset by name, filled when read
    trial = scenario_from_dict(spec.scenario_dict(0))
    assert "variometer" in trial.instruments and trial.imu.preset == "impact"
    study = BenchmarkStudy(
        tasks=("wall",), sensors=("variometer-impact",), references=False, limit=2
    )
    result = run_benchmark(study, tmp_path / "bench", workers=1, cache=tmp_path / "cache")
    cells = [c for c in result.cells if c["sensors"] == "variometer-impact"]
    assert len(cells) == 1 and cells[0]["source"] == "run" and cells[0]["trials"] == 2
