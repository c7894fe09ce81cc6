"""The recovery study end to end at small N: table, figures, report, resume, determinism."""

from __future__ import annotations

import json
import re

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from quadimpact.errors import InputError
from quadimpact.packing.constants import RPM
from quadimpact.studies.recovery import recovery_analysis as analysis
from quadimpact.studies.recovery.recovery_study import RecoveryStudy, run_study, sample_trials
from quadimpact.studies.statistics import percent, wilson_interval
from quadimpact.sweep import SUMMARY_COLUMNS, SweepSpec

from helpers import assert_same_table

N = 30
METRICS = (
    "recovered", "not_detected", "false_detection", "t_detect_s", "detection_latency_s",
    "normal_error_deg", "t_stage1_s", "t_stage2_s", "t_stage3_s", "t_stage4_s",
    "time_to_recover_s", "height_loss_m", "horizontal_drift_m", "min_altitude_m",
    "impacts_after_detection", "max_tilt_deg", "max_rate_rad_s", "final_speed_m_s",
)  # fmt: skip
DERIVED = ("inclination_deg", "inclination_bin", "speed_bin", "outcome_class")


@pytest.fixture(scope="module")
def study_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("recovery")
    result = run_study(RecoveryStudy(n=N, seed=5), out, workers=1, animation=False)
    return out, result


@pytest.mark.slow  # the module's study: 30 trials, the figures, the example
def test_the_study_writes_its_table_figures_and_example(study_dir) -> None:
    out, result = study_dir
    table = pd.read_parquet(out / "trials.parquet")
    assert len(table) == N and list(table["run_id"]) == list(range(N))
    for column in (*METRICS, *DERIVED, "roll_deg", "pitch_deg", "yaw_deg", "speed_m_s", "seed"):
        assert column in table.columns, column
    assert {c for c, _ in SUMMARY_COLUMNS} - {"inclination_deg"} <= set(table.columns)
    assert (table["inclination_deg"] == -table["pitch_deg"]).all()
    # the sampled conditions are the rows' (and the trials really ran: every one hit the wall)
    trials = sample_trials(N, seed=5)
    for name in ("roll_deg", "pitch_deg", "yaw_deg", "speed_m_s", "seed"):
        assert table[name].tolist() == [t[name] for t in trials]
    assert table["first_contact_s"].notna().all() and (table["status"] == "completed").all()
    assert table["seed"].nunique() == N  # every trial its own IMU seed
    for name in ("success_map.png", "success_by_bin.png", "distributions.png", "report.md",
                 "study.json", "example/summary.json", "example/recovery.png",
                 "example/viewer.html", "example/timeseries.parquet"):  # fmt: skip
        assert (out / name).is_file(), name
    # the example is the trial nearest the median conditions, run again identically
    ex = json.loads((out / "example/summary.json").read_text())
    row = table.set_index("run_id").loc[analysis.example_trial(table)]
    assert ex["t_stage4_s"] == row["t_stage4_s"] and ex["height_loss_m"] == row["height_loss_m"]


@pytest.mark.slow
def test_the_report_numbers_are_the_tables(study_dir) -> None:
    out, result = study_dir
    table = pd.read_parquet(out / "trials.parquet")
    text = (out / "report.md").read_text()
    # a success: stage 4 reached and never below altitude 0, over the valid trials (a
    # steep impact may tumble down the wall and recover 10 m lower: not a success)
    valid = ~table["outcome_class"].astype(str).isin(analysis.EXCLUDED_CLASSES)
    above = table["min_altitude_m"] >= 0.0
    k = int((table["recovered"].fillna(False).astype(bool) & above & valid).sum())
    n = int(valid.sum())
    lo, hi = wilson_interval(k, n)
    assert (f"**{k} / {n} = {percent(k / n)} [{percent(lo)}, {percent(hi)}]**") in text
    assert f"**Trials**: {N} impact trials" in text and "study seed 5" in text
    for cls in analysis.OUTCOME_CLASSES:
        count = int((table["outcome_class"].astype(str) == cls).sum())
        assert f"| {cls} | {count} |" in text
    for r in analysis.rate_by(table, "inclination_bin").itertuples():
        assert re.search(rf"\| {re.escape(r.bin)} \| {r.n} \| {r.recovered} \| ", text), r.bin
    good = table[table["outcome_class"].astype(str) == "recovered"]
    q = np.quantile(good["time_to_recover_s"], [0.5, 0.9])
    assert f"| {len(good)} | {q[0]:.3f} | {q[1]:.3f} |" in text
    assert "`navi`" in text and "friction μ = 0.3" in text and "0.1.0" in text


@pytest.mark.slow
def test_rerunning_resumes_and_gives_the_same_table(study_dir) -> None:
    out, first = study_dir
    before = pd.read_parquet(out / "trials.parquet")
    drawn = {p: p.stat().st_mtime_ns for p in out.iterdir() if p.suffix in (".png", ".md")}
    again = run_study(RecoveryStudy(n=N, seed=5), out, workers=1, example=False)
    assert again.run_info["n_ran"] == 0 and again.run_info["n_already_done"] == N
    # nothing ran: nothing is drawn again, the numbers are the table's
    assert {p: p.stat().st_mtime_ns for p in drawn} == drawn
    assert again.numbers["success"] == first.numbers["success"]
    first_sweep = first.run_info["elapsed_s"]
    # a finished study's rerun says so and leaves its report as the first run wrote it
    assert f"{N} trials run now in {first_sweep:.1f} s (serial)" in again.report.read_text()
    pd.testing.assert_frame_equal(pd.read_parquet(out / "trials.parquet"), before)
    # an interrupted sweep: keep its first 10 runs; the rerun does only the other 20
    runs = out / "sweep" / "runs.parquet"
    pq.write_table(pq.read_table(runs).slice(0, 10), runs)
    resumed = run_study(RecoveryStudy(n=N, seed=5), out, workers=1, example=False)
    assert resumed.run_info["n_already_done"] == 10 and resumed.run_info["n_ran"] == N - 10
    assert_same_table(pd.read_parquet(out / "trials.parquet"), before)
    with pytest.raises(InputError, match=r"holds a recovery study with other options "
                                         r"\(--seed 5 there, 6 asked\)"):  # fmt: skip
        run_study(RecoveryStudy(n=N, seed=6), out, workers=1, example=False)


def test_spiri_gets_the_navi_slew_limit_and_the_replica_can_hold() -> None:
    assert "rotor_slew_limit_rad_s2" not in RecoveryStudy(n=1).base()
    base = RecoveryStudy(vehicle="spiri", n=1).base()
    assert base["rotor_slew_limit_rad_s2"] == pytest.approx(70_000 * RPM)
    replica = RecoveryStudy(n=1, model="recovery-replica", pre_impact="hold").base()
    assert replica["model_options"] == {"pre_impact": "scenario"}
    assert "model_options" not in RecoveryStudy(n=1, model="recovery-replica").base()
    for bad, match in ((dict(n=0), "n: must be an integer >= 1"),
                       (dict(imu="loud"), "imu: must be one of"),
                       (dict(vehicle="nope"), "vehicle: vehicle 'nope'"),
                       (dict(model="paper-replica"), "model: must be one of")):  # fmt: skip
        with pytest.raises(InputError, match=match):
            RecoveryStudy(**bad)


def test_the_replica_holding_its_rotors_holds_them_until_the_detection() -> None:
    from quadimpact.inputs.scenarios import scenario_from_dict
    from quadimpact.simulation import simulate

    def run(pre_impact):
        spec = RecoveryStudy(n=1, model="recovery-replica", pre_impact=pre_impact).sweep_spec()
        return simulate(scenario_from_dict(spec.scenario_dict(0)))

    for pre_impact in ("hold", "spin-down"):
        r = run(pre_impact)
        s, ts = r.summary, r.timeseries
        assert s["pre_impact"] == pre_impact and s["model_options"]["contact_gate_m"] == 0.3
        before = ts[ts["t_s"] < s["t_detect_s"]]
        w = before[[f"omega{j}_rad_s" for j in (1, 2, 3, 4)]].to_numpy()
        drop = w[0] - w[-1]
        if pre_impact == "hold":
            assert np.abs(drop).max() == 0.0
        else:  # the slew limit, 70,000 RPM/s, from the first interval on
            ticks = np.floor(before["t_s"].iloc[-1] / 0.005 + 1e-9) + 1
            assert drop == pytest.approx(np.full(4, 70_000 * RPM * 0.005 * ticks), rel=1e-9)


def test_a_users_sweep_runs_and_must_be_an_impact_trial(tmp_path) -> None:
    spec = SweepSpec(
        base={"kind": "impact-trial", "vehicle": "navi", "yaw_deg": 10.0},
        runs=[{"pitch_deg": -20.0, "speed_m_s": 1.0}, {"pitch_deg": 40.0, "speed_m_s": 2.0}],
        where="mine.toml",
    )
    r = run_study(spec, tmp_path, workers=1, example=False)
    assert list(r.table["pitch_deg"]) == [-20.0, 40.0] and list(r.table["yaw_deg"]) == [10, 10]
    assert list(r.table["inclination_deg"]) == [20.0, -40.0]
    assert "sweep file `mine.toml`" in r.report.read_text()
    with pytest.raises(InputError, match="must be 'impact-trial'"):
        run_study(SweepSpec(grid={"speed_m_s": [1.0]}), tmp_path / "w", workers=1)


@pytest.mark.slow
def test_the_table_is_the_same_on_one_or_two_workers(tmp_path) -> None:
    study = RecoveryStudy(n=16, seed=2, imu="noisy")
    one = run_study(study, tmp_path / "one", workers=1, example=False)
    two = run_study(study, tmp_path / "two", workers=2, example=False)
    assert two.run_info["backend"] == "2 processes"
    assert_same_table(
        pd.read_parquet(tmp_path / "one" / "trials.parquet"),
        pd.read_parquet(tmp_path / "two" / "trials.parquet"),
    )
    assert one.table["seed"].nunique() == 16


@pytest.mark.slow
def test_the_example_runs_beside_the_trials_on_a_pool(tmp_path, study_dir) -> None:
    """On worker processes the example trial (chosen from the inputs) is written beside them."""
    out, serial = study_dir
    r = run_study(RecoveryStudy(n=N, seed=5), tmp_path, workers=2, animation=False)
    assert r.description["example"] == serial.description["example"]
    drop = ("cost", "integrator")
    ex = {k: v for k, v in json.loads((tmp_path / "example/summary.json").read_text()).items()
          if k not in drop}  # fmt: skip
    ex_serial = {k: v for k, v in json.loads((out / "example/summary.json").read_text()).items()
                 if k not in drop}  # fmt: skip
    assert ex == ex_serial
    assert sorted(p.name for p in r.figures) == sorted(p.name for p in serial.figures)
    assert not list(tmp_path.glob(".example.partial-*"))


def test_a_script_that_imports_the_studies_costs_their_workers_no_pandas() -> None:
    """A pool's workers run the main script again (multiprocessing, so that its plug-ins
    register): importing the study modules loads no pandas (0.4 s of CPU per worker),
    while running a study still has it (the table is read with it)."""
    import subprocess
    import sys

    code = (
        "import sys\n"
        "import quadimpact.studies.recovery.recovery_study, quadimpact.studies.pole.pole_study\n"
        "print('pandas' in sys.modules)\n"
        "quadimpact.studies.recovery.recovery_study.trial_inputs(quadimpact.studies.recovery.recovery_study.RecoveryStudy(n=3)"
        ".sweep_spec())\n"
        "print('pandas' in sys.modules)\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["False", "True"]


def test_the_pole_replica_holds_its_rotors_unless_told_otherwise() -> None:
    # the variant's own pre-impact behaviour is the study's default: hold
    study = RecoveryStudy(n=1, model="pole-replica")
    assert study.pre_impact == "hold" and study.options()["pre_impact"] == "hold"
    base = study.base()
    assert base["model"] == "pole-replica" and base["pre_impact"] == "hold"
    assert "model_options" not in base
    # the law alone on the authors' trials: spin-down, the switch set to the scenario's
    spun = RecoveryStudy(n=1, model="pole-replica", pre_impact="spin-down").base()
    assert spun["pre_impact"] == "spin-down"
    assert spun["model_options"] == {"pre_impact": "scenario"}
    # the other models keep spin-down as the study's default, as before
    assert RecoveryStudy(n=1).pre_impact == "spin-down"
    assert RecoveryStudy(n=1, model="recovery-replica").pre_impact == "spin-down"
