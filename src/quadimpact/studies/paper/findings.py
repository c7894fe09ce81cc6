"""The paper's findings (docs/STUDIES.md section 4) as verdicts computed from data.

Each finding is a pure function of a Figure 4 sweep table (one row per run,
with ``heading_deg``, ``inclination_deg``, ``speed_m_s``, ``delta_init_m``,
``response_type``) or of the example run, returning a :class:`Finding`: what
the paper says, what was measured, a verdict (``agrees``, ``partly``,
``disagrees``), the number behind it and the rule that turned the measure
into the verdict (its thresholds: the named constants here), which the
report prints beside the verdict. Nothing is written in by hand.

The verdicts are not generous: a finding that holds in one reading of the
paper's words and not in the plainest one is ``partly`` (the slope of
Figure 4 is first the slope in mm per degree; relative to ``delta_init``
only, it is ``partly``), and a qualifier of the paper's ("slightly lower")
is a threshold of its own.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd

from quadimpact import libm

# thresholds of the verdicts
PEAK_NEAR_DEG = 10.0  # "the peak is at about +10 deg"
PEAK_TOL_DEG = 3.0  # ... within this
ASYMMETRY_MIN = 0.05  # |delta(peak - 10) / delta(peak + 10) - 1| above this: asymmetric
SHARE_AGREES = 0.9  # share of grid points that must show a trend for "agrees"
SHARE_PARTLY = 0.5  # ... for "partly"
SLIGHTLY_LOWER_MIN_RATIO = 0.8  # "slightly lower": on average at most 20 % lower
TYPE_SPLIT_DEG = 10.0  # "A and B below about 10 deg, C and D above"
FEW_CM = (0.01, 0.10)  # "delta_init is a few centimetres", m
Y_STILL_M = 0.05  # Figure 6: "Y stays put"
ALTITUDE_HOLD_S = 0.3  # Figure 6: "altitude holds for about 0.3 s after impact"
ALTITUDE_HOLD_DROP_M = 0.2  # ... losing less than this
X_NEAR_WALL_M = 0.4  # Figure 6: "X oscillates around the wall" (CM within this of it)
BIG_DEFLECTION_M = 0.02  # Figure 5: the large (alternating) vs the small deflections


@dataclass(frozen=True)
class Finding:
    """One of the paper's findings and what a variant measured."""

    key: str
    claim: str
    measured: str
    verdict: str  # "agrees", "partly", "disagrees" or "n/a"
    value: float
    rule: str = ""  # the measure and the thresholds that make the verdict


def _share_rule(what: str, cases: str) -> str:
    """The rule of a verdict on the share of ``cases`` where ``what`` holds."""
    return (f"agrees when {what} on at least {SHARE_AGREES:.0%} of the {cases}, partly "
            f"from {SHARE_PARTLY:.0%}, disagrees below")  # fmt: skip


def _verdict_share(share: float) -> str:
    if share >= SHARE_AGREES:
        return "agrees"
    return "partly" if share >= SHARE_PARTLY else "disagrees"


def fig4_curves(table: pd.DataFrame) -> pd.DataFrame:
    """delta_init (m) indexed by inclination, one column per (heading, speed)."""
    ok = table[table["delta_init_m"].notna()]
    return ok.pivot_table(
        index="inclination_deg", columns=["heading_deg", "speed_m_s"], values="delta_init_m"
    ).sort_index()


def peak_near_10(table: pd.DataFrame) -> Finding:
    curves = fig4_curves(table)
    peaks = curves.idxmax()
    off = (peaks - PEAK_NEAR_DEG).abs()
    share = float((off <= PEAK_TOL_DEG).mean())
    listed = ", ".join(f"psi {h:g}/{v:g} m/s: {p:+g}" for (h, v), p in peaks.items())
    return Finding("peak_near_10", "delta_init peaks at about +10 deg inclination on every curve",
                   f"peaks (deg) {listed}", _verdict_share(share), share,
                   "the inclination of each curve's largest delta_init; "
                   + _share_rule(f"it is within {PEAK_TOL_DEG:g} deg of +{PEAK_NEAR_DEG:g} deg",
                                 "curves"))  # fmt: skip


def asymmetric(table: pd.DataFrame) -> Finding:
    curves = fig4_curves(table)
    ratios = []
    for col in curves:
        c = curves[col].dropna()
        p = c.idxmax()
        lo = c.reindex([p - 10.0]).iloc[0] if (p - 10.0) in c.index else c.iloc[0]
        hi = c.reindex([p + 10.0]).iloc[0] if (p + 10.0) in c.index else c.iloc[-1]
        ratios.append(lo / hi)
    ratios = np.array(ratios)
    share = float(np.mean(np.abs(ratios - 1.0) > ASYMMETRY_MIN))
    return Finding(
        "asymmetric",
        "the curves are asymmetric about the peak",
        "delta(peak-10)/delta(peak+10) = " + ", ".join(f"{r:.2f}" for r in ratios),
        _verdict_share(share),
        share,
        "delta_init 10 deg below the peak over 10 deg above, per curve; "
        + _share_rule(f"it differs from 1 by more than {ASYMMETRY_MIN:g}", "curves"),
    )


def steeper_negative(table: pd.DataFrame) -> Finding:
    """ "The slope is steeper for negative inclinations."

    Judged first on the slope itself, the mean |d delta / d iota| (mm/deg)
    over -20..0 deg against 0..20 deg, per curve; and, as a second reading,
    on the slope relative to delta_init (mean |d ln delta / d iota|), which
    weighs the smaller deflections of negative inclinations more. Agrees when
    the slope is steeper for negative inclinations on at least
    ``SHARE_AGREES`` of the curves; partly when only the relative slope is
    (on that share of the curves), or the slope on at least ``SHARE_PARTLY``
    of them; disagrees otherwise. ``value``: the share of curves where the
    slope (mm/deg) is steeper for negative inclinations.
    """
    curves = fig4_curves(table)
    rel, absolute = [], []
    for col in curves:
        c = curves[col].dropna()
        neg, pos = c[c.index <= 0.0], c[c.index >= 0.0]

        def mean_slope(s: pd.Series) -> float:
            return float(np.mean(np.abs(np.diff(s.to_numpy()) / np.diff(s.index.to_numpy()))))

        def log_of(s: pd.Series) -> pd.Series:
            return pd.Series(libm.log(s.to_numpy()), index=s.index)

        rel.append((mean_slope(log_of(neg)), mean_slope(log_of(pos))))
        absolute.append((mean_slope(neg), mean_slope(pos)))
    share_abs = float(np.mean([a > b for a, b in absolute]))
    share_rel = float(np.mean([a > b for a, b in rel]))
    if share_abs >= SHARE_AGREES:
        verdict = "agrees"
    elif share_rel >= SHARE_AGREES or share_abs >= SHARE_PARTLY:
        verdict = "partly"
    else:
        verdict = "disagrees"
    n = len(absolute)
    return Finding(
        "steeper_negative",
        "the slope of delta_init is steeper for negative inclinations",
        "mean |d delta/d iota| (mm/deg), negative vs positive inclinations: "
        + ", ".join(f"{a * 1e3:.2f}/{b * 1e3:.2f}" for a, b in absolute)
        + f" (steeper for negative on {round(share_abs * n)} of {n} curves); relative to "
        "delta, mean |d ln(delta)/d iota| (%/deg): "
        + ", ".join(f"{a * 100:.1f}/{b * 100:.1f}" for a, b in rel)
        + f" (on {round(share_rel * n)} of {n})",
        verdict,
        share_abs,
        f"the slope in mm/deg over -20..0 vs 0..20 deg, per curve: agrees when steeper for "
        f"negative inclinations on at least {SHARE_AGREES:.0%} of the curves; partly when "
        f"only the slope relative to delta_init is (on {SHARE_AGREES:.0%}), or the slope on "
        f"at least {SHARE_PARTLY:.0%}; disagrees otherwise",
    )


def grows_with_speed(table: pd.DataFrame) -> Finding:
    curves = fig4_curves(table)
    checks = []
    for h in sorted({h for h, _ in curves.columns}):
        sub = curves[h][sorted(curves[h].columns)].dropna()
        checks.extend(np.all(np.diff(sub.to_numpy(), axis=1) > 0, axis=1))
    share = float(np.mean(checks))
    return Finding("grows_with_speed", "delta_init grows with the impact speed",
                   f"increasing with V_c at {share:.0%} of (heading, inclination) points",
                   _verdict_share(share), share,
                   "whether delta_init increases from each speed to the next at each "
                   "(heading, inclination); "
                   + _share_rule("it does", "points"))  # fmt: skip


def psi0_below_psi45(table: pd.DataFrame) -> Finding:
    """ "psi = 0 gives slightly lower delta_init than psi = 45 deg."

    Lower at each (speed, inclination) point, and "slightly": the mean ratio
    delta(psi 0) / delta(psi 45) at least ``SLIGHTLY_LOWER_MIN_RATIO``. Agrees
    when lower at ``SHARE_AGREES`` of the points and slightly so; partly when
    lower at ``SHARE_PARTLY`` of them (or at more, but by more than slightly);
    disagrees otherwise. ``value``: the share of points where it is lower.
    """
    curves = fig4_curves(table)
    rule = (f"the share of (speed, inclination) points where psi 0 is lower, and the mean ratio "
            f"psi 0 / psi 45: agrees when lower at {SHARE_AGREES:.0%} of them with a mean ratio "
            f"of at least {SLIGHTLY_LOWER_MIN_RATIO:g} (slightly: at most "
            f"{1 - SLIGHTLY_LOWER_MIN_RATIO:.0%} lower); partly when lower at "
            f"{SHARE_PARTLY:.0%} (or by more than slightly); disagrees otherwise")  # fmt: skip
    if 0.0 not in curves.columns.get_level_values(0) or 45.0 not in curves.columns.get_level_values(
        0
    ):
        return Finding("psi0_below_psi45", "psi 0 gives lower delta_init than psi 45", "no data",
                       "n/a", float("nan"), rule)  # fmt: skip
    a, b = curves[0.0], curves[45.0]
    both = a.notna() & b.notna()
    share = float((a[both] < b[both]).to_numpy().mean())
    mean_ratio = float(np.nanmean((a[both] / b[both]).to_numpy()))
    slight = mean_ratio >= SLIGHTLY_LOWER_MIN_RATIO
    if share >= SHARE_AGREES and slight:
        verdict = "agrees"
    elif share >= SHARE_PARTLY:
        verdict = "partly"
    else:
        verdict = "disagrees"
    how = "slightly" if slight else f"more than slightly (below {SLIGHTLY_LOWER_MIN_RATIO:g})"
    return Finding(
        "psi0_below_psi45",
        "psi = 0 (two-bumper impact) gives slightly lower delta_init than psi = 45 deg",
        f"lower at {share:.0%} of (speed, inclination) points; mean ratio {mean_ratio:.3f}: "
        + ("higher" if mean_ratio >= 1.0 else f"lower {how}"),
        verdict,
        share,
        rule,
    )


def few_centimetres(table: pd.DataFrame) -> Finding:
    sel = table[(table["heading_deg"] == 45.0) & (table["speed_m_s"] == 0.75)]
    d = sel["delta_init_m"].dropna()
    inside = float(((d >= FEW_CM[0]) & (d <= FEW_CM[1])).mean()) if len(d) else float("nan")
    return Finding(
        "few_centimetres",
        "at psi 45, V_c 0.75 m/s delta_init is a few centimetres (soft bumpers)",
        f"{d.min() * 100:.1f} to {d.max() * 100:.1f} cm over the inclinations",
        _verdict_share(inside),
        inside,
        "delta_init at psi 45, V_c 0.75 m/s, every inclination; "
        + _share_rule(f"it is {FEW_CM[0] * 100:g} to {FEW_CM[1] * 100:g} cm", "inclinations"),
    )


def _types(table: pd.DataFrame) -> pd.DataFrame:
    return table[table["response_type"].notna() & (table["status"] != "failed")]


def ab_below_cd_above(table: pd.DataFrame) -> Finding:
    t = _types(table)
    below = t[t["inclination_deg"] < TYPE_SPLIT_DEG]
    above = t[t["inclination_deg"] > TYPE_SPLIT_DEG]
    s_below = float(below["response_type"].isin(["A", "B"]).mean())
    s_above = float(above["response_type"].isin(["C", "D"]).mean())
    share = min(s_below, s_above)
    return Finding(
        "types_split_at_10",
        "types A and B below about 10 deg inclination, C and D above",
        f"A/B below 10 deg: {s_below:.0%}; C/D above 10 deg: {s_above:.0%}",
        _verdict_share(share),
        share,
        f"the smaller of the two shares (A or B below {TYPE_SPLIT_DEG:g} deg, C or D above); "
        f"agrees from {SHARE_AGREES:.0%}, partly from {SHARE_PARTLY:.0%}, disagrees below",
    )


def a_dominates_at_low_speed(table: pd.DataFrame) -> Finding:
    t = _types(table)
    below = t[t["inclination_deg"] < TYPE_SPLIT_DEG]
    share_a = below.groupby("speed_m_s")["response_type"].apply(lambda s: float((s == "A").mean()))
    slow = share_a.index.min()
    ok = bool(share_a[slow] >= share_a.max() and share_a[slow] > 0.5)
    return Finding(
        "a_at_low_speed",
        "below 10 deg, type A dominates at low speed",
        "share of A below 10 deg by speed: "
        + ", ".join(f"{v:g} m/s {s:.0%}" for v, s in share_a.items()),
        "agrees" if ok else ("partly" if 0.0 < share_a[slow] >= share_a.max() else "disagrees"),
        float(share_a[slow]),
        f"the share of type A below {TYPE_SPLIT_DEG:g} deg at each speed: agrees when the "
        "lowest speed has the largest share and more than half; partly when it has the "
        "largest share but not more than half; disagrees otherwise",
    )


def figure5_pattern(summary: dict, episodes: pd.DataFrame) -> Finding:
    t0 = summary.get("first_contact_s") or 0.0
    initial_end = t0 + (summary.get("initial_impact_duration_s") or 0.0)
    later = episodes[(episodes["surface"] == "wall") & (episodes["t_start_s"] > initial_end)]
    big = later[later["peak_delta_m"] > BIG_DEFLECTION_M]["bumper"].tolist()
    small = later[later["peak_delta_m"] <= BIG_DEFLECTION_M]["bumper"].tolist()
    checks = {
        "bumper 4 leads": summary.get("leading_bumpers") == [4],
        "large hits alternate 2 and 4": bool(big)
        and big[0] == 2
        and set(big) <= {2, 4}
        and all(a != b for a, b in zip(big, big[1:], strict=False)),
        "small hits only on 1 and 3": set(small) <= {1, 3},
        "type D": summary.get("response_type") == "D",
    }
    share = float(np.mean(list(checks.values())))
    return Finding(
        "figure5",
        "Figure 5: bumper 4 leads, then alternating 2 and 4, little on 1 and 3: type D",
        f"type {summary.get('response_type')}; large hits {big}; small hits {small}; "
        + "; ".join(f"{k}: {'yes' if v else 'no'}" for k, v in checks.items()),
        "agrees" if share == 1.0 else ("partly" if share >= SHARE_PARTLY else "disagrees"),
        share,
        f"the four checks (large hits: deeper than {BIG_DEFLECTION_M * 1e3:g} mm): agrees "
        f"when all hold, partly from {SHARE_PARTLY:.0%} of them, disagrees below",
    )


def figure6_states(summary: dict, ts: pd.DataFrame) -> Finding:
    t_c = summary.get("first_contact_s")
    if t_c is None or len(ts) == 0:
        return Finding("figure6", "Figure 6 states", "no impact", "n/a", float("nan"))
    d = summary.get("wall_distance_m")
    after = ts[ts["t_s"] >= t_c]
    h_ref = summary["references"]["altitude_m"]
    h_hold = float(np.interp(t_c + ALTITUDE_HOLD_S, ts["t_s"], ts["altitude_m"]))
    checks = {
        "Y stays put": float(np.abs(ts["y_m"]).max()) < Y_STILL_M,
        "X stays at the wall": d is not None and float((d - after["x_m"]).max()) < X_NEAR_WALL_M,
        "altitude holds 0.3 s": h_hold > h_ref - ALTITUDE_HOLD_DROP_M,
        "then falls (crash)": summary.get("crash_time_s") is not None,
    }
    share = float(np.mean(list(checks.values())))
    return Finding(
        "figure6",
        "Figure 6: X at the wall, Y put, altitude holds ~0.3 s after impact then falls",
        f"max |Y| {np.abs(ts['y_m']).max() * 100:.1f} cm; altitude {h_hold:.2f} m at "
        f"T_c + 0.3 s; crash at {summary.get('crash_time_s') or float('nan'):.3f} s; "
        + "; ".join(f"{k}: {'yes' if v else 'no'}" for k, v in checks.items()),
        "agrees" if share == 1.0 else ("partly" if share >= SHARE_PARTLY else "disagrees"),
        share,
        f"the four checks (|Y| below {Y_STILL_M * 100:g} cm; CM within {X_NEAR_WALL_M:g} m of "
        f"the wall; altitude lost by T_c + {ALTITUDE_HOLD_S:g} s below "
        f"{ALTITUDE_HOLD_DROP_M:g} m; a crash): agrees when all hold, partly from "
        f"{SHARE_PARTLY:.0%} of them, disagrees below",
    )


SWEEP_FINDINGS: tuple[Callable[[pd.DataFrame], Finding], ...] = (
    peak_near_10,
    asymmetric,
    steeper_negative,
    grows_with_speed,
    psi0_below_psi45,
    few_centimetres,
    ab_below_cd_above,
    a_dominates_at_low_speed,
)


def evaluate(
    table: pd.DataFrame, example: tuple[dict, pd.DataFrame, pd.DataFrame] | None
) -> list[Finding]:
    """All findings for one variant: the sweep's, then the example run's (summary, episodes, ts)."""
    out = [f(table) for f in SWEEP_FINDINGS]
    if example is not None:
        summary, episodes, ts = example
        out += [figure5_pattern(summary, episodes), figure6_states(summary, ts)]
    return out


def findings_frame(by_variant: dict[str, list[Finding]]) -> pd.DataFrame:
    """One row per (variant, finding)."""
    rows = [{"variant": v, **asdict(f)} for v, fs in by_variant.items() for f in fs]
    return pd.DataFrame(rows)
