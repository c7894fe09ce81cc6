"""What the commands refuse, limit and say: starts in contact, response types where they
apply, stop signals, worker caps, records and pictures beyond reason, the one-folder rule,
damaged files, model switches and controller parameters from flags, the flight logs' folder.

Most run ``quadimpact.cli.main`` in this process (fast); those that need a
process of their own (signals, exit codes of a whole program) use ``run_cli``.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from quadimpact.cli import main

from helpers import sigint_as_on_a_terminal


def cli(capsys, *args: str) -> tuple[int, str, str]:
    """``quadimpact ARGS`` in this process: (exit status, stdout, stderr)."""
    shown = warnings.showwarning
    try:
        main(list(args))
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0) if not isinstance(exc.code, str) else 1
    finally:
        warnings.showwarning = shown
    out = capsys.readouterr()
    return code, out.out, out.err


def input_error(result: tuple[int, str, str], *fragments: str) -> str:
    code, out, err = result
    assert code == 2, (code, out, err)
    lines = [line for line in err.strip().splitlines() if "error" in line]
    assert len(lines) == 1 and lines[0].startswith("quadimpact: error: "), err
    assert err.strip().splitlines()[-1] == lines[0] and "Traceback" not in err, err
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    return lines[0]


# ------------------------------------------------------------------ item 1
def test_run_refuses_an_impact_trial_started_in_contact(tmp_path, capsys, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    Path("t.toml").write_text('kind = "impact-trial"\nstart_distance_m = 0.05\n')
    input_error(cli(capsys, "run", "t.toml", "--out", "o"), "starts in contact with the wall",
                "start_distance_m = 0.05")  # fmt: skip
    assert not Path("o").exists()


def test_run_says_when_a_recovery_went_below_ground_level() -> None:
    from quadimpact.cli import format_summary

    summary = {"status": "completed", "controller": "recovery", "t_detect_s": 0.05,
               "t_stage4_s": 1.2, "time_to_recover_s": 1.15, "min_altitude_m": -3.9}  # fmt: skip
    text = format_summary(summary, Path("o"))
    assert "but below ground level on the way (lowest altitude -3.9 m" in text


# ------------------------------------------------------------------ item 3
def test_a_response_type_is_printed_only_where_it_applies_with_its_meaning() -> None:
    from quadimpact import ImpactTrial, WallApproach
    from quadimpact.cli import format_summary
    from quadimpact.inputs.scenarios import FlightScenario

    s = {"status": "completed", "response_type": "A", "crash_time_s": None}
    text = format_summary(s, Path("o"), WallApproach())
    assert "response type  A (no crash before the end of the run; says nothing of the " in text
    for scenario in (ImpactTrial(), FlightScenario()):
        text = format_summary(s, Path("o"), scenario)
        assert "response type  n/a (a" in text and "defined for the wall approach" in text
    text = format_summary(s, Path("o"), WallApproach(ground="none"))
    assert "response type  n/a (no ground, so no crash rule" in text


def test_the_viewer_title_names_its_speeds_and_types_only_wall_approaches() -> None:
    from quadimpact import ImpactTrial, WallApproach, simulate
    from quadimpact.viz.scene import Scene

    wall = Scene.from_result(simulate(WallApproach(final_time_s=0.8))).describe()
    assert "impact speed 0.75 m/s" in wall and "type A" in wall
    trial = Scene.from_result(simulate(ImpactTrial(final_time_s=0.3))).describe()
    assert trial.startswith("impact trial") and "initial speed 1.50 m/s" in trial
    assert "impact speed" in trial and "type" not in trial


# ------------------------------------------------------------------ item 5
@pytest.mark.slow
@pytest.mark.parametrize(("signum", "code", "name"), [(15, 143, "SIGTERM"), (2, 130, "SIGINT")])
def test_recovery_stops_on_a_signal_like_sweep(tmp_path, signum, code, name) -> None:
    import os
    import subprocess
    import sys
    import time

    import quadimpact

    env = dict(os.environ)
    src = str(Path(quadimpact.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [src, env.get("PYTHONPATH")]))
    env.pop("QUADIMPACT_DEBUG", None)
    proc = subprocess.Popen(
        [sys.executable, "-m", "quadimpact.cli", "recovery", "--n", "5000", "--out", "r",
         "--workers", "1", "--no-progress", "--no-animation"],
        cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        preexec_fn=sigint_as_on_a_terminal,
    )  # fmt: skip
    try:
        end = time.monotonic() + 120
        while not list((tmp_path / "r" / "sweep").glob("sweep.json")):
            assert proc.poll() is None and time.monotonic() < end, proc.stderr.read()
            time.sleep(0.1)
        time.sleep(1.5)  # some trials run
        proc.send_signal(signum)
        out, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == code, err
    assert f"quadimpact: interrupted by {name}: " in err
    assert " of 5000 runs saved in r/sweep; " in err
    assert "run the same command again to resume" in err and "Traceback" not in err


# ------------------------------------------------------------------ item 6
def test_workers_are_capped_at_four_per_core(tmp_path, capsys, monkeypatch) -> None:
    from quadimpact.sweep import runner as sweep_run

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sweep_run, "default_workers", lambda: 2)
    seen = {}

    def fake_run_sweep(spec, out, **kw):
        seen.update(kw)
        raise SystemExit(0)

    monkeypatch.setattr("quadimpact.sweep.run_sweep", fake_run_sweep)
    code, _, err = cli(capsys, "sweep", "--grid", "heading_deg=0,45", "--out", "s",
                       "--workers", "1000", "--no-plots")  # fmt: skip
    assert seen["workers"] == 8
    assert "quadimpact: warning: --workers 1000: capped at 8 (4 per core on the 2 core(s)" in err
    assert sweep_run.cap_workers(8) == (8, "")


# ------------------------------------------------------------------ item 7
def test_run_refuses_a_record_too_large_for_memory_with_its_estimate(
    tmp_path, capsys, monkeypatch
) -> None:
    from quadimpact.cli.options import MAX_RECORD_MB
    from quadimpact.simulation import checks

    assert MAX_RECORD_MB == checks.MAX_RECORD_MB
    monkeypatch.chdir(tmp_path)
    args = ("--final-time", "600", "--output-rate", "100000", "--ground", "none", "--out", "o")
    input_error(cli(capsys, "run", *args), "record would take 17.5 GiB (600 s at output_rate_hz "
                "= 100000)", "--max-record-mb MB raises the limit")  # fmt: skip
    assert not Path("o").exists()
    # the option raises the limit (checked here without running: the estimate passes)
    from quadimpact import WallApproach

    big = WallApproach(final_time_s=600, output_rate_hz=100000, ground="none")
    checks.check_record_size(big, 20000.0)
    input_error(cli(capsys, "sweep", "--grid", "output_rate_hz=1000,100000", "--grid",
                    "final_time_s=600", "--out", "s"), "run 1 (", "17.5 GiB")  # fmt: skip


def test_snapshots_and_animate_refuse_pictures_beyond_reason(tmp_path, capsys) -> None:
    times = ",".join(f"{0.001 * k:g}" for k in range(300))
    input_error(cli(capsys, "snapshots", str(tmp_path), "--times", times),
                "--times: 300 frames would make a 103,500 pixel wide strip",
                "--max-frames N")  # fmt: skip
    input_error(cli(capsys, "animate", str(tmp_path), "--size", "100000x100000"),
                "a frame of 10,000 Mpx (37.3 GiB to draw) is larger than 8K")  # fmt: skip


# ------------------------------------------------------------------ item 8
@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from quadimpact import WallApproach, simulate

    out = tmp_path_factory.mktemp("h2run") / "run"
    simulate(WallApproach(final_time_s=0.7)).write(out)
    return out


def test_one_folder_rule_for_every_command(tmp_path, capsys, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    Path("mine").mkdir()
    Path("mine/notes.txt").write_text("mine")
    for command in (["sweep", "--grid", "heading_deg=0"], ["recovery", "--n", "2"],
                    ["experiments"], ["reproduce"], ["run"]):  # fmt: skip
        input_error(cli(capsys, *command, "--out", "mine"),
                    "--out mine: holds files that are not quadimpact's (notes.txt)")  # fmt: skip
    input_error(cli(capsys, "sweep", "--grid", "heading_deg=0", "--out", "/proc/x"),
                "--out /proc/x: cannot be created in /proc")  # fmt: skip
    Path("s").mkdir()
    Path("s/sweep.json").write_text("{}")
    input_error(cli(capsys, "recovery", "--n", "2", "--out", "s"), "--out s: holds a sweep")
    Path("r").mkdir()
    Path("r/trials.parquet").write_text("")
    input_error(cli(capsys, "sweep", "--grid", "heading_deg=0", "--out", "r"),
                "--out r: holds a recovery study")  # fmt: skip


@pytest.mark.parametrize("command", ["view", "snapshots", "animate"])
def test_the_drawing_commands_refuse_a_folder_they_cannot_write(
    run_dir, capsys, monkeypatch, command
) -> None:
    import tempfile

    def refuse(*_args, **_kw):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    input_error(cli(capsys, command, str(run_dir)),
                "the pictures cannot be written there (Permission denied)")  # fmt: skip


@pytest.mark.parametrize(
    ("text", "fragment"),
    [('{"scenario": 5}', "scenario: must be a JSON object (got a JSON number)"),
     ('{"surfaces": [{"kind": "plane"}]}', "surfaces.0: must be a surface record"),
     ('{"surfaces": [{"name": "w", "point_m": 1, "normal": [1, 0, 0], "is_ground": false, '
      '"kind": "plane"}]}', "damaged or not written by quadimpact (TypeError")],
)  # fmt: skip
def test_a_damaged_scenario_json_is_named_in_one_line(
    run_dir, tmp_path, capsys, text, fragment
) -> None:
    import shutil

    d = tmp_path / "copy"
    shutil.copytree(run_dir, d)
    (d / "scenario.json").write_text(text)
    input_error(cli(capsys, "view", str(d)), "scenario.json", fragment)


# ------------------------------------------------------------------ item 9
def test_numeric_model_switches_are_parsed_from_the_flag() -> None:
    from quadimpact.cli.run_command import build_scenario

    for text, value in (("0.3", 0.3), ("1", 1.0), ("2.5e-1", 0.25)):
        s = build_scenario(None, {}, (f"contact_gate_m={text}",))
        assert s.model_options.contact_gate_m == value
    s = build_scenario(None, {}, ("crash_rule=cm-ground", "bumper1_yaw_twice=TRUE"))
    assert s.model_options.crash_rule == "cm-ground" and s.model_options.bumper1_yaw_twice is True
    from quadimpact.errors import InputError

    with pytest.raises(InputError, match="contact_gate_m: must be a finite number .got 'nan'"):
        build_scenario(None, {}, ("contact_gate_m=nan",))


# ------------------------------------------------------------------ item 11
def test_recovery_names_a_vehicle_file_as_typed(tmp_path, capsys, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    Path("veh_x.toml").write_text("mass_kg = -1\n")
    line = input_error(cli(capsys, "recovery", "--vehicle", "veh_x.toml", "--out", "r"),
                       "--vehicle: ", "veh_x.toml")  # fmt: skip
    assert "veh-x" not in line


# ------------------------------------------------------------------ items 14, 18
def test_run_has_flags_for_an_impact_trial_and_controller_parameters() -> None:
    from quadimpact.cli.run_command import build_scenario
    from quadimpact.errors import InputError

    flags = {"roll": 5.0, "pitch": -20.0, "yaw": 30.0, "speed": 1.5, "imu": "noisy",
             "seed": 7, "start_distance": 0.4, "vehicle": "spiri"}  # fmt: skip
    s = build_scenario(None, flags, kind="impact-trial", params=("k_att_1_s=25",))
    assert (s.kind, s.roll_deg, s.pitch_deg, s.yaw_deg, s.speed_m_s) == (
        "impact-trial", 5.0, -20.0, 30.0, 1.5)  # fmt: skip
    assert (s.imu.preset, s.seed, s.start_distance_m, s.vehicle) == ("noisy", 7, 0.4, "spiri")
    assert s.controller_params["k_att_1_s"] == 25
    with pytest.raises(InputError, match="--yaw: applies to impact trials only"):
        build_scenario(None, {"yaw": 3.0})
    with pytest.raises(InputError, match="--heading: applies to wall-approach scenarios only"):
        build_scenario(None, {"heading": 3.0}, kind="impact-trial")
    with pytest.raises(InputError, match="--param: k_att_1_s: must be >= 0"):
        build_scenario(None, {}, kind="impact-trial", params=("k_att_1_s=-1",))


# ------------------------------------------------------------------ item 16
def test_the_flight_log_folder_used_is_said(tmp_path, monkeypatch) -> None:
    from quadimpact.experiments import logs
    from quadimpact.studies.table3.crash_logs import logs_source

    data = tmp_path / "data"
    (data / "spiri-crash-set-1").mkdir(parents=True)
    monkeypatch.setenv(logs.DATA_ENV_VAR, str(data))
    assert logs_source(None) == f"flight logs read from {data} (found: $QUADIMPACT_DATA)"
    assert logs_source(data) == f"flight logs read from {data} (--data)"
    monkeypatch.setenv(logs.DATA_ENV_VAR, str(tmp_path / "nothing"))
    assert logs_source(None).startswith("no flight logs: $QUADIMPACT_DATA=")
    from quadimpact.cli.experiments_command import experiments

    data_help = next(p.help for p in experiments.params if p.name == "data")
    assert "$QUADIMPACT_DATA" in data_help and "../shared/data" in data_help
    assert "/work" not in data_help  # no machine's own path
    assert "The folder used is printed" in data_help
