"""The study's report: Table III in Markdown, with what the data say about each row."""

import math

import pandas as pd


def test_table3_report_flags_depths_beyond_the_bumper_radius():
    from quadimpact.experiments.table3 import EXTRA_COLUMNS, TABLE3_COLUMNS
    from quadimpact.paper.report import table3_markdown

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
