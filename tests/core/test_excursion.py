"""The loop's attitude excursion (``core/excursion.py``): what a run's summary reports
is the excursion of its time-series table, bit for bit, in every kind of run."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadimpact import FlightScenario, ImpactTrial, WallApproach, simulate
from quadimpact.core import excursion as E
from quadimpact.core.excursion_slots import EX_COS_TILT, EX_DEV, NEX
from quadimpact.inputs.world import Cylinder
from quadimpact.rotations import GIMBAL_LOCK_COS
from quadimpact.simulation.metrics import attitude_excursion_deg

POLE = Cylinder(name="pole", point_m=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0), radius_m=0.1)


def test_the_gimbal_lock_rule_is_the_rotations_modules():
    assert E.GIMBAL_LOCK_COS == GIMBAL_LOCK_COS
    assert E.DEG == 180.0 / math.pi and E.RAD == math.pi / 180.0


@pytest.mark.parametrize(
    "scenario",
    [
        WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75, model="paper-replica"),
        ImpactTrial(controller="recovery", roll_deg=12, pitch_deg=-40, yaw_deg=30, speed_m_s=2.2),
        ImpactTrial(controller="recovery", roll_deg=-8, speed_m_s=2.0, obstacles=(POLE,)),
        FlightScenario(final_time_s=1.0),
    ],
    ids=["wall-approach", "recovery-trial", "pole", "flight"],
)
def test_the_summarys_excursion_is_the_time_series_tables(scenario):
    """The loop adds every output sample to the excursion as it writes it; the summary's
    ``attitude_excursion`` equals the table's (``metrics.attitude_excursion_deg`` of the
    time series), and the state at the end is the last row's."""
    r = simulate(scenario)
    ts = r.timeseries
    assert r.summary["attitude_excursion"] == attitude_excursion_deg(ts, r.references)
    if not isinstance(scenario, FlightScenario):  # a hover holds level
        assert r.summary["attitude_excursion"]["tilt_max_deg"] > 1.0  # something to measure
    assert r.summary["final_altitude_m"] == -ts["z_m"].iloc[-1]
    final = (ts["u_m_s"].iloc[-1], ts["v_m_s"].iloc[-1], ts["w_m_s"].iloc[-1])
    assert r.summary["final_speed_m_s"] == pytest.approx(float(np.linalg.norm(final)), rel=1e-15)


def test_a_rotation_about_one_axis_departs_by_its_angle():
    """Analytic: samples rolling from 0 to 50 deg (references 0): roll and tilt excursions
    are 50 deg, pitch and yaw 0."""
    e = np.zeros(NEX)
    E.excursion_start(0.0, 0.0, 0.0, e)
    z_ref = np.array([0.0, 0.0, 1.0])
    for deg in np.linspace(0.0, 50.0, 11):
        a = math.radians(deg)
        C = np.array(
            [[1.0, 0.0, 0.0], [0.0, math.cos(a), -math.sin(a)], [0.0, math.sin(a), math.cos(a)]]
        )
        E.excursion_add(C, 0.0, 0.0, 0.0, z_ref, e)
    assert math.degrees(e[EX_DEV]) == pytest.approx(50.0, abs=1e-12)
    assert e[EX_DEV + 1] == 0.0 and e[EX_DEV + 2] == 0.0
    assert math.degrees(math.acos(e[EX_COS_TILT])) == pytest.approx(50.0, abs=1e-9)
