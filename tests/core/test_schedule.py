"""Motor power-off schedules drive the rotors exactly: rates, zero floor, segment joins."""

import numpy as np
import pytest

from quadimpact import FlightScenario, WallApproach, simulate

RPM = 2 * np.pi / 60
STARTS = [0.0, 0.05, 0.12]
RATES_RPM_S = [[-30000, -10000, 20000, -60000], [-200000, 50000, -10000, 0], [0, -300000, 0, 10000]]


def expected_speeds(t, t_p, w0):
    """Piecewise-linear schedule with a zero floor, integrated by hand (rad/s)."""
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
                # with a zero floor: a falling motor stops at 0, a rising one starts again
                w_t = np.where((w_t <= 0) & (rate < 0), 0.0, np.maximum(w_t + rate * (b - a), 0.0))
        out[n] = w_t
    return out


def test_schedule_drives_the_rotors_exactly():
    w0 = (600.0, 600.0, 600.0, 600.0)
    t_p = 0.1025  # between two control ticks: the speeds held since 0.1 s are the start
    r = simulate(
        FlightScenario(
            rotor_speeds_rad_s=w0,
            final_time_s=0.4,
            power_off={"trigger": t_p, "segment_start_s": STARTS, "rates_rpm_per_s": RATES_RPM_S},
        )
    )
    ts = r.timeseries
    assert r.summary["power_off_time_s"] == pytest.approx(t_p)
    t = ts["t_s"].to_numpy()
    got = ts[[f"omega{j}_rad_s" for j in range(1, 5)]].to_numpy()
    after = t > t_p + 1e-12
    np.testing.assert_allclose(
        got[after], expected_speeds(t[after], t_p, got[~after][-1]), atol=1e-8
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
