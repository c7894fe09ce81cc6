"""The paper's study, end to end (reduced where it costs)."""

import io
import re
import sys

import pandas as pd
import pytest

from quadimpact.simulation.response_types import RESPONSE_TYPES
from quadimpact.studies.paper import paper_study as study
from quadimpact.studies.paper.paper_study import reproduce
from quadimpact.studies.recovery.recovery_analysis import EXCLUDED_CLASSES
from quadimpact.studies.statistics import rate_text

from helpers import assert_same_table


@pytest.mark.slow
def test_reproduce_writes_a_report_with_computed_verdicts(tmp_path, monkeypatch, capsys):
    # the recovery part at 40 and 20 trials instead of 2,000 and 1,000 (its grid and crashes
    # in full)
    monkeypatch.setattr(study, "RECOVERY_N", 40)
    monkeypatch.setattr(study, "RECOVERY_COMPARE_N", 20)
    monkeypatch.setattr(study, "COMPARE_N", 20)  # the estimators' comparison, not 1,000
    # the pole at 2 x 3 points instead of 10 x 15
    monkeypatch.setattr(study, "POLE_GRID", {"pitch_step_deg": 45.0, "offset_step_m": 0.35})
    r = reproduce(tmp_path, ablation=False, experiments=False, workers=2, progress=True)
    err = capsys.readouterr().err.splitlines()
    timed = re.compile(r"^reproduce: (.+): (\d+\.\d) s$")  # a stage's or a piece's end
    err = [line for line in err if ": still running (" not in line]  # a slow machine's notes
    stages = [line for line in err if line.startswith("reproduce: ") and not timed.match(line)]
    ends = [timed.match(line).group(1) for line in err if timed.match(line)]
    pieces = ["Figure 4 sweep and the example run, paper-replica",
              "Figure 4 sweep and the example run, default"]  # fmt: skip
    # the two pieces (on two processes, in the order they finish), then each stage's end
    assert sorted(ends[:2]) == sorted(pieces) and sorted(n for n, _ in r.piece_times) == sorted(
        pieces
    )
    assert ends[2:] == [s.removeprefix("reproduce: ") for s in stages]  # in order, timed
    assert [name for name, _ in r.stage_times] == ends[2:]
    assert sum(t for _, t in r.stage_times) <= r.elapsed_s
    assert stages == [
        "reproduce: the paper's runs: 2 pieces on 2 processes (Figure 4 and the example in "
        "both variants)",
        "reproduce: recovery: 40 impact trials of the Navi, default",
        "reproduce: recovery: 40 impact trials of the Navi, recovery-replica",
        "reproduce: recovery: 20 trials with the noisy IMU, 20 of the Spiri",
        "reproduce: recovery: the Figure 4 grid with the recovery controller, paper-replica",
        "reproduce: recovery: the Figure 4 grid with the recovery controller, default",
        "reproduce: recovery: the crashes without their power-off, nominal and recovery",
        "reproduce: recovery: 20 trials with each estimator, impact sensors",
        "reproduce: the pole: 6 grid points, without and with recovery",
        "reproduce: figures, tables and the report",
    ]
    assert err[err.index(stages[1]) + 1] == "sweep: 40 runs to do"  # each sweep is named
    text = r.report.read_text()
    assert "## Time per stage" in text
    for name, seconds in r.stage_times + r.piece_times:
        assert f"| {name} | {seconds:.1f} |" in text
    f = r.findings
    assert set(f["variant"]) == {"paper-replica", "default"}
    assert len(f) == 2 * 10 and set(f["verdict"]) <= {"agrees", "partly", "disagrees", "n/a"}
    for _, row in f.iterrows():  # every verdict in the report is the computed one
        measured = row["measured"].replace("|", "\\|")  # escaped in the Markdown table
        assert f"**{row['verdict']}**: {measured}" in text
    rows = [line for line in text.splitlines() if line.startswith("| ") and "**" in line
            and line.split(" | ")[0][2:] in set(f["key"])]  # fmt: skip
    assert len(rows) == 10  # one per finding, five cells each: no "|" of |Y| splits a cell
    assert all(len(re.findall(r"(?<!\\)\|", line)) == 6 for line in rows)
    # the replica reproduces the paper's Figure 5 pattern and Figure 4's peak
    rep = f[f["variant"] == "paper-replica"].set_index("key")
    assert rep.loc["figure5", "verdict"] == "agrees"
    assert rep.loc["peak_near_10", "verdict"] == "agrees"
    for name in (
        "fig4_paper-replica.png",
        "table2_default.png",
        "fig4.parquet",
        "table2.parquet",
        "example-default/snapshots.png",
        "example-paper-replica/fig5.png",
    ):
        assert (tmp_path / name).is_file(), name
    t2 = pd.read_parquet(tmp_path / "table2.parquet")
    assert len(t2) == 2 * 246 and set(t2["response_type"].dropna()) <= set(RESPONSE_TYPES)
    # beyond the paper: recovery, its numbers those of its tables
    part = r.recovery
    assert "## Beyond the paper: recovery" in text and "(40 trials per variant)" in text
    assert "## Beyond the paper: the pole" in text and (tmp_path / "pole" / "maps.png").is_file()
    assert r.pole.numbers["n_points"] == 6
    for variant, numbers in part.monte_carlo.items():
        assert f"| {variant} | 40 | {rate_text(numbers['success'])} |" in text
    trials = pd.read_parquet(tmp_path / "recovery_trials.parquet")
    navi = trials[trials["study"] == "navi, default"]
    # a success: stage 4 reached and never below altitude 0 (the recovery study's classes)
    won = navi["recovered"].fillna(False).astype(bool) & (navi["min_altitude_m"] >= 0.0)
    won &= ~navi["outcome_class"].astype(str).isin(EXCLUDED_CLASSES)  # valid trials only
    assert len(navi) == 40 and part.monte_carlo["default"]["success"].k == won.sum()
    estimators = {"estimator ideal", "estimator complementary", "estimator ekf"}
    assert set(trials["study"]) == {"navi, default", "navi, recovery-replica", "navi, noisy IMU",
                                    "spiri"} | estimators  # fmt: skip
    assert (trials[trials["study"].isin(estimators)].groupby("study").size() == 20).all()
    fig4 = pd.read_parquet(tmp_path / "recovery_fig4.parquet")
    assert len(fig4) == 2 * 246 and set(fig4["variant"]) == {"paper-replica", "default"}
    for variant, grid in part.grid.items():
        rows = grid.set_index("nominal_type")
        assert rows.loc["all", "runs"] == 246
        assert rows.loc["all", "saved"] == fig4[fig4["variant"] == variant]["saved"].sum()
        n_a = rows.loc["A", "runs"] if "A" in rows.index else 0
        assert n_a == (r.tables[variant]["response_type"] == "A").sum()
    crashes = pd.read_parquet(tmp_path / "recovery_crashes.parquet")
    assert len(crashes) == 14 and (tmp_path / "recovery_by_inclination.png").is_file()
    assert f"This part took {part.elapsed_s:.1f} s" in text


@pytest.mark.slow
def test_reproduce_tables_do_not_depend_on_the_processes(tmp_path, capsys):
    """The paper's pieces on two processes or one after the other here: the same tables."""
    kw = {"ablation": False, "experiments": False, "recovery": False, "progress": True}
    two = reproduce(tmp_path / "two", workers=2, **kw)
    one = reproduce(tmp_path / "one", workers=1, **kw)
    err = capsys.readouterr().err
    assert "reproduce: Figure 4 sweep and the example run, default\nsweep: 246 runs to do" in err
    assert not one.piece_times and len(two.piece_times) == 2
    for name in ("fig4.parquet", "table2.parquet", "findings.parquet",
                 "example-default/timeseries.parquet"):  # fmt: skip
        assert_same_table(
            pd.read_parquet(tmp_path / "two" / name), pd.read_parquet(tmp_path / "one" / name)
        )


def test_a_long_stage_of_pieces_is_never_silent(capsys, monkeypatch) -> None:
    """Issue 20 item 20: make run printed nothing for ~85 s (a compile and the first piece)."""
    import time

    from quadimpact.studies.paper.paper_study import StageClock

    monkeypatch.setattr(StageClock, "HEARTBEAT_S", 0.2)
    clock = StageClock(progress=True)
    clock.start("the paper's runs: 3 pieces on 2 processes", n_pieces=3)
    time.sleep(1.6)
    clock.piece("piece 1", 1.5)
    clock.stop()
    err = capsys.readouterr().err
    assert "reproduce: the paper's runs: 3 pieces on 2 processes: still running (0 of 3 " \
           "pieces done, 1 s so far; a first run compiles the simulator first)" in err  # fmt: skip
    assert err.rstrip().endswith("s") and "piece 1: 1.5 s" in err
    time.sleep(1.2)  # stopped: no more lines
    assert capsys.readouterr().err == ""


class _Terminal(io.StringIO):
    """A stderr that says it is a terminal (what ``make run`` in a shell writes to)."""

    def isatty(self) -> bool:
        return True


def test_a_long_stage_on_a_terminal_is_one_line_redrawn_in_place(monkeypatch) -> None:
    """Issue 60 item 4: the compile printed eleven 150-character lines, one every 15 s."""
    import time

    from quadimpact.studies.paper.paper_study import StageClock

    monkeypatch.setattr(StageClock, "TICK_S", 0.05)
    monkeypatch.setattr(StageClock, "HEARTBEAT_S", 0.05)  # (what a non-terminal would use)
    monkeypatch.setenv("COLUMNS", "60")
    terminal = _Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    clock = StageClock(progress=True)
    stage = "the paper's runs: 3 pieces on 2 processes (sweeps, crashes and more)"
    clock.start(stage, n_pieces=3)
    time.sleep(0.6)
    clock.piece("piece 1", 0.5)
    time.sleep(0.3)
    clock.stop()
    time.sleep(0.2)  # stopped: nothing more
    text = terminal.getvalue()
    lines = text.split("\n")
    # Three lines said (the stage, its piece, its end), and the status between them drawn
    # over itself: never a line of its own, never wider than the terminal.
    assert len(lines) == 4 and lines[-1] == "", lines
    assert lines[0] == f"reproduce: {stage}"
    assert lines[1].endswith("\r\x1b[Kreproduce: piece 1: 0.5 s"), lines[1]
    assert re.search(rf"\r\x1b\[Kreproduce: {re.escape(stage)}: \d+\.\d s$", lines[2]), lines[2]
    drawn = lines[1].split("\r\x1b[K")[1:-1]  # before the piece
    assert len(drawn) >= 5, drawn  # redrawn about every TICK_S
    assert drawn[0] == "reproduce: still running: 0 s so far, 0 of 3 pieces done..."
    assert drawn[0].endswith("...") and len(drawn[0]) == 59  # cut to the 60 columns
    redrawn = lines[2].split("\r\x1b[K")[1:-1]  # after the piece, before the stage's end
    assert redrawn and all(d.endswith(", 1 of 3 pieces done") for d in redrawn), redrawn
    assert all(len(d) <= 59 for d in drawn + redrawn)


def test_a_long_stage_off_a_terminal_prints_a_line_only_every_heartbeat(capsys, monkeypatch):
    """Issue 60 item 4: off a terminal, a line after each HEARTBEAT_S without one, no '\\r'."""
    import time

    from quadimpact.studies.paper.paper_study import StageClock

    monkeypatch.setattr(StageClock, "TICK_S", 0.05)
    monkeypatch.setattr(StageClock, "HEARTBEAT_S", 1.0)
    clock = StageClock(progress=True)
    clock.start("the paper's runs: 3 pieces on 2 processes (sweeps)", n_pieces=3)
    time.sleep(2.6)
    clock.stop()
    err = capsys.readouterr().err
    assert "\r" not in err
    still = [line for line in err.splitlines() if "still running" in line]
    assert len(still) == 2, err
    assert still[0].startswith("reproduce: the paper's runs: 3 pieces on 2 processes: still")
