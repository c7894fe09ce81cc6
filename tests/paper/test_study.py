"""The paper's study, end to end (reduced where it costs)."""

import re

import pandas as pd
import pytest

from quadimpact.paper.study import reproduce
from quadimpact.simulation.metrics import RESPONSE_TYPES


@pytest.mark.slow
def test_reproduce_writes_a_report_with_computed_verdicts(tmp_path, capsys):
    r = reproduce(tmp_path, ablation=False, experiments=False, workers=2, progress=True)
    err = capsys.readouterr().err.splitlines()
    stages = [line for line in err if line.startswith("reproduce: ")]
    assert stages == [
        "reproduce: Figure 4 sweep and the example run, paper-replica",
        "reproduce: Figure 4 sweep and the example run, default",
        "reproduce: figures, tables and the report",
    ]
    assert err[err.index(stages[0]) + 1] == "sweep: 246 runs to do"  # each sweep is named
    text = r.report.read_text()
    f = r.findings
    assert set(f["variant"]) == {"paper-replica", "default"}
    assert len(f) == 2 * 10 and set(f["verdict"]) <= {"agrees", "partly", "disagrees", "n/a"}
    for _, row in f.iterrows():  # every verdict in the report is the computed one
        measured = row["measured"].replace("|", "\\|")  # escaped in the Markdown table
        assert f"**{row['verdict']}**: {measured}" in text
    rows = [line for line in text.splitlines() if line.startswith("| ") and "**" in line
            and line.split(" | ")[0][2:] in set(f["key"])]  # fmt: skip
    assert len(rows) == 10  # one per finding, five cells each: no "|" of |Y| splits a cell
    assert all(len(re.findall(r"(?<!\\)\|", line)) == 6 for line in rows)
    # the replica reproduces the paper's Figure 5 pattern and Figure 4's peak
    rep = f[f["variant"] == "paper-replica"].set_index("key")
    assert rep.loc["figure5", "verdict"] == "agrees"
    assert rep.loc["peak_near_10", "verdict"] == "agrees"
    for name in (
        "fig4_paper-replica.png",
        "table2_default.png",
        "fig4.parquet",
        "table2.parquet",
        "example-default/snapshots.png",
        "example-paper-replica/fig5.png",
    ):
        assert (tmp_path / name).is_file(), name
    t2 = pd.read_parquet(tmp_path / "table2.parquet")
    assert len(t2) == 2 * 246 and set(t2["response_type"].dropna()) <= set(RESPONSE_TYPES)
