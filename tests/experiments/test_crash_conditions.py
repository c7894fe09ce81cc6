"""The crashes at the authors' matched conditions, the replica's crash-run switches, and the
schedules' zero rates against the logs' powered-off marker."""

import numpy as np
import pytest

from quadimpact import FlightScenario, simulate
from quadimpact.core import vehicle_slots as VS
from quadimpact.experiments.crashes import (
    AUTHORS_THRUST_COEFFICIENT_N_PER_RPM2,
    HAND_MODIFICATION,
    MATCHED_APPROACH_OPTIONS,
    MATCHED_CONTACT_TIME_S,
    REPLICA_CRASH_SWITCHES,
    TABLE3,
    scenario_file,
)
from quadimpact.inputs.model import resolve_model_options
from quadimpact.packing.constants import RPM
from quadimpact.packing.vehicle_block import pack_vehicle
from quadimpact.rotations import euler_zyx_to_quat, quat_to_matrix

KEYS = ("crash_rule", "cut_step_motors", "bumper_force_scale")


@pytest.mark.parametrize(("number", "model"), [(3, "default"), (5, "default"),
                                               (5, "paper-replica")])  # fmt: skip
def test_matched_approach_arrives_climbing_and_drifting_at_the_matched_speed(number, model):
    """The authors' approach in every variant: a start at t = 0 at the start altitude with
    the rotors at level hover; at the first contact, 0.5 s later, the matched speed toward
    the wall and attitude, climbing and drifting as the same flight without the wall does."""
    crash = TABLE3[number - 1]
    m = crash.matched
    scenario = crash.scenario(model, "matched")
    r = simulate(scenario)
    s, ts = r.summary, r.timeseries
    t_c = s["first_contact_s"]
    assert ts["t_s"].iloc[0] == 0.0 and ts["vz_m_s"].iloc[0] == pytest.approx(0.0, abs=1e-12)
    v = scenario.build_vehicle()  # as flown: the replica's thrust coefficient included
    hover = np.sqrt(v.mass_kg * v.gravity_m_s2 / (4.0 * v.thrust_coefficient))
    for j in range(1, 5):
        assert ts[f"omega{j}_rad_s"].iloc[0] == pytest.approx(hover, rel=1e-12)
    assert t_c == pytest.approx(MATCHED_CONTACT_TIME_S, abs=1e-9)
    assert s["impact_speed_m_s"] == pytest.approx(m.speed_m_s, abs=1e-6)  # the wall's normal: X
    assert ts["altitude_m"].iloc[0] == pytest.approx(m.altitude_at_start_m, abs=1e-12)
    t = ts["t_s"].to_numpy()
    at = {c: float(np.interp(t_c, t, ts[c].to_numpy())) for c in ts.columns}
    assert at["vx_m_s"] == pytest.approx(m.speed_m_s, abs=1e-6)
    # the attitude held; the replica's spin-up reaction (no spin sign) turns the collective
    # step of the first tick into a yaw kick: its heading at the contact is 1.4 deg off here
    yaw_tolerance = 0.05 if model == "default" else 2.0
    for got, want, tol in ((at["roll_deg"], m.roll_deg, 0.1), (at["pitch_deg"], m.pitch_deg, 0.1),
                           (at["yaw_deg"], m.heading_deg, yaw_tolerance)):  # fmt: skip
        assert got == pytest.approx(want, abs=tol)
    climb, drift = -at["vz_m_s"], at["vy_m_s"]
    assert 0.2 < climb < 0.7 and m.altitude_at_start_m < at["altitude_m"] < m.altitude_setpoint_m
    # the drift: the held thrust's sideways share (inertial Y of -z_B), from rest sideways
    q = euler_zyx_to_quat(*np.radians([m.roll_deg, m.pitch_deg, m.heading_deg]))
    thrust_y = -quat_to_matrix(q)[1, 2]
    assert np.sign(drift) == np.sign(thrust_y) and abs(drift) > 0.2
    assert ts["vy_m_s"].iloc[0] == pytest.approx(0.0, abs=1e-12)  # from rest sideways
    # the same flight from the same start, without the wall: the same state at the contact
    x0 = ts.iloc[0]
    free = simulate(FlightScenario(
        position_m=(x0["x_m"], x0["y_m"], x0["z_m"]),
        velocity_m_s=(x0["vx_m_s"], x0["vy_m_s"], x0["vz_m_s"]),
        euler_deg=(m.roll_deg, m.pitch_deg, m.heading_deg),
        rotor_speeds_rad_s=tuple(x0[f"omega{j}_rad_s"] for j in range(1, 5)),
        altitude_ref_m=m.altitude_setpoint_m, final_time_s=t_c + 0.01, ground="none",
        model=model, model_options=scenario.model_options,
        vehicle_overrides=scenario.vehicle_overrides,
    )).timeseries  # fmt: skip
    for col in ("altitude_m", "vz_m_s", "vy_m_s", "y_m"):
        got = np.interp(t_c, free["t_s"].to_numpy(), free[col].to_numpy())
        assert got == pytest.approx(at[col], abs=1e-9), col


def test_matched_fields_hold_the_data_files_conditions():
    for crash in TABLE3:
        m = crash.matched
        s = crash.scenario("default", "matched")
        assert s.heading_deg == pytest.approx(m.yaw_from_wall_normal_deg - 180.0)  # rear first
        assert (s.speed_m_s, s.roll_deg, s.pitch_deg) == (m.speed_m_s, m.roll_deg, m.pitch_deg)
        assert (s.start_altitude_m, s.altitude_m) == (m.altitude_at_start_m,
                                                      m.altitude_setpoint_m)  # fmt: skip
        assert s.power_off == scenario_file(crash.number).power_off
        assert crash.scenario("default") == scenario_file(crash.number)  # nominal: the file


def test_each_replica_switch_changes_exactly_what_it_names():
    crash = TABLE3[4]  # motor 2 off from the contact
    base = crash.scenario("paper-replica", "matched", ())
    none = base.resolved_model_options().model_dump()
    assert base.vehicle_overrides == {} and base.model == "paper-replica"
    expected = {
        "ground_tick_crash": ({"crash_rule": "ground-ticks"}, {}),
        "thrust_coefficient": ({}, {"thrust_coefficient":
                                    AUTHORS_THRUST_COEFFICIENT_N_PER_RPM2 / RPM**2}),
        "motor2_cut_step": ({"cut_step_motors": (2,)}, {}),
    }  # fmt: skip
    assert set(expected) == set(REPLICA_CRASH_SWITCHES)
    for switch, (options, overrides) in expected.items():
        s = crash.scenario("paper-replica", "matched", [switch])
        got = s.resolved_model_options().model_dump()
        assert {k: v for k, v in got.items() if none[k] != v} == options, switch
        assert s.vehicle_overrides == overrides, switch
        assert s.model_copy(update={"model_options": base.model_options,
                                    "vehicle_overrides": {}}) == base  # fmt: skip
    # by default the replica's crash runs have all three, the default variant none
    full = crash.scenario("paper-replica", "matched").resolved_model_options()
    assert (full.crash_rule, full.cut_step_motors) == ("ground-ticks", (2,))
    assert crash.scenario("default", "matched").resolved_model_options() == (
        resolve_model_options("default", MATCHED_APPROACH_OPTIONS)
    )  # the default variant: the authors' approach (conditions), no crash-run switch
    assert crash.scenario("default").resolved_model_options() == resolve_model_options("default")
    # the packed vehicles differ in the thrust coefficient alone
    kt = crash.scenario("paper-replica", "matched", ["thrust_coefficient"]).build_vehicle()
    a, b = pack_vehicle(base.build_vehicle()), pack_vehicle(kt)
    assert np.flatnonzero(a != b).tolist() == list(range(VS.V_KT, VS.V_KT + 4))  # each rotor's kt
    assert b[VS.V_KT] * RPM**2 == pytest.approx(8.7e-8)


def test_motor2_cut_and_the_hand_modification_of_crash_1():
    """Crash 1's motor 2 runs (its log shows it): no cut, unless with the hand modification,
    which also doubles bumper 2's contact force; elsewhere the modification does nothing."""
    one = TABLE3[0]
    plain = one.scenario("paper-replica", "matched").resolved_model_options()
    assert plain.cut_step_motors == () and plain.bumper_force_scale == (1.0, 1.0, 1.0, 1.0)
    hand = one.scenario("paper-replica", "matched", [HAND_MODIFICATION]).resolved_model_options()
    assert hand.cut_step_motors == (2,) and hand.bumper_force_scale == (1.0, 2.0, 1.0, 1.0)
    two = TABLE3[1]
    assert two.scenario("paper-replica", "matched", [HAND_MODIFICATION]) == two.scenario(
        "paper-replica", "matched", ()
    )


@pytest.mark.data
def test_shipped_conditions_and_schedules_are_the_data_files():
    from quadimpact.experiments.spiri_mat import crash_set_1

    data = {int(c["paper_crash"]): c for c in crash_set_1().values()}
    for crash in TABLE3:
        c, m = data[crash.number], crash.matched
        assert c["log"] == crash.log_file
        assert (m.speed_m_s, m.roll_deg, m.pitch_deg, m.yaw_from_wall_normal_deg,
                m.altitude_at_start_m, m.altitude_setpoint_m) == (
            c["impact_speed_m_s"], c["roll_deg"], c["pitch_deg"], c["yaw_from_wall_normal_deg"],
            c["altitude_at_start_m"], c["altitude_setpoint_m"])  # fmt: skip
        po = scenario_file(crash.number).power_off
        assert list(po.segment_start_s) == c["segment_start_s"]
        assert [list(r) for r in po.rates_rpm_per_s] == c["rates_rpm_per_s"]
        assert po.stopped_motors == () and po.zero_rate == "off"


def _schedule_clock_offset(starts: np.ndarray, t_log: np.ndarray) -> float | None:
    """The shift putting the log's motor samples (time since its impact) on the schedule's
    clock: every segment start after the first falls on a sample (within 2 ms; the middle
    of the shifts that do it). None when no shift does."""
    fits = [d for d in np.arange(-0.2, 0.2, 1e-4)
            if all(np.min(np.abs(s - (t_log + d))) < 0.002 for s in starts[1:])]  # fmt: skip
    return float(np.median(fits)) if fits else None


@pytest.mark.data
@pytest.mark.slow
@pytest.mark.parametrize("zero_rate", ["off", "hold"])
def test_zero_rates_stop_the_motors_where_the_logs_read_powered_off(zero_rate):
    """A segment of the schedule runs from one of the log's motor samples to the next: the
    simulated motor is stopped over it exactly where the log's next sample reads its
    powered-off marker (<= 1 rpm), for every segment after the first up to the crash and
    every motor. Read the earlier way (a zero rate holding the speed), motors keep running
    where the logs read off."""
    from quadimpact.experiments.logs import data_dir
    from quadimpact.experiments.spiri_mat import SpiriMatLog

    checked, disagree = 0, 0
    for crash in TABLE3:
        log = SpiriMatLog(data_dir() / crash.log_file)
        raw = log._raw["motors"]
        t_log = raw["t_s"].to_numpy() - log.impact_time_s
        rpm = raw[["rpm1", "rpm2", "rpm3", "rpm4"]].to_numpy()  # the log's (real) motors
        base = crash.scenario("default")
        starts = np.asarray(base.power_off.segment_start_s)
        shift = _schedule_clock_offset(starts, t_log)
        if shift is None:  # crash 7: four segments, too few to place its clock
            assert crash.number == 7
            continue
        po = base.power_off.model_copy(update={"zero_rate": zero_rate})
        r = simulate(base.model_copy(update={"power_off": po}))
        ts, t_c = r.timeseries, r.summary["first_contact_s"]
        t_on = t_log + shift
        for start in starts[1:]:
            i = int(np.argmin(np.abs(t_on - start)))  # the segment's own sample
            mid = 0.5 * (start + t_on[i + 1])  # inside the segment, before the next sample
            if t_c + mid >= r.summary["crash_time_s"]:
                break
            for j in range(4):
                w = np.interp(t_c + mid, ts["t_s"], ts[f"omega{j + 1}_rad_s"])
                checked += 1
                disagree += (rpm[i + 1, j] <= 1.0) != (w == 0.0)
    assert checked > 80
    if zero_rate == "off":
        assert disagree == 0
    else:
        assert disagree > 0.25 * checked


def test_chaining_margin_names_the_overlap_a_type_hinges_on():
    """Crash 6's aft bumpers touch as the leading one leaves the wall: the classifier's
    chaining turns D into B within a few milliseconds (docs/STUDIES.md 2)."""
    import pandas as pd

    from quadimpact.simulation.response_types import closest_chaining

    eps = pd.DataFrame({
        "bumper": [2, 3, 1, 4], "surface": ["wall"] * 4,
        "t_start_s": [0.5, 0.5066, 0.6175, 0.6211], "t_end_s": [0.6199, 0.6152, 0.7179, 0.738],
        "peak_delta_m": [0.13, 0.11, 0.14, 0.16], "peak_force_n": [10.0] * 4,
    })  # fmt: skip
    c = closest_chaining(eps, crashed=True)
    assert c["bumper"] == 1 and c["joined"] and c["margin_s"] == pytest.approx(-0.0024)
    assert (c["type"], c["type_flipped"]) == ("B", "D")
    later = eps.assign(t_start_s=[0.5, 0.5066, 0.6205, 0.6211])
    c = closest_chaining(later, crashed=True)
    assert c["bumper"] == 1 and not c["joined"] and c["margin_s"] == pytest.approx(0.0006)
    assert (c["type"], c["type_flipped"]) == ("D", "B")
    assert closest_chaining(eps.iloc[:1], crashed=True) is None


def test_matched_approach_may_start_on_the_ground():
    """Crash 7's matched start is at altitude 0: no crash at the start (the tick test and the
    located crossing both look after it); it climbs into the wall."""
    for model in ("default", "paper-replica"):
        r = simulate(TABLE3[6].scenario(model, "matched"))
        assert r.timeseries["altitude_m"].iloc[0] == 0.0
        assert r.summary["first_contact_s"] == pytest.approx(0.5, abs=1e-9)
        assert r.summary["crash_time_s"] > 0.6


def test_offs_within_segment_move_only_the_switch_offs_after_the_contact():
    """Crash 5: motor 2 off from the contact, motor 3 from 82 ms, motor 4 from 197 ms,
    motor 1 from 374 ms; fraction 0 is the schedule itself, 1 keeps each motor running to
    its segment's end (the log's next sample) and nothing else changes."""
    from quadimpact.studies.table3.switch_runs import HELD_RATE_RPM_PER_S, offs_within_segment

    scenario = TABLE3[4].scenario("default", "matched")
    po = scenario.power_off
    assert offs_within_segment(po, 0.0) == po
    late = offs_within_segment(po, 1.0)
    # the ends are the next segments' starts (the last segment's: 0.1 s after its start)
    assert late.segment_start_s[:-1] == po.segment_start_s
    assert late.segment_start_s[-1] == pytest.approx(po.segment_start_s[-1] + 0.1)
    assert late.rates_rpm_per_s[-1] == po.rates_rpm_per_s[-1]
    for k, (was, now) in enumerate(zip(po.rates_rpm_per_s, late.rates_rpm_per_s, strict=False)):
        for j in range(4):
            first_off = k > 0 and was[j] == 0.0 and po.rates_rpm_per_s[k - 1][j] != 0.0
            assert now[j] == (HELD_RATE_RPM_PER_S if first_off else was[j]), (k, j)
    assert [r[2] for r in late.rates_rpm_per_s[:3]] == [-16292.6, HELD_RATE_RPM_PER_S, 0.0]
    assert late.rates_rpm_per_s[0][1] == 0.0  # motor 2: off from the contact, kept
    half = offs_within_segment(po, 0.5)
    mid = 0.5 * (po.segment_start_s[1] + po.segment_start_s[2])
    assert mid in half.segment_start_s and len(half.segment_start_s) > len(po.segment_start_s)
    # simulated: motor 3 runs at 0.15 s after the contact with the late offs only
    speeds = []
    for schedule in (po, late):
        r = simulate(scenario.model_copy(update={"power_off": schedule}))
        ts = r.timeseries
        speeds.append(np.interp(r.summary["first_contact_s"] + 0.15, ts["t_s"], ts["omega3_rad_s"]))
    assert speeds[0] == 0.0 and speeds[1] > 300.0
