"""The slowest trials of a study's table: ranked by CPU, with their steps and contact onsets."""

from __future__ import annotations

import pandas as pd
import pytest

from quadimpact.studies.slowest import slowest_lines, slowest_trials


def _table() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "run_id": [0, 1, 2, 3, 4],
            "pitch_deg": [0.0, -3.0, -6.0, -9.0, -12.0],
            "cost__kernel_cpu_s": [0.010, 0.012, 0.400, 0.011, float("nan")],
            "cost__total_cpu_s": [0.5, 0.02, 0.41, 0.02, 0.02],
            "integrator__steps": [900, 1000, 40_000, 950, 800],
            "integrator__rejected_steps": [10, 20, 19_000, 12, 9],
            "n_episodes": [1, 2, 3, 2, 1],
            "status": ["completed", "completed", "failed", "completed", "crashed"],
            "reason": ["", "", "step budget exhausted", "", ""],
        }
    )


def test_the_slowest_trial_comes_first_with_why():
    found = slowest_trials(_table(), ("run_id", "pitch_deg"), n=2)
    assert found is not None and found["cpu_column"] == "cost__kernel_cpu_s"
    assert found["median_cpu_ms"] == pytest.approx(11.5)  # of the four finite values
    first, second = found["trials"]
    assert (first["run_id"], second["run_id"]) == (2, 1)
    assert first["cpu_ms"] == pytest.approx(400.0)
    assert first["times_median"] == pytest.approx(400.0 / 11.5)
    assert (first["steps"], first["rejected_steps"], first["contact_onsets"]) == (40_000, 19_000, 3)
    assert (first["status"], first["reason"]) == ("failed", "step budget exhausted")
    lines = slowest_lines(found)
    assert lines[0] == "## Slowest trials"
    assert any(line.startswith("| 2 | -6 | 400.0 |") and "step budget exhausted" in line
               for line in lines)  # fmt: skip


def test_without_a_cpu_column_there_is_no_section():
    table = _table().drop(columns=["cost__kernel_cpu_s", "cost__total_cpu_s"])
    assert slowest_trials(table) is None
    assert slowest_lines(None) == []
