"""``quadimpact recovery`` and impact-trial sweeps on the command line."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from test_cli import assert_input_error

from helpers import run_cli

TRIAL_SWEEP = """
[base]
kind = "impact-trial"
vehicle = "navi"
model = "recovery-replica"

[[runs]]
pitch_deg = -10.0
speed_m_s = 1.0
seed = 1

[[runs]]
pitch_deg = -44.0
roll_deg = 3.0
speed_m_s = 2.0
seed = 2
"""


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (["--n", "0"], ["'--n'", "0 is not in the range x>=1"]),
        (["--vehicle", "nope"], ["--vehicle: vehicle 'nope': unknown vehicle name"]),
        (["--imu", "loud"], ["'--imu'", "'loud' is not one of 'ideal', 'noisy'"]),
        (["--model", "paper-replica"], ["'--model'", "'paper-replica' is not one of"]),
        (["--pre-impact", "nominal"], ["'--pre-impact'", "'nominal' is not one of"]),
        (["--seed", "-3"], ["'--seed'", "-3 is not in the range x>=0"]),
        (["--sweep", "missing.toml"], ["missing.toml: file not found"]),
        (
            ["--sweep", "trials.toml", "--n", "5"],
            ["--sweep: the sweep file sets the trials", "--n"],
        ),
        (["--sweep", "approach.toml"], ["approach.toml: base: kind: must be 'impact-trial'"]),
        (["--estimator", "kalman"], ["--estimator: must be one of 'ideal', 'complementary'"]),
        (["--sensors", "all"], ["--sensors: must be one of 'ideal', 'noisy'", "(got 'all')"]),
        (["--imu", "noisy", "--sensors", "impact"], ["--imu and --sensors: give one"]),
        (["--policy", "none.npz"], ["--policy: none.npz: no such file"]),
        (["--policy", "trials.toml"], ["--policy: trials.toml: not a .npz policy file"]),
    ],
)
def test_bad_arguments_exit_2_with_one_line(tmp_path: Path, args, fragments) -> None:
    (tmp_path / "trials.toml").write_text(TRIAL_SWEEP)
    (tmp_path / "approach.toml").write_text("[base]\nspeed_m_s = 1.0\n[grid]\nheading_deg = [0]\n")
    proc = run_cli("recovery", *args, "--out", "out", "--workers", "1", cwd=tmp_path)
    assert_input_error(proc, *fragments)
    assert not (tmp_path / "out" / "trials.parquet").exists()


def test_an_impact_trial_sweep_file_runs_with_quadimpact_sweep(tmp_path: Path) -> None:
    (tmp_path / "trials.toml").write_text(TRIAL_SWEEP)
    proc = run_cli("sweep", "trials.toml", "--out", "s", "--workers", "1", "--no-progress",
                   cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    t = pd.read_parquet(tmp_path / "s" / "runs.parquet")
    for column in ("recovered", "t_detect_s", "t_stage4_s", "time_to_recover_s",
                   "height_loss_m", "horizontal_drift_m", "impacts_after_detection",
                   "detection_latency_s", "not_detected", "false_detection"):  # fmt: skip
        assert column in t.columns, column
    assert list(t["pitch_deg"]) == [-10.0, -44.0] and (t["controller"] == "recovery").all()
    assert (t["model_options__contact_gate_m"] == 0.3).all() and t["detected"].all()
    # detected after the first contact, and stage 4 after the detection where reached
    assert (t["t_detect_s"] >= t["first_contact_s"]).all()
    ok = t["recovered"].astype(bool)
    assert (t.loc[ok, "t_stage4_s"] > t.loc[ok, "t_detect_s"]).all()


def test_the_recovery_command_without_the_example_writes_no_example(tmp_path: Path) -> None:
    proc = run_cli("recovery", "--n", "3", "--out", "r", "--workers", "1", "--no-example",
                   "--no-progress", cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "r"
    assert len(pd.read_parquet(out / "trials.parquet")) == 3
    assert not (out / "example").exists()
    assert (out / "success_map.png").is_file()
    report = (out / "report.md").read_text()
    assert "## Example trial" not in report and "example/" not in report
    assert "the example included" not in report and "(tables and figures included)" in report


@pytest.mark.slow  # three processes, one with the example and its viewer
def test_the_recovery_command_runs_a_small_study(tmp_path: Path) -> None:
    proc = run_cli("recovery", "--n", "6", "--seed", "1", "--out", "r", "--workers", "1",
                   "--no-animation", "--no-progress", cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "success     " in proc.stdout and "report      r/report.md" in proc.stdout
    t = pd.read_parquet(tmp_path / "r" / "trials.parquet")
    k = int(t["recovered"].fillna(False).sum())
    assert f"success     {k} / 6 = " in proc.stdout
    assert "excluded    none (all 6 trials valid)" in proc.stdout
    # issue 20 item 15: the line of the detected impacts says what it is
    d = int(t["detected"].fillna(False).sum())
    assert f"if detected {k} / {d} = " in proc.stdout
    assert "(recovered / detected impacts)" in proc.stdout
    again = run_cli("recovery", "--n", "6", "--seed", "1", "--out", "r", "--workers", "1",
                    "--no-animation", "--no-progress", cwd=tmp_path)  # fmt: skip
    assert again.returncode == 0 and "all done before, nothing to run" in again.stdout
    other = run_cli("recovery", "--n", "7", "--seed", "1", "--out", "r", "--workers", "1",
                    cwd=tmp_path)  # fmt: skip
    assert_input_error(other, "holds a recovery study with other options (--n 6 there, 7 asked)")
    other = run_cli("recovery", "--n", "7", "--out", "r", "--workers", "1", cwd=tmp_path)
    assert_input_error(other, "holds a recovery study with other options (--n 6 there, 7 asked; "
                              "--seed 1 there, 0 asked)")  # fmt: skip


@pytest.mark.slow  # the study's example with its viewer
def test_the_recovery_command_takes_an_estimator_and_sensors(tmp_path: Path) -> None:
    proc = run_cli("recovery", "--n", "4", "--estimator", "complementary", "--sensors", "impact",
                   "--out", "r", "--workers", "1", "--no-animation", "--no-progress",
                   cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    t = pd.read_parquet(tmp_path / "r" / "trials.parquet")
    assert (t["estimator"] == "complementary").all() and (t["sensors"] == "impact").all()
    assert t["impact_disturbance"].all() and t["est_attitude_rms_crash_deg"].notna().all()
    report = (tmp_path / "r" / "report.md").read_text()
    assert "## Estimation" in report and "Estimator: complementary; sensors: impact" in report
    assert (tmp_path / "r" / "example" / "estimate.png").is_file()


def test_the_recovery_command_flies_a_policy_file_and_records_it(tmp_path: Path) -> None:
    """--policy FILE: the trials fly the law with the file's residual; study.json names the
    file and its weights' digest; a changed file is another study (refused in the folder)."""
    import json

    import numpy as np

    from quadimpact.inputs.policy_file import initial_policy, save_policy

    p = initial_policy(4, 0.3, 4.0, seed=2)
    path = save_policy(p.with_vector(np.full(p.vector().size, 0.1)), tmp_path / "mine.npz")
    args = ("recovery", "--n", "3", "--out", "r", "--workers", "1", "--no-example",
            "--no-progress", "--sensors", "impact", "--estimator", "ekf")  # fmt: skip
    law = run_cli(*args[:4], "law", *args[5:], cwd=tmp_path)
    proc = run_cli(*args, "--policy", "mine.npz", cwd=tmp_path)
    assert law.returncode == 0 and proc.returncode == 0, proc.stderr
    study = json.loads((tmp_path / "r" / "study.json").read_text())["study"]
    assert study["policy"] == str(path.resolve())
    assert study["policy_sha256"] == load_sha(path)
    assert "Learned policy" in (tmp_path / "r" / "report.md").read_text()
    mine = pd.read_parquet(tmp_path / "r" / "trials.parquet")
    theirs = pd.read_parquet(tmp_path / "law" / "trials.parquet")
    for col in ("recovered", "height_loss_m", "time_to_recover_s", "time_to_hover_s"):
        assert col in mine.columns
    assert not mine["min_altitude_m"].equals(theirs["min_altitude_m"])  # the residual acts
    save_policy(p, path)  # other weights, same file: another study
    other = run_cli(*args, "--policy", "mine.npz", cwd=tmp_path)
    assert_input_error(other, "holds a recovery study with other options", "--policy")


def load_sha(path: Path) -> str:
    from quadimpact.inputs.policy_file import load_policy

    return load_policy(path).sha256
