"""The recovery study's numbers: bins, outcome classes, the summary."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from quadimpact.studies.recovery import recovery_analysis as analysis
from quadimpact.studies.recovery.recovery_study import DISTRIBUTION, sample_trials
from quadimpact.studies.statistics import wilson_interval
from quadimpact.sweep.trials import SEED_LIMIT


# --------------------------------------------------------------------- bins
def test_inclination_bins_are_10_deg_centred_on_multiples_of_10() -> None:
    values = pd.Series([-45.0, -35.0, -5.0001, -5.0, 4.9999, 5.0, 44.0, 45.0])
    labels = analysis.binned(values, *analysis.INCLINATION_BIN)
    cats = list(labels.cat.categories)
    assert cats[0] == "[-45, -35)" and cats[-1] == "[35, 45]" and len(cats) == 9
    assert "[-5, 5)" in cats
    assert list(labels.astype(str)) == [
        "[-45, -35)", "[-35, -25)", "[-15, -5)", "[-5, 5)", "[-5, 5)", "[5, 15)",
        "[35, 45]", "[35, 45]",
    ]  # fmt: skip
    speed = analysis.binned(pd.Series([0.5, 0.74, 0.75, 2.5]), *analysis.SPEED_BIN)
    assert list(speed.cat.categories) == [
        "[0.5, 0.75)", "[0.75, 1)", "[1, 1.25)", "[1.25, 1.5)", "[1.5, 1.75)", "[1.75, 2)",
        "[2, 2.25)", "[2.25, 2.5]",
    ]  # fmt: skip
    assert list(speed.astype(str)) == ["[0.5, 0.75)", "[0.5, 0.75)", "[0.75, 1)", "[2.25, 2.5]"]


# ------------------------------------------------------------------ classes
def _row(**kw):
    row = {
        "run_id": 0, "status": "completed", "detected": True, "not_detected": False,
        "false_detection": False, "recovered": True, "pitch_deg": 0.0, "roll_deg": 0.0,
        "yaw_deg": 0.0, "speed_m_s": 1.0, "t_stage1_s": 0.02, "t_stage2_s": 0.1,
        "t_stage3_s": 0.2, "t_stage4_s": 0.3, "time_to_recover_s": 0.28, "height_loss_m": 0.1,
        "horizontal_drift_m": 0.2, "detection_latency_s": 0.004, "normal_error_deg": 3.0,
        "max_tilt_deg": 40.0, "impacts_after_detection": 0, "references__altitude_m": 5.0,
        "min_altitude_m": 4.8, "final_speed_m_s": 0.1,
    }  # fmt: skip
    row.update(kw)
    return row


def _table(rows) -> pd.DataFrame:
    t = pd.DataFrame(rows)
    t["run_id"] = range(len(t))
    for c in ("detected", "not_detected", "false_detection", "recovered"):
        t[c] = t[c].astype("boolean")
    return analysis.add_derived(t)


FAILED = dict(recovered=False, t_stage2_s=None, t_stage3_s=None, t_stage4_s=None,
              time_to_recover_s=None, height_loss_m=None, horizontal_drift_m=None,
              max_tilt_deg=120.0, impacts_after_detection=12, min_altitude_m=-20.0,
              final_speed_m_s=20.0, pitch_deg=-40.0)  # fmt: skip


def test_outcome_classes_and_the_two_rates() -> None:
    t = _table([
        _row(), _row(), _row(), _row(**FAILED),
        _row(detected=False, not_detected=True, recovered=False, t_stage1_s=None,
             t_stage2_s=None, t_stage3_s=None, t_stage4_s=None),
        _row(false_detection=True),  # fired before the contact, then recovered
        _row(status="failed", detected=None, not_detected=None, false_detection=None,
             recovered=None),
        _row(detected=False, recovered=False, t_stage1_s=None, t_stage4_s=None),
    ])  # fmt: skip
    assert list(t["outcome_class"].astype(str)) == [
        "recovered", "recovered", "recovered", "not recovered", "not detected",
        "false detection", "failed", "no contact",
    ]  # fmt: skip
    n = analysis.summarise(t)
    assert n["classes"]["recovered"] == 3 and n["classes"]["not recovered"] == 1
    # success: the recovered column over the valid trials (the false detection that
    # recovered counts; the failed run is excluded)
    assert (n["success"].k, n["success"].n) == (4, 7) and n["false_recovered"] == 1
    # recovered / detected: the detected impacts only
    assert (n["success_detected"].k, n["success_detected"].n) == (3, 4)
    assert n["time_to_recover_s"]["n"] == 3 and n["time_to_recover_s"]["median"] == 0.28
    f = n["failures"]
    assert f["n_failed"] == 1 and f["stage_reached"] == {1: 1}
    assert f["flipped"] == {"failed": 1.0, "recovered": 0.0}
    assert f["fall_m"]["failed"]["median"] == pytest.approx(25.0)
    assert f["inclination"]["median"] == 40.0


def test_rate_by_counts_every_bin_with_its_interval() -> None:
    t = _table([_row(pitch_deg=-40.0), _row(**FAILED), _row(pitch_deg=0.0)])
    r = analysis.rate_by(t, "inclination_bin").set_index("bin")
    assert r.loc["[35, 45]", "n"] == 2 and r.loc["[35, 45]", "recovered"] == 1
    assert (r.loc["[35, 45]", "low"], r.loc["[35, 45]", "high"]) == wilson_interval(1, 2)
    assert r.loc["[15, 25)", "n"] == 0 and math.isnan(r.loc["[15, 25)", "rate"])
    assert r["n"].sum() == 3


def test_example_trial_is_the_one_nearest_the_median_conditions() -> None:
    t = _table([
        _row(roll_deg=-10.0, pitch_deg=30.0, yaw_deg=40.0, speed_m_s=0.6),
        _row(roll_deg=1.0, pitch_deg=-2.0, yaw_deg=3.0, speed_m_s=1.4),
        _row(roll_deg=12.0, pitch_deg=-40.0, yaw_deg=-30.0, speed_m_s=2.4),
        _row(roll_deg=0.0, pitch_deg=20.0, yaw_deg=0.0, speed_m_s=1.6),
        _row(roll_deg=-1.0, pitch_deg=-25.0, yaw_deg=-3.0, speed_m_s=1.5),
    ])  # fmt: skip
    assert analysis.example_trial(t) == 1


# ----------------------------------------------------------------- sampling
def test_sampling_is_seeded_per_trial_and_within_the_distribution() -> None:
    a = sample_trials(200, seed=7)
    assert a == sample_trials(200, seed=7)
    assert a[:50] == sample_trials(50, seed=7)  # trial i depends on (seed, i) only
    assert a != sample_trials(200, seed=8)
    seeds = [t["seed"] for t in a]
    assert len(set(seeds)) == len(seeds) and all(0 <= s < SEED_LIMIT for s in seeds)
    for name, (lo, hi) in DISTRIBUTION.items():
        v = np.array([t[name] for t in a])
        assert v.min() >= lo and v.max() <= hi
        # uniform: the 200 draws spread over the range (each quarter holds some)
        counts = np.histogram(v, bins=4, range=(lo, hi))[0]
        assert counts.min() > 25


def test_invalid_and_below_ground_trials_are_classed_and_left_out_of_the_rates() -> None:
    # issue 20 item 1: none of these reads as a success, and the rates say what they left out
    t = _table([
        _row(), _row(),
        _row(min_altitude_m=-3.9),  # recovered, but through where the ground would be
        _row(bumper_model_valid=False),  # 518 mm into the wall
        _row(status="failed", detected=None, not_detected=None, false_detection=None,
             recovered=None, reason="InputError: impact trial: starts in contact with the "
             "wall: bumper 1 is 209.9 mm into it at the start"),
        _row(status="failed", detected=None, not_detected=None, false_detection=None,
             recovered=None, reason="step size fell below the floor"),
    ])  # fmt: skip
    assert list(t["outcome_class"].astype(str)) == [
        "recovered", "recovered", "recovered below ground level",
        "invalid: bumper model exceeded", "invalid: started in contact", "failed",
    ]  # fmt: skip
    n = analysis.summarise(t)
    assert n["n_valid"] == 3 and n["below_ground"] == 1
    assert n["excluded"] == {"invalid: started in contact": 1,
                             "invalid: bumper model exceeded": 1, "failed": 1}  # fmt: skip
    assert (n["success"].k, n["success"].n) == (2, 3)
    assert (n["success_detected"].k, n["success_detected"].n) == (2, 3)
    r = analysis.rate_by(t, "speed_bin")
    assert r["n"].sum() == 3 and r["recovered"].sum() == 2 and r["excluded"].sum() == 3
    from quadimpact.studies.recovery.recovery_report import excluded_text

    assert excluded_text(n) == (
        "3 of 6 trials (1 invalid: started in contact, 1 invalid: bumper model exceeded, 1 failed)"
    )
    assert excluded_text(analysis.summarise(_table([_row()]))) == "none (all 1 trials valid)"


# ------------------------------------------------------------------ figures
def test_figures_drawn_on_another_process_are_the_same_files(tmp_path) -> None:
    """The distributions figure rendered elsewhere (``submit``) is written byte for byte as
    here, and a failure there draws it here."""
    from concurrent.futures import Future

    from quadimpact.studies.recovery import recovery_figures as figures

    t = _table([_row(height_loss_m=0.05 * k, time_to_recover_s=0.2 + 0.01 * k) for k in range(9)])
    calls = []

    def submit(fn, *args):  # "another process": run now, hand back a finished future
        calls.append(args[0].columns.tolist())
        done = Future()
        done.set_result(fn(*args))
        return done

    def broken(fn, *args):
        lost = Future()
        lost.set_exception(RuntimeError("the process died"))
        return lost

    for name in ("here", "there", "fallback"):
        (tmp_path / name).mkdir()
    here = figures.write_figures(t, tmp_path / "here")
    there = figures.write_figures(t, tmp_path / "there", submit=submit)
    fallback = figures.write_figures(t, tmp_path / "fallback", submit=broken)
    assert calls == [list(figures.DISTRIBUTION_COLUMNS)]  # only the columns it draws go there
    for a, b, c in zip(here, there, fallback, strict=True):
        assert a.name == b.name == c.name
        assert a.read_bytes() == b.read_bytes() == c.read_bytes()
