"""Verdicts of the paper's findings are computed from data: they change when the data do."""

import itertools

import numpy as np
import pandas as pd

from quadimpact.studies.paper import findings as F


def table(
    peak=11.0,
    speed_exp=1.3,
    psi0_factor=0.85,
    left=0.02,
    right=0.04,
    split=10.0,
    low_speed_type="A",
    negative=0.035,
):
    """Figure 4-like curves: exponential about the peak (``left``/``right`` rates), and for
    negative inclinations a straight line falling by ``negative`` of delta(0) per degree
    (steeper than the rest; None: the exponential goes on)."""
    rows = []
    for h, i, v in itertools.product((0.0, 45.0), range(-20, 21), (0.5, 0.75, 1.0)):
        rate = left if i <= peak else right
        shape = np.exp(-rate * abs(i - peak))
        if negative is not None and i < 0 <= peak:
            shape = np.exp(-rate * peak) * (1.0 + negative * i)
        d = 0.06 * shape * v**speed_exp * (psi0_factor if h == 0 else 1.0)
        if i < split:
            t = low_speed_type if v == 0.5 else "B"
        else:
            t = "D"
        rows.append(
            {
                "heading_deg": h,
                "inclination_deg": float(i),
                "speed_m_s": v,
                "delta_init_m": d,
                "response_type": t,
                "n_subsequent_impacts": 3,
                "status": "crashed",
            }
        )
    return pd.DataFrame(rows)


def verdict(fn, t):
    return fn(t).verdict


def test_paper_like_data_agree_with_every_sweep_finding():
    t = table()
    for fn in F.SWEEP_FINDINGS:
        assert fn(t).verdict == "agrees", fn.__name__


def test_verdicts_follow_the_data():
    assert verdict(F.peak_near_10, table(peak=-5.0)) == "disagrees"
    assert verdict(F.asymmetric, table(left=0.03, right=0.03)) == "disagrees"
    assert verdict(F.steeper_negative, table(left=0.01, right=0.05, peak=0.0,
                                             negative=None)) == "disagrees"  # fmt: skip
    assert verdict(F.grows_with_speed, table(speed_exp=-1.0)) == "disagrees"
    assert verdict(F.psi0_below_psi45, table(psi0_factor=1.2)) == "disagrees"
    assert verdict(F.few_centimetres, table(speed_exp=8.0)) != "agrees"
    assert verdict(F.ab_below_cd_above, table(split=-30.0)) == "disagrees"
    assert verdict(F.a_dominates_at_low_speed, table(low_speed_type="B")) == "disagrees"


def test_verdicts_are_not_generous():
    """Steeper only relative to delta_init is partly; 32 % lower is not "slightly" lower."""
    relative_only = table(negative=None, left=0.04, right=0.02)  # the rise to +11 is in 0..20
    f = F.steeper_negative(relative_only)
    assert f.verdict == "partly" and f.value == 0.0
    assert "(steeper for negative on 0 of 6 curves)" in f.measured and "(on 6 of 6)" in f.measured
    assert "mm/deg" in f.rule and "partly when only the slope relative" in f.rule
    much = F.psi0_below_psi45(table(psi0_factor=0.68))
    assert much.verdict == "partly" and "lower more than slightly (below 0.8)" in much.measured
    slight = F.psi0_below_psi45(table(psi0_factor=0.85))
    assert slight.verdict == "agrees" and "lower slightly" in slight.measured
    assert "at least 0.8" in slight.rule
    for fn in F.SWEEP_FINDINGS:  # every verdict says its measure and thresholds
        rule = fn(table()).rule
        assert "agrees" in rule and ("%" in rule or "half" in rule), fn.__name__


def episodes(*rows):
    return pd.DataFrame(
        [
            {"bumper": b, "surface": "wall", "t_start_s": t0, "t_end_s": t1, "peak_delta_m": d}
            for b, t0, t1, d in rows
        ]
    )


def test_figure5_pattern():
    summary = {
        "first_contact_s": 0.5,
        "initial_impact_duration_s": 0.2,
        "leading_bumpers": [4],
        "response_type": "D",
    }
    good = episodes(
        (4, 0.5, 0.7, 0.05),
        (2, 0.85, 0.94, 0.06),
        (3, 0.89, 0.93, 0.01),
        (4, 0.96, 1.05, 0.067),
        (1, 1.0, 1.04, 0.007),
    )
    assert F.figure5_pattern(summary, good).verdict == "agrees"
    bad = episodes((4, 0.5, 0.7, 0.05), (3, 0.85, 0.94, 0.06), (1, 0.96, 1.05, 0.05))
    assert F.figure5_pattern(summary, bad).verdict != "agrees"
