"""Table III: the seven crashes as scenarios, simulated, with their uncertainty."""

import math

import pandas as pd
import pytest

from quadimpact.experiments.crashes import SWITCH_CHANGES, TABLE3, scenario_file
from quadimpact.experiments.logs import data_dir
from quadimpact.simulation.response_types import RESPONSE_TYPES
from quadimpact.studies.table3.table3_study import (
    EXTRA_COLUMNS,
    RUN_COLUMNS,
    SWITCH_COLUMNS,
    TABLE3_COLUMNS,
    run_experiments,
)


def test_crash_scenarios_match_table3():
    for c in TABLE3:
        s = scenario_file(c.number)
        assert s.heading_deg == pytest.approx(c.heading_deg - 180.0)  # flown rear first
        assert (s.speed_m_s, s.inclination_deg) == (c.speed_m_s, c.inclination_deg)
        assert s.power_off is not None and s.power_off.trigger == "first-contact"


@pytest.mark.slow
def test_experiments_table3(tmp_path):
    table = run_experiments(tmp_path, samples=0, log_samples=0, workers=1)
    csv = pd.read_csv(tmp_path / "table3.csv")
    assert list(csv.columns) == [*TABLE3_COLUMNS, *EXTRA_COLUMNS] and len(csv) == 7
    assert set(csv["type_ours"]) <= set(RESPONSE_TYPES)
    runs = pd.read_csv(tmp_path / "table3_runs.csv")
    assert list(runs.columns) == list(RUN_COLUMNS) and len(runs) == 7 * 2 * 2
    assert set(runs["type"]) <= set(RESPONSE_TYPES)
    switches = pd.read_csv(tmp_path / "table3_switches.csv")
    assert list(switches.columns) == list(SWITCH_COLUMNS)
    # per crash: as run, zero rate held, the offs at the segments' ends and the other
    # heading in both variants, the late start and two replica switches on in the default,
    # three switches off in the replica; crash 1 also with the hand modification
    assert len(switches) == 7 * (4 + 3 + 4 + 3) + 1
    assert set(switches["change"]) == {"as run", *SWITCH_CHANGES}
    t = table.set_index("crash")
    by = runs.set_index(["crash", "conditions", "model"])
    for c in TABLE3:
        for conditions in ("nominal", "matched"):
            for model in ("default", "paper-replica"):
                folder = tmp_path / f"crash_{c.number}" / f"{conditions}-{model}"
                s = pd.read_json(folder / "summary.json", typ="series")
                # the motors are powered off at the first contact in every run
                assert s["power_off_time_s"] == pytest.approx(s["first_contact_s"])
                r = by.loc[(c.number, conditions, model)]
                assert r["type"] == s["response_type"]
                assert r["delta_init_mm"] == pytest.approx(1e3 * s["delta_init_m"])
                assert r["crash_after_contact_s"] == pytest.approx(
                    s["crash_time_s"] - s["first_contact_s"]
                )
                if conditions == "matched":  # the authors' approach: from t = 0, tilted
                    assert r["contact_after_start_s"] == pytest.approx(0.5, abs=1e-9)
                    assert r["contact_inclination_deg"] == pytest.approx(
                        c.matched.inclination_deg, abs=0.5
                    )
        # the table's types are the runs'
        assert t.loc[c.number, "type_ours"] == by.loc[(c.number, "nominal", "default"), "type"]
        assert (
            t.loc[c.number, "type_matched_replica"]
            == by.loc[(c.number, "matched", "paper-replica"), "type"]
        )
        # the deepest deflection is the nominal run's own
        assert t.loc[c.number, "max_penetration_mm"] == pytest.approx(
            by.loc[(c.number, "nominal", "default"), "max_penetration_mm"]
        )
        # the replica's crash runs end at a tick with the CM at or below the ground
        rep = by.loc[(c.number, "matched", "paper-replica")]
        assert rep["crash_time_s"] / 0.005 == pytest.approx(round(rep["crash_time_s"] / 0.005))
    report = (tmp_path / "table3.md").read_text()
    assert "Experiment types matched: nominal conditions: default" in report
    assert "| 6 | D | D |" in report and "zero rate held" in report
    if data_dir() is None:
        assert table["attitude_rms_deg_0_3s"].isna().all()
        assert runs["position_rms_mm_0_3s"].isna().all()
        assert table["log_speed_m_s"].isna().all() and table["type_log"].isna().all()
    else:
        assert table["attitude_rms_deg_0_3s"].notna().all()
        assert runs["attitude_rms_deg_0_3s"].notna().all()
        assert runs["position_rms_mm_0_3s"].notna().all()
        assert (tmp_path / "crash_2" / "matched-paper-replica" / "compare.png").is_file()
        # crash 1's log shows no wall contact; the others are simulated at their estimates
        assert math.isnan(t.loc[1, "log_speed_m_s"]) and t.loc[1, "type_log"] == "unknown"
        assert t.loc[2, "type_log"] == "B"  # tracked through the landing
        others = t.loc[2:7]
        assert set(others["type_log_conditions"]) <= set(RESPONSE_TYPES)
        assert others["attitude_rms_log_conditions_deg_0_3s"].notna().all()
        assert (tmp_path / "crash_4" / "log-conditions" / "compare.png").is_file()


def test_sensitivity_shares_sum_to_one(tmp_path):
    from quadimpact.studies.table3.table3_study import sensitivity_spec
    from quadimpact.sweep import run_sweep

    crash = TABLE3[1]
    table = run_sweep(sensitivity_spec(crash, 12), tmp_path, workers=2)
    assert len(table) == 12
    h = table["heading_deg"]
    assert (abs(h - crash.heading_deg + 180.0) <= 6.4 + 1e-9).all()
    shares = table["response_type"].value_counts(normalize=True)
    assert math.isclose(shares.sum(), 1.0)
