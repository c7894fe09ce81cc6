"""Implausible and inconsistent inputs are refused with the rule that fails (one line each)."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from quadimpact import InputError, WallApproach
from quadimpact.inputs.scenarios import scenario_from_dict
from quadimpact.inputs.vehicle import load_vehicle

SPIRI = load_vehicle("spiri")


@pytest.mark.parametrize(
    ("override", "fragment"),
    [
        ({"bumper_radius_m": 110}, "bumper_radius_m: must be at most 2 m"),
        ({"inertia_kg_m2": [[1e-3, 0, 0], [0, 1e-3, 0], [0, 0, 3e-3]]}, "triangle inequality"),
        ({"rotor_speed_range_rpm": [314, 838]}, "cannot hold the vehicle up (rad/s typed as rpm?)"),
        ({"mass_kg": 1e308}, "mass_kg: must be <= 1000"),
        ({"mass_kg": 1e-300}, "mass_kg: must be >= 0.001"),
        ({"thrust_coefficient": 1e-300}, "rotor_speed_range_rpm: hovering needs"),
        ({"spin_directions": [1, 1, -1, -1]}, "the allocation is singular"),
        ({"rotor_positions_m": [[0.1, 0.1, 0.0]] * 4}, "the allocation is singular"),
        ({"inertia_kg_m2": [[1e308, 0, 0], [0, 1e308, 0], [0, 0, 1e308]]}, "at most 1e9 kg m^2"),
        ({"rotor_positions_m": [[0.0, 0.0, 0.0]] * 4}, "rotor arms"),
    ],
)
def test_vehicle_rules(override, fragment):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no NumPy warning on the way
        with pytest.raises(InputError) as info:
            SPIRI.with_overrides(**override)
    message = str(info.value)
    assert "\n" not in message and fragment in message, message


def test_unusual_values_warn_not_fail():
    assert SPIRI.plausibility_warnings() == []
    assert load_vehicle("navi").plausibility_warnings() == []
    odd = SPIRI.with_overrides(bumper_radius_m=0.02, restitution=0.1)
    text = " ".join(odd.plausibility_warnings())
    assert "bumper_radius_m" in text and "restitution" in text


@pytest.mark.parametrize(
    ("fields", "fragment"),
    [
        ({"model_options": {"bumper1_yaw_twice": "yes"}}, "must be true or false (got 'yes')"),
        ({"model_options": {"bumper1_yaw_twice": 1}}, "must be true or false (got 1)"),
        ({"impact_time_s": 1e-320}, "impact_time_s: must be >= 0.005"),
        ({"final_time_s": 1e-320}, "final_time_s: must be >= 0.005"),
        ({"vehicle_overrides": {"restitusion": 0.5}}, "did you mean 'restitution'?"),
        ({"friction": 0.3}, "friction: unknown key; did you mean 'friction_coefficient'?"),
        ({"speed": 0.5}, "did you mean 'speed_m_s'?"),
        ({"detection": {"enabled": "no"}}, "detection.enabled: must be true or false"),
    ],
)
def test_scenario_rules(fields, fragment):
    with pytest.raises(InputError) as info:
        scenario_from_dict(fields, where="s.toml")
    assert fragment in str(info.value), str(info.value)


def test_a_misspelled_required_key_is_named(tmp_path: Path):
    text = Path(__file__).resolve().parents[2] / "src/quadimpact/inputs/vehicles/spiri.toml"
    bad = tmp_path / "v.toml"
    bad.write_text(text.read_text().replace("mass_kg = 0.933", "mass_kgg = 0.933"))
    with pytest.raises(InputError, match=r"mass_kg: is required \('mass_kgg' is there"):
        load_vehicle(bad)
    with pytest.raises(InputError, match="mass_kgg"):
        WallApproach(vehicle=str(bad)).build_vehicle()


# ---------------------------------------------- issue 20 item 10: accepted silently before
@pytest.mark.parametrize(
    ("override", "fragment"),
    [
        ({"bumper_radius_m": 0.4}, "not less than the shortest rotor arm (0.175 m)"),
        ({"imu_position_m": [100.0, 0.0, 0.0]}, "imu_position_m: 100 m from the CM, off the"),
    ],
)
def test_bumpers_and_imu_must_fit_the_vehicle(override, fragment):
    with pytest.raises(InputError) as info:
        SPIRI.with_overrides(**override)
    assert fragment in str(info.value), str(info.value)


def test_overlapping_bumper_rings_are_named_in_a_warning():
    text = " ".join(SPIRI.with_overrides(bumper_radius_m=0.15).plausibility_warnings())
    assert "bumper rings overlap: 2 x bumper_radius_m = 0.3 m is more than the 0.253 m" in text
    assert SPIRI.plausibility_warnings() == []


@pytest.mark.parametrize(
    ("imu", "fragment"),
    [
        ({"position": [100, 0, 0]}, "imu: position: (100, 0, 0) m is 100 m from the CM, off"),
        ({"accel_range_m_s2": 1}, "imu: accel_range_m_s2: must be at least g = 9.81"),
        ({"accel_range_m_s2": 10}, None),
    ],
)
def test_an_imu_off_the_vehicle_or_saturated_in_hover_is_refused(imu, fragment):
    from quadimpact.simulation.setup import prepare

    trial = scenario_from_dict({"kind": "impact-trial", "imu": imu})
    if fragment is None:
        prepare(trial)
        return
    with pytest.raises(InputError) as info:
        prepare(trial)
    assert fragment in str(info.value), str(info.value)


def test_a_detection_threshold_beyond_the_accelerometer_range_is_refused():
    from quadimpact.simulation.setup import prepare

    trial = scenario_from_dict({"kind": "impact-trial", "imu": {"accel_range_m_s2": 10},
                                "detection": {"threshold_g": 2.0}})  # fmt: skip
    with pytest.raises(InputError, match="detection: threshold_g: 2 g = 19.6.* can never be read"):
        prepare(trial)
