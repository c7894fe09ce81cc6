"""Impact detection on whole runs: silent in contact-free flight, and on the Figure 4 grid."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from quadimpact import FlightScenario, WallApproach, simulate
from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP
from quadimpact.core.kernel import execute
from quadimpact.core.sensors import detection as DET
from quadimpact.simulation.setup import prepare

G = 9.81


@pytest.mark.parametrize("vehicle", ["spiri", "navi"])
def test_hover_never_detects(vehicle):
    s = simulate(FlightScenario(vehicle=vehicle, final_time_s=5.0)).summary
    assert s["n_detections"] == 0 and not s["detected"] and not s["false_detection"]


def test_wall_approaches_without_the_wall_never_detect():
    """The approach phase of Figure 4 runs, flown on with the wall removed."""
    count = 0
    for model, heading, incl, speed in itertools.product(
        ("paper-replica", "default"), (0.0, 45.0), (-20.0, -10.0, 0.0, 10.0, 20.0), (0.5, 1.0)
    ):
        off_cm = {"imu_position_m": (0.02, 0.01, -0.05)}
        setup = prepare(WallApproach(heading_deg=heading, inclination_deg=incl, speed_m_s=speed,
                                     model=model, vehicle_overrides=off_cm))  # fmt: skip
        no_wall = np.zeros((0, SHP.NSHAPE))
        rec = execute(setup.model(shapes=no_wall), n_imu=setup.n_imu)
        assert rec.stats[L.ST_N_DETECTIONS] == 0 and math.isnan(rec.stats[L.ST_T_DETECT])
        assert rec.imu[:, DET.I_HORIZONTAL].max() < 0.1 * 0.5 * G
        count += 1
    assert count == 40


@pytest.mark.parametrize("controller", ["paper", "cascade-pid"])
def test_a_60_degree_roll_manoeuvre_never_detects(controller):
    """Level hover, then a 60-deg roll command: lever-arm terms at the Navi's off-CM IMU."""
    r = simulate(FlightScenario(vehicle="navi", position_m=(0, 0, -50), attitude_ref_deg=(60, 0, 0),
                                controller=controller, final_time_s=3.0))  # fmt: skip
    assert r.timeseries["roll_deg"].abs().max() > 45.0  # the manoeuvre happened
    assert r.imu["f_horizontal_m_s2"].max() > 0.05  # and the IMU saw its lever-arm terms
    assert r.summary["n_detections"] == 0


def test_false_detections_count_rising_edges_at_the_expected_rate():
    """Hover with white noise only: rising edges of |f_xy| >= 0.5 g come at (N-1) p (1-p)."""
    sigma = 2.5  # large enough for many events in a short run (the 'noisy' preset has 1.0)
    r = simulate(FlightScenario(final_time_s=20.0, seed=11,
                                imu={"rate_hz": 1000, "accel_noise_m_s2": sigma}))  # fmt: skip
    n = len(r.imu)
    p = math.exp(-((0.5 * G / sigma) ** 2) / 2)  # Rayleigh tail of |(f_x, f_y)|
    expected = (n - 1) * p * (1 - p)
    assert abs(r.summary["n_detections"] - expected) < 5 * math.sqrt(expected)
    assert r.summary["false_detection"] and r.summary["detection_latency_s"] is None


def test_figure4_grid_detection():
    """Every impact at 1 m/s is detected; the misses at 0.5-0.75 m/s are impacts whose
    horizontal specific force never reaches 0.5 g (the Spiri's soft bumpers)."""
    latency = []
    missed = []
    for model, heading, incl, speed in itertools.product(
        ("paper-replica", "default"), (0.0, 45.0), np.arange(-20.0, 21.0, 4.0), (0.5, 0.75, 1.0)
    ):
        r = simulate(WallApproach(heading_deg=heading, inclination_deg=float(incl),
                                  speed_m_s=speed, model=model, output_rate_hz=200))  # fmt: skip
        s = r.summary
        assert not s["false_detection"]
        if s["detected"]:
            latency.append(s["detection_latency_s"])
            assert s["normal_error_deg"] < 2.0
        else:
            missed.append((model, heading, incl, speed))
            assert speed < 1.0
            assert r.imu["f_horizontal_m_s2"].max() < 0.5 * G  # never reached the threshold
            assert s["not_detected"]
    assert 0.0 < np.median(latency) < 0.015 and max(latency) < 0.05
    assert len(missed) < 0.2 * 2 * 2 * 11 * 3
