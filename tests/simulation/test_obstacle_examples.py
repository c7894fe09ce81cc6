"""The example scenario files of examples/ run, and touch what they say they touch.

A pole, a box corner, a caged vehicle hitting the wall and a vehicle on
landing-gear legs settling on the ground (docs/OBSTACLES.md); each file is
read as ``quadimpact run FILE`` reads it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from quadimpact import simulate
from quadimpact.inputs.scenarios import load_scenario_file
from quadimpact.inputs.vehicle import load_vehicle

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _run(name: str, **changes):
    scenario = load_scenario_file(EXAMPLES / f"{name}.toml")
    return simulate(scenario.model_copy(update=changes) if changes else scenario)


def test_the_example_vehicles_load_and_say_where_their_numbers_come_from():
    for name in ("navi_cage", "navi_legs"):
        path = EXAMPLES / "vehicles" / f"{name}.toml"
        assert "Where the numbers come from" in path.read_text()
        v = load_vehicle(path)
        assert v.features is not None and v.plausibility_warnings() == []
    cage = load_vehicle(EXAMPLES / "vehicles" / "navi_cage.toml")
    assert [f.kind for f in cage.contact_features()] == ["sphere"]
    legs = load_vehicle(EXAMPLES / "vehicles" / "navi_legs.toml")
    assert [f.kind for f in legs.contact_features()] == ["ring"] * 4 + ["point"] * 4
    # its rings are the Navi's, number for number
    navi = load_vehicle("navi").contact_features()
    for mine, theirs in zip(legs.contact_features()[:4], navi, strict=True):
        np.testing.assert_allclose(mine.centre_m, theirs.centre_m, rtol=0, atol=0)
        np.testing.assert_allclose(mine.normal, theirs.normal, atol=1e-10)


def test_the_pole_example_hits_the_pole_and_recovers():
    s = _run("pole").summary
    assert s["status"] == "completed" and s["leading_bumpers"] == [1, 4]
    assert s["recovered"]
    n = np.array(s["first_contact_normal"])
    assert n[2] == pytest.approx(0.0, abs=1e-12) and n[0] < -0.9  # radial, toward -X


def test_the_box_corner_example_meets_the_corner_region():
    result = _run("box_corner", final_time_s=0.5)
    s = result.summary
    assert s["status"] == "completed" and s["first_contact_s"] is not None
    assert set(result.episodes["surface"]) == {"box"}
    n = np.array(s["first_contact_normal"])
    assert np.count_nonzero(np.abs(n) > 1e-3) >= 2  # off the box's faces: an edge or the corner


def test_the_caged_vehicle_meets_the_wall_with_its_cage():
    result = _run("caged_wall")
    s = result.summary
    assert s["status"] == "completed"
    assert s["first_contact_s"] == pytest.approx(0.5, abs=1e-6)
    assert s["impact_speed_m_s"] == pytest.approx(1.0, abs=1e-6)
    assert s["leading_bumpers"] == [1] and "feature(s) cage" in s["outcome"]
    assert "delta_cage_m" in result.timeseries and "force_cage_n" in result.timeseries


def test_the_legged_vehicle_lands_on_its_feet():
    result = _run("landing")
    s = result.summary
    assert s["status"] == "completed" and s["crash_time_s"] is None
    eps = result.episodes
    assert set(eps["surface"]) == {"floor"}
    assert set(eps["bumper"]) <= {5, 6, 7, 8}  # the feet, never a ring
    assert s["final_altitude_m"] == pytest.approx(0.15, abs=0.01)  # standing on 0.15-m legs
    for name in ("foot_fr", "foot_rr", "foot_rl", "foot_fl"):
        assert f"delta_{name}_m" in result.timeseries
