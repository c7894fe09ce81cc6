"""A study's folder: its own from the first file, refused with other options (named), no
temporary file of a killed writer left, nothing drawn again when nothing ran."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
import tracemalloc
from pathlib import Path

import pytest

from quadimpact.errors import InputError
from quadimpact.results.files import folder_kind, remove_stale_temporaries
from quadimpact.studies.study_folder import StudyFolder, read_study_json

from helpers import run_cli


def _dead_pid() -> int:
    """The pid of a process that has ended."""
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_a_study_folder_is_its_own_from_its_first_file(tmp_path: Path) -> None:
    folder = StudyFolder(tmp_path / "s", "pole", {"n": 10, "seed": 0}, flags={"n": "--n"})
    folder.claim()
    assert sorted(p.name for p in folder.path.iterdir()) == ["study.json"]
    assert folder_kind(folder.path) == ("pole", ["study.json"])
    held = read_study_json(folder.path)
    assert held["kind"] == "pole" and held["status"] == "running"
    # a crash's folder appears (an interrupted study): still the study's, resumed
    (folder.path / "crash_1").mkdir()
    (folder.path / "crash_1" / "summary.json").write_text("{}")
    StudyFolder(tmp_path / "s", "pole", {"n": 10, "seed": 0}).claim()
    with pytest.raises(InputError, match=r"holds a pole study with other options \(--n 10 there, "
                                         r"20 asked\); use a new folder"):  # fmt: skip
        StudyFolder(tmp_path / "s", "pole", {"n": 20, "seed": 0}, flags={"n": "--n"}).check()
    with pytest.raises(InputError, match="holds a pole study"):
        StudyFolder(tmp_path / "s", "recovery", {"n": 10}).check()


def test_a_killed_writers_temporaries_are_removed_and_a_live_ones_kept(tmp_path: Path) -> None:
    StudyFolder(tmp_path, "experiments", {}).claim()
    (tmp_path / "crash_1").mkdir()
    dead, live = _dead_pid(), os.getpid()
    stale = tmp_path / "crash_1" / f".compare.png.{dead}.0123abcd.tmp"
    staged = tmp_path / f".crash_2.partial-{dead}-ab12cd34"
    mine = tmp_path / f".table3.csv.{live}.89abcdef"
    for p in (stale, mine):
        p.write_text("x")
    staged.mkdir()
    (staged / "summary.json").write_text("{}")
    removed = remove_stale_temporaries(tmp_path)
    assert sorted(removed) == sorted([stale, staged])
    assert not stale.exists() and not staged.exists() and mine.exists()
    StudyFolder(tmp_path, "experiments", {}).claim()  # resumed: the crash's folder is its own
    assert folder_kind(tmp_path)[0] == "experiments"


def test_a_finished_description_needs_the_same_options_and_its_files(tmp_path: Path) -> None:
    folder = StudyFolder(tmp_path, "recovery", {"n": 3})
    folder.claim()
    assert folder.finished_description() is None  # running
    report = folder.finish({"numbers": {"x": 1}}, "# report\n")
    assert report.read_text() == "# report\n"
    assert folder.finished_description()["numbers"] == {"x": 1}
    assert folder.finished_description("maps.png") is None  # a file it lacks
    assert StudyFolder(tmp_path, "recovery", {"n": 4}).finished_description() is None
    assert json.loads((tmp_path / "study.json").read_text())["status"] == "finished"


def test_a_million_trials_are_planned_with_flat_memory() -> None:
    """The recovery study's trials are drawn when they run: planning a million of them
    (the spec, its validation, any trial) holds none of them in memory."""
    from quadimpact.studies.recovery.recovery_spec import RecoveryStudy, sample_trials

    tracemalloc.start()
    try:
        start = time.perf_counter()
        spec = RecoveryStudy(n=1_000_000).sweep_spec()
        spec.validate()
        last = spec.inputs(999_999)
        elapsed = time.perf_counter() - start
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 20e6 and elapsed < 10.0, (peak, elapsed)
    # the trials are those of the study's own sampling, whatever its size
    first = sample_trials(3, 0)
    assert [spec.inputs(i) for i in range(3)] == [
        {k: float(v) for k, v in t.items()} for t in first
    ]
    assert set(last) == {"roll_deg", "pitch_deg", "yaw_deg", "speed_m_s", "seed"}


@pytest.mark.parametrize(
    ("args", "flag"),
    [
        (["recovery", "--n", "2000000"], "--n 2000000: 2000000 runs, more than 1000000"),
        (["recovery", "--n", "100000000000"], "more than 10000000 (the most one sweep holds)"),
        (["pole", "--pitch-step", "0.001", "--offset-step", "0.0001"], "more than 1000000"),
    ],
)
def test_a_huge_study_is_refused_at_once_naming_allow_large(tmp_path, args, flag) -> None:
    start = time.perf_counter()
    proc = run_cli(*args, "--out", str(tmp_path / "big"), cwd=tmp_path, timeout=60)
    elapsed = time.perf_counter() - start
    assert proc.returncode == 2 and flag in proc.stderr, proc.stderr
    assert "--allow-large" in proc.stderr or "the most one sweep holds" in proc.stderr
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
    assert elapsed < 5.0 and not (tmp_path / "big").exists()
