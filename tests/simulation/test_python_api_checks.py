"""The Python API says what it accepts (issue 20 item 13)."""

from __future__ import annotations

from pathlib import Path

import pytest

from quadimpact import ImpactTrial, Simulation, simulate
from quadimpact.inputs.controllers import register_controller


@pytest.mark.parametrize(
    ("value", "hint"),
    [(None, ""), ({"heading_deg": 45}, "scenario_from_dict"), ("x.toml", "load_scenario_file"),
     (Path("x.toml"), "load_scenario_file")],
)  # fmt: skip
def test_simulate_of_anything_but_a_scenario_is_a_type_error(value, hint) -> None:
    with pytest.raises(TypeError, match="scenario: must be a WallApproach, FlightScenario or "
                       "ImpactTrial") as info:  # fmt: skip
        simulate(value)
    assert hint in str(info.value)
    with pytest.raises(TypeError, match="scenario: must be"):
        Simulation(value)


def test_a_plain_python_step_is_refused_when_registered() -> None:
    def step(t, meas, ctrl, mem, veh, dt, cmd):  # not compiled
        return None

    with pytest.raises(TypeError, match="step must be compiled with numba.njit"):
        register_controller("plain-python", step=step)


def test_advance_takes_whole_ticks_only() -> None:
    sim = Simulation(ImpactTrial(final_time_s=0.1))
    for bad in (1.5, True, "2"):
        with pytest.raises(TypeError, match="n_ticks: must be a whole number"):
            sim.advance(bad)
    with pytest.raises(ValueError, match="n_ticks: must be >= 0, or -1"):
        sim.advance(-2)
    assert sim.advance(2) == 2 and sim.tick == 2
