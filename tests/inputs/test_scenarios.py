"""Run inputs: defaults, ranges, model-variant resolution and scenario files."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from pydantic import ValidationError

from quadimpact.errors import InputError, input_error_from_validation
from quadimpact.inputs.model import MODEL_VARIANTS, ModelOptions, resolve_model_options
from quadimpact.inputs.scenarios import FlightScenario, WallApproach, load_scenario_file
from quadimpact.inputs.world import Plane

from helpers import SPIRI_TOML

DEFAULT_SWITCHES = {
    "yaw_reaction": "physical",
    "bumper1_yaw_twice": False,
    "initial_rotor_speeds": "trimmed",
    "attitude_mapping": "exact",
    "crash_rule": "cm-ground",
    "approach_start": "late-start",
    "spinup_reaction": "physical",
    "detection_tick_reference": "tilt-away",
    "contact_gate_m": 0.0,
    "pre_impact": "scenario",
    "recovery_law": "lean-cut",  # the benchmark's law since issue #45 ("default" before)
    "cut_step_motors": (),
    "bumper_force_scale": (1.0, 1.0, 1.0, 1.0),
}
REPLICA_SWITCHES = {
    "yaw_reaction": "paper",
    "bumper1_yaw_twice": True,
    "initial_rotor_speeds": "level-hover",
    "attitude_mapping": "paper-fit",
    "crash_rule": "paper-ticks",
    "approach_start": "paper",
    "spinup_reaction": "paper",
    "detection_tick_reference": "tilt-away",
    "contact_gate_m": 0.0,
    "pre_impact": "scenario",
    "recovery_law": "classic",
    "cut_step_motors": (),
    "bumper_force_scale": (1.0, 1.0, 1.0, 1.0),
}
# the recovery replica: the paper replica's drag sense, the rest its own (docs/VARIANTS.md 5)
RECOVERY_REPLICA_SWITCHES = {
    **DEFAULT_SWITCHES,
    "yaw_reaction": "paper",
    "detection_tick_reference": "level",
    "contact_gate_m": 0.30,
    "pre_impact": "spin-down",
    "recovery_law": "classic",  # the law that was the default before issue #45
}
# the previous default model: the default physics with the law it had before issue #45
CLASSIC_SWITCHES = {**DEFAULT_SWITCHES, "recovery_law": "classic"}
# the pole replica: the default physics, the retuned staged law and held rotors
# (docs/VARIANTS.md 8)
POLE_REPLICA_SWITCHES = {
    **DEFAULT_SWITCHES,
    "pre_impact": "hold",
    "recovery_law": "pole-replica",
}


def _message(cls: type, **fields: object) -> str:
    with pytest.raises(ValidationError) as info:
        cls(**fields)
    text = str(input_error_from_validation(info.value, "s.toml", model=cls))
    assert "\n" not in text
    return text


# ---------------------------------------------------------------- defaults
def test_wall_approach_defaults_are_the_papers_setup() -> None:
    w = WallApproach()
    assert w.kind == "wall-approach"
    assert (w.heading_deg, w.inclination_deg, w.speed_m_s) == (0.0, 0.0, 0.75)
    assert (w.impact_time_s, w.wall_distance_m, w.altitude_m, w.final_time_s) == (
        0.5,
        1.5,
        2.0,
        3.0,
    )
    assert (w.model, w.controller, w.vehicle, w.rotor_mode, w.ground) == (
        "default",
        "paper",
        "spiri",
        "ideal",
        "crash",
    )
    assert w.friction_coefficient == 0.0 and w.output_rate_hz == 1000.0
    assert w.rtol is None and w.atol is None
    assert w.rotor_speed_limits_rpm is None and w.rotor_slew_limit_rad_s2 is None
    assert w.vehicle_overrides == {}
    assert w.model_options == ModelOptions()


def test_flight_defaults() -> None:
    f = FlightScenario()
    assert f.kind == "flight"
    assert f.position_m == (0.0, 0.0, -2.0)
    assert f.velocity_m_s == f.euler_deg == f.angular_velocity_rad_s == (0.0, 0.0, 0.0)
    assert f.rotor_speeds_rad_s is None and f.altitude_ref_m is None
    assert f.attitude_ref_deg is None and f.surfaces == () and f.start_time_s == 0.0


def test_models_are_frozen_and_forbid_extras() -> None:
    w = WallApproach()
    with pytest.raises(ValidationError, match="frozen"):
        w.heading_deg = 10.0  # type: ignore[misc]
    assert "heading: unknown key; did you mean 'heading_deg'?" in _message(WallApproach, heading=10)


# ------------------------------------------------------------------ ranges
@pytest.mark.parametrize(
    ("fields", "expected"),
    [
        ({"heading_deg": 500}, "s.toml: heading_deg: must be <= 360 (got 500)"),
        ({"heading_deg": -361}, "heading_deg: must be >= -360 (got -361)"),
        ({"inclination_deg": 61}, "inclination_deg: must be <= 60 (got 61)"),
        ({"inclination_deg": -60.5}, "inclination_deg: must be >= -60 (got -60.5)"),
        ({"speed_m_s": 0}, "speed_m_s: must be > 0 (got 0)"),
        ({"speed_m_s": 25}, "speed_m_s: must be <= 20 (got 25)"),
        ({"impact_time_s": 0}, "impact_time_s: must be >= 0.005 (got 0)"),
        ({"impact_time_s": 3.0}, "impact_time_s: must be < final_time_s (3) (got 3)"),
        ({"final_time_s": 0.4}, "impact_time_s: must be < final_time_s (0.4) (got 0.5)"),
        ({"final_time_s": 601}, "final_time_s: must be <= 600 (got 601)"),
        ({"altitude_m": 0}, "altitude_m: must be > 0 (got 0)"),
        ({"output_rate_hz": 0}, "output_rate_hz: must be > 0 (got 0)"),
        ({"output_rate_hz": 2e5}, "output_rate_hz: must be <= 100000 (got 200000.0)"),
        ({"rtol": 0.1}, "rtol: must be < 0.1 (got 0.1)"),
        ({"rtol": 0}, "rtol: must be > 0 (got 0)"),
        ({"atol": -1e-9}, "atol: must be > 0 (got -1e-09)"),
        ({"friction_coefficient": -0.1}, "friction_coefficient: must be >= 0 (got -0.1)"),
        ({"rotor_speed_limits_rpm": [8000, 3000]}, "must be [min, max] with min < max"),
        ({"rotor_speed_limits_rpm": [3000]}, "must have exactly 2 numbers (got 1)"),
        ({"rotor_slew_limit_rad_s2": 0}, "rotor_slew_limit_rad_s2: must be > 0 (got 0)"),
        (
            {"model": "replica"},
            "model: must be one of 'default', 'classic', 'paper-replica', 'recovery-replica' or "
            "'pole-replica'",
        ),
        ({"controller": "pid"}, "controller: must be one of 'paper', 'cascade-pid', 'recovery'"),
        ({"rotor_mode": "lag"}, "rotor_mode: must be one of 'ideal' or 'first-order'"),
        ({"ground": "bounce"}, "ground: must be one of 'crash', 'contact' or 'none'"),
        ({"heading_deg": math.inf}, "heading_deg: must be a finite number (got inf)"),
        ({"heading_deg": True}, "heading_deg: must be a number (got True)"),
        ({"vehicle_overrides": {"colour": 1}}, "vehicle_overrides: unknown vehicle field"),
        ({"model_options": {"crash_rule": "x"}}, "model_options.crash_rule: must be one of"),
    ],
)
def test_wall_approach_ranges(fields: dict, expected: str) -> None:
    assert expected in _message(WallApproach, **fields)


def test_wall_approach_accepts_range_edges() -> None:
    w = WallApproach(heading_deg=-180, inclination_deg=60, speed_m_s=20, final_time_s=600)
    assert (w.heading_deg, w.inclination_deg, w.speed_m_s) == (-180.0, 60.0, 20.0)
    assert WallApproach(rtol=1e-10, atol=1e-12, rotor_speed_limits_rpm=(3000, 8000)).rtol == 1e-10


@pytest.mark.parametrize(
    ("fields", "expected"),
    [
        ({"position_m": [0, 0, 1]}, "position_m: must start above the ground"),
        ({"position_m": [0, 0]}, "position_m: must have exactly 3 numbers (got 2)"),
        ({"euler_deg": [0, 90, 0]}, "euler_deg: pitch (second entry) must be in (-90, 90)"),
        ({"euler_deg": [200, 0, 0]}, "euler_deg: roll (first entry) must be in [-180, 180]"),
        ({"attitude_ref_deg": [0, 0, 181]}, "attitude_ref_deg: yaw (third entry)"),
        ({"rotor_speeds_rad_s": [600, 600, 600, -1]}, "rotor speeds must be >= 0"),
        ({"altitude_ref_m": -1}, "altitude_ref_m: must be > 0 (got -1)"),
        ({"start_time_s": 3}, "start_time_s: must be < final_time_s (3) (got 3)"),
        (
            {"surfaces": [{"name": "w", "point_m": [1, 0, 0], "normal": [0, 0, 0]}]},
            "surfaces.0.normal: must be a non-zero vector",
        ),
        (
            {
                "surfaces": [
                    {"name": "w", "point_m": [1, 0, 0], "normal": [-1, 0, 0]},
                    {"name": "w", "point_m": [-1, 0, 0], "normal": [1, 0, 0]},
                ]
            },
            "surfaces: surface names must be unique ('w' repeats)",
        ),
        ({"heading_deg": 10}, "heading_deg: unknown key"),
    ],
)
def test_flight_ranges(fields: dict, expected: str) -> None:
    assert expected in _message(FlightScenario, **fields)


def test_plane_normal_is_normalised() -> None:
    plane = Plane(name="wall", point_m=(1.5, 0, 0), normal=(-3.0, 0.0, 4.0))
    assert plane.normal == pytest.approx((-0.6, 0.0, 0.8), abs=1e-15)
    assert plane.point_m == (1.5, 0.0, 0.0)


# ---------------------------------------------------------------- options
def test_variants_resolve_every_switch() -> None:
    assert MODEL_VARIANTS["default"] == DEFAULT_SWITCHES
    assert MODEL_VARIANTS["paper-replica"] == REPLICA_SWITCHES
    assert MODEL_VARIANTS["recovery-replica"] == RECOVERY_REPLICA_SWITCHES
    assert MODEL_VARIANTS["pole-replica"] == POLE_REPLICA_SWITCHES
    assert MODEL_VARIANTS["classic"] == CLASSIC_SWITCHES
    assert resolve_model_options("default", None).model_dump() == DEFAULT_SWITCHES
    assert resolve_model_options("paper-replica", ModelOptions()).model_dump() == REPLICA_SWITCHES
    assert WallApproach(model="paper-replica").resolved_model_options().model_dump() == (
        REPLICA_SWITCHES
    )


def test_override_of_one_switch() -> None:
    resolved = resolve_model_options("paper-replica", {"crash_rule": "cm-ground"})
    assert resolved.model_dump() == {**REPLICA_SWITCHES, "crash_rule": "cm-ground"}
    scenario = WallApproach(model_options={"bumper1_yaw_twice": True})
    assert scenario.resolved_model_options().model_dump() == {
        **DEFAULT_SWITCHES,
        "bumper1_yaw_twice": True,
    }


def test_option_resolution_errors() -> None:
    with pytest.raises(InputError, match=r"model: must be one of 'default', 'paper-replica'"):
        resolve_model_options("paper", None)
    with pytest.raises(InputError, match=r"model_options.crash: unknown key; did you mean"):
        resolve_model_options("default", {"crash": "cm-ground"})


def test_build_vehicle_applies_overrides() -> None:
    vehicle = WallApproach(vehicle_overrides={"restitution": 0.5}).build_vehicle()
    assert vehicle.restitution == 0.5 and vehicle.mass_kg == 0.933
    with pytest.raises(InputError, match=r"restitution: must be <= 1 \(got 2\)"):
        WallApproach(vehicle_overrides={"restitution": 2}).build_vehicle()


# ------------------------------------------------------------------ files
def _write(tmp_path: Path, text: str, name: str = "scenario.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_load_wall_approach_file(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        """
heading_deg = 45
inclination_deg = 15
speed_m_s = 0.75
model = "paper-replica"
controller = "cascade-pid"

[model_options]
crash_rule = "cm-ground"

[vehicle_overrides]
restitution = 0.5
""",
    )
    scenario = load_scenario_file(path)
    assert isinstance(scenario, WallApproach)
    assert (scenario.heading_deg, scenario.inclination_deg, scenario.speed_m_s) == (45, 15, 0.75)
    assert scenario.controller == "cascade-pid"
    assert scenario.resolved_model_options().model_dump() == {
        **REPLICA_SWITCHES,
        "crash_rule": "cm-ground",
    }
    assert scenario.vehicle_overrides == {"restitution": 0.5}
    assert scenario.build_vehicle().restitution == 0.5


def test_load_flight_file_with_surfaces(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        """
kind = "flight"
position_m = [0.0, 0.0, -1.5]
velocity_m_s = [1.0, 0.0, 0.0]
euler_deg = [0.0, -10.0, 30.0]

[[surfaces]]
name = "wall"
point_m = [1.5, 0.0, 0.0]
normal = [-2.0, 0.0, 0.0]

[[surfaces]]
name = "ceiling"
point_m = [0.0, 0.0, -3.0]
normal = [0.0, 0.0, 1.0]
""",
    )
    scenario = load_scenario_file(path)
    assert isinstance(scenario, FlightScenario)
    assert scenario.position_m == (0.0, 0.0, -1.5)
    assert scenario.euler_deg == (0.0, -10.0, 30.0)
    assert [p.name for p in scenario.surfaces] == ["wall", "ceiling"]
    assert scenario.surfaces[0].normal == (-1.0, 0.0, 0.0)
    assert scenario.surfaces[1].point_m == (0.0, 0.0, -3.0)


def test_vehicle_path_relative_to_scenario_file(tmp_path: Path) -> None:
    spiri = SPIRI_TOML
    sub = tmp_path / "cases"
    sub.mkdir()
    (sub / "heavy.toml").write_text(spiri.read_text().replace("0.933", "1.2"))
    path = _write(sub, 'vehicle = "heavy.toml"\n')
    scenario = load_scenario_file(path)
    assert Path(scenario.vehicle) == sub / "heavy.toml"
    assert scenario.build_vehicle().mass_kg == 1.2


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("heading_deg = 500\n", "scenario.toml: heading_deg: must be <= 360 (got 500)"),
        (
            "hedding_deg = 5\n",
            "scenario.toml: hedding_deg: unknown key; did you mean 'heading_deg'",
        ),
        (
            'kind = "orbit"\n',
            "scenario.toml: kind: must be one of 'wall-approach', 'flight', 'impact-trial'",
        ),
        ("[model_options]\ncrash_rule = 1\n", "scenario.toml: model_options.crash_rule: must be"),
        (
            "[vehicle_overrides]\nrestitution = 1.5\n",
            "scenario.toml: vehicle_overrides.restitution: must be <= 1 (got 1.5)",
        ),
        ("[vehicle_overrides]\nmass = 1.5\n", "scenario.toml: vehicle_overrides: unknown vehicle"),
        ('vehicle = "nope.toml"\n', "vehicle nope.toml: file not found"),
        ('kind = "flight"\n[[surfaces]]\nname = "w"\n', "scenario.toml: surfaces.0.point_m: is"),
        ("heading_deg = 10\nheading_deg = 20\n", "scenario.toml: invalid TOML:"),
        ("heading_deg = \n", "(at line 1, column 15)"),
    ],
)
def test_scenario_file_errors(tmp_path: Path, text: str, expected: str, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    _write(tmp_path, text)
    with pytest.raises(InputError) as info:
        load_scenario_file("scenario.toml")
    message = str(info.value)
    assert "\n" not in message
    assert expected in message


def test_missing_scenario_file(tmp_path: Path) -> None:
    missing = tmp_path / "missing.toml"
    # a long path (a deep temporary folder) is cut in the middle and its length given
    with pytest.raises(InputError, match=r"missing.toml( \(\d+ characters\))?: file not found"):
        load_scenario_file(missing)


def test_the_classic_law_is_named_classic_and_its_old_name_still_reads():
    """The law named ``"default"`` before issue #45 is not the default model's: it is
    ``"classic"`` now, and a file of then that names it ``"default"`` gets the same law."""
    from quadimpact.inputs.scenarios import scenario_from_dict

    old = scenario_from_dict({"kind": "impact-trial", "model_options": {"recovery_law": "default"}})
    new = scenario_from_dict({"kind": "impact-trial", "model_options": {"recovery_law": "classic"}})
    assert old.resolved_model_options().recovery_law == "classic"
    assert old.resolved_controller_params() == new.resolved_controller_params()
    assert ModelOptions(recovery_law="default").recovery_law == "classic"
