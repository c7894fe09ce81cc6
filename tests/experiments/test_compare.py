"""Comparison of a simulated run with a flight log (synthetic logs; a real log if present)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadimpact import WallApproach, simulate
from quadimpact.experiments.compare import GROUPS, Comparison, compare, log_response
from quadimpact.experiments.logs import FlightLog, data_dir
from quadimpact.experiments.spiri_mat import SpiriMatLog

from synthetic_log import synthetic_log

WINDOWS = (0.3, 0.5)


@pytest.fixture(scope="module")
def run():
    return simulate(WallApproach(heading_deg=10, inclination_deg=15, speed_m_s=1.0,
                                 final_time_s=1.0))  # fmt: skip


def test_synthetic_log_has_the_log_interface(run):
    log = synthetic_log(run)
    assert isinstance(log, FlightLog)
    assert log.impact_time_s == pytest.approx(run.summary["first_contact_s"])
    for name, table in log.signals.items():
        assert "t_s" in table.columns, name
    mot = log.motors()
    assert [f"off{j}" for j in range(1, 5)] == list(mot.columns[-4:])
    pre = log.pre_impact()
    assert pre.speed_m_s == pytest.approx(1.0, abs=1e-6)
    assert pre.heading_deg == pytest.approx(10.0, abs=1e-4)
    assert pre.inclination_deg == pytest.approx(15.0, abs=1e-4)


def test_run_against_itself_has_zero_error(run):
    c = compare(run, synthetic_log(run), windows=WINDOWS)
    assert isinstance(c, Comparison)
    table = c.table()
    assert set(table["group"]) == set(GROUPS)
    assert sorted(set(table["window_s"])) == list(WINDOWS)
    for group in ("position", "attitude", "rates", "motors"):
        for w in WINDOWS:
            row = table[(table.group == group) & (table.quantity == "all") & (table.window_s == w)]
            assert int(row["n"].iloc[0]) > 0
    assert np.nanmax(table["rms"]) <= 1e-9
    assert np.nanmax(table["max_abs"]) <= 1e-9
    assert c.error("attitude", 0.5, "rotation") <= 1e-9


def test_constant_offsets_give_their_own_size(run):
    log = synthetic_log(run, offsets={"roll_deg": 2.0, "omega1_rad_s": 10.0})
    c = compare(run, log, windows=WINDOWS)
    for w in WINDOWS:
        assert c.error("attitude", w, "roll") == pytest.approx(2.0, abs=1e-9)
        assert c.error("attitude", w, "roll", "max_abs") == pytest.approx(2.0, abs=1e-9)
        assert c.error("attitude", w, "pitch") == pytest.approx(0.0, abs=1e-9)
        # group RMS over roll, pitch, yaw samples alike: sqrt(2^2 / 3)
        assert c.error("attitude", w) == pytest.approx(math.sqrt(4.0 / 3.0), abs=1e-9)
        assert c.error("motors", w, "omega1") == pytest.approx(10.0, abs=1e-9)
        assert c.error("position", w) == pytest.approx(0.0, abs=1e-9)
        assert c.error("rates", w) == pytest.approx(0.0, abs=1e-9)


def test_time_shifted_copy_gives_the_expected_error(run):
    """The log's samples delayed by d (impact time kept): X error = dX(tau) - dX(tau - d)."""
    d = 0.005
    c = compare(run, synthetic_log(run, time_shift_s=d), windows=WINDOWS)
    ts = run.timeseries
    t0 = run.summary["first_contact_s"]
    for w in WINDOWS:
        # the log's samples: tau = t_sim + d - t0 in [0, w]
        tau = ts["t_s"].to_numpy() + d - t0
        tau = tau[(tau >= 0) & (tau <= w)]

        def x_at(s):
            return np.interp(s + t0, ts["t_s"], ts["x_m"])

        sim_rel = x_at(tau) - x_at(0.0)
        log_rel = x_at(tau - d) - x_at(-d)
        expected = np.sqrt(np.mean((sim_rel - log_rel) ** 2))
        assert expected > 1e-4
        assert c.error("position", w, "X") == pytest.approx(expected, rel=1e-6)
        assert c.error("attitude", w) > 0.0


def test_log_response_of_a_synthetic_log_matches_the_run(run):
    resp = log_response(synthetic_log(run))
    assert resp.type == run.summary["response_type"]
    assert set(resp.leading_bumpers) == set(run.summary["leading_bumpers"])


def test_timeseries_input_needs_the_impact_time(run):
    with pytest.raises(ValueError):
        compare(run.timeseries, synthetic_log(run))
    c = compare(run.timeseries, synthetic_log(run), t_impact_sim=run.summary["first_contact_s"])
    assert c.error("position", 0.3) <= 1e-9
    assert c.sim_response is None


def test_plot_is_written(run, tmp_path):
    c = compare(run, synthetic_log(run, offsets={"pitch_deg": 3.0}))
    out = c.plot(tmp_path / "cmp.png")
    assert out.exists() and out.stat().st_size > 10_000


@pytest.mark.data
def test_real_log_comparison_runs(tmp_path):
    log = SpiriMatLog(data_dir() / "spiri-crash-set-1" / "crash_5.mat", front_first=True)
    pre = log.pre_impact()
    scenario = WallApproach(heading_deg=pre.heading_deg, inclination_deg=pre.inclination_deg,
                            speed_m_s=pre.speed_m_s, altitude_m=pre.altitude_m,
                            final_time_s=1.2)  # fmt: skip
    c = compare(simulate(scenario), log)
    t = c.table()
    pos = t[(t.group == "position") & (t.quantity == "all")]
    assert (pos["n"] > 10).all() and np.isfinite(pos["rms"]).all()
    assert c.log_response is not None and c.log_response.type in {"B", "unknown"}
    assert not c.notes  # like with like: no heading warning
    c.plot(tmp_path / "real.png")


def test_angles_are_unwrapped_onto_one_branch():
    """A yaw that crosses +-180 deg: the log is drawn and compared on the run's branch."""
    run = simulate(WallApproach(heading_deg=179, inclination_deg=10, speed_m_s=0.5,
                                final_time_s=1.0))  # fmt: skip
    assert np.abs(np.diff(run.timeseries["yaw_deg"])).max() > 350  # wrapped: it jumps a turn
    c = compare(run, synthetic_log(run, offsets={"yaw_deg": 5.0}), windows=WINDOWS)
    log_yaw = c.log_pose["yaw_deg"].to_numpy()
    assert np.abs(np.diff(log_yaw)).max() < 30  # continuous, as plotted
    sim_yaw = np.interp(c.log_pose["tau_s"], c.sim["tau_s"], c.sim["yaw_deg"])
    inside = (c.log_pose["tau_s"] >= c.sim["tau_s"].min()).to_numpy()
    np.testing.assert_allclose((log_yaw - sim_yaw)[inside], 5.0, atol=1e-6)
    for w in WINDOWS:
        assert c.error("attitude", w, "yaw", "max_abs") == pytest.approx(5.0, abs=1e-6)
    # a log a whole turn off is the same attitude: no error
    turned = compare(run, synthetic_log(run, offsets={"yaw_deg": 360.0}), windows=WINDOWS)
    assert turned.error("attitude", 0.5, "yaw", "max_abs") == pytest.approx(0.0, abs=1e-6)
    sim_dep, log_dep = c.departures(0.5)["yaw"]
    assert sim_dep == pytest.approx(log_dep, abs=1e-6) and abs(sim_dep) > 1  # across 180


def test_errors_beyond_half_a_turn_are_not_folded_back():
    """A logged roll that turns away from the run's, 400 deg/s, wrapped as a log is: at
    0.5 s it is 200 deg apart (unwrapped), not 160."""
    from quadimpact.rotations import wrap_angle_deg

    from synthetic_log import SyntheticLog

    run = simulate(WallApproach(heading_deg=10, inclination_deg=15, speed_m_s=1.0,
                                final_time_s=1.0))  # fmt: skip
    ts = run.timeseries.copy()
    t0 = run.summary["first_contact_s"]
    ts["roll_deg"] = wrap_angle_deg(ts["roll_deg"] + 400.0 * np.clip(ts["t_s"] - t0, 0.0, None))
    c = compare(run, SyntheticLog(ts, t0), windows=WINDOWS)
    assert c.error("attitude", 0.5, "roll", "max_abs") == pytest.approx(200.0, abs=1e-6)
