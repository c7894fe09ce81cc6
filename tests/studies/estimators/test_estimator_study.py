"""``quadimpact estimators``: the estimator study (docs/ESTIMATION.md 8)."""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd
import pytest

from quadimpact.errors import InputError
from quadimpact.studies.estimators.estimator_scenarios import ESTIMATORS, trial_scenario
from quadimpact.studies.estimators.estimator_study import EstimatorStudy

from helpers import run_cli

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "cli"))
from test_cli import assert_input_error  # noqa: E402

COLUMNS = ["estimator", "crash_rms_mean_deg", "crash_rms_median_deg", "crash_rms_p90_deg",
           "crash_rms_sd_deg", "not_crash_rms_mean_deg"]  # fmt: skip


def test_trials_are_seeded_and_the_same_for_every_estimator():
    a = [trial_scenario("authors-2016", i) for i in range(5)]
    assert a == [trial_scenario("authors-2016", i) for i in range(5)]
    assert len({d["seed"] for d in a}) == 5
    study = EstimatorStudy(scenario="authors-2016", n=3)
    spec = study.sweep_spec()
    assert spec.n_runs == 3 * len(ESTIMATORS)
    behind = [d["waypoint"]["x_m"] for d in a]
    assert all(1.5 <= x <= 3.5 for x in behind)
    assert all(-180 <= d["euler_deg"][2] <= 180 for d in a)
    # the replica's switches, each on its own
    back = trial_scenario("authors-2016", 0, back=frozenset({"rate"}))
    assert "rate_hz" not in back["imu"] and a[0]["imu"]["rate_hz"] == 100.0
    back = trial_scenario("authors-2016", 0, back=frozenset({"impact_noise"}))
    assert back["imu"]["impact_disturbance"] == {"mode": "add"}
    back = trial_scenario("authors-2016", 0, back=frozenset({"flight"}))
    assert back["kind"] == "impact-trial" and back["sensors"] == "authors-2016"


def test_bad_options_are_refused():
    with pytest.raises(InputError, match="back: only with scenario 'authors-2016'"):
        EstimatorStudy(scenario="impact", back=("gain",))
    with pytest.raises(InputError, match="initial_error: must be one of"):
        EstimatorStudy(initial_error="some")


def test_the_command_writes_its_table_and_resumes(tmp_path: Path) -> None:
    out = tmp_path / "est"
    args = ("estimators", "--scenario", "authors-2016", "--n", "2", "--workers", "1",
            "--no-progress", "--out", str(out))  # fmt: skip
    proc = run_cli(*args, cwd=tmp_path, timeout=600)
    assert proc.returncode == 0, proc.stderr
    table = pd.read_csv(out / "estimators.csv")
    assert list(table.columns[: len(COLUMNS)]) == COLUMNS
    assert list(table["estimator"]) == [label for label, _, _ in ESTIMATORS]
    assert "success_share" not in table.columns  # observers: the loop reads the truth
    report = (out / "report.md").read_text()
    assert "10.85" in report and "1.6" in report
    for name in ("error_around_contact.png", "crash_error_per_trial.png", "trials.parquet"):
        assert (out / name).is_file()
    again = run_cli(*args, cwd=tmp_path, timeout=600)
    assert again.returncode == 0 and "0 run now" in again.stdout
    assert_input_error(
        run_cli("estimators", "--back", "gain", "--out", str(tmp_path / "x"), cwd=tmp_path),
        "back: only with scenario 'authors-2016'",
    )


@pytest.mark.parametrize("initial_error", ["none", "authors"])
def test_the_report_gives_both_of_the_authors_numbers(initial_error: str) -> None:
    """Issue 60 item 5: the column "authors: crash / not-crash" showed one number."""
    from quadimpact.studies.estimators.estimator_report import render_report
    from quadimpact.studies.estimators.estimator_scenarios import AUTHORS_2016, AUTHORS_ROWS

    study = EstimatorStudy(scenario="authors-2016", n=2, initial_error=initial_error)
    rows = [
        {"estimator": label, "crash_rms_mean_deg": 1.0, "crash_rms_mean_ci95_deg": 0.1,
         "crash_rms_median_deg": 1.0, "crash_rms_p90_deg": 1.5, "crash_rms_sd_deg": 0.2,
         "not_crash_rms_mean_deg": 0.5, "trials": 2, "trials_counted": 2}
        for label, _, _ in ESTIMATORS
    ]  # fmt: skip
    run = {"n_runs": 12, "n_ran": 12, "sweep_s": 1.0, "backend": "serial"}
    report = render_report(study, rows, [Path("a.png"), Path("b.png")], run)
    table = [line for line in report.splitlines() if line.startswith("| ")]
    assert table[0].endswith("| authors: crash / not-crash (°) |")
    for line in table[1:]:
        label = line.split(" | ")[0][2:]
        theirs = line.rstrip(" |").rsplit("| ", 1)[1]
        if label not in AUTHORS_ROWS:
            assert theirs == "–", line
            continue
        a = AUTHORS_2016[initial_error][AUTHORS_ROWS[label]]
        crash, not_crash = theirs.split(" / ")
        assert float(crash) == a["crash"], line
        assert not_crash == (f"{a['not_crash']:.2f}" if "not_crash" in a else "–"), line
    assert ("no not-crash figure" in report) == (initial_error == "none")
