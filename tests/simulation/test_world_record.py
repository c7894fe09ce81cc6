"""The world a run records (``SimulationResult.world``, ``scenario.json``): complete,
resolved, and the surfaces exactly as the kernel received them."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from quadimpact import FlightScenario, Plane, Simulation, WallApproach, read_result, simulate
from quadimpact.core import shape_slots as SHP
from quadimpact.inputs.controllers import RecoveryParams
from quadimpact.inputs.model import recovery_law_params, resolve_model_options
from quadimpact.inputs.scenarios import scenario_from_dict
from quadimpact.inputs.sensors import ImuSettings
from quadimpact.inputs.vehicle import Vehicle
from quadimpact.packing.world_block import pack_surface_records, surface_records
from quadimpact.results.schema import SUMMARY_KEYS
from quadimpact.simulation.setup import prepare

FLIGHT = FlightScenario(
    position_m=(0.0, 0.0, -1.0),
    velocity_m_s=(1.0, 0.0, 0.0),
    final_time_s=0.7,
    output_rate_hz=100,
    surfaces=(
        Plane(name="slope", point_m=(0.3, 0.0, 0.0), normal=(-1.0, 0.0, -0.5)),
        Plane(name="side", point_m=(0.0, 0.7, 0.0), normal=(0.0, -1.0, 0.1)),
    ),
    ground="contact",
    model="recovery-replica",
    model_options={"contact_gate_m": 0.0},
    controller="recovery",
    controller_params={"k_att_1_s": 15.0},
    pre_impact="hold",
    vehicle_overrides={"bumper_radius_m": 0.13, "restitution": 0.6},
    imu={"preset": "noisy", "rate_hz": 1000},
    detection={"threshold_g": 0.8},
    seed=7,
)


@pytest.fixture(scope="module")
def flight_result():
    return simulate(FLIGHT)


def test_the_world_holds_the_whole_scenario_resolved(flight_result) -> None:
    w = flight_result.world
    assert set(w) == {
        "scenario",
        "resolved",
        "vehicle",
        "surfaces",
        "features",
        "quadimpact_version",
    }
    # every field of the validated scenario, and it validates back to the same scenario
    assert w["scenario"] == FLIGHT.model_dump(mode="json")
    again = scenario_from_dict(w["scenario"])
    assert again.model_dump(exclude={"surfaces"}) == FLIGHT.model_dump(exclude={"surfaces"})
    for a, b in zip(again.surfaces, FLIGHT.surfaces, strict=True):  # normalised once more:
        assert a.normal == pytest.approx(b.normal, rel=1e-15)  # why surfaces are kept as packed
    r = w["resolved"]
    options = resolve_model_options("recovery-replica", FLIGHT.model_options)
    assert r["model"] == "recovery-replica"
    assert r["model_options"] == options.model_dump(mode="json")  # tuples as JSON lists
    assert None not in r["model_options"].values() and r["model_options"]["contact_gate_m"] == 0
    assert r["controller"] == "recovery"
    # the replica flies the classic law (its recovery_law switch, "classic")
    law = recovery_law_params(options.recovery_law, {"k_att_1_s": 15.0})
    assert r["controller_params"] == RecoveryParams(**law).model_dump(mode="json")
    assert set(r["controller_params"]) == set(RecoveryParams.model_fields)
    # the replica forces spin-down whatever the scenario says (docs/VARIANTS.md)
    assert r["pre_impact"] == FLIGHT.resolved_pre_impact() == "spin-down"
    imu = ImuSettings(preset="noisy", rate_hz=1000).resolved((0.0, 0.0, 0.0), 200.0)
    assert r["imu"] == imu.model_dump(mode="json") and r["imu"]["accel_noise_m_s2"] == 1.0
    assert w["scenario"]["detection"]["threshold_g"] == 0.8 and w["scenario"]["seed"] == 7
    # the vehicle with its overrides applied, every field
    assert set(w["vehicle"]) == set(Vehicle.model_fields)
    assert Vehicle.model_validate(w["vehicle"]) == FLIGHT.build_vehicle()
    assert w["vehicle"]["bumper_radius_m"] == 0.13 and w["vehicle"]["restitution"] == 0.6


def test_the_surfaces_are_the_packed_ones_bit_for_bit(flight_result, tmp_path: Path) -> None:
    surf = prepare(FLIGHT).shapes
    records = flight_result.world["surfaces"]
    assert [(s["name"], s["is_ground"], s["kind"]) for s in records] == [
        ("slope", False, "plane"), ("side", False, "plane"), ("ground", True, "plane")
    ]  # fmt: skip
    np.testing.assert_array_equal(pack_surface_records(records), surf)
    normals = surf[:, SHP.SH_NORMAL : SHP.SH_NORMAL + 3]
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, rtol=1e-15)
    # through the file: the same numbers (floats are written in full)
    back = read_result(flight_result.write(tmp_path / "run"))
    assert back.world == json.loads(json.dumps(flight_result.world))
    np.testing.assert_array_equal(pack_surface_records(back.world["surfaces"]), surf)
    assert back.vehicle() == FLIGHT.build_vehicle()
    # the summary keeps its schema: the world is beside it, not in it
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert not {"surfaces", "resolved", "world"} & set(summary)
    assert "scenario" not in {k.name for k in SUMMARY_KEYS}
    with pytest.raises(ValueError, match="kind must be one of"):
        pack_surface_records([{**records[0], "kind": "torus"}])
    with pytest.raises(ValueError, match="a sphere record needs centre_m"):
        pack_surface_records([{**records[0], "kind": "sphere"}])
    assert surface_records(surf, ["a", "b", "c"])[1]["name"] == "b"


def test_wall_approach_and_stepping_record_the_same_world() -> None:
    sc = WallApproach(heading_deg=45, inclination_deg=15, wall_distance_m=1.2, final_time_s=0.6)
    result = simulate(sc)
    (wall,) = result.world["surfaces"]
    assert wall == {"name": "wall", "point_m": [1.2, 0.0, 0.0], "normal": [-1.0, 0.0, 0.0],
                    "is_ground": False, "kind": "plane"}  # fmt: skip
    assert result.world["resolved"]["controller_params"]["attitude_pid"] == [7.2, 4.0, 4.2]
    assert Simulation(sc).run().world == result.world


def test_every_kind_of_run_has_a_plot_title(flight_result) -> None:
    """Figures 5 and 6 of a flight or an impact trial are titled too, also when read back."""
    from quadimpact import ImpactTrial, WallApproach

    assert flight_result.plot_title() == "flight: slope, side; ground contact"
    trial = simulate(ImpactTrial(pitch_deg=-20, final_time_s=0.3))
    assert trial.plot_title() == "impact trial: roll 0°, pitch -20°, 1.5 m/s"
    wall = simulate(WallApproach(heading_deg=45, final_time_s=0.8))
    assert wall.plot_title() == "ψ = 45°, V_c = 0.75 m/s, inclination = 0°"


def test_a_flight_read_back_keeps_its_title(flight_result, tmp_path) -> None:
    back = read_result(flight_result.write(tmp_path / "run"))
    assert back.plot_title() == "flight: slope, side; ground contact"
