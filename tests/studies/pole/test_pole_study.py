"""The pole study on a small grid: its table, figures, report, resume and command."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from quadimpact.cli import cli
from quadimpact.errors import InputError
from quadimpact.studies.pole.pole_study import PoleStudy, pitch_bands, run_pole_study

SMALL = {"pitch_step_deg": 22.5, "offset_step_m": 0.35}  # 3 pitches x 3 offsets


@pytest.fixture(scope="module")
def study_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("pole")
    run_pole_study(PoleStudy(**SMALL), out, workers=1)
    return out


def test_the_authors_grid_is_the_default():
    study = PoleStudy()
    assert len(study.pitches()) == 46 and study.pitches()[0] == 0.0
    assert study.pitches()[-1] == -45.0
    offsets = study.offsets()
    assert len(offsets) == 71 and offsets[0] == -0.35 and offsets[35] == 0.0
    spec = study.sweep_spec()
    assert spec.n_runs == 46 * 71 * 2
    first, second = spec.scenario_dict(0), spec.scenario_dict(1)
    assert first["controller"] == "paper" and second["controller"] == "recovery"
    assert second["pre_impact"] == "nominal" and second["nominal_controller"] == "paper"
    assert first["obstacles"][0]["radius_m"] == 0.1
    assert (first["speed_m_s"], first["altitude_m"], first["start_distance_m"]) == (2.0, 2.0, 0.3)


def test_the_start_is_the_authors(study_dir):
    from quadimpact.inputs.scenarios import scenario_from_dict
    from quadimpact.simulation.setup import prepare

    spec = PoleStudy(**SMALL).sweep_spec()
    for run_id in range(spec.n_runs):
        data = spec.scenario_dict(run_id)
        x0 = prepare(scenario_from_dict(data)).x0
        assert x0[0] == pytest.approx(-0.4, abs=1e-15)
        assert x0[1] == data["lateral_offset_m"] and x0[2] == -2.0


def test_the_study_writes_its_table_figures_and_report(study_dir):
    table = pd.read_parquet(study_dir / "trials.parquet")
    assert len(table) == 18
    assert list(table["arm"][:2]) == ["baseline", "recovery"]
    for col in ("height_lost_m", "success", "pitch_band", "first_contact_normal", "recovered"):
        assert col in table
    lost = 2.0 - table["final_altitude_m"].astype(float)
    np.testing.assert_array_equal(table["height_lost_m"], lost)
    np.testing.assert_array_equal(table["success"], lost < 2.0)
    for name in ("maps.png", "success_by_pitch.png", "report.md", "study.json"):
        assert (study_dir / name).is_file()
    report = (study_dir / "report.md").read_text()
    assert "## Where recovery fails, and why" in report
    numbers = json.loads((study_dir / "study.json").read_text())["numbers"]
    k = int(table[table["arm"] == "recovery"]["success"].sum())
    assert numbers["arms"]["recovery"]["success"]["k"] == k
    assert f"{k} / 9 = " in report


def test_rerunning_resumes(study_dir):
    before = pd.read_parquet(study_dir / "trials.parquet")
    result = run_pole_study(PoleStudy(**SMALL), study_dir, workers=1)
    assert result.run_info["n_ran"] == 0
    cols = [c for c in before.columns if c != "integrator__wall_time_s"]
    pd.testing.assert_frame_equal(result.table[cols], before[cols])


def test_pitch_bands_keep_the_last_pitch_with_the_band_below():
    bands = pitch_bands(np.arange(0.0, 46.0))
    assert bands[0] == "0-4" and bands[39] == "35-39"
    assert bands[40] == bands[45] == "40-45"


def test_bad_options_are_one_line_errors(tmp_path):
    with pytest.raises(InputError, match="baseline: must be one of"):
        PoleStudy(baseline="recovery")
    bad = tmp_path / "obstacle.toml"
    bad.write_text('[[obstacles]]\nkind = "cone"\nname = "x"\n')
    with pytest.raises(InputError, match=r"obstacles: obstacle 1 \('x'\): kind: must be one of"):
        PoleStudy(obstacle_file=str(bad))


def test_the_command(tmp_path):
    out = tmp_path / "cli"
    result = CliRunner().invoke(
        cli,
        ["pole", "--pitch-step", "45", "--offset-step", "0.35", "--workers", "1",
         "--no-progress", "--out", str(out)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert "lose < 2 m" in result.output and (out / "report.md").is_file()


# ------------------------------------------------------------ the pole replica
REPLICA_SMALL = {
    "pitch_max_deg": 28.0,
    "pitch_step_deg": 28.0,
    "offset_max_m": 0.1,
    "offset_step_m": 0.1,
}  # fmt: skip  (0, -28 deg x -0.1, 0, 0.1 m; -40 deg before the default law changed, #45)


def test_the_default_study_keeps_its_two_arms():
    # the sweep of `quadimpact pole` as before the variant (an old folder resumes)
    assert PoleStudy().arms() == [
        {"controller": "paper"},
        {"controller": "recovery", "pre_impact": "nominal", "nominal_controller": "paper"},
    ]
    assert PoleStudy().arm_names() == ("baseline", "recovery")
    with pytest.raises(InputError, match="model: must be one of 'default', 'classic', 'pole-"):
        PoleStudy(model="recovery-replica")


def test_the_replica_study_flies_three_arms(tmp_path):
    study = PoleStudy(model="pole-replica", **REPLICA_SMALL)
    assert study.arm_names() == ("baseline", "recovery", "recovery-default")
    base, replica, default = study.arms()
    assert base == {"controller": "paper", "model": "default"}
    assert replica["model"] == "pole-replica" and default["model"] == "default"
    result = run_pole_study(study, tmp_path / "replica", workers=1)
    plain = run_pole_study(PoleStudy(**REPLICA_SMALL), tmp_path / "default", workers=1)
    t, d = result.table, plain.table
    assert list(t["arm"][:3]) == ["baseline", "recovery", "recovery-default"] and len(t) == 18
    assert list(t["model"][:3]) == ["default", "pole-replica", "default"]
    assert set(t[t["arm"] == "recovery"]["pre_impact"]) == {"hold"}
    # the baseline and the default law's arms are the default study's runs, number for number
    skip = {"run_id", "model", "integrator__wall_time_s", "cost__kernel_cpu_s", "cost__total_cpu_s"}
    cols = [c for c in d.columns if c not in skip]
    for mine, theirs in (("baseline", "baseline"), ("recovery-default", "recovery")):
        a = t[t["arm"] == mine][cols].reset_index(drop=True).assign(arm=theirs)
        pd.testing.assert_frame_equal(a, d[d["arm"] == theirs][cols].reset_index(drop=True))
    # the laws side by side: at -28 deg on the centre line only the replica succeeds (of 198
    # points at -24 to -45 deg within 0.12 m, the one such point of the default law)
    laws = result.numbers["laws"]
    both = t.pivot_table(index=["pitch_deg", "lateral_offset_m"], columns="arm", values="success")
    only = both["recovery"].astype(bool) & ~both["recovery-default"].astype(bool)
    assert laws["variant_only"] == int(only.sum()) >= 1 and laws["n"] == 6
    ex = laws["example"]
    assert only[(ex["pitch_deg"], ex["lateral_offset_m"])]
    report = result.report.read_text()
    assert "## The two laws side by side" in report and "`pole-replica` model variant" in report
    for name in ("example_default_law.png", "example_pole_replica.png"):
        assert (tmp_path / "replica" / name).is_file() and f"({name})" in report
    assert "## The two laws" not in plain.report.read_text()


def test_the_command_takes_the_model(tmp_path):
    out = tmp_path / "cli"
    result = CliRunner().invoke(
        cli,
        ["pole", "--model", "pole-replica", "--pitch-step", "45", "--offset-step", "0.35",
         "--workers", "1", "--no-progress", "--out", str(out)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert "(pole-replica)" in result.output and "(the default law)" in result.output
    bad = CliRunner().invoke(cli, ["pole", "--model", "paper-replica", "--out", str(out)])
    assert bad.exit_code == 2 and "'paper-replica' is not one of" in bad.output


# ------------------------------------------------------------ sensors and estimator
def test_the_ideal_sensors_keep_the_study_as_it_was():
    """Without sensors the study's identity and sweep are those it had before the options
    existed (an old folder resumes)."""
    study = PoleStudy(**SMALL)
    assert not {"estimator", "sensors", "seed"} & set(study.options())
    assert study.sweep_spec().grid == {"pitch_deg": study.pitches(),
                                       "lateral_offset_m": study.offsets()}  # fmt: skip


def test_with_sensors_each_point_draws_its_own_noise():
    study = PoleStudy(**SMALL, sensors="impact", estimator="ekf")
    spec = study.sweep_spec()
    assert spec.n_runs == 2 * 9 and (spec.base["sensors"], spec.base["estimator"]) == (
        "impact", "ekf")  # fmt: skip
    seeds = [spec.inputs(i)["seed"] for i in range(spec.n_runs)]
    assert seeds[0::2] == seeds[1::2]  # both arms of a point share its seed
    assert len(set(seeds[0::2])) == 9  # every point its own
    assert seeds[0::2] == [float(s) for s in PoleStudy(**SMALL, sensors="impact").point_seeds()]
    assert study.options()["sensors"] == "impact" and study.options()["seed"] == 0
    with pytest.raises(InputError, match="sensors: must be one of"):
        PoleStudy(sensors="perfect")


def test_the_command_takes_the_estimator_and_sensors(tmp_path):
    out = tmp_path / "ekf"
    result = CliRunner().invoke(
        cli,
        ["pole", "--estimator", "ekf", "--sensors", "impact", "--pitch-step", "45",
         "--offset-step", "0.35", "--workers", "1", "--no-progress", "--out", str(out)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    t = pd.read_parquet(out / "trials.parquet")
    assert set(t["estimator"]) == {"ekf"} and set(t["sensors"]) == {"impact"}
    assert "the `impact` sensors" in (out / "report.md").read_text()
    bad = CliRunner().invoke(cli, ["pole", "--estimator", "nope", "--out", str(out)])
    assert bad.exit_code != 0 and "--estimator: " in str(bad.exception)
