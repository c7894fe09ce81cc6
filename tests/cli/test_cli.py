"""The command line: one-line errors with exit status 2, and a complete run."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path
from typing import Any

import pytest

from quadimpact.errors import InputError

from helpers import SPIRI_TOML, run_cli

SUMMARY_KEYS = (
    "status reason warnings model controller delta_init_m peak_force_n impact_speed_m_s "
    "inclination_deg heading_deg leading_bumpers n_episodes crash_time_s t_start_s t_final_s"
).split()
OUTPUT_FILES = ("summary.json", "timeseries.parquet", "episodes.csv", "fig5.png", "fig6.png")


def assert_input_error(proc: subprocess.CompletedProcess, *fragments: str) -> None:
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stdout + proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("quadimpact: error: ")
    for fragment in fragments:
        assert fragment in lines[0], f"{fragment!r} not in {lines[0]!r}"


def test_help_and_version(tmp_path: Path) -> None:
    proc = run_cli("--help", cwd=tmp_path)
    assert proc.returncode == 0 and "run" in proc.stdout and "NED" in proc.stdout
    proc = run_cli("run", "--help", cwd=tmp_path)
    assert proc.returncode == 0
    for text in (
        "--heading, --heading-deg DEG",
        "--inclination, --inclination-deg DEG",
        "--speed, --speed-m-s M/S",
        "--model",
        "results/run",
    ):
        assert text in proc.stdout
    proc = run_cli("--version", cwd=tmp_path)
    assert proc.returncode == 0 and proc.stdout.startswith("quadimpact ")


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (["run", "--model", "best"], ["'--model'", "'best' is not one of"]),
        (["run", "--controller", "lqr"], ["'--controller'", "'lqr'"]),
        (["run", "--heading", "abc"], ["'--heading'", "'abc' is not a valid number"]),
        (["run", "--heading", "500"], ["--heading: must be <= 360 (got 500.0)"]),
        (["run", "--inclination", "-75"], ["--inclination: must be >= -60 (got -75.0)"]),
        (["run", "--speed", "0"], ["--speed: must be > 0 (got 0.0)"]),
        (["run", "--impact-time", "4"], ["--impact-time: must be < final_time_s (3)"]),
        (["run", "--rtol", "0.5"], ["--rtol: must be < 0.1 (got 0.5)"]),
        (["run", "--option", "crash_rule=never"], ["--option: crash_rule: must be one of"]),
        (["run", "--frobnicate"], ["No such option", "--frobnicate"]),
        (["run", "missing.toml"], ["missing.toml: file not found"]),
        (["run", "--vehicle", "spirit"], ["vehicle 'spirit': unknown vehicle name"]),
        (["launch"], ["No such command 'launch'"]),
        (["experiments", "--log-samples", "-1"], ["'--log-samples'", "-1 is not in the range"]),
        (["run", "--heading", "nan"], ["'--heading'", "'nan' is not a finite number"]),
        (["run", "--friction", "inf"], ["'--friction'", "'inf' is not a finite number"]),
        (["view", "r", "--rate", "nan"], ["'--rate'", "'nan' is not a finite number"]),
        (["view", "r", "--azimuth", "nan"], ["'--azimuth'", "'nan' is not a finite number"]),
        (["snapshots", "r", "--elevation", "-inf"], ["'--elevation'", "'-inf' is not a finite"]),
        (["animate", "r", "--fps", "nan"], ["'--fps'", "'nan' is not a finite number"]),
        (["animate", "r", "--start", "nan"], ["'--start'", "'nan' is not a finite number"]),
    ],
)
def test_bad_flags_exit_2_with_one_line(tmp_path: Path, args: list[str], fragments) -> None:
    assert_input_error(run_cli(*args, cwd=tmp_path), *fragments)


@pytest.mark.parametrize(
    ("text", "fragments"),
    [
        ("heading_deg = 500\n", ["scenario.toml: heading_deg: must be <= 360 (got 500)"]),
        ("heading_deg = = 5\n", ["scenario.toml: invalid TOML", "line 1"]),
        ("speed = 0.5\n", ["scenario.toml: speed: unknown key; did you mean 'speed_m_s'?"]),
        (
            'kind = "flight"\n',
            ["--heading: applies to wall-approach scenarios only"],
        ),
    ],
)
def test_bad_scenario_file_exits_2(tmp_path: Path, text: str, fragments) -> None:
    (tmp_path / "scenario.toml").write_text(text)
    proc = run_cli("run", "scenario.toml", "--heading", "10", cwd=tmp_path)
    assert_input_error(proc, *fragments)


def test_run_takes_an_impact_trial_file(tmp_path: Path) -> None:
    """Each kind of scenario file runs; flags apply when the kind has the field."""
    import json

    (tmp_path / "trial.toml").write_text('kind = "impact-trial"\npitch_deg = -20\n')
    proc = run_cli("run", "trial.toml", "--heading", "10", cwd=tmp_path)
    assert_input_error(proc, "--heading: applies to wall-approach scenarios only")
    out = tmp_path / "out"
    proc = run_cli("run", "trial.toml", "--speed", "1.2", "--final-time", "0.3", "--out",
                   str(out), cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "impact trial, roll 0 deg, pitch -20 deg" in proc.stderr
    world = json.loads((out / "scenario.json").read_text())
    assert world["scenario"]["kind"] == "impact-trial" and world["scenario"]["speed_m_s"] == 1.2
    assert world["scenario"]["pitch_deg"] == -20 and world["vehicle"]["name"] == "navi"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["controller"] == "recovery" and summary["detected"] is True


def test_bad_vehicle_file_exits_2(tmp_path: Path) -> None:
    bad = SPIRI_TOML.read_text().replace("restitution = 0.9", "restitution = 0")
    (tmp_path / "bad.toml").write_text(bad)
    proc = run_cli("run", "--vehicle", "bad.toml", cwd=tmp_path)
    assert_input_error(proc, "vehicle bad.toml: restitution: must be > 0 (got 0)")
    (tmp_path / "extra.toml").write_text(bad.replace("restitution = 0", "restitution = 0.9\nfoo=1"))
    proc = run_cli("run", "--vehicle", "extra.toml", cwd=tmp_path)
    assert_input_error(proc, "vehicle extra.toml: foo: unknown key")


def test_flags_override_file_values(tmp_path: Path) -> None:
    from quadimpact.cli import build_scenario

    path = tmp_path / "scenario.toml"
    path.write_text('heading_deg = 45\nspeed_m_s = 0.5\nmodel = "paper-replica"\n')
    flags = {"heading": None, "speed": 1.0, "controller": "cascade-pid"}
    scenario = build_scenario(path, flags, ("crash_rule=cm-ground", "bumper1_yaw_twice=false"))
    assert (scenario.heading_deg, scenario.speed_m_s) == (45.0, 1.0)
    assert (scenario.model, scenario.controller) == ("paper-replica", "cascade-pid")
    options = scenario.resolved_model_options()
    assert options.crash_rule == "cm-ground" and options.bumper1_yaw_twice is False
    assert options.yaw_reaction == "paper"


def test_sensors_and_estimator_flags_set_the_scenarios_sensing(tmp_path: Path) -> None:
    """--sensors fills the sensors a file leaves unset (its own IMU stays); --estimator
    overrides the file's; an unknown name is refused in one line naming the flag."""
    from quadimpact.cli import build_scenario

    path = tmp_path / "trial.toml"
    path.write_text('kind = "impact-trial"\nvehicle = "navi"\nimu = "noisy"\nestimator = "ekf"\n')
    s = build_scenario(path, {"sensors": "onboard", "estimator": "nav-ekf"})
    assert (s.sensors, s.estimator, s.imu.preset) == ("onboard", "nav-ekf", "noisy")
    assert s.magnetometer is not None
    assert set(s.instruments) == {"barometer", "rangefinder", "optical_flow"}
    assert build_scenario(path, {"sensors": None, "estimator": None}).estimator == "ekf"
    with pytest.raises(InputError, match="--sensors: unknown preset of sensors 'bogus'"):
        build_scenario(path, {"sensors": "bogus"})
    with pytest.raises(InputError, match="--estimator: must be one of"):
        build_scenario(path, {"estimator": "nope"})


def test_authors_approach_from_flags_and_list_valued_switches(tmp_path: Path) -> None:
    """--start-altitude, --roll, --pitch: the authors' approach of a crash run; --option takes
    numbers and lists ([2], 1,2,1,1) for the crash-run switches."""
    from quadimpact.cli import build_scenario

    flags = {"heading": -163.0, "speed": 2.0283, "roll": -2.7, "pitch": 9.4,
             "start_altitude": 0.6, "altitude": 1.02}  # fmt: skip
    options = ("crash_rule=ground-ticks", "cut_step_motors=[2]", "bumper_force_scale=1,2,1,1",
               "contact_gate_m=0.3")  # fmt: skip
    scenario = build_scenario(None, flags, options)
    assert (scenario.roll_deg, scenario.pitch_deg, scenario.start_altitude_m) == (-2.7, 9.4, 0.6)
    resolved = scenario.resolved_model_options()
    assert resolved.cut_step_motors == (2,) and resolved.bumper_force_scale == (1, 2, 1, 1)
    assert resolved.crash_rule == "ground-ticks" and resolved.contact_gate_m == 0.3
    path = tmp_path / "flight.toml"
    path.write_text('kind = "flight"\n')
    with pytest.raises(InputError, match="--start-altitude: applies to wall-approach"):
        build_scenario(path, {"start_altitude": 0.5})


def test_valid_run_writes_all_outputs(tmp_path: Path) -> None:
    proc = run_cli(
        "run",
        "--heading",
        "45",
        "--inclination",
        "15",
        "--speed",
        "0.75",
        "--model",
        "paper-replica",
        "--out",
        "out",
        cwd=tmp_path,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    out = tmp_path / "out"
    for name in OUTPUT_FILES:
        assert (out / name).is_file(), name
    summary = json.loads((out / "summary.json").read_text())
    missing = [key for key in SUMMARY_KEYS if key not in summary]
    assert not missing, missing
    assert summary["model"] == "paper-replica"
    assert summary["heading_deg"] == pytest.approx(45.0)
    assert "delta_init" in proc.stdout and "out" in proc.stdout


def test_format_summary_for_people() -> None:
    from quadimpact.cli import format_summary

    summary = {
        "status": "crashed",
        "reason": "CM reached the ground",
        "warnings": ["penetration larger than the bumper radius"],
        "delta_init_m": 0.012345,
        "peak_force_n": 3.21,
        "leading_bumpers": [4],
        "n_episodes": 5,
        "crash_time_s": 1.875,
        "response_type": "D",
    }
    text = format_summary(summary, Path("results/run"))
    assert "response type  D" in text and "detection" not in text
    assert "status         crashed (CM reached the ground)" in text
    assert "delta_init     12.35 mm" in text
    assert "peak force     3.21 N" in text
    assert "leading bumper 4" in text
    assert "episodes       5" in text
    assert "crash time     1.875 s" in text
    assert "warning        penetration larger than the bumper radius" in text
    assert text.splitlines()[-1].startswith("output         results/run (summary.json")
    quiet = format_summary({"status": "completed", "crash_time_s": None}, Path("o"))
    assert "crash time     no crash" in quiet and "delta_init     n/a" in quiet
    assert "response type  n/a" in quiet


def test_format_summary_of_a_recovery_run() -> None:
    """A recovery run says when the impact was detected and when stage 4 was reached."""
    from quadimpact.cli import format_summary

    summary = {"status": "completed", "controller": "recovery", "response_type": "A",
               "t_detect_s": 0.045, "detection_latency_s": 0.0049, "t_stage4_s": 0.77,
               "time_to_recover_s": 0.725}  # fmt: skip
    text = format_summary(summary, Path("o"))
    assert "detection      at 0.045 s (4.9 ms after the first contact)" in text
    assert "recovered      stage 4 at 0.77 s (0.725 s after the detection)" in text
    missed = format_summary({"controller": "recovery", "t_detect_s": None}, Path("o"))
    assert "detection      no detection" in missed
    assert "recovered      stage 4 not reached" in missed


def test_a_failed_run_exits_3(tmp_path: Path) -> None:
    """A numerical failure is not a success: status 3 (documented in --help), folder written."""
    proc = run_cli("run", "--friction", "1e308", "--final-time", "1", "--out", "out",
                   cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 3, proc.stderr
    assert "status         failed (state became NaN or infinite)" in proc.stdout
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["status"] == "failed"
    assert "Traceback" not in proc.stderr
    helptext = run_cli("run", "--help", cwd=tmp_path).stdout
    assert "Exit status" in helptext and "3  the run failed numerically" in helptext


@pytest.mark.slow
def test_experiments_writes_table3(tmp_path: Path) -> None:
    """The stable interface: ``quadimpact experiments --out DIR [--data PATH]``."""
    import pandas as pd

    from quadimpact.studies.table3.table3_study import EXTRA_COLUMNS, TABLE3_COLUMNS

    missing = tmp_path / "no-data"
    missing.mkdir()
    args = ["experiments", "--out", "exp", "--samples", "0", "--log-samples", "0", "--workers", "1"]
    proc = run_cli(*args, cwd=tmp_path, timeout=300, env={"QUADIMPACT_DATA": str(missing)})
    assert proc.returncode == 0, proc.stderr
    assert "QUADIMPACT_DATA" in proc.stderr and "holds none of the crash logs" in proc.stderr
    table = pd.read_csv(tmp_path / "exp" / "table3.csv")
    assert list(table.columns) == [*TABLE3_COLUMNS, *EXTRA_COLUMNS] and len(table) == 7
    # no logs in that folder: the log columns are empty, the simulations are not
    assert table["attitude_rms_deg_0_3s"].isna().all() and table["type_log"].isna().all()
    assert table["type_ours"].notna().all()
    assert "ours_at_log" in proc.stdout and "table3.csv" in proc.stdout


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (["--data", "/nonexistent"], ["--data /nonexistent: no such folder"]),
        (["--data", "empty"], ["--data empty: holds none of the crash logs"]),
        (["--scheduler", "nonsense"], ["--scheduler: must be an address like tcp://HOST:PORT"]),
        (["--scheduler", "tcp://127.0.0.1:1"], ["no Dask scheduler answers there"]),
        (["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], ["give one or the other"]),
        (["--out", "afile/sub"], ["--out afile/sub: cannot be created: afile is a file"]),
        (["--out", "run"], ["--out run: holds a run (summary.json); use a new or empty"]),
    ],
)
def test_experiments_refuses_bad_options_before_any_work(
    tmp_path: Path, args: list[str], fragments: list[str]
) -> None:
    """A given --data without logs, a bad --scheduler or --out: one line, at once."""
    import time

    (tmp_path / "empty").mkdir()
    (tmp_path / "afile").write_text("x")
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "summary.json").write_text("{}")
    start = time.monotonic()
    proc = run_cli("experiments", *args, cwd=tmp_path)
    assert_input_error(proc, *fragments)
    assert time.monotonic() - start < 15  # nothing simulated (that takes 30 s and more)
    assert not (tmp_path / "results").exists()


@pytest.mark.parametrize("command", ["reproduce", "sweep"])
def test_reproduce_and_sweep_check_the_scheduler_first(tmp_path: Path, command: str) -> None:
    extra = ["--grid", "speed_m_s=0.5,1", "--out", "s"] if command == "sweep" else []
    proc = run_cli(command, *extra, "--scheduler", "tcp://127.0.0.1:1", cwd=tmp_path)
    assert_input_error(proc, "--scheduler tcp://127.0.0.1:1: no Dask scheduler answers there")
    assert not (tmp_path / "s").exists() and not (tmp_path / "results").exists()


def test_out_folders_of_another_kind_are_refused_before_simulating(tmp_path: Path) -> None:
    """run --out into a sweep folder, sweep --out into a run folder, --out under a file."""
    (tmp_path / "sweep").mkdir()
    (tmp_path / "sweep" / "sweep.json").write_text("{}")
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "summary.json").write_text("{}")
    (tmp_path / "afile").write_text("x")
    proc = run_cli("run", "--out", "sweep", cwd=tmp_path)
    assert_input_error(proc, "--out sweep: holds a sweep (sweep.json); use a new or empty folder")
    proc = run_cli("run", "--out", "afile/sub", cwd=tmp_path)
    assert_input_error(proc, "--out afile/sub: cannot be created: afile is a file, not a folder")
    proc = run_cli("run", "--out", "x" * 5000, cwd=tmp_path)
    assert_input_error(proc, "(5000 characters): path too long")
    assert len(proc.stderr) < 300
    proc = run_cli("sweep", "--grid", "speed_m_s=0.5,1", "--out", "run", cwd=tmp_path)
    assert_input_error(proc, "run: holds a run (summary.json); use a new or empty folder")
    assert sorted(p.name for p in (tmp_path / "run").iterdir()) == ["summary.json"]


def test_disk_full_during_run_leaves_no_half_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The parquet writer fails part-way: one line, exit 1, no folder, no hidden stage left."""
    import errno

    import quadimpact.results.files as files
    from quadimpact.cli import main

    def full(_df: object, path: Path) -> None:
        Path(path).write_bytes(b"PAR1 half")
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(files, "write_timeseries_parquet", full)
    out = tmp_path / "run"
    with pytest.raises(SystemExit) as info:
        main(["run", "--final-time", "0.6", "--out", str(out)])
    assert info.value.code == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == (
        f"quadimpact: error: {out}: the result folder could not be written (No space left on "
        "device); nothing was changed there"
    )
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("files", "args", "fragments"),
    [
        (
            {"k.toml": 'kind = ["flight"]\n'},
            ["run", "k.toml"],
            [
                "k.toml: kind: must be one of 'wall-approach', 'flight', 'impact-trial'",
                "(got ['flight'])",
            ],
        ),
        (
            {},
            ["sweep", "--grid", "vehicle_overrides=1", "--out", "s"],
            ["vehicle_overrides: must be a table of vehicle field = value (got 1.0)"],
        ),
        (
            {"s.toml": "[sample]\nn = 3\nranges = [1, 2]\n"},
            ["sweep", "s.toml", "--out", "s"],
            ["s.toml: sample.ranges: must be a table of field = values (got [1, 2])"],
        ),
        (
            {"s.toml": '[sample]\nn = 3\nchoices = "abc"\n'},
            ["sweep", "s.toml", "--out", "s"],
            ["s.toml: sample.choices: must be a table of field = values (got 'abc')"],
        ),
        (
            {"s.toml": 'base = {kind = ["flight"]}\n[grid]\nspeed_m_s = [1, 2]\n'},
            ["sweep", "s.toml", "--out", "s"],
            ["s.toml: base: kind: must be one of"],
        ),
        (
            {"d.toml": "a = " + "[" * 3000 + "]" * 3000 + "\n"},
            ["run", "d.toml"],
            ["d.toml: invalid TOML: nested too deeply"],
        ),
        (
            {"d.toml": "a = " + "{x = " * 600 + "1" + "}" * 600 + "\n"},
            ["run", "d.toml"],
            ["d.toml: invalid TOML: nested too deeply"],
        ),
        (
            {"d.toml": "vehicle_overrides = " + "[" * 400 + "]" * 400 + "\n"},
            ["run", "d.toml"],
            ["d.toml: tables and lists nested 17 deep; no input has more than 16 levels"],
        ),
        (
            {"b.toml": "heading_deg = " + "9" * 5000 + "\n"},
            ["run", "b.toml"],
            ["b.toml: invalid TOML: Exceeds the limit (4300 digits)"],
        ),
        ({}, ["run", "a" * 5000 + ".toml"], ["(5005 characters): cannot read file (File name"]),
    ],
)
def test_malformed_inputs_are_one_line_input_errors(
    tmp_path: Path, files: dict[str, str], args: list[str], fragments: list[str]
) -> None:
    """Types no rule expected (a list for a name, a number for a table...), sizes beyond reason."""
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    proc = run_cli(*args, cwd=tmp_path)
    assert_input_error(proc, *fragments)
    assert len(proc.stderr) < 400 and not (tmp_path / "s").exists()


@pytest.fixture(scope="module")
def short_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("short") / "run"
    proc = run_cli("run", "--final-time", "0.8", "--out", str(out), cwd=out.parent)
    assert proc.returncode == 0, proc.stderr
    return out


@pytest.mark.parametrize(
    ("damage", "fragment"),
    [
        ("array", "summary.json: must be a JSON object of summary fields (got a JSON array)"),
        ("json", "summary.json: cannot be read (JSONDecodeError: Expecting"),
        ("columns", "timeseries.parquet: missing column(s) q0, delta2_m: not a time series"),
        ("parquet", "timeseries.parquet: cannot be read (ArrowInvalid:"),
    ],
)
@pytest.mark.parametrize("command", ["view", "snapshots", "animate"])
def test_damaged_result_folders_are_named_in_one_line(
    short_run: Path, tmp_path: Path, damage: str, fragment: str, command: str
) -> None:
    import shutil

    import pandas as pd

    d = tmp_path / "run"
    shutil.copytree(short_run, d)
    if damage == "array":
        (d / "summary.json").write_text("[1, 2]\n")
    elif damage == "json":
        (d / "summary.json").write_text("{bad json\n")
    elif damage == "columns":
        ts = pd.read_parquet(d / "timeseries.parquet").drop(columns=["q0", "delta2_m"])
        ts.to_parquet(d / "timeseries.parquet")
    else:
        (d / "timeseries.parquet").write_text("not parquet")
    assert_input_error(run_cli(command, "run", cwd=tmp_path), fragment)


def test_a_garbage_crash_log_is_named_before_any_run(tmp_path: Path) -> None:
    (tmp_path / "data" / "spiri-crash-set-1").mkdir(parents=True)
    (tmp_path / "data" / "spiri-crash-set-1" / "crash_3.mat").write_text("garbage")
    proc = run_cli("experiments", "--data", "data", "--samples", "0", "--out", "x", cwd=tmp_path)
    assert_input_error(proc, "crash_3.mat: not a readable crash log of the set (MatReadError")
    assert not (tmp_path / "x" / "crash_1").exists()


def test_every_run_flag_is_also_named_by_its_file_key(tmp_path: Path) -> None:
    """--heading and --heading-deg, --friction and --friction-coefficient...: both work."""
    from quadimpact.cli.run_command import _FLAGS, run

    names = {p.name: p.opts for p in run.params}
    for param, (field, flag) in _FLAGS.items():
        key_flag = "--" + field.replace("_", "-")
        assert flag in names[param] and key_flag in names[param], (param, names[param])
    args = ["--heading-deg", "10", "--speed-m-s", "0.6", "--friction-coefficient", "0.2",
            "--final-time-s", "0.7", "--output-rate-hz", "200"]  # fmt: skip
    proc = run_cli("run", *args, "--inclination", "5", "--out", "out", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    sc = json.loads((tmp_path / "out" / "scenario.json").read_text())["scenario"]
    assert (sc["heading_deg"], sc["speed_m_s"], sc["friction_coefficient"]) == (10, 0.6, 0.2)
    assert (sc["final_time_s"], sc["output_rate_hz"], sc["inclination_deg"]) == (0.7, 200, 5)


def _rewrite_series(src: Path, dst: Path, change) -> Path:
    import shutil

    import pandas as pd

    shutil.copytree(src, dst)
    ts = change(pd.read_parquet(dst / "timeseries.parquet"))
    ts.to_parquet(dst / "timeseries.parquet")
    return dst


@pytest.mark.parametrize("command", ["animate", "view", "snapshots"])
def test_no_library_warnings_leak_from_the_drawing_commands(
    short_run: Path, tmp_path: Path, command: str
) -> None:
    """All-NaN samples: one line saying so (no ffmpeg, NumPy or cast messages); one sample: no
    Matplotlib warning."""
    import numpy as np

    def all_nan(ts):
        return ts.assign(**{c: np.nan for c in ts.columns if c != "t_s"})

    _rewrite_series(short_run, tmp_path / "nan", all_nan)
    extra = ["--size", "320x180"] if command == "animate" else []
    proc = run_cli(command, "nan", *extra, cwd=tmp_path)
    assert_input_error(proc, "nan: nothing to draw: every sample of the run is NaN or infinite")
    _rewrite_series(short_run, tmp_path / "one", lambda ts: ts.iloc[:1])
    extra += ["--times", "-0.5"] if command == "snapshots" else []
    proc = run_cli(command, "one", *extra, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "Warning" not in proc.stderr and "frames have been written" not in proc.stderr


def test_a_cold_numba_cache_is_announced(tmp_path: Path, monkeypatch) -> None:
    """The compiled loop's cache index is looked for where Numba itself puts it."""
    from numba.core.caching import UserProvidedCacheLocator

    import quadimpact.core as core

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(core, "_checked", set())
    said: list[str] = []
    assert not core.cache_is_warm()
    assert core.announce_compilation(say=said.append)
    seconds = core.COMPILED_PARTS["simulator"][2]
    assert said == [
        f"quadimpact: compiling the simulator (first use only: about {seconds} s of CPU on a "
        "2-core machine, more on a slower one; Numba keeps it in its disk cache for every "
        "later process, and `quadimpact compile` does it ahead of time) ..."
    ]
    run_py = str(Path(core.__file__).parent / "kernel.py")
    where = tmp_path / UserProvidedCacheLocator.get_suitable_cache_subpath(run_py)
    where.mkdir(parents=True)
    (where / "step.advance-44.py311.nbi").write_bytes(b"")
    assert core.cache_is_warm()
    core._checked.clear()
    assert not core.announce_compilation(say=said.append)
    assert len(said) == 1


def _refusals(cases: list[list[str]], modules: tuple[str, ...], cwd: Path) -> list[list[Any]]:
    """Each command line run in one fresh process: ``[command, exit code, *(module loaded)]``
    after it; its errors are checked to be one ``quadimpact: error:`` line each."""
    import sys

    code = (
        "import json, sys\n"
        "from quadimpact.cli import main\n"
        "seen = []\n"
        f"for args in {cases!r}:\n"
        "    try:\n"
        "        main(args)\n"
        "    except SystemExit as exc:\n"
        f"        loaded = [m in sys.modules for m in {modules!r}]\n"
        "        seen.append([args[0], exc.code, *loaded])\n"
        "print(json.dumps(seen))\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd=cwd
    )
    assert proc.returncode == 0, proc.stderr
    seen = json.loads(proc.stdout.strip().splitlines()[-1])
    assert [s[0] for s in seen] == [c[0] for c in cases]
    errors = [line for line in proc.stderr.splitlines() if line.startswith("quadimpact: error:")]
    assert len(errors) == len(cases) and "Traceback" not in proc.stderr, proc.stderr
    return [[*s, e] for s, e in zip(seen, errors, strict=True)]


def test_wrong_folders_and_files_are_refused_before_the_simulator_loads(tmp_path: Path) -> None:
    """A missing result folder, scenario file, an unusable --out or a bad value is said
    before the simulator (the compiled kernel's driver), the drawing code (Matplotlib) or
    Numba is imported: the inputs and a sweep's checks pack and validate without the
    compiled code (the controllers' slots are in ``core/controller_slots.py``)."""
    afile = tmp_path / "a-file"
    afile.write_text("not a folder\n")
    cases = [
        ["view", str(tmp_path / "nowhere")],
        ["animate", str(tmp_path / "nowhere")],
        ["snapshots", str(tmp_path / "nowhere")],
        ["reproduce", "--out", str(afile)],
        ["experiments", "--out", str(afile)],
        ["run", str(tmp_path / "nowhere.toml")],
        ["run", "--speed", "-1"],
        ["sweep", "--grid", "speed_m_s=-1", "--workers", "1", "--out", str(tmp_path / "s")],
        ["recovery", "--vehicle", "nowhere.toml", "--workers", "1", "--out", str(tmp_path / "r")],
    ]
    seen = _refusals(cases, ("numba", "quadimpact.core.kernel", "matplotlib"), tmp_path)
    for command, exit_code, numba_loaded, kernel_loaded, mpl_loaded, _error in seen:
        assert exit_code == 2, command
        assert not kernel_loaded and not mpl_loaded, (command, kernel_loaded, mpl_loaded)
        assert not numba_loaded, command


def test_a_bad_recovery_option_is_refused_before_the_pool_or_pandas_start(tmp_path: Path) -> None:
    """``quadimpact recovery`` checks its study's options with ``recovery.spec`` alone: a
    bad vehicle, estimator or pair of options is said before the worker pool starts and
    before pandas (the study's tables) is imported, and the folder is left unclaimed."""
    out = tmp_path / "r"
    cases = [
        ["recovery", "--vehicle", "nowhere.toml", "--out", str(out)],
        ["recovery", "--estimator", "no-such-estimator", "--out", str(out)],
        ["recovery", "--imu", "noisy", "--sensors", "impact", "--out", str(out)],
    ]
    seen = _refusals(
        cases,
        ("pandas", "quadimpact.sweep.runner", "quadimpact.studies.recovery.recovery_study"),
        tmp_path,
    )
    assert [s[1:5] for s in seen] == [[2, False, False, False]] * len(cases), seen
    assert "--vehicle" in seen[0][-1] and "--estimator" in seen[1][-1], seen
    assert not out.exists() or not any(out.iterdir())
