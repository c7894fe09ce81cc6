"""Response types (docs/STUDIES.md 3) on hand-made episode lists, and on real runs."""

import pandas as pd
import pytest

from quadimpact import WallApproach, simulate
from quadimpact.simulation.metrics import GRAZE_IMPULSE_FRACTION, graze_mask, impact_metrics
from quadimpact.simulation.response_types import classify_response


def episodes(*rows):
    """rows: (bumper, t_start, t_end, peak_delta[, surface[, peak_force]])."""
    data = []
    for r in rows:
        b, t0, t1, d = r[:4]
        data.append(
            {
                "bumper": b,
                "surface": r[4] if len(r) > 4 else "wall",
                "t_start_s": t0,
                "t_end_s": t1,
                "v_i_m_s": 0.5,
                "peak_delta_m": d,
                "t_peak_s": t0,
                "peak_force_n": r[5] if len(r) > 5 else 1.0,
                "t_peak_force_s": t0,
                "open": False,
            }
        )
    return pd.DataFrame(data)


def rtype(eps, crashed):
    m = impact_metrics(eps, graze_fraction=GRAZE_IMPULSE_FRACTION)
    return classify_response(m["leading_bumpers"], m["subsequent_impacts"], crashed), m


def test_no_contact_at_all():
    assert rtype(episodes(), crashed=False)[0] == "A"
    assert rtype(episodes(), crashed=True)[0] == "Other"


def test_type_a_bounces_away_even_with_later_impacts():
    eps = episodes((4, 0.5, 0.7, 0.05), (4, 1.5, 1.6, 0.02))
    t, m = rtype(eps, crashed=False)
    assert t == "A" and m["n_subsequent_impacts"] == 1


def test_type_b_single_impact_then_crash():
    assert rtype(episodes((4, 0.5, 0.7, 0.05)), crashed=True)[0] == "B"


def test_type_b_with_simultaneous_two_bumper_impact():
    eps = episodes((1, 0.5, 0.64, 0.03), (4, 0.5, 0.64, 0.03))
    t, m = rtype(eps, crashed=True)
    assert t == "B" and m["leading_bumpers"] == [1, 4]


def test_type_d_figure_5_pattern():
    # leading 4; then aft 2 (with a light 3), 4, 1, 2, 4: alternating, sliding down
    eps = episodes(
        (4, 0.5, 0.7, 0.055),
        (2, 0.85, 0.94, 0.06),
        (3, 0.89, 0.93, 0.01),
        (4, 0.96, 1.05, 0.067),
        (1, 1.0, 1.04, 0.007),
        (2, 1.08, 1.16, 0.05),
    )
    t, m = rtype(eps, crashed=True)
    assert t == "D" and m["n_subsequent_impacts"] == 3


def test_type_d_after_two_bumper_initial_impact():
    eps = episodes(
        (1, 0.5, 0.6, 0.03), (4, 0.5, 0.6, 0.03), (2, 0.9, 1.0, 0.04), (3, 0.9, 1.0, 0.04)
    )
    assert rtype(eps, crashed=True)[0] == "D"


def test_single_aft_episode_then_crash_is_other():
    eps = episodes((4, 0.5, 0.7, 0.05), (2, 0.9, 1.0, 0.04))
    assert rtype(eps, crashed=True)[0] == "Other"


def test_type_c_extra_leading_hit_then_aft():
    eps = episodes(
        (4, 0.5, 0.7, 0.05), (4, 0.8, 0.85, 0.02), (2, 1.0, 1.1, 0.05), (4, 1.2, 1.3, 0.04)
    )
    t, m = rtype(eps, crashed=True)
    assert t == "C" and m["n_subsequent_impacts"] == 3


def test_type_c_aft_in_the_same_impact_after_the_leading_one():
    eps = episodes((4, 0.5, 0.7, 0.05), (4, 0.8, 0.95, 0.02), (2, 0.9, 1.0, 0.05))
    assert rtype(eps, crashed=True)[0] == "C"


def test_leading_hit_without_aft_follow_up_is_other():
    eps = episodes((4, 0.5, 0.7, 0.05), (4, 0.8, 0.85, 0.02), (4, 1.0, 1.1, 0.01))
    assert rtype(eps, crashed=True)[0] == "Other"


def test_grazes_are_not_impacts():
    # a light touch of bumper 2 (impulse scale 0.1 N x 0.01 s, 0.5 % of the
    # impact's 1 N x 0.2 s) after the impact does not make it D
    eps = episodes((4, 0.5, 0.7, 0.05), (2, 0.9, 0.91, 0.0002, "wall", 0.1))
    t, m = rtype(eps, crashed=True)
    assert t == "B" and m["n_grazes"] == 1 and m["n_episodes"] == 2
    # a graze that starts first is not the initial impact
    eps = episodes((1, 0.45, 0.46, 0.0001, "wall", 0.1), (4, 0.5, 0.7, 0.05))
    assert rtype(eps, crashed=True)[1]["leading_bumpers"] == [4]


def test_a_graze_is_small_in_impulse_not_in_depth():
    # bumpers 1000 times stiffer: every deflection under 1 mm, the same impulses;
    # the impact stays an impact (the old 1-mm rule made both episodes grazes)
    eps = episodes(
        (4, 0.5, 0.5002, 0.0004, "wall", 1000.0), (2, 0.9, 0.9002, 0.0003, "wall", 600.0)
    )
    t, m = rtype(eps, crashed=True)
    assert m["n_grazes"] == 0 and m["delta_init_m"] == 0.0004 and m["leading_bumpers"] == [4]
    assert t == "Other" and m["n_subsequent_impacts"] == 1
    # a deep but feeble contact (1 % of the impulse or less) is a graze
    eps = episodes((4, 0.5, 0.7, 0.05, "wall", 10.0), (2, 0.9, 0.92, 0.02, "wall", 0.9))
    assert list(graze_mask(eps, fraction=GRAZE_IMPULSE_FRACTION)) == [False, True]
    # ground episodes are never grazes, and never the reference
    eps = episodes((4, 0.5, 0.7, 0.05, "wall", 10.0), (1, 0.9, 1.9, 0.02, "ground", 100.0))
    assert list(graze_mask(eps, fraction=GRAZE_IMPULSE_FRACTION)) == [False, False]


def test_stiff_bumpers_keep_their_impact_and_warn_of_the_imu():
    # issue 20 item 2: from k = 4e4 the 1-mm rule gave NaN delta_init and two grazes
    for k in (4e4, 1e12):
        s = simulate(WallApproach(vehicle_overrides={"contact_stiffness": k})).summary
        assert s["delta_init_m"] is not None and s["delta_init_m"] < 1e-3
        assert s["peak_force_n"] > 100 and s["n_grazes"] == 0 and s["leading_bumpers"] == [1, 4]
        assert any("shorter than the IMU's sample period" in w for w in s["warnings"])
    # the default bumpers: no such warning
    s = simulate(WallApproach()).summary
    assert not any("IMU" in w for w in s["warnings"])


def test_ground_contacts_are_not_impacts():
    eps = episodes(
        (4, 0.5, 0.7, 0.05), (1, 1.2, 1.3, 0.02, "ground"), (2, 1.2, 1.3, 0.02, "ground")
    )
    assert rtype(eps, crashed=True)[0] == "B"


@pytest.mark.parametrize(
    "kw, expected",
    [
        ({"inclination_deg": 15, "speed_m_s": 0.75, "model": "paper-replica"}, "D"),
        ({"inclination_deg": -10, "speed_m_s": 0.5, "model": "paper-replica"}, "A"),
    ],
)
def test_summary_carries_the_type(kw, expected):
    s = simulate(WallApproach(heading_deg=45, **kw)).summary
    assert s["response_type"] == expected


def test_sinking_into_the_ground_is_explained_in_the_warning() -> None:
    """ground = "contact": only the rims touch; the paper example sinks its body into the floor."""
    s = simulate(WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75,
                              ground="contact")).summary  # fmt: skip
    assert s["max_penetration_m"] > 0.3 and s["min_altitude_m"] < -0.1  # the CM below the floor
    (deep,) = [w for w in s["warnings"] if w.startswith("penetration")]
    assert "mm into the ground, beyond the bumper radius 110 mm" in deep
    assert "only the bumper rims can touch a surface" in deep and 'ground = "crash"' in deep
