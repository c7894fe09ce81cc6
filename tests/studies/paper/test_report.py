"""The study's report: Table III in Markdown, with what the data say about each row."""

import math

import pandas as pd


def test_table3_report_flags_depths_beyond_the_bumper_radius():
    from quadimpact.studies.paper.paper_report import table3_markdown
    from quadimpact.studies.table3.table3_study import EXTRA_COLUMNS, TABLE3_COLUMNS

    row = {c: math.nan for c in (*TABLE3_COLUMNS, *EXTRA_COLUMNS)}
    row.update(crash=5, heading_deg=11.0, speed_m_s=2.0, inclination_deg=15.0,
               type_paper_experiment="Other", type_paper_simulation="Other", type_ours="D",
               type_replica="D", share_B=0.13, share_D=0.73, share_Other=0.14,
               max_penetration_mm=163.0, log_heading_deg=-168.3, log_speed_m_s=2.26,
               log_inclination_deg=30.4, log_roll_deg=0.6, log_pitch_deg=30.9,
               type_log="unknown", type_log_conditions="Other", log_share_Other=0.999,
               log_share_B=0.001, log_max_penetration_mm=100.0)  # fmt: skip
    shallow = {**row, "crash": 2, "type_ours": "Other", "max_penetration_mm": 57.0,
               "type_log": None, "type_log_conditions": None}  # fmt: skip
    text = table3_markdown(pd.DataFrame([row, shallow]))
    assert "| 163 † |" in text and "| 57 |" in text  # 110 mm: the Spiri's bumper radius
    assert "| 100 |" in text  # the log-conditions run stays within the radius
    assert "Other >99%, B <1%" in text or "B <1%, Other >99%" in text
    assert "the bumpers deflect 163 mm, beyond their radius" in text
    assert "there ours is Other" in text
    assert "| 2 | no log |" in text
    assert "+0.26 to +0.26 m/s" in text  # computed from the rows with a log estimate


def test_table3_rows_have_verdicts_that_say_why():
    """Same type, other motion: partly, and the report says how the motions differ; the log
    table gives ψ as Table III does (front-first equivalent)."""
    from quadimpact.studies.paper.paper_report import table3_markdown
    from quadimpact.studies.table3.table3_study import EXTRA_COLUMNS, TABLE3_COLUMNS, crash_verdict

    row = {c: math.nan for c in (*TABLE3_COLUMNS, *EXTRA_COLUMNS)}
    row.update(crash=1, heading_deg=20.0, speed_m_s=0.7, inclination_deg=4.5,
               type_paper_experiment="B", type_paper_simulation="B", type_ours="B",
               type_replica="B", share_B=0.99, attitude_rms_deg_0_3s=70.8,
               max_penetration_mm=36.0, type_log="unknown", type_log_conditions=None,
               sim_roll_change_deg_0_3s=48.2, log_roll_change_deg_0_3s=-23.2,
               sim_pitch_change_deg_0_3s=-48.6, log_pitch_change_deg_0_3s=41.9,
               sim_yaw_change_deg_0_3s=-79.0, log_yaw_change_deg_0_3s=4.0)  # fmt: skip
    good = {**row, "crash": 2, "attitude_rms_deg_0_3s": 12.2, "type_log": "B",
            "type_log_conditions": "B", "log_heading_deg": -170.2, "log_speed_m_s": 1.19,
            "log_inclination_deg": 0.0, "log_roll_deg": 2.8, "log_pitch_deg": -0.5}  # fmt: skip
    other = {**row, "crash": 5, "type_ours": "D", "type_paper_experiment": "Other",
             "share_Other": 0.14, "share_D": 0.73}  # fmt: skip
    assert crash_verdict(row) == ("partly", "type B, but not the motion: attitude RMS 70.8° > 20°")
    assert crash_verdict(good)[0] == "agrees" and crash_verdict(other)[0] == "disagrees"
    text = table3_markdown(pd.DataFrame([row, good, other]))
    assert "| **partly**: type B, but not the motion: attitude RMS 70.8° > 20° |" in text
    assert "| **agrees**: type B; attitude RMS 12.2° ≤ 20° |" in text
    assert "Other in 14% of the runs over the uncertainty (< 20%)" in text
    assert "Verdict of each row: agrees:" in text
    note = next(line for line in text.splitlines() if line.startswith("- Crash 1:"))
    assert "the motion is not" in note and "Ours turn the other way in roll and pitch" in note
    assert "does not show the wall contact" in note
    assert "| 2 | 9.8 | 1.19 |" in text and "-170.2" not in text  # Table III's convention
