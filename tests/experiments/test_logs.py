"""Flight-log reader on the real Spiri crash set I (skipped without the shared data).

Table III of the paper (docs/STUDIES.md section 4) is the reference; the mapping of
log files to its rows is the crash set's ``paper_crash``. Where our estimate
and Table III disagree beyond the stated uncertainty the tests pin what the
data show instead, and docs/EXPERIMENTS.md explains the discrepancy:

- speed: ours is the CM speed toward the wall at the contact; the approach
  accelerates (2-6 m/s^2) and the paper's values match our speed about 0.1 s
  earlier (``speed_lookback_m_s``), so the contact speed is higher. Table III's
  +-0.01 m/s is not reachable from these data by any estimator of the paper's
  kind (``benchmarks/log_speed_estimators.py``: 464 band-limited
  differentiators, the best 0.095 m/s off), so the tests pin what the data
  support;
- inclination: ours (motion capture alone) is 12-17 deg larger than Table III
  for the three fast crashes (5-7); the measured acceleration supports ours;
- crash 1 (crash_3.mat): the motion capture shows no approach to the wall.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadimpact.experiments.log_estimates import (
    IMPACT_RATE_THRESHOLD,
    IMPACT_SEARCH_AFTER_S,
    IMPACT_SEARCH_BEFORE_S,
)
from quadimpact.experiments.logs import data_dir, rpm_to_rad_s
from quadimpact.experiments.spiri_mat import SpiriMatLog, crash_set_1

DATA = data_dir()
pytestmark = pytest.mark.data

# Table III: crash -> (heading deg, V_c m/s, inclination deg, inclination +-)
TABLE3 = {
    1: (20.0, 0.7, 4.5, 7.0),
    2: (10.0, 1.1, 4.4, 7.0),
    3: (14.0, 1.1, 6.8, 7.0),
    4: (14.0, 1.3, 11.0, 8.0),
    5: (11.0, 2.0, 15.0, 7.0),
    6: (4.0, 2.7, 16.0, 7.0),
    7: (11.0, 2.0, 19.0, 8.0),
}
HEADING_TOL_DEG = 6.4


def _table3_logs() -> dict[int, str]:
    if DATA is None:
        return {}
    return {int(v["paper_crash"]): v["log"] for v in crash_set_1(DATA).values()}


LOGS = _table3_logs()
CRASHES = sorted(TABLE3)


@pytest.fixture(scope="module")
def logs() -> dict[int, SpiriMatLog]:
    return {c: SpiriMatLog(DATA / LOGS[c]) for c in CRASHES}


def test_table3_mapping_covers_seven_crashes():
    assert sorted(LOGS) == CRASHES


@pytest.mark.parametrize("crash", CRASHES)
def test_impact_is_the_first_spike_near_the_power_off(logs, crash):
    log = logs[crash]
    acc = log.signals["accel"]
    t = acc["t_s"].to_numpy()
    mag = np.hypot(acc["x_raw"], acc["y_raw"]).to_numpy()
    k = int(np.flatnonzero(t == log.impact_time_s)[0])
    assert mag[k] > IMPACT_RATE_THRESHOLD  # a spike there
    assert mag[k - 1] <= IMPACT_RATE_THRESHOLD  # quiet just before
    assert log.impact_bracket_s == (t[k - 1], t[k])
    t_off = log.power_off_time_s
    assert t_off is not None
    assert t_off - IMPACT_SEARCH_BEFORE_S <= log.impact_time_s <= t_off + IMPACT_SEARCH_AFTER_S


@pytest.mark.parametrize("crash", CRASHES)
def test_impact_comes_before_the_landing(logs, crash):
    log = logs[crash]
    pre = log.pre_impact()
    # still flying at the impact: well above the crash bed (~0.3-0.4 m)
    assert pre.altitude_m > 0.7
    # the vehicle settles (on-board rates quiet) only well after the impact
    if log.rest_time_s is not None:
        assert log.rest_time_s > log.impact_time_s + 0.3


@pytest.mark.parametrize("crash", [c for c in CRASHES if c != 1])
def test_speed_at_contact_is_not_below_table3(logs, crash):
    """The contact is observed on the motion capture; V_c(contact) >= Table III - 0.05.

    Not within +-0.01 (the paper's stated uncertainty): the vehicle is still
    accelerating toward the wall and the paper's values match our speed
    LOOKBACK_S (0.1 s) before the contact to within 0.15 m/s.
    """
    pre = logs[crash].pre_impact()
    v_table = TABLE3[crash][1]
    assert pre.contact_observed and pre.method == "changepoint"
    assert pre.speed_m_s >= v_table - 0.05
    assert pre.speed_m_s <= v_table + 0.7
    assert abs(pre.speed_lookback_m_s - v_table) <= 0.15
    assert 0.0 < pre.uncertainty["speed_m_s"] < 0.15


@pytest.mark.parametrize("crash", CRASHES)
def test_heading_within_table3(logs, crash):
    """Every crash is flown rear-first; the equivalent front-first heading is Table III's."""
    pre = logs[crash].pre_impact()
    assert pre.rear_first
    assert abs(pre.heading_front_equiv_deg - TABLE3[crash][0]) <= HEADING_TOL_DEG
    assert pre.leading_bumper == 2  # starboard rear: the first motor to stall (but crash 1)


@pytest.mark.parametrize("crash", [1, 2, 3, 4])
def test_inclination_within_table3(logs, crash):
    pre = logs[crash].pre_impact()
    _, _, incl, tol = TABLE3[crash]
    assert abs(pre.inclination_deg - incl) <= tol


@pytest.mark.parametrize("crash", [5, 6, 7])
def test_inclination_of_the_fast_crashes_exceeds_table3(logs, crash):
    """Documented discrepancy (docs/EXPERIMENTS.md): 12-17 deg above Table III.

    The measured acceleration toward the wall alone needs a tilt of 14-36 deg
    (drag-free lower bound), beyond Table III's range for crashes 6 and 7.
    """
    pre = logs[crash].pre_impact()
    _, _, incl, tol = TABLE3[crash]
    assert incl + tol < pre.inclination_deg < incl + 25.0
    ax = pre.acceleration_m_s2[0]
    assert ax > 0.0
    assert pre.inclination_deg >= math.degrees(math.atan(ax / 9.81)) - 2.0


def test_crash_1_shows_no_wall_approach(logs):
    """crash_3.mat (Table III crash 1): at the on-board impact the motion capture
    puts the vehicle ~0.8 m short of the wall, moving at ~0.3 m/s along X."""
    pre = logs[1].pre_impact()
    assert not pre.contact_observed
    assert pre.method == "clock-offset"
    assert pre.speed_m_s < 0.5
    assert any("short of the set's wall plane" in n for n in pre.notes)


@pytest.mark.parametrize("crash", CRASHES)
def test_motor_power_off_marked_where_rpm_is_1(logs, crash):
    log = logs[crash]
    raw = log.signals["motors"]
    mot = log.motors()
    assert list(mot.columns[:5]) == ["t_s"] + [f"omega{j}_rad_s" for j in range(1, 5)]
    for j in range(1, 5):
        rpm = raw[f"rpm{j}"].to_numpy()
        off = mot[f"off{j}"].to_numpy()
        assert np.array_equal(off, rpm <= 1.0)
        assert off[rpm == 1.0].all()
        om = mot[f"omega{j}_rad_s"].to_numpy()
        assert np.isnan(om[off]).all()
        np.testing.assert_allclose(om[~off], rpm_to_rad_s(rpm[~off]))
    # the first power-off is at (or just after) the impact, on the impact's side
    first = mot[mot["t_s"] == log.power_off_time_s]
    assert first[[f"off{j}" for j in range(1, 5)]].to_numpy().any()


def test_front_first_view_turns_the_body_and_renumbers_the_motors():
    path = DATA / LOGS[6]
    a, b = SpiriMatLog(path), SpiriMatLog(path, front_first=True)
    pa, pb = a.pre_impact(), b.pre_impact()
    assert pa.rear_first and not pb.rear_first
    assert pb.heading_deg == pytest.approx(pa.heading_front_equiv_deg, abs=1e-6)
    assert pb.inclination_deg == pytest.approx(pa.inclination_deg, abs=1e-6)
    assert pb.roll_deg == pytest.approx(-pa.roll_deg, abs=1e-6)
    assert pb.pitch_deg == pytest.approx(-pa.pitch_deg, abs=1e-6)
    assert pb.speed_m_s == pytest.approx(pa.speed_m_s)
    assert pb.leading_bumper == 4
    ma, mb = a.motors(), b.motors()
    for j, k in ((1, 3), (2, 4), (3, 1), (4, 2)):
        assert np.array_equal(mb[f"off{j}"], ma[f"off{k}"])


def test_frames_at_rest_before_take_off():
    """crash_5.mat has motion capture on the floor before take-off: level, altitude ~0."""
    log = SpiriMatLog(DATA / "spiri-crash-set-1" / "crash_5.mat")
    pose = log.pose()
    rest = pose[pose["t_s"] < 5.0]
    assert len(rest) > 100
    assert abs(rest["altitude_m"].median()) < 0.03
    assert abs(rest["roll_deg"].median()) < 5.0 and abs(rest["pitch_deg"].median()) < 5.0
    # quaternion and Euler angles agree (ZYX, body FRD -> NED)
    from quadimpact.rotations import quat_to_euler_zyx

    r, p, y = quat_to_euler_zyx(pose[["q0", "q1", "q2", "q3"]].to_numpy())
    np.testing.assert_allclose(np.degrees(p), pose["pitch_deg"], atol=1e-6)
    d = (np.degrees(y) - pose["yaw_deg"] + 180.0) % 360.0 - 180.0
    np.testing.assert_allclose(d, 0.0, atol=1e-6)


def test_every_log_reads_and_its_time_bases_increase():
    for n in range(1, 13):
        log = SpiriMatLog(DATA / "spiri-crash-set-1" / f"crash_{n}.mat")
        for name, table in log.signals.items():
            assert "t_s" in table.columns, name
            assert np.all(np.diff(table["t_s"].to_numpy()) > 0), (n, name)
        assert math.isfinite(log.impact_time_s)
