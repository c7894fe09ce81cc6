"""Wall approach: attitude mapping, the approach solver, convergence, the paper's example."""

import math

import numpy as np
import pytest

from quadimpact import WallApproach, simulate
from quadimpact.rotations import euler_zyx_to_quat, quat_to_matrix
from quadimpact.simulation.approach import inclination_deg_of, wall_attitude


@pytest.mark.parametrize("heading", [0.0, 30.0, 45.0, -45.0, 90.0])
@pytest.mark.parametrize("incl", [-20.0, 0.0, 15.0])
def test_exact_attitude_puts_thrust_in_the_x_z_plane(heading, incl):
    roll, pitch, yaw = wall_attitude(heading, incl)
    q = euler_zyx_to_quat(roll, pitch, yaw)
    z = quat_to_matrix(q)[:, 2]
    assert yaw == pytest.approx(math.radians(heading))
    assert z[1] == pytest.approx(0.0, abs=1e-15)
    assert inclination_deg_of(q) == pytest.approx(incl, abs=1e-12)


def test_paper_fit_mapping_is_the_authors():
    assert wall_attitude(0.0, 12.0, "paper-fit") == pytest.approx((0.0, -math.radians(12), 0.0))
    a = -(math.radians(15) - 0.0042477) / 1.3836686
    assert wall_attitude(45.0, 15.0, "paper-fit") == pytest.approx((a, a, math.pi / 4))


@pytest.mark.parametrize(
    "kw, late",
    [
        ({"heading_deg": 45, "inclination_deg": 5, "speed_m_s": 1.0}, False),
        ({"heading_deg": 0, "inclination_deg": -10, "speed_m_s": 0.75}, False),
        ({"heading_deg": 45, "inclination_deg": 15, "speed_m_s": 0.5}, True),
        ({"heading_deg": 0, "inclination_deg": 20, "speed_m_s": 0.5}, True),
    ],
)
@pytest.mark.parametrize("model", ["default", "paper-replica"])
def test_approach_hits_impact_time_and_speed(kw, late, model):
    r = simulate(WallApproach(**kw, model=model))
    s = r.summary
    assert s["first_contact_s"] == pytest.approx(0.5, abs=1e-6)
    assert s["impact_speed_m_s"] == pytest.approx(kw["speed_m_s"], abs=1e-6)
    if model == "default":
        assert s["approach"]["late_start"] is late
        if late:
            assert 0.0 < s["t_start_s"] < 0.5
            assert s["approach"]["start_speed_m_s"] == 0.0
            assert r.timeseries["t_s"].iloc[0] == pytest.approx(s["t_start_s"])
        else:
            assert s["t_start_s"] == 0.0 and s["approach"]["start_speed_m_s"] > 0.0
    elif not s["approach"]["late_start"]:  # the authors start at t = 0
        assert s["t_start_s"] == 0.0
    # nothing touched the wall before T_c
    before = r.timeseries[r.timeseries["t_s"] < 0.5 - 1e-6]
    assert before[["delta1_m", "delta2_m", "delta3_m", "delta4_m"]].to_numpy().max() == 0.0


@pytest.mark.parametrize("model", ["default", "paper-replica"])
def test_delta_init_converges_under_tighter_tolerances(model):
    base = {"heading_deg": 45, "inclination_deg": 15, "speed_m_s": 0.75, "model": model}
    d = simulate(WallApproach(**base)).summary["delta_init_m"]
    d_tight = simulate(WallApproach(**base, rtol=1e-9, atol=1e-11)).summary["delta_init_m"]
    assert abs(d_tight - d) / d < 1e-4
    assert abs(d_tight - d) / d < 1e-7  # what the defaults actually achieve


def test_paper_example_replica_reproduces_figure_5():
    r = simulate(
        WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75, model="paper-replica")
    )
    s, ep = r.summary, r.episodes
    assert s["status"] == "crashed" and s["crash_time_s"] is not None
    assert s["leading_bumpers"] == [4]
    assert 0.02 < s["delta_init_m"] < 0.08  # "a few centimetres"
    later = ep[ep["t_start_s"] > ep["t_end_s"].iloc[0]]
    big = later[later["peak_delta_m"] > 0.02]
    small = later[later["peak_delta_m"] <= 0.02]
    # the large subsequent impacts alternate between the aft bumper 2 and bumper 4
    seq = big["bumper"].tolist()
    assert seq[0] == 2 and set(seq) == {2, 4}
    assert all(a != b for a, b in zip(seq, seq[1:], strict=False))
    assert len(seq) >= 3
    # the side bumpers 1 and 3 only touch lightly
    assert set(small["bumper"]) <= {1, 3} and len(small) >= 1
    # type D: the first subsequent impact is aft-only, two or more subsequent episodes
    assert s["subsequent_impacts"][0][0] == 2
    assert set(s["subsequent_impacts"][0]) <= set(s["aft_bumpers"]) == {1, 2, 3}
    assert s["n_subsequent_episodes"] >= 2
    # the authors' start: at t = 0, first moving away from the wall
    assert s["t_start_s"] == 0.0 and s["approach"]["start_speed_m_s"] < 0.0
    # Figure 6: Y stays put, the altitude holds ~0.3 s after impact then falls
    ts = r.timeseries
    assert np.max(np.abs(ts["y_m"])) < 0.05
    h_03 = np.interp(0.8, ts["t_s"], ts["altitude_m"])
    assert h_03 > 1.8 and ts["altitude_m"].iloc[-1] < 0.0


def test_paper_example_default_variant_same_initial_impact():
    kw = {"heading_deg": 45, "inclination_deg": 15, "speed_m_s": 0.75}
    rep = simulate(WallApproach(**kw, model="paper-replica")).summary
    dft = simulate(WallApproach(**kw, model="default")).summary
    assert dft["leading_bumpers"] == [4]
    assert dft["delta_init_m"] == pytest.approx(rep["delta_init_m"], rel=0.03)
    # the run says what it does after the initial impact
    assert "subsequent impact" in dft["outcome"]
    assert dft["status"] in ("crashed", "completed")
    assert ("crashed at" in dft["outcome"]) == (dft["status"] == "crashed")


def test_heading_zero_two_bumpers_touch_together():
    r = simulate(WallApproach(heading_deg=0, inclination_deg=5, speed_m_s=0.75))
    ep = r.episodes
    # both front bumpers start within 1e-4 s (the Spiri is not exactly symmetric)
    first = ep[ep["t_start_s"] < 0.5 + 1e-4]
    assert sorted(first["bumper"]) == [1, 4]
    assert r.summary["leading_bumpers"] == [1, 4]
    # the two peak deflections are nearly equal (the vehicle is nearly symmetric)
    assert first["peak_delta_m"].iloc[0] == pytest.approx(first["peak_delta_m"].iloc[1], rel=0.02)


def test_public_simulate_is_the_function_after_submodule_imports():
    import quadimpact
    import quadimpact.simulation  # noqa: F401  (the module must not shadow the function)
    from quadimpact import simulate as sim

    assert callable(sim) and sim is quadimpact.simulation.simulate
