"""Messages and reports that say what is true (issue 46 item 6): a refused folder names
what differs in plain words (and a recovery study its --n or --seed), a missing base
file its sweep file and key, animate's time span its flags, a resumed sweep's progress
only what it knows.
"""

from __future__ import annotations

import io
import time
from pathlib import Path

import pytest

from quadimpact.sweep.progress import Progress

from helpers import cli_here


def error_line(result: tuple[int, str]) -> str:
    code, err = result
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("quadimpact: error: "), err
    return lines[0]


RUNS = (
    "base = {{ final_time_s = 0.6 }}\n[[runs]]\ninclination_deg = {}\n[[runs]]\nspeed_m_s = 1.0\n"
)


def test_a_folder_of_another_sweep_says_in_words_what_is_not_the_same(
    tmp_path: Path, monkeypatch, capsys
) -> None:
    monkeypatch.chdir(tmp_path)
    Path("a.toml").write_text(RUNS.format(5))
    Path("b.toml").write_text(RUNS.format(10))
    code, err = cli_here(capsys, "sweep", "a.toml", "--out", "o", "--workers", "1", "--no-plots")
    assert code == 0, err
    line = error_line(cli_here(capsys, "sweep", "b.toml", "--out", "o", "--workers", "1"))
    assert line == (
        "quadimpact: error: o: holds a different sweep (not the same runs, see sweep.json); "
        "use another output folder, or delete this one to start over"
    )


def test_a_missing_base_file_names_the_sweep_file_and_its_base_key(
    tmp_path: Path, monkeypatch, capsys
) -> None:
    monkeypatch.chdir(tmp_path)
    Path("studies").mkdir()
    Path("studies/s.toml").write_text('base = "wall.toml"\n[grid]\ninclination_deg = [0, 5]\n')
    line = error_line(cli_here(capsys, "sweep", "studies/s.toml", "--out", "o"))
    assert line == "quadimpact: error: studies/s.toml: base: studies/wall.toml: file not found"


def test_a_recovery_folder_names_the_study_it_holds(tmp_path: Path, monkeypatch, capsys) -> None:
    from quadimpact.errors import InputError
    from quadimpact.studies.recovery.recovery_study import RecoveryStudy, run_study, run_trials

    monkeypatch.chdir(tmp_path)
    run_trials(RecoveryStudy(n=2, seed=3), "r", workers=1)
    line = error_line(cli_here(capsys, "recovery", "--n", "3", "--seed", "3", "--out", "r",
                          "--workers", "1", "--no-example"))  # fmt: skip
    assert line == (
        "quadimpact: error: r: holds a recovery study with other options (--n 2 there, 3 "
        "asked); use a new folder, or the same options to resume it"
    )
    with pytest.raises(InputError, match=r"^r: holds a recovery study with other options "
                                         r"\(--n 2 there, 1 asked\)"):  # fmt: skip
        run_study(RecoveryStudy(n=1, seed=3), "r", workers=1, example=False)  # fewer too
    with pytest.raises(InputError, match=r"\(--seed 3 there, 4 asked\)"):
        run_study(RecoveryStudy(n=2, seed=4), "r", workers=1, example=False)
    with pytest.raises(InputError, match=r"\(--vehicle 'navi' there, 'spiri' asked\)"):
        run_study(RecoveryStudy(n=2, seed=3, vehicle="spiri"), "r", workers=1, example=False)


@pytest.fixture(scope="module")
def short_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from quadimpact import WallApproach, simulate

    out = tmp_path_factory.mktemp("short") / "run"
    simulate(WallApproach(final_time_s=0.8)).write(out)
    return out


@pytest.mark.parametrize(
    ("flags", "expected"),
    [
        (["--start", "2", "--end", "1"], "--start 2, --end 1: --end must not precede --start"),
        (["--start", "5"], "--start 5: after the end of the run (the run spans "),
        (["--end", "-3"], "--end -3: before the start of the run (the run spans "),
    ],
)
def test_animate_names_the_flags_of_a_span_it_cannot_show(
    short_run: Path, capsys, flags: list[str], expected: str
) -> None:
    line = error_line(cli_here(capsys, "animate", str(short_run), *flags))
    assert line.startswith(f"quadimpact: error: {expected}"), line


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_a_resumed_sweep_shows_no_rate_before_its_first_run_and_no_past_marks() -> None:
    stream = io.StringIO()
    bar = Progress(100, 60, stream=stream)  # resumed: 60 of 100 done before
    time.sleep(0.05)
    bar.update(5)
    bar.update(15)  # 80 %: past the 75 % mark
    bar.update(20)
    bar.close()
    lines = stream.getvalue().splitlines()
    assert lines[0] == "sweep: 40 runs to do, 60 already done"
    assert [line.split(" runs ")[0] for line in lines[1:]] == ["sweep 80/100", "sweep 100/100"]
    tty = Terminal()
    Progress(100, 60, stream=tty)
    first = tty.getvalue()
    assert "sweep 60/100 runs ( 60%)      -- runs/s" in first and "left --:--" in first
    assert "0.0 runs/s" not in first
