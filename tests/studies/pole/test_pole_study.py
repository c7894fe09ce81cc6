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
