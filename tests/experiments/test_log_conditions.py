"""Simulating a crash at its flight log's own pre-impact estimates (needs the shared data)."""

import math

import numpy as np
import pytest

from quadimpact.experiments.crashes import TABLE3, scenario_file
from quadimpact.inputs.scenarios import WallApproach
from quadimpact.simulation import simulate
from quadimpact.studies.table3.crash_logs import (
    LOG_RANGE_SIGMAS,
    log_conditions,
    log_sensitivity_spec,
    read_log,
)

pytestmark = pytest.mark.data


@pytest.fixture(scope="module")
def pres():
    return {c.number: read_log(c).pre_impact() for c in TABLE3}


def test_no_conditions_without_an_observed_contact(pres):
    assert not pres[1].contact_observed
    assert log_conditions(TABLE3[0], pres[1]) is None
    assert log_sensitivity_spec(TABLE3[0], pres[1]) is None


@pytest.mark.parametrize("number", [2, 4, 6])
def test_the_run_reaches_the_logged_state_at_the_contact(pres, number):
    """Speed, heading and attitude at the first contact are the log's estimates."""
    crash, pre = TABLE3[number - 1], pres[number]
    fields = log_conditions(crash, pre)
    assert abs(fields["heading_deg"] - scenario_file(number).heading_deg) < 180.0
    r = simulate(WallApproach.model_validate(fields))
    s = r.summary
    scenario = WallApproach.model_validate(fields)
    assert s["first_contact_s"] == pytest.approx(scenario.impact_time_s, abs=1e-9)
    assert s["impact_speed_m_s"] == pytest.approx(pre.speed_m_s, abs=1e-3)  # rounded to mm/s
    d_heading = (s["impact_heading_deg"] - pre.heading_deg + 180.0) % 360.0 - 180.0
    assert abs(d_heading) < 0.01
    assert s["impact_inclination_deg"] == pytest.approx(pre.inclination_deg, abs=0.02)
    ts = r.timeseries
    for name, logged in (("roll_deg", pre.roll_deg), ("pitch_deg", pre.pitch_deg)):
        at_contact = np.interp(s["first_contact_s"], ts["t_s"], ts[name])
        assert at_contact == pytest.approx(logged, abs=0.02)  # rounded to 0.01 deg
    # the motors are the crash's: powered off at the contact
    assert s["power_off_time_s"] == pytest.approx(s["first_contact_s"])


def test_log_sensitivity_spans_two_standard_uncertainties(pres):
    crash, pre = TABLE3[4], pres[5]
    spec = log_sensitivity_spec(crash, pre, 8)
    base = log_conditions(crash, pre)
    for name, (lo, hi) in spec.sample["ranges"].items():
        assert math.isclose(hi - lo, 2 * LOG_RANGE_SIGMAS * pre.uncertainty[name])
        assert math.isclose((lo + hi) / 2, base[name])
