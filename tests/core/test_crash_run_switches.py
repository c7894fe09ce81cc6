"""The switches of the authors' crash runs each change exactly what they name.

* ``cut_step_motors``: the motor keeps its speed from the power-off trigger to the
  next control tick, is then at 0, and the spin-up reaction of that one-tick step
  (``Jr Omega / dt`` for 5 ms) kicks the yaw rate by ``Jr Omega / Izz``;
* ``crash_rule = "ground-ticks"``: the crash at the first control tick with the CM
  at or below the ground, the start itself not tested;
* ``bumper_force_scale``: that bumper's contact force times the factor, the
  others' unchanged.
"""

import math

import numpy as np
import pytest

from quadimpact import FlightScenario, WallApproach, simulate
from quadimpact.core import feature_slots as FS
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.contact import contact_wrench
from quadimpact.core.contact_slots import CS_ACTIVE, CS_LAMBDA, NCS
from quadimpact.simulation.setup import prepare

T_P = 0.1025  # between the ticks at 0.100 and 0.105 s
DT = 0.005
W0 = 600.0


def _free_flight(cut: tuple[int, ...], model: str = "default"):
    """Hovering rotors; from T_P motor 2 off (zero rate), the others falling slowly."""
    return simulate(FlightScenario(
        rotor_speeds_rad_s=(W0,) * 4, final_time_s=0.14, output_rate_hz=20000, model=model,
        model_options={"cut_step_motors": cut},
        power_off={"trigger": T_P, "segment_start_s": [0.0],
                   "rates_rpm_per_s": [[-1000.0, 0.0, -1000.0, -1000.0]]},
    )).timeseries  # fmt: skip


@pytest.mark.parametrize("model", ["default", "paper-replica"])
def test_cut_step_holds_the_motor_to_the_next_tick_then_kicks_the_yaw(model):
    plain, cut = _free_flight((), model), _free_flight((2,), model)
    t = cut["t_s"].to_numpy()
    before = t < T_P
    assert cut[before].equals(plain[before])
    for j in (1, 3, 4):  # the schedule alone drives the others (dense output: to rounding)
        col = f"omega{j}_rad_s"
        np.testing.assert_allclose(cut[col].to_numpy(), plain[col].to_numpy(), rtol=1e-14)
    w2 = cut["omega2_rad_s"].to_numpy()
    held = w2[t < T_P][-1]
    assert (w2[(t > T_P) & (t < T_P + 0.0025 - 1e-9)] == held).all()  # to the tick at 0.105
    assert (w2[t >= 0.105] == 0.0).all()
    assert (plain["omega2_rad_s"].to_numpy()[t > T_P] == 0.0).all()  # off at the trigger
    # the kick: +Jr Omega / dt about z_B over [0.105, 0.110] (motor 2 spins +z_B, so the
    # physical -s Jr dOmega/dt and the replica's -Jr dOmega/dt agree), nothing after
    r_cut, r_plain = cut["r_rad_s"].to_numpy(), plain["r_rad_s"].to_numpy()
    veh = prepare(FlightScenario()).veh
    izz, jr = veh[VS.V_INERTIA + 8], veh[VS.V_JR]

    def gain(r, a, b):
        return np.interp(b, t, r) - np.interp(a, t, r)

    kick = gain(r_cut, 0.105, 0.110) - gain(r_plain, 0.105, 0.110)
    assert kick == pytest.approx(jr * held / izz, rel=0.03)
    after = gain(r_cut, 0.110, 0.115) - gain(r_plain, 0.110, 0.115)
    assert abs(after) < 0.03 * abs(kick)


def _falling(rule: str, **fields):
    """Every motor off at t = 0.0125 s (a zero rate): a free fall from 0.4 m."""
    return simulate(FlightScenario(
        position_m=(0.0, 0.0, -0.4), final_time_s=1.0, model_options={"crash_rule": rule},
        power_off={"trigger": 0.0125, "segment_start_s": [0.0], "rates_rpm_per_s": [[0.0] * 4]},
        **fields,
    ))  # fmt: skip


def test_ground_tick_crash_is_the_first_tick_at_or_below_the_ground():
    exact, ticks, paper = (_falling(r) for r in ("cm-ground", "ground-ticks", "paper-ticks"))
    t_exact = exact.summary["crash_time_s"]
    assert t_exact == pytest.approx(0.0125 + math.sqrt(2 * 0.4 / 9.81), abs=2e-3)
    t_tick = ticks.summary["crash_time_s"]
    assert t_tick == pytest.approx(math.ceil(t_exact / DT - 1e-9) * DT, abs=1e-12)
    assert ticks.summary["crash_position_m"][2] >= 0.0  # at or below the ground (NED)
    ts = ticks.timeseries
    t = ts["t_s"].to_numpy()
    assert np.interp(t_tick - DT, t, ts["altitude_m"].to_numpy()) > 0.0
    # the same flight up to the exact crash; the paper's rule waits for -0.3 m
    n = int((exact.timeseries["t_s"] < t_exact).sum())
    assert exact.timeseries.iloc[:n].equals(ts.iloc[:n])
    assert paper.summary["crash_time_s"] > t_tick + 0.05
    assert paper.summary["crash_position_m"][2] >= 0.3


def test_ground_tick_crash_is_not_tested_at_the_start():
    s = simulate(
        WallApproach(
            start_altitude_m=0.0,
            altitude_m=1.0,
            speed_m_s=0.5,
            final_time_s=0.6,
            model_options={"crash_rule": "ground-ticks"},
        )
    )
    assert s.summary["crash_time_s"] is None and s.summary["first_contact_s"] == pytest.approx(0.5)
    assert s.timeseries["altitude_m"].iloc[0] == 0.0


def test_bumper_force_scale_scales_that_bumper_only():
    """Bumpers 2 and 3 in the wall (rear first): the wrench with bumper 2's force doubled is
    bumper 3's plus twice bumper 2's (the factor is the feature table's ``F_FORCE_SCALE``)."""
    setup = prepare(WallApproach(heading_deg=180.0, inclination_deg=5.0))
    x = setup.x0.copy()
    x[L.X_POS] += setup.wall.point_m[0] - x[L.X_POS] - 0.06  # CM 6 cm from the wall
    from quadimpact.rotations import quat_to_matrix

    C = np.ascontiguousarray(quat_to_matrix(x[L.X_QUAT : L.X_QUAT + 4]))
    assert (setup.feat[:, FS.F_FORCE_SCALE] == 1.0).all()

    def wrench(active, scale=(1.0, 1.0, 1.0, 1.0)):
        m = setup.model()
        cs = np.zeros((m.pairs.shape[0], NCS))
        for j in active:
            cs[j, CS_ACTIVE] = 1.0
            cs[j, CS_LAMBDA] = 3.0
        feat = m.feat.copy()
        feat[:, FS.F_FORCE_SCALE] = scale
        return np.array(contact_wrench(x, C, m._replace(feat=feat), cs))

    both, b2, b3 = wrench((1, 2)), wrench((1,)), wrench((2,))
    assert np.abs(b2).max() > 1.0 and np.abs(b3).max() > 1.0  # both bumpers in the wall
    np.testing.assert_allclose(both, b2 + b3, rtol=1e-12)
    np.testing.assert_allclose(wrench((1, 2), (1.0, 2.0, 1.0, 1.0)), 2 * b2 + b3, rtol=1e-12)
    np.testing.assert_array_equal(wrench((1, 2), (0.0, 0.0, 0.0, 0.0)), both)  # 0: unscaled


def test_bumper_force_scale_is_packed_into_the_feature_table():
    o = {"bumper_force_scale": (1.0, 2.0, 1.0, 1.0)}
    feat = prepare(WallApproach(heading_deg=180.0, model_options=o)).feat
    np.testing.assert_array_equal(feat[:, FS.F_FORCE_SCALE], [1.0, 2.0, 1.0, 1.0])
    plain = prepare(WallApproach(heading_deg=180.0)).feat
    same = [i for i in range(FS.NFEAT) if i != FS.F_FORCE_SCALE]
    np.testing.assert_array_equal(feat[:, same], plain[:, same])


def test_bumper_force_scale_in_a_run():
    """The run is the same until bumper 2 touches; from then its recorded force is doubled
    at (nearly) the same deflection: 20 us after the onset, where the runs still agree."""
    runs = [simulate(WallApproach(heading_deg=180.0, inclination_deg=5.0, final_time_s=0.52,
                                  output_rate_hz=100000,
                                  model_options={"bumper_force_scale": s}))
            for s in ((1.0, 1.0, 1.0, 1.0), (1.0, 2.0, 1.0, 1.0))]  # fmt: skip
    a, b = (r.timeseries for r in runs)
    onset = runs[0].summary["first_contact_s"]
    assert a[a["t_s"] <= onset].equals(b[b["t_s"] <= onset])
    k = int(np.searchsorted(a["t_s"].to_numpy(), onset + 2e-5))
    assert a["delta2_m"].iloc[k] == pytest.approx(b["delta2_m"].iloc[k], rel=1e-5)
    assert b["force2_n"].iloc[k] == pytest.approx(2 * a["force2_n"].iloc[k], rel=1e-4)
    assert b["force3_n"].iloc[k] == pytest.approx(a["force3_n"].iloc[k], rel=1e-4, abs=1e-12)
