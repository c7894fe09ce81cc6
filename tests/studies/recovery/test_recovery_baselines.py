"""Nominal against recovery: the grid comparison and the crashes without power-off."""

from __future__ import annotations

import pandas as pd
import pytest

from quadimpact.inputs.scenarios import WallApproach
from quadimpact.simulation import simulate
from quadimpact.studies.recovery.baselines import (
    crashes_without_power_off,
    grid_comparison,
    recovery_base,
    saved_by_type,
)


def _sweep_row(speed, **kw):
    row = {
        "speed_m_s": speed,
        "status": "crashed",
        "response_type": "D",
        "crash_time_s": 1.3,
        "detected": None,
        "recovered": None,
        "t_stage4_s": None,
        "height_loss_m": None,
    }
    row.update(kw)
    return row


def test_saved_means_no_crash_and_stage_4() -> None:
    nominal = pd.DataFrame([
        _sweep_row(0.5, status="completed", response_type="A", crash_time_s=None),
        _sweep_row(0.75, response_type="B"), _sweep_row(1.0), _sweep_row(1.25),
    ])  # fmt: skip
    recovery = pd.DataFrame([
        _sweep_row(0.5, status="completed", response_type="A", crash_time_s=None,
                   detected=True, recovered=True, t_stage4_s=0.9),
        _sweep_row(0.75, status="completed", response_type="A", crash_time_s=None,
                   detected=True, recovered=True, t_stage4_s=0.8),
        _sweep_row(1.0, detected=True, recovered=True, t_stage4_s=0.7),  # stage 4, then crashed
        _sweep_row(1.25, status="completed", response_type="A", crash_time_s=None,
                   detected=True, recovered=False),  # no crash, never stage 4
    ])  # fmt: skip
    both = grid_comparison(nominal, recovery.iloc[::-1], ["speed_m_s"])  # any row order
    assert list(both["saved"]) == [True, True, False, False]
    t = saved_by_type(both).set_index("nominal_type")
    assert list(t.index) == ["A", "B", "D", "all"]
    assert t.loc["D", "runs"] == 2 and t.loc["D", "not_crashed"] == 1
    assert t.loc["D", "stage4"] == 1 and t.loc["D", "saved"] == 0
    assert t.loc["B", "saved"] == 1 and t.loc["all", "saved"] == 2
    assert t.loc["all", "nominal_crashed"] == 3
    with pytest.raises(ValueError, match="same grid"):
        grid_comparison(nominal, recovery.iloc[:3], ["speed_m_s"])


def test_the_recovery_base_flies_the_nominal_controller_until_detection() -> None:
    base = recovery_base({"model": "paper-replica", "heading_deg": 45.0})
    assert base == {"model": "paper-replica", "heading_deg": 45.0, "controller": "recovery",
                    "pre_impact": "nominal", "nominal_controller": "paper"}  # fmt: skip
    args = {"heading_deg": 45.0, "inclination_deg": 15.0, "speed_m_s": 0.75}
    nominal = simulate(WallApproach(**args))
    rec = simulate(WallApproach(**args, **recovery_base({})))
    ts_n, ts_r = nominal.timeseries, rec.timeseries
    before = ts_r["t_s"] < rec.summary["t_detect_s"]
    assert before.sum() > 100  # the approach: identical until the detection
    cols = ["x_m", "altitude_m", "roll_deg", "pitch_deg", "omega1_rad_s"]
    assert (ts_r.loc[before, cols].to_numpy() == ts_n.loc[before, cols].to_numpy()).all()
    assert rec.summary["t_detect_s"] >= rec.summary["first_contact_s"]
    assert (ts_r.loc[~before, "stage"] > 0).all()


def test_the_crashes_without_power_off() -> None:
    t = crashes_without_power_off(["default"])
    assert list(t["crash"]) == [1, 2, 3, 4, 5, 6, 7] and set(t["model"]) == {"default"}
    assert t["detected"].all()  # every crash's impact is seen by the detector
    assert (t["t_detect_s"] > 0).all()
    # saved = stage 4 and no crash, recomputed from the row
    assert list(t["saved"]) == list(t["recovered"] & t["recovery_crash_s"].isna())
    assert set(t["nominal_type"]) <= {"A", "B", "C", "D", "Other"}
    assert (t.loc[t["recovered"], "stage"] == 4).all()
