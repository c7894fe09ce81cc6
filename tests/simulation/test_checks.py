"""A run never starts in contact: an impact trial touching the wall, or any scenario deeper
than the tolerance in a surface, is an input error (issue 20 item 1)."""

from __future__ import annotations

import pytest

from quadimpact import ImpactTrial, simulate
from quadimpact.errors import InputError
from quadimpact.inputs.scenarios import FlightScenario
from quadimpact.inputs.world import Plane
from quadimpact.simulation.checks import INITIAL_PENETRATION_TOL_M, STARTED_IN_CONTACT
from quadimpact.simulation.setup import prepare


@pytest.mark.parametrize("distance", [0.05, 0.25])
def test_an_impact_trial_started_in_contact_is_an_input_error(distance) -> None:
    with pytest.raises(InputError, match=STARTED_IN_CONTACT) as err:
        prepare(ImpactTrial(start_distance_m=distance))
    assert "start_distance_m" in str(err.value) and "bumper 1" in str(err.value)


def test_the_authors_start_is_not_in_contact() -> None:
    prepare(ImpactTrial())  # 0.32 m, level
    prepare(ImpactTrial(pitch_deg=-45, yaw_deg=45, roll_deg=15))  # the distribution's corner


def _flight(x_wall: float) -> FlightScenario:
    wall = Plane(name="wall", point_m=(x_wall, 0.0, 0.0), normal=(-1.0, 0.0, 0.0))
    return FlightScenario(position_m=(0.0, 0.0, -2.0), surfaces=(wall,), final_time_s=0.05)


def test_a_flight_started_inside_a_surface_beyond_the_tolerance_is_refused() -> None:
    reach = 0.0
    # find the bumpers' reach along +X by moving the wall until it is touched
    from quadimpact.simulation.approach import feature_depths

    setup = prepare(_flight(5.0))
    reach = 5.0 + float(feature_depths(setup.x0, setup.feat, setup.shapes, 0).max())
    # a touch within the tolerance runs, deeper is refused
    simulate(_flight(reach - 0.5 * INITIAL_PENETRATION_TOL_M))
    with pytest.raises(InputError, match=r"flight: the initial state has bumper \d 2\.0 mm inside"):
        prepare(_flight(reach - 2e-3))
