"""The studies' proportions: the Wilson interval against published values and SciPy, and
the one way every study writes a rate."""

from __future__ import annotations

import math

import pytest

from quadimpact.studies.statistics import Rate, percent, rate, rate_text, wilson_interval


@pytest.mark.parametrize(
    ("k", "n", "low", "high"),
    [  # Newcombe (1998), Statistics in Medicine 17:857, Table I, method 3 (Wilson score)
        (81, 263, 0.2553, 0.3662),
        (15, 148, 0.0624, 0.1605),
        (0, 20, 0.0000, 0.1611),
        (1, 29, 0.0061, 0.1718),
    ],
)
def test_wilson_interval_against_published_values(k, n, low, high) -> None:
    lo, hi = wilson_interval(k, n)
    assert lo == pytest.approx(low, abs=5e-5) and hi == pytest.approx(high, abs=5e-5)


def test_wilson_interval_against_scipy_and_its_symmetry() -> None:
    stats = pytest.importorskip("scipy.stats")
    for k, n in [(0, 1), (3, 7), (50, 100), (9223, 10000), (10000, 10000)]:
        ci = stats.binomtest(k, n).proportion_ci(confidence_level=0.95, method="wilson")
        lo, hi = wilson_interval(k, n, z=stats.norm.ppf(0.975))
        assert (lo, hi) == pytest.approx((ci.low, ci.high), abs=1e-12)
        mlo, mhi = wilson_interval(n - k, n)
        assert (mlo, mhi) == pytest.approx(
            (1 - wilson_interval(k, n)[1], 1 - wilson_interval(k, n)[0]),
            abs=1e-12,
        )
    assert wilson_interval(0, 5)[0] == 0.0 and wilson_interval(5, 5)[1] == 1.0
    assert all(math.isnan(x) for x in wilson_interval(0, 0))
    with pytest.raises(ValueError):
        wilson_interval(6, 5)


def test_a_rate_is_written_one_way_from_a_record_or_from_its_json() -> None:
    r = rate(9223, 10000)
    assert r == Rate(9223, 10000, 0.9223, *wilson_interval(9223, 10000))
    assert rate_text(r) == "9223 / 10000 = 92.2 % [91.7 %, 92.7 %]"
    assert rate_text({"k": 9223, "n": 10000, "value": 0.9223, "low": r.low, "high": r.high}) == (
        rate_text(r)
    )
    assert rate_text(rate(0, 0)) == "no trials" and math.isnan(rate(0, 0).value)
    assert percent(float("nan")) == "–" and percent(None) == "–" and percent(0.5) == "50.0 %"
