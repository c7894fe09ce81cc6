"""The compiled impact pass (core/impacts.py) against the Python reference, bit for bit.

A run's summary finds its impacts (chained episodes, grazes and the ground left
out, docs/STUDIES.md 2) by one compiled pass over the loop's raw episode rows;
the Python functions of ``simulation.metrics`` are the definition. Both must
give the same numbers to the bit on any record: ties in start, chains that
outlast their first member, zero-length grazes, open episodes, NaN peaks,
surfaces flagged as the ground under another name.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadimpact import WallApproach
from quadimpact.core import shape_slots as SHP
from quadimpact.core.kernel import execute
from quadimpact.core.recording_slots import (
    E_FEATURE,
    E_OPEN,
    E_PEAK_DELTA,
    E_PEAK_FORCE,
    E_SHAPE,
    E_T_END,
    E_T_PEAK,
    E_T_PEAK_FORCE,
    E_T_START,
    E_V_I,
    NEP,
)
from quadimpact.simulation.impacts import RunEpisodes, run_episodes
from quadimpact.simulation.metrics import (
    GRAZE_IMPULSE_FRACTION,
    RunImpacts,
    impact_metrics,
    impact_metrics_of,
)
from quadimpact.simulation.setup import prepare
from quadimpact.simulation.summary import build_summary
from quadimpact.simulation.tables import episodes_frame

NAMES = ("wall", "pole", "ground")


def _shapes(ground_flags: tuple[bool, ...]) -> np.ndarray:
    shapes = np.zeros((len(ground_flags), SHP.NSHAPE))
    shapes[:, SHP.SH_IS_GROUND] = [1.0 if g else 0.0 for g in ground_flags]
    return shapes


def _random_record(rng: np.random.Generator, n: int) -> np.ndarray:
    """Episodes on a coarse time grid (many equal starts and chained ends), some grazes."""
    raw = np.full((n + 3, NEP), -7.0)  # rows beyond n: never read
    for i in range(n):
        start = rng.integers(0, 12) * 0.01
        length = rng.choice([0.0, 0.005, 0.01, 0.02, 0.05])
        raw[i, E_FEATURE] = rng.integers(0, 4)
        raw[i, E_SHAPE] = rng.choice([0, 0, 1, 2])
        raw[i, E_T_START] = start
        raw[i, E_T_END] = start + length
        raw[i, E_V_I] = rng.uniform(0.1, 2.0)
        raw[i, E_PEAK_DELTA] = math.nan if rng.random() < 0.05 else rng.uniform(0.0, 0.03)
        raw[i, E_T_PEAK] = start
        raw[i, E_PEAK_FORCE] = rng.choice([0.05, 1.0, 40.0, 300.0]) * rng.uniform(0.5, 1.5)
        raw[i, E_T_PEAK_FORCE] = start
        raw[i, E_OPEN] = float(rng.random() < 0.1)
    return raw


def _same(a: RunImpacts, b: RunImpacts) -> bool:
    """Equal to the bit, NaN equal to NaN."""

    def bits(values: list[float]) -> list[bytes]:
        return [np.float64(v).tobytes() for v in values]

    return (
        (a.n_episodes, a.n_grazes, a.bumpers) == (b.n_episodes, b.n_grazes, b.bumpers)
        and bits(a.start_s) == bits(b.start_s)
        and bits(a.end_s) == bits(b.end_s)
        and bits(a.peak_delta_m) == bits(b.peak_delta_m)
        and bits(a.peak_force_n) == bits(b.peak_force_n)
    )


@pytest.mark.parametrize("ground_flags", [(False, False, True), (False, True, True)])
def test_compiled_impacts_equal_the_python_definition_to_the_bit(ground_flags):
    """3,000 random records, with the pole an obstacle and then flagged as ground."""
    rng = np.random.default_rng(7)
    shapes = _shapes(ground_flags)
    obstacles = [n for n, g in zip(NAMES, ground_flags, strict=True) if not g]
    grouped = chained = grazed = 0
    for trial in range(3000):
        n = int(rng.integers(0, 9))
        raw = _random_record(rng, n)
        compiled = run_episodes(raw, n, NAMES, 4, shapes)
        reference = RunEpisodes.of_table(episodes_frame(raw, n, NAMES, 4), obstacles)
        assert _same(compiled.impacts, reference.impacts), trial
        assert _same(compiled.obstacle_impacts, reference.obstacle_impacts), trial
        assert compiled.first_obstacle == reference.first_obstacle, trial
        grouped += len(compiled.impacts.bumpers) > 1
        chained += any(len(g) > 1 for g in compiled.impacts.bumpers)
        grazed += compiled.impacts.n_grazes > 0
    assert min(grouped, chained, grazed) > 300  # the cases the test is about did occur


def test_a_chain_is_one_impact_until_a_gap_and_a_graze_is_left_out():
    """Three episodes chained by overlap (the third starts after the first ended), a gap,
    a touch with 1/1000 of the largest impulse (a graze), then a second impact; the
    ground's touch-down is no impact."""
    rows = [  # feature, shape, start, end, peak deflection, peak force
        (3, 0, 0.50, 0.53, 0.020, 80.0),
        (0, 0, 0.52, 0.56, 0.018, 60.0),
        (1, 0, 0.55, 0.57, 0.004, 10.0),
        (2, 0, 0.60, 0.61, 0.001, 0.24),
        (2, 0, 0.70, 0.72, 0.010, 30.0),
        (1, 2, 0.90, 0.95, 0.002, 5.0),
    ]
    raw = np.zeros((len(rows), NEP))
    for i, (f, s, t0, t1, d, force) in enumerate(rows):
        raw[i, [E_FEATURE, E_SHAPE, E_T_START, E_T_END]] = f, s, t0, t1
        raw[i, [E_PEAK_DELTA, E_PEAK_FORCE]] = d, force
    found = run_episodes(raw, len(rows), NAMES, 4, _shapes((False, False, True)))
    imp = found.impacts
    assert imp.bumpers == [[4, 1, 2], [3]]
    assert (imp.n_episodes, imp.n_grazes) == (5, 1)
    assert imp.start_s == [0.50, 0.70] and imp.end_s == [0.57, 0.72]
    assert imp.peak_delta_m == [0.020, 0.010] and imp.peak_force_n == [80.0, 30.0]
    assert found.first_obstacle == (4, "wall")
    metrics = impact_metrics_of(imp)
    assert metrics["leading_bumpers"] == [1, 2, 4] and metrics["aft_bumpers"] == [3]
    assert metrics["subsequent_impacts"] == [[3]]
    table = episodes_frame(raw, len(rows), NAMES, 4)
    assert metrics == impact_metrics(table, graze_fraction=GRAZE_IMPULSE_FRACTION)


def test_a_record_the_compiled_pass_cannot_group_takes_the_definition_and_its_error():
    """A NaN start: the reference path, which refuses it with the same message."""
    raw = np.zeros((2, NEP))
    raw[:, E_T_START] = [0.5, math.nan]
    raw[:, E_T_END] = [0.6, 0.7]
    with pytest.raises(ValueError, match="t_start_s must be finite"):
        run_episodes(raw, 2, NAMES, 4, _shapes((False, False, True)))
    raw[1, E_T_START] = 0.55
    raw[1, E_SHAPE] = 5.0  # no such surface
    with pytest.raises(ValueError, match="surface index outside"):
        run_episodes(raw, 2, NAMES, 4, _shapes((False, False, True)))


@pytest.mark.parametrize("model", ["paper-replica", "default"])
def test_a_summary_from_the_compiled_pass_equals_the_summary_from_the_episodes_table(model):
    """The paper's example (an initial impact, several later ones, a detection, a crash):
    every summary value the same from the raw record as from its episodes table."""
    scenario = WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75, model=model)
    setup = prepare(scenario)
    rec = execute(setup.model(), n_imu=setup.n_imu, kernel=setup.kernel)
    n, nf = rec.episodes.shape[0], len(setup.feature_names)
    compiled = run_episodes(rec.episodes, n, setup.shape_names, nf, setup.shapes)
    assert len(compiled.impacts.bumpers) >= 3  # an initial impact and later ones
    from_raw = build_summary(setup, scenario, compiled, rec.stats)
    from_table = build_summary(
        setup, scenario, episodes_frame(rec.episodes, n, setup.shape_names, nf), rec.stats
    )
    assert repr(from_raw) == repr(from_table)  # NaN and None alike, every float to its repr
