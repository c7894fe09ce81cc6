"""The pole replica (docs/VARIANTS.md 8): its table, each switch on its own, held rotors.

The variant is the default model with the staged recovery law retuned as the
authors' pole branch had it (docs/OBSTACLES.md 6.1): a_mag 4.8 m/s^2, the
stage 1 test at 0.15 and 2 rad/s, stage 2's Euler-angle test at 0.2 rad and
2 rad/s, stage 3 ending at w < 0.2 m/s, and rotors held at their trimmed
speeds until the detection.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from quadimpact import ImpactTrial, simulate
from quadimpact.cli import cli
from quadimpact.core import controller_slots as CTL
from quadimpact.core.controllers import recovery as CL
from quadimpact.inputs.model import CLASSIC_LAW, MODEL_VARIANTS, RECOVERY_LAWS
from quadimpact.inputs.scenarios import load_scenario_file, scenario_from_dict
from quadimpact.simulation.setup import prepare
from quadimpact.studies.pole.pole_study import PoleStudy, pitch_bands

from helpers import run_cli

#: docs/OBSTACLES.md 6.1 (the authors' pole figures), as packed slots.
POLE_TABLE = {
    CL.R_A_MAG: 4.8,
    CL.R_Q_TOL: 0.15,
    CL.R_RATE_TOL: 2.0,
    CL.R_LEVEL_TEST: CL.LEVEL_EULER,
    CL.R_EULER_TOL: 0.2,
    CL.R_W_TOL: 0.2,
}
#: The default law before the benchmark (the ``classic`` variant) in the same slots (the
#: Navi's g): the law these tests compared the pole law with before issue #45.
CLASSIC_TABLE = {
    CL.R_A_MAG: 9.81,
    CL.R_Q_TOL: 0.3,
    CL.R_RATE_TOL: 0.5,
    CL.R_LEVEL_TEST: CL.LEVEL_TILT_ERROR,
    CL.R_EULER_TOL: 0.2,
    CL.R_W_TOL: 0.3,
}
#: The default law since the benchmark (docs/RECOVERY.md 3.5), in the same slots.
DEFAULT_TABLE = {**CLASSIC_TABLE, CL.R_A_MAG: 4.8, CL.R_RATE_TOL: 1.0}
#: The pole trial of docs/OBSTACLES.md 3 at one point: the recovery arm.
POLE = {
    "vehicle": "navi",
    "controller": "recovery",
    "pre_impact": "nominal",
    "obstacles": [
        {"kind": "cylinder", "name": "pole", "point_m": [0.0, 0.0, 0.0], "radius_m": 0.1}
    ],
    "speed_m_s": 2.0,
    "altitude_m": 2.0,
    "start_distance_m": 0.3,
    "friction_coefficient": 0.3,
    "pitch_deg": -30.0,
    "lateral_offset_m": 0.05,
}


def _slots(scenario) -> dict[int, float]:
    c = prepare(scenario).ctrl[CTL.C_PARAMS :]
    return {slot: float(c[slot]) for slot in POLE_TABLE}


def _pre_impact(scenario) -> int:
    return int(prepare(scenario).ctrl[CTL.C_PARAMS + CL.R_PRE_IMPACT])


def test_the_variant_is_the_default_model_with_the_pole_law_and_hold():
    pole, default = MODEL_VARIANTS["pole-replica"], MODEL_VARIANTS["default"]
    differ = {k for k in default if pole[k] != default[k]}
    assert differ == {"pre_impact", "recovery_law"}
    assert (pole["pre_impact"], pole["recovery_law"]) == ("hold", "pole-replica")
    # the replicas and the classic variant keep the law that was the default before the
    # benchmark (issue #45: the switch's value "default" then, "classic" now), the default
    # model the new one
    laws = {k: v["recovery_law"] for k, v in MODEL_VARIANTS.items() if k != "pole-replica"}
    assert laws.pop("default") == "lean-cut" and set(laws.values()) == {"classic"}
    assert RECOVERY_LAWS["classic"] == CLASSIC_LAW and RECOVERY_LAWS["lean-cut"] == {}
    assert "default" not in RECOVERY_LAWS  # no law is named after a model it is not
    # the pole law is the classic law with the table's values
    assert (
        RECOVERY_LAWS["pole-replica"].items()
        >= {
            k: v for k, v in CLASSIC_LAW.items() if k not in ("a_mag_m_s2", "rate_tol_rad_s")
        }.items()
    )


def test_the_variant_resolves_to_the_table():
    trial = ImpactTrial(model="pole-replica", **POLE)
    assert _slots(trial) == POLE_TABLE
    # k_z of stages 1-4 unchanged: 10 1/s in stage 3; the gains too
    c = prepare(trial).ctrl[CTL.C_PARAMS :]
    assert tuple(c[CL.R_K_Z : CL.R_K_Z + 4]) == (0.0, 0.0, 10.0, 10.0)
    assert c[CL.R_K_ATT] == 20.0 and tuple(c[CL.R_K_RATE : CL.R_K_RATE + 3]) == (20, 20, 2)
    # before the detection: hold, whatever the scenario says
    assert trial.resolved_pre_impact() == "hold" and _pre_impact(trial) == CL.PRE_HOLD
    # the default model packs the default law (the Euler tolerance is packed, unused), the
    # classic variant the law before the benchmark
    assert _slots(ImpactTrial(**POLE)) == DEFAULT_TABLE
    assert _slots(ImpactTrial(model="classic", **POLE)) == CLASSIC_TABLE


@pytest.mark.parametrize(
    ("params", "changed"),
    [
        ({"a_mag_m_s2": 4.8}, {CL.R_A_MAG: 4.8}),
        ({"tilt_error_tol": 0.15}, {CL.R_Q_TOL: 0.15}),
        ({"rate_tol_rad_s": 2.0}, {CL.R_RATE_TOL: 2.0}),
        ({"level_test": "euler"}, {CL.R_LEVEL_TEST: CL.LEVEL_EULER}),
        ({"level_test": "euler", "euler_tol_rad": 0.1}, {CL.R_LEVEL_TEST: 1, CL.R_EULER_TOL: 0.1}),
        ({"w_tol_m_s": 0.2}, {CL.R_W_TOL: 0.2}),
    ],
)
def test_each_switch_on_its_own(params, changed):
    """One parameter of the law in [controller_params] changes that slot alone (on the classic
    law, which these tests compared with the pole law before issue #45)."""
    trial = ImpactTrial(model="classic", controller_params=params, **POLE)
    assert _slots(trial) == {**CLASSIC_TABLE, **changed}


def test_given_parameters_win_over_the_variant_and_the_switches_mix():
    # the variant with one parameter of the default law back
    trial = ImpactTrial(model="pole-replica", controller_params={"a_mag_m_s2": 9.81}, **POLE)
    assert _slots(trial) == {**POLE_TABLE, CL.R_A_MAG: 9.81}
    # the law alone, without held rotors: the model switch in the default model
    law_only = ImpactTrial(model_options={"recovery_law": "pole-replica"}, **POLE)
    assert _slots(law_only) == POLE_TABLE and _pre_impact(law_only) == CL.PRE_NOMINAL
    # held rotors alone
    hold_only = ImpactTrial(model="classic", model_options={"pre_impact": "hold"}, **POLE)
    assert _slots(hold_only) == CLASSIC_TABLE and _pre_impact(hold_only) == CL.PRE_HOLD
    # the variant with the scenario's pre-impact behaviour back
    nominal = ImpactTrial(model="pole-replica", model_options={"pre_impact": "scenario"}, **POLE)
    assert _slots(nominal) == POLE_TABLE and _pre_impact(nominal) == CL.PRE_NOMINAL


def test_bad_values_are_one_line_errors(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('kind = "impact-trial"\ncontroller = "recovery"\n'
                    '[controller_params]\nlevel_test = "quaternion"\n')  # fmt: skip
    with pytest.raises(Exception, match=r"controller_params.level_test: must be one of") as info:
        load_scenario_file(path)
    assert "\n" not in str(info.value)
    path.write_text('kind = "impact-trial"\n[model_options]\nrecovery_law = "pole"\n')
    with pytest.raises(Exception, match=r"model_options.recovery_law: must be one of"):
        load_scenario_file(path)


def test_a_scenario_file_selects_the_variant_or_a_single_switch(tmp_path):
    path = tmp_path / "pole.toml"
    path.write_text('kind = "impact-trial"\nvehicle = "navi"\ncontroller = "recovery"\n'
                    'model = "pole-replica"\n')  # fmt: skip
    assert _slots(load_scenario_file(path)) == POLE_TABLE
    path.write_text('kind = "impact-trial"\nvehicle = "navi"\ncontroller = "recovery"\n'
                    'model = "classic"\n[controller_params]\nlevel_test = "euler"\n')  # fmt: skip
    assert _slots(load_scenario_file(path)) == {**CLASSIC_TABLE, CL.R_LEVEL_TEST: CL.LEVEL_EULER}


def test_hold_keeps_the_trimmed_speeds_until_the_detection():
    runs = {m: simulate(ImpactTrial(model=m, **POLE)) for m in ("default", "pole-replica")}
    for model, r in runs.items():
        s, ts = r.summary, r.timeseries
        assert s["detected"] and s["model"] == model
        omega = ts[[f"omega{j}_rad_s" for j in (1, 2, 3, 4)]].to_numpy()
        t = ts["t_s"].to_numpy()
        before, after = omega[t <= s["t_detect_s"]], omega[t > s["t_detect_s"] + 0.005]
        moved = np.abs(before - before[0]).max()
        if model == "pole-replica":
            assert s["pre_impact"] == "hold"
            assert moved == 0.0  # the trimmed speeds, exactly, up to the detecting tick
            assert np.abs(after - before[0]).max() > 10.0  # then the staged law moves them
        else:
            assert s["pre_impact"] == "nominal" and moved > 0.0  # the baseline flies
    # both start from the same trim
    w0 = [runs[m].timeseries[[f"omega{j}_rad_s" for j in (1, 2, 3, 4)]].iloc[0] for m in runs]
    np.testing.assert_array_equal(w0[0], w0[1])


def test_the_run_command_takes_the_variant_and_single_parameters(tmp_path):
    path = tmp_path / "pole.toml"
    path.write_text('kind = "impact-trial"\nvehicle = "navi"\ncontroller = "recovery"\n'
                    'final_time_s = 0.1\n')  # fmt: skip
    for args in (["--model", "pole-replica"], ["--param", "level_test=euler"]):
        out = tmp_path / args[1]
        result = CliRunner().invoke(cli, ["run", str(path), *args, "--out", str(out)])
        assert result.exit_code == 0, result.output
    bad = run_cli("run", str(path), "--param", "level_test=x", "--out", "bad", cwd=tmp_path)
    assert bad.returncode == 2 and "Traceback" not in bad.stderr
    assert bad.stderr.strip() == (
        "quadimpact: error: --param: level_test: must be one of 'tilt-error' or 'euler' (got 'x')"
    )


# ------------------------------------------------------- a small grid, pinned
GRID = json.loads((Path(__file__).parent / "data" / "pole_replica_grid.json").read_text())


def test_the_pinned_grid_has_points_in_every_pitch_band():
    bands = {pitch_bands(np.arange(0.0, 46.0))[int(abs(p["pitch_deg"]))] for p in GRID["points"]}
    assert len(bands) == 9 and all(len(p) == 4 for p in GRID["points"])


@pytest.mark.pinned
@pytest.mark.parametrize(
    "point", GRID["points"], ids=lambda p: f"{p['pitch_deg']:g}|{p['lateral_offset_m']:g}"
)
def test_small_grid_outcomes_are_pinned(point):
    """Both laws at a few points of each pitch band, as the whole grid's reviewed run gave
    them (its trials.parquet rows): the same numbers through simulate() on every machine.
    The file's "default" is the default law of that run: the ``classic`` variant since the
    benchmark's law became the default (issue #45), pinned under that name."""
    study = PoleStudy(model="pole-replica")
    _, replica, default = study.arms()
    classic = {**default, "model": "classic"}
    for model, arm in (("pole-replica", replica), ("default", classic)):
        data = {**study.base(), **arm, "pitch_deg": point["pitch_deg"],
                "lateral_offset_m": point["lateral_offset_m"]}  # fmt: skip
        s = simulate(scenario_from_dict(data)).summary
        want = point[model]
        got = {
            "success": 2.0 - s["final_altitude_m"] < 2.0,
            "recovered": s["recovered"],
            "t_stage4_s": s["t_stage4_s"],
            "height_lost_m": 2.0 - s["final_altitude_m"],
            "final_altitude_m": s["final_altitude_m"],
        }
        assert got == want, model


def test_a_sweep_selects_the_variant_and_single_parameters(tmp_path):
    from quadimpact.sweep import SweepSpec, read_runs, run_sweep

    base = {"kind": "impact-trial", **POLE, "final_time_s": 0.3}
    runs = [{}, {"model": "pole-replica"}, {"controller_params": {"level_test": "euler"}}]
    run_sweep(SweepSpec(base=base, runs=runs, where="t"), tmp_path, workers=1, load=False)
    rows = read_runs(tmp_path).sort_values("run_id")
    assert list(rows["model_options__recovery_law"]) == ["lean-cut", "pole-replica", "lean-cut"]
    assert list(rows["pre_impact"]) == ["nominal", "hold", "nominal"]
    assert list(rows["status"]) == ["completed"] * 3
