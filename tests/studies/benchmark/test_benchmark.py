"""The benchmark: its suite, its rows, a smoke run with the cache, its command, a plug-in."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from quadimpact import simulate
from quadimpact.cli import cli
from quadimpact.errors import InputError
from quadimpact.inputs.scenarios import scenario_from_dict
from quadimpact.studies.benchmark.benchmark_study import BenchmarkStudy, run_benchmark
from quadimpact.studies.benchmark.cells import cell_numbers
from quadimpact.studies.benchmark.subject import PUBLISHED, REFERENCES, Subject
from quadimpact.studies.benchmark.suite import (
    EDGE_PILLAR,
    SUITE_VERSION,
    TASKS,
    parse_tasks,
    sensor_set,
)

SQRT_HALF = math.sqrt(0.5)


def test_the_suite_sizes():
    assert [TASKS[t].size(False) for t in TASKS] == [10_000, 3_266, 3_266]
    assert [TASKS[t].size(True) for t in TASKS] == [1_000, 240, 240]
    assert parse_tasks(None) == ("wall", "pole", "edge")
    assert parse_tasks("edge, wall") == ("wall", "edge")
    with pytest.raises(InputError, match="--tasks: unknown task 'roof'"):
        parse_tasks("wall,roof")
    with pytest.raises(InputError, match="--tasks: empty task name"):
        parse_tasks("wall,")


def test_the_sensor_sets_of_each_suite():
    """Suite 3 flies ideal, lab and onboard, suite 2 ideal and lab, both impact only when
    named; suite 1 ideal and impact."""
    from quadimpact.studies.benchmark.suite import parse_sensor_sets, suite

    assert parse_sensor_sets(None) == ("ideal", "lab", "onboard")
    assert parse_sensor_sets(None, "2") == ("ideal", "lab")
    with pytest.raises(InputError, match="--sensors: suite 2 flies ideal, lab, impact"):
        parse_sensor_sets("onboard", "2")
    assert parse_sensor_sets("impact, ideal") == ("ideal", "impact")
    assert parse_sensor_sets(None, "1") == ("ideal", "impact")
    with pytest.raises(InputError, match="--sensors: suite 1 flies ideal, impact"):
        parse_sensor_sets("lab", "1")
    with pytest.raises(InputError, match="--sensors: a sensor set named twice"):
        parse_sensor_sets("lab,lab")
    with pytest.raises(InputError, match="--sensors: unknown sensor set 'gps'"):
        parse_sensor_sets("gps")
    with pytest.raises(InputError, match="--suite: unknown suite version '4'"):
        suite("4")
    assert sensor_set("lab").sensors == "indoor" and sensor_set("lab", "ekf-additive").estimator \
        == "ekf-additive"  # fmt: skip
    # the onboard set keeps its navigation filter unless a row names another estimator
    assert sensor_set("onboard").estimator == "nav-ekf"
    assert sensor_set("onboard", "complementary").estimator == "complementary"


def test_the_wall_task_is_the_recovery_studys_trials():
    from quadimpact.studies.recovery.recovery_spec import RecoveryStudy

    spec = Subject("default").spec(TASKS["wall"], True, sensor_set("ideal"), version="1")
    theirs = RecoveryStudy(n=1_000).sweep_spec()
    assert spec.n_runs == 1_000 and spec.trials == theirs.trials
    assert spec.base == theirs.base
    impact = Subject("default").spec(TASKS["wall"], True, sensor_set("impact"), version="1")
    assert (impact.base["sensors"], impact.base["estimator"]) == ("impact", "ekf")
    # suite 2: the same trials, 4 s long over a ground that ends a run
    v2 = Subject("default").spec(TASKS["wall"], True, sensor_set("lab"))
    assert v2.trials == theirs.trials
    lab = RecoveryStudy(n=1_000, sensors="indoor", estimator="ekf").sweep_spec()
    assert v2.base == {**lab.base, "final_time_s": 4.0, "ground": "crash"}


def test_the_pillars_edge_is_on_the_poles_axis_and_its_faces_at_45_degrees():
    """A level trial well to one side meets a face whose normal is 45 deg off the approach,
    mirrored on the other side; the start touches nothing (the edge is 0.3 m ahead)."""
    spec = Subject("default").spec(TASKS["edge"], True, sensor_set("ideal"))
    assert spec.base["obstacles"] == [EDGE_PILLAR]
    normals = {}
    for offset in (0.3, -0.3):
        d = {**spec.scenario_dict(0), "pitch_deg": 0.0, "lateral_offset_m": offset}
        d["final_time_s"] = 0.4
        s = simulate(scenario_from_dict(d)).summary
        normals[offset] = s["first_contact_normal"]
        # the face there is X = |Y|: the CM starts 0.6 m from it along X - |Y|, the nearest
        # rim point (bumper 1 or 4, its centre 0.27 m along X - |Y|, radius 0.125 m) reaches
        # 0.27 + 0.125 sqrt(2) m of that: 0.153 m to fly at 2 m/s (the rings' 5 deg tilt
        # aside)
        reach = 0.27 + 0.125 * math.sqrt(2.0)
        assert s["first_contact_s"] == pytest.approx((0.6 - reach) / 2.0, abs=0.003)
    assert normals[0.3] == pytest.approx([-SQRT_HALF, SQRT_HALF, 0.0], abs=1e-12)
    assert normals[-0.3] == pytest.approx([-SQRT_HALF, -SQRT_HALF, 0.0], abs=1e-12)


def test_rows_fly_their_own_controller_and_model():
    quick, ideal = True, sensor_set("ideal")
    rows = {r.name: r for r in REFERENCES}
    pole = rows["pole-replica"].spec(TASKS["pole"], quick, ideal).scenario_dict(0)
    assert (pole["model"], pole["pre_impact"]) == ("pole-replica", "hold")
    base = rows["baseline"].spec(TASKS["wall"], quick, ideal).base
    assert base["controller"] == "paper" and "pre_impact" not in base
    classic = rows["classic"].spec(TASKS["wall"], quick, ideal).base
    assert classic["model"] == "classic" and classic["pre_impact"] == "spin-down"
    mine = Subject("mine", params={"a_mag_m_s2": 4.8}).spec(TASKS["edge"], quick, ideal)
    assert mine.scenario_dict(0)["controller_params"] == {"a_mag_m_s2": 4.8}
    with pytest.raises(InputError, match="--policy: .*none.npz: no such file"):
        Subject("p", kind="policy", policy="none.npz")
    with pytest.raises(InputError, match="--model: must be one of"):
        Subject("m", model="nope")


def test_a_residual_policy_row_flies_the_law_with_the_policy_in_its_model(tmp_path):
    """--policy FILE: the recovery controller in the row's model with the file's residual,
    the pre-impact behaviour of the law kept, compiled in the cached kernel; a user's file
    is never cached (it may change under the same path), its digest is in the row."""
    from quadimpact.inputs.policy_file import initial_policy, save_policy

    path = save_policy(initial_policy(4, 0.3, 4.0, seed=1), tmp_path / "mine.npz")
    quick, ideal = True, sensor_set("ideal")
    row = Subject("mine", kind="policy", policy=str(path))
    assert row.residual and row.law and not row.plugin and not row.cacheable
    wall = row.spec(TASKS["wall"], quick, ideal).base
    assert wall["controller"] == "recovery" and wall["pre_impact"] == "spin-down"
    assert wall["controller_params"] == {"policy": str(path.resolve())}
    pole = row.spec(TASKS["pole"], quick, ideal).scenario_dict(0)
    assert pole["pre_impact"] == "nominal" and pole["controller_params"]["policy"]
    replica = Subject("r", kind="policy", policy=str(path), model="pole-replica")
    assert replica.spec(TASKS["pole"], quick, ideal).scenario_dict(0)["pre_impact"] == "hold"
    assert row.describe()["policy"].startswith(f"{path.resolve()} (sha256 ")


def test_cell_numbers_of_a_hand_made_table():
    t = pd.DataFrame({
        "run_id": range(5), "status": ["completed"] * 4 + ["failed"],
        "success": [True, True, False, True, False], "valid": [True] * 4 + [False],
        "recovered": [True, True, False, True, None],
        "time_to_recover_s": [0.1, 0.2, np.nan, 0.3, np.nan],
        "time_to_hover_s": [1.0, np.nan, np.nan, 2.0, np.nan],
        "height_lost_m": [0.5, 1.0, 20.0, 1.5, np.nan],
        "horizontal_drift_m": [1.0, 2.0, np.nan, 3.0, np.nan],
        "not_detected": [False, False, True, False, None],
        "false_detection": [False] * 5, "t_stage1_s": [0.05, 0.05, np.nan, 0.05, np.nan],
        "cost__kernel_cpu_s": [0.01] * 4 + [np.nan], "cost__total_cpu_s": [0.02] * 4 + [np.nan],
    })  # fmt: skip
    n = cell_numbers(t, "1")
    assert (n["success_k"], n["valid"], n["excluded"], n["failed_runs"]) == (3, 4, 1, 1)
    assert n["success"] == 0.75 and n["success_low"] < 0.75 < n["success_high"]
    assert n["recover_p50_s"] == pytest.approx(0.2)
    assert n["hover_k"] == 2 and n["hover_p50_s"] == pytest.approx(1.5)
    assert n["height_lost_p50_m"] == pytest.approx(1.25)
    assert n["missed_detections"] == 1 and n["declares_recovery"]
    assert n["cpu_s"] == pytest.approx(0.08) and n["cpu_ms_per_trial"] == pytest.approx(20.0)


def test_suite_2_numbers_of_a_hand_made_table():
    """Suite 2 counts the held hover (``success``), keeps the published criterion beside
    it, and gives the time and distance to the hover of the successes."""
    t = pd.DataFrame({
        "run_id": range(5), "status": ["completed"] * 4 + ["failed"],
        "success": [True, False, False, True, False], "valid": [True] * 4 + [False],
        "published_success": [True, True, False, True, False],
        "held_hover": [True, False, False, True, None],
        "time_to_held_hover_s": [1.0, np.nan, np.nan, 2.0, np.nan],
        "held_hover_distance_m": [0.2, np.nan, np.nan, 0.4, np.nan],
        "height_lost_m": [0.5, -1.0, 3.0, 1.5, np.nan],
        "not_detected": [False] * 5, "false_detection": [False] * 5,
        "t_stage1_s": [0.05] * 5,
        "cost__kernel_cpu_s": [0.01] * 4 + [np.nan], "cost__total_cpu_s": [0.02] * 4 + [np.nan],
    })  # fmt: skip
    n = cell_numbers(t, "2")
    assert (n["success_k"], n["valid"], n["excluded"]) == (2, 4, 1)
    assert n["success"] == 0.5 and n["published_success"] == 0.75
    assert n["hover_p50_s"] == pytest.approx(1.5) and n["hover_distance_p50_m"] == pytest.approx(
        0.3
    )
    assert n["height_lost_p50_m"] == pytest.approx(1.0)


@pytest.fixture(scope="module")
def smoke(tmp_path_factory):
    root = tmp_path_factory.mktemp("bench")
    study = BenchmarkStudy(tasks=("wall", "pole"), limit=3)
    first = run_benchmark(study, root / "a", workers=1, cache=root / "cache")
    again = run_benchmark(study, root / "b", workers=1, cache=root / "cache")
    return root, first, again


def test_a_smoke_run_writes_every_output_with_the_suite_version(smoke):
    root, first, _ = smoke
    out = first.out_dir
    for name in ("benchmark.csv", "benchmark.parquet", "report.md", "leaderboard.png"):
        assert (out / name).is_file(), name
    t = pd.read_csv(out / "benchmark.csv")
    assert set(t["suite_version"].astype(str)) == {SUITE_VERSION}
    computed = t[t["source"] != "published"]
    # every row, task and sensor set; the subject is the default law, so no second "default"
    from quadimpact.studies.benchmark.suite import suite

    assert len(computed) == len(REFERENCES) * 2 * len(suite(SUITE_VERSION).sensor_sets)
    assert set(computed["sensors"]) == {"ideal", "lab", "onboard"}
    assert set(computed["row"]) == {r.name for r in REFERENCES}
    published = t[t["source"] == "published"]
    assert sorted(published["published_success"]) == sorted(p.share for p in PUBLISHED)
    assert all(isinstance(n, str) and n for n in published["note"])
    report = (out / "report.md").read_text()
    assert f"Suite {SUITE_VERSION}" in report and "A smoke test, not a benchmark" in report
    study = json.loads((out / "study.json").read_text())
    assert study["identity"]["suite_version"] == SUITE_VERSION
    cell = pd.read_parquet(out / "cells" / "baseline" / "pole-lab.parquet")
    assert len(cell) == 3 and "success" in cell


def test_the_second_run_reads_the_cache_and_agrees(smoke):
    _, first, again = smoke
    assert {c["source"] for c in first.cells} == {"run"}
    assert {c["source"] for c in again.cells} == {"cache"}
    cols = ["row", "task", "sensors", "success_k", "valid", "height_lost_p50_m"]
    a = first.table[first.table["source"] != "published"][cols].reset_index(drop=True)
    b = again.table[again.table["source"] != "published"][cols].reset_index(drop=True)
    pd.testing.assert_frame_equal(a, b)


def test_changed_code_does_not_read_the_cache_of_other_code(smoke, monkeypatch):
    """Same suite, version number and sweep, other code: the cache has nothing for it."""
    from quadimpact.studies.benchmark import cells

    root, _, _ = smoke
    study = BenchmarkStudy(tasks=("wall", "pole"), limit=3)
    row = study.rows()[0]
    spec = row.spec(TASKS["wall"], study.quick, sensor_set("ideal"), study.limit)
    store = cells.CellCache(root / "cache")
    assert store.get(cells.cell_key(spec)) is not None
    monkeypatch.setattr(cells, "code_digest", lambda: "0123456789abcdef")
    assert store.get(cells.cell_key(spec)) is None


def test_the_folder_resumes_only_the_same_benchmark(smoke):
    root, first, _ = smoke
    with pytest.raises(InputError, match="holds a benchmark with other options"):
        run_benchmark(BenchmarkStudy(tasks=("wall",), limit=3), first.out_dir, workers=1)


def test_the_command_refuses_bad_options_in_one_line(tmp_path):
    runner = CliRunner()
    for args, expected in [
        (["--tasks", "wall,roof"], "--tasks: unknown task 'roof'"),
        (["--param", "a_mag_m_s2=-1"], "--param: a_mag_m_s2"),
        (["--controller", "nope"], "--controller: "),
        (["--estimator", "nope"], "--estimator: "),
        (["--name", "pole-replica", "--param", "a_mag_m_s2=4"], "--name: 'pole-replica'"),
        (["--plugin", str(tmp_path / "missing.py")], "--plugin: no such file"),
    ]:
        result = runner.invoke(cli, ["benchmark", *args, "--out", str(tmp_path / "o")])
        assert result.exit_code != 0
        assert expected in str(result.exception) or expected in result.output, (args, result)


PLUGIN = """
from numba import njit
from pydantic import BaseModel, ConfigDict
from quadimpact import register_controller
from quadimpact.core import named
from quadimpact.core.layout import MEM_STAGE


class Params(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


@njit
def step(t, meas, ctrl, mem, veh, dt, cmd):
    speeds = named.rotor_speeds(meas)
    for j in range(4):
        cmd[j] = speeds[j]
    if named.detected(meas):
        mem[MEM_STAGE] = 4.0


register_controller("test-hold-declare", step=step, params=Params, replace=True)
"""


@pytest.mark.slow  # benchmark cells of the quick suite
def test_a_plugin_controller_runs_tasks_of_the_quick_suite(tmp_path):
    """A plug-in that only holds its rotors and declares recovery at the detection: the
    wall's success is the share it detects without going below ground, and the grids'
    criterion does not read its declaration."""
    plugin = tmp_path / "hold_plugin.py"
    plugin.write_text(PLUGIN)
    out = tmp_path / "bench"
    result = CliRunner().invoke(cli, [
        "benchmark", "--suite", "1", "--quick", "--tasks", "wall,pole", "--plugin", str(plugin),
        "--controller", "test-hold-declare", "--no-references", "--no-cache",
        "--workers", "1", "--out", str(out), "--no-progress",
    ])  # fmt: skip
    assert result.exit_code == 0, result.output
    t = pd.read_csv(out / "benchmark.csv")
    mine = t[t["row"] == "test-hold-declare"]
    assert len(mine) == 4 and set(mine["kind"]) == {"controller"}
    wall = pd.read_parquet(out / "cells" / "test-hold-declare" / "wall-ideal.parquet")
    assert len(wall) == 1_000
    # declared at the detection: success = detected and never below altitude 0
    assert (wall["success"] == (wall["recovered"].fillna(False).astype(bool)
                                & (wall["min_altitude_m"] >= 0))).all()  # fmt: skip
    pole = pd.read_parquet(out / "cells" / "test-hold-declare" / "pole-ideal.parquet")
    assert len(pole) == 240
    assert (pole["success"] == (pole["height_lost_m"] < 2.0)).all()
