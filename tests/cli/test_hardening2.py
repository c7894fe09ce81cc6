"""The command line after issue 20 ("Hardening 2"): one test (or more) per item.

Most run ``quadimpact.cli.main`` in this process (fast); those that need a
process of their own (signals, exit codes of a whole program) use ``run_cli``.
"""

from __future__ import annotations

import warnings
from pathlib import Path

from quadimpact.cli import main


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
        assert "response type  n/a (a " in text and "defined for the wall approach" in text
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
