"""``quadimpact experiments`` runs its crashes on worker processes: Ctrl-C or kill -9
of the command leaves no process and no temporary folder behind."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

import quadimpact

from helpers import assert_all_gone, process_cpu_s, sigint_as_on_a_terminal

SRC = Path(quadimpact.__file__).resolve().parents[1]
GONE_S = 5.0


def _start(out: Path, tmp: Path) -> subprocess.Popen:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
    env["TMPDIR"] = str(tmp)
    env.pop("QUADIMPACT_DEBUG", None)
    return subprocess.Popen(
        [sys.executable, "-m", "quadimpact.cli", "experiments", "--out", str(out),
         "--workers", "2"],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True,
        preexec_fn=sigint_as_on_a_terminal,
    )  # fmt: skip


def _busy_workers(proc: subprocess.Popen, seen: dict[int, psutil.Process]) -> None:
    """Wait until two of the command's grandchildren (the task workers) are busy."""
    end = time.monotonic() + 90
    while time.monotonic() < end:
        assert proc.poll() is None, proc.stderr.read().decode()
        found = psutil.Process(proc.pid).children(recursive=True)
        seen.update((p.pid, p) for p in found)
        if sum(1 for p in found if p.ppid() != proc.pid and process_cpu_s(p) >= 0.3) >= 2:
            return
        time.sleep(0.05)
    raise AssertionError("the crashes' workers never got busy")


@pytest.mark.slow
@pytest.mark.parametrize("how", ["ctrl-c", "kill-9"])
def test_stopping_experiments_leaves_nothing_running(tmp_path, tmpdir_env, how):
    proc = _start(tmp_path / "out", tmpdir_env)
    seen: dict[int, psutil.Process] = {}
    try:
        _busy_workers(proc, seen)
        t = time.monotonic()
        if how == "ctrl-c":
            os.killpg(proc.pid, signal.SIGINT)  # a terminal sends it to the group
            assert proc.wait(timeout=15) == 130
            assert time.monotonic() - t < 10
            err = proc.stderr.read().decode()
            assert "Traceback" not in err and "Exception ignored" not in err, err
        else:
            proc.kill()  # the command alone
            proc.wait(timeout=10)
        assert len(seen) >= 3, seen  # the fork server and two workers were seen
        assert_all_gone(list(seen.values()), tmpdir_env, GONE_S)
    finally:
        for p in [proc, *seen.values()]:
            try:
                os.kill(p.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
        proc.wait(timeout=10)


@pytest.mark.slow
def test_experiments_interrupted_early_resume_to_the_same_tables(tmp_path, tmpdir_env) -> None:
    """Ctrl-C as soon as the crashes' workers are busy (the folder holds only the study's
    first file and unfinished crash folders), then the same command: it resumes in its own
    folder, leaves no temporary file and gives the tables of an uninterrupted run."""
    import pandas as pd

    def start(out: Path) -> subprocess.Popen:
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
        env["TMPDIR"] = str(tmpdir_env)
        return subprocess.Popen(
            [sys.executable, "-m", "quadimpact.cli", "experiments", "--out", str(out),
             "--samples", "0", "--log-samples", "0", "--workers", "2", "--no-progress"],
            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True,
            preexec_fn=sigint_as_on_a_terminal,
        )  # fmt: skip

    out = tmp_path / "ex2"
    proc = start(out)
    seen: dict[int, psutil.Process] = {}
    _busy_workers(proc, seen)
    os.killpg(proc.pid, signal.SIGINT)
    assert proc.wait(timeout=30) == 130
    assert (out / "study.json").is_file()
    again = start(out)
    assert again.wait(timeout=900) == 0, again.stderr.read().decode()
    assert not [p for p in out.rglob(".*")], "temporary files left"
    reference = start(tmp_path / "reference")
    assert reference.wait(timeout=900) == 0
    for name in ("table3.parquet", "table3_runs.parquet", "table3_switches.parquet"):
        a = pd.read_parquet(out / name)
        b = pd.read_parquet(tmp_path / "reference" / name)
        pd.testing.assert_frame_equal(a, b)
