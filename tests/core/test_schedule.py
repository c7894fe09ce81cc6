"""Motor power-off schedules drive the rotors exactly: rates, zero floor, segment joins,
a zero rate switching the motor off (or holding it), the authors' one-tick motor cut."""

import numpy as np
import pytest

from quadimpact import FlightScenario, WallApproach, simulate

RPM = 2 * np.pi / 60
STARTS = [0.0, 0.05, 0.12]
RATES_RPM_S = [[-30000, -10000, 20000, -60000], [-200000, 50000, -10000, 0], [0, -300000, 0, 10000]]


def expected_speeds(t, t_p, w0, zero_rate="off"):
    """Piecewise-linear schedule with a zero floor, integrated by hand (rad/s); a rate of
    exactly 0 switches the motor off from its segment's start (``zero_rate="off"``)."""
    w = np.array(w0, dtype=float)
    out = np.empty((len(t), 4))
    bounds = [t_p + s for s in STARTS] + [np.inf]
    for n, tn in enumerate(t):
        w_t = np.array(w0, dtype=float)
        if tn > t_p:
            w_t = w.copy()
            for k in range(len(STARTS)):
                a, b = bounds[k], min(bounds[k + 1], tn)
                if b <= a:
                    break
                rate = np.array(RATES_RPM_S[k]) * RPM
                if zero_rate == "off":
                    w_t = np.where(rate == 0.0, 0.0, w_t)
                # with a zero floor: a falling motor stops at 0, a rising one starts again
                w_t = np.where((w_t <= 0) & (rate < 0), 0.0, np.maximum(w_t + rate * (b - a), 0.0))
        out[n] = w_t
    return out


@pytest.mark.parametrize("zero_rate", ["off", "hold"])
def test_schedule_drives_the_rotors_exactly(zero_rate):
    w0 = (600.0, 600.0, 600.0, 600.0)
    t_p = 0.1025  # between two control ticks: the speeds held since 0.1 s are the start
    power_off = {"trigger": t_p, "segment_start_s": STARTS, "rates_rpm_per_s": RATES_RPM_S,
                 "zero_rate": zero_rate}  # fmt: skip
    r = simulate(FlightScenario(rotor_speeds_rad_s=w0, final_time_s=0.4, power_off=power_off))
    ts = r.timeseries
    assert r.summary["power_off_time_s"] == pytest.approx(t_p)
    t = ts["t_s"].to_numpy()
    got = ts[[f"omega{j}_rad_s" for j in range(1, 5)]].to_numpy()
    after = t > t_p + 1e-12
    np.testing.assert_allclose(
        got[after], expected_speeds(t[after], t_p, got[~after][-1], zero_rate), atol=1e-8
    )
    # every motor of this schedule reaches the floor and none goes below it
    assert got.min() == 0.0
    assert np.all((got[after] == 0.0).any(axis=0) | (got[after][-1] > 0))
    # the controller still runs (its commands change) but no longer moves the rotors
    cmd = ts[[f"omega_cmd{j}_rad_s" for j in range(1, 5)]].to_numpy()
    assert np.ptp(cmd[after], axis=0).max() > 1.0


def test_first_contact_triggers_the_power_off():
    r = simulate(
        WallApproach(
            heading_deg=45,
            inclination_deg=5,
            speed_m_s=1.0,
            final_time_s=1.0,
            power_off={"segment_start_s": [0.0], "rates_rpm_per_s": [[-20000] * 4]},
        )
    )
    s = r.summary
    assert s["power_off_time_s"] == pytest.approx(s["first_contact_s"], abs=1e-12)
    ts = r.timeseries
    cols = [f"omega{j}_rad_s" for j in range(1, 5)]
    w_p = ts[ts["t_s"] <= s["first_contact_s"]][cols].iloc[-1].max()
    stop = s["first_contact_s"] + w_p / (20000 * RPM)
    assert (ts[ts["t_s"] >= stop + 1e-6][cols].to_numpy() == 0.0).all()
    assert (ts[ts["t_s"] <= stop - 1e-3][cols].to_numpy() > 0.0).any(axis=1).all()


def test_a_zero_rate_segment_stops_the_motor():
    """Motor 4's zero rate in segment 1 stops it at that segment's start (the crash data: a
    zero rate is the motor powered off over the segment); segment 2's rise starts it again
    from 0. Motor 2 is off from the trigger. Read with ``zero_rate = "hold"`` both keep their
    speeds over their zero-rate segments."""
    t_p = 0.1025
    starts = [0.0, 0.0333, 0.08]
    rates = [[-1000.0, 0.0, -1000.0, -2000.0], [-1000.0, -0.0, -1000.0, 0.0],
             [-1000.0, 5000.0, -1000.0, 5000.0]]  # fmt: skip
    runs = {}
    for zero_rate in ("off", "hold"):
        runs[zero_rate] = simulate(FlightScenario(
            rotor_speeds_rad_s=(600.0,) * 4, final_time_s=0.3,
            power_off={"trigger": t_p, "segment_start_s": starts, "rates_rpm_per_s": rates,
                       "zero_rate": zero_rate},
        )).timeseries  # fmt: skip
    ts = runs["off"]
    t = ts["t_s"].to_numpy()
    w2, w4 = ts["omega2_rad_s"].to_numpy(), ts["omega4_rad_s"].to_numpy()
    seg1, seg2 = t_p + starts[1], t_p + starts[2]
    assert (w2[(t > t_p + 1e-9) & (t <= seg2)] == 0.0).all() and (w2[t < t_p] > 500.0).all()
    assert (w4[(t > seg1 + 1e-9) & (t <= seg2)] == 0.0).all()
    rise = t > seg2
    np.testing.assert_allclose(w4[rise], 5000.0 * RPM * (t[rise] - seg2), atol=1e-8)
    before = (t > t_p + 1e-3) & (t < seg1 - 1e-3)
    assert (w4[before] > 0.0).all()
    held = runs["hold"]
    w4h = held["omega4_rad_s"].to_numpy()
    k = np.searchsorted(t, seg1) - 1
    w_seg1 = w4h[k] - 2000.0 * RPM * (seg1 - t[k])  # its speed when segment 1 starts
    assert w4h[(t > seg1) & (t < seg2)] == pytest.approx(w_seg1, abs=1e-9)
    w2h = held["omega2_rad_s"].to_numpy()
    assert w2h[(t > t_p) & (t <= seg2)] == pytest.approx(w2h[np.searchsorted(t, t_p) - 1])
    assert w2h[-1] > 600.0  # held, then rising at 5000 rpm/s
