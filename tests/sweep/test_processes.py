"""A sweep's processes: Ctrl-C (any number of presses), SIGTERM and SIGKILL end it with
every child and no temporary folder left, a stopped worker times out, a killed fork
server or worker costs one retried run, and every rerun gives the reference table.

Each test runs the command in its own process group, with its own ``TMPDIR`` (so
that multiprocessing's ``pymp-*`` folders of this sweep are the ones in it), and
waits for the workers to be busy before it signals: whatever the machine's speed,
the sweep is still running then (its runs take several times longer).
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import psutil
import pytest

import quadimpact
from quadimpact.sweep import SweepSpec, read_runs, run_sweep

from helpers import assert_all_gone, assert_same_table, process_cpu_s, sigint_as_on_a_terminal

SRC = Path(quadimpact.__file__).resolve().parents[1]
# 720 runs of 3-7 ms each (360 of them, on a fast machine, were done before the fourth
# sweep's workers had been busy long enough for the test to see them)
GRID = {"heading_deg": "0:359.5:0.5", "final_time_s": [1.0]}
GRID_ARGS = ["--grid=heading_deg=0:359.5:0.5", "--grid=final_time_s=1"]
N_RUNS = 720
GONE_S = 5.0  # a child may outlive the sweep by this much at most


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> pd.DataFrame:
    return run_sweep(SweepSpec(grid=GRID), tmp_path_factory.mktemp("ref") / "out", workers=2)


class Sweep:
    """``quadimpact sweep`` in its own process group; its output in files."""

    def __init__(self, out: Path, tmp: Path, *args: str, workers: int | None = 2) -> None:
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
        env["TMPDIR"] = str(tmp)
        env.pop("QUADIMPACT_DEBUG", None)
        self.out, self.tmp = out, tmp
        self.stdout, self.stderr = out.parent / "stdout.txt", out.parent / "stderr.txt"
        command = [sys.executable, "-m", "quadimpact.cli", "sweep", *GRID_ARGS, "--out", str(out)]
        with self.stdout.open("w") as so, self.stderr.open("w") as se:
            self.proc = subprocess.Popen(
                [*command, *(["--workers", str(workers)] if workers else []), "--no-plots", *args],
                env=env,
                stdout=so,
                stderr=se,
                start_new_session=True,
                preexec_fn=sigint_as_on_a_terminal,
            )
        self.children: dict[int, psutil.Process] = {}

    def workers(self) -> list[psutil.Process]:
        """The pool's worker processes (grandchildren), remembering every descendant seen."""
        try:
            found = psutil.Process(self.proc.pid).children(recursive=True)
        except psutil.NoSuchProcess:
            return []
        self.children.update((p.pid, p) for p in found)
        return [p for p in found if _ppid(p) != self.proc.pid]

    def wait_busy(self, timeout: float = 90) -> list[psutil.Process]:
        """Wait until two workers have each run for a while; return them."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            assert self.proc.poll() is None, f"the sweep ended early: {self.err()}"
            busy = [w for w in self.workers() if process_cpu_s(w) >= 0.05]
            if len(busy) >= 2:
                return busy
            time.sleep(0.02)
        raise AssertionError(f"the workers never got busy: {self.err()}")

    def wait(self, timeout: float) -> int:
        try:
            return self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            raise AssertionError(
                f"the sweep did not end within {timeout} s: {self.err()}"
            ) from None

    def kill(self) -> None:
        for p in [self.proc, *self.children.values()]:
            try:
                os.kill(p.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
        self.proc.wait(timeout=10)

    def err(self) -> str:
        return self.stderr.read_text()

    def assert_all_gone(self) -> None:
        """No descendant seen is alive a few seconds later; no pymp-* folder is left."""
        self.workers()
        assert len(self.children) >= 4, self.children  # tracker, server, 2 workers were seen
        assert_all_gone(list(self.children.values()), self.tmp, GONE_S)


def _ppid(p: psutil.Process) -> int | None:
    try:
        return p.ppid()
    except psutil.Error:
        return None


def _parts_rows(out: Path) -> int:
    return sum(len(pd.read_parquet(p)) for p in (out / "parts").glob("part-*.parquet"))


def _resume(out: Path, tmp: Path, reference: pd.DataFrame, n_before: int) -> None:
    """The same command again completes the folder: the reference table, bit for bit."""
    again = Sweep(out, tmp, "--no-progress")
    assert again.wait(120) == 0, again.err()
    if n_before:
        assert f"{n_before} done before" in again.stdout.read_text()
    assert_same_table(read_runs(out), reference)
    assert not list((out / "parts").iterdir())


def _saved(stderr: str, signame: str) -> int:
    """The saved-run count of the one-line interrupt message (its only line of that kind)."""
    lines = [line for line in stderr.splitlines() if line.startswith("quadimpact: interrupted")]
    assert len(lines) == 1, stderr
    head = f"quadimpact: interrupted by {signame}: "
    tail = "run the same command again to resume"
    assert lines[0].startswith(head) and lines[0].endswith(tail), lines[0]
    saved, _, rest = lines[0].removeprefix(head).partition(" of ")
    assert rest.startswith(f"{N_RUNS} runs saved in "), lines[0]
    return int(saved)


# ------------------------------------------------------------------ signals
def _interrupted(sweep: Sweep, signame: str, code: int, before: int) -> int:
    """The sweep ended with ``code`` within 5 s, saying what is saved (more than before)."""
    start = time.monotonic()
    assert sweep.wait(10) == code
    assert time.monotonic() - start < 5
    sweep.assert_all_gone()
    err = sweep.err()
    assert "Traceback" not in err and "Exception ignored" not in err, err
    saved = _saved(err, signame)
    assert before < saved < N_RUNS and _parts_rows(sweep.out) == saved
    assert f"{before} already done" in err if before else "already done" not in err
    return saved


@pytest.mark.slow
def test_signals_end_the_sweep_cleanly(tmp_path, tmpdir_env, reference):
    """One folder, stopped four times, then completed by a rerun (the reference table):

    one Ctrl-C; a burst of six 0.1-0.4 s apart (two used to hang it forever, with
    "Exception ignored in threading"); SIGTERM to the sweep alone (it used to leave its
    server and workers, and their pymp-* folders); kill -9 of the sweep alone, with a
    stopped worker. Each time the sweep and all its children are gone within seconds and
    what finished is saved."""
    out = tmp_path / "out"
    sweep = Sweep(out, tmpdir_env)
    sweep.wait_busy()
    os.killpg(sweep.proc.pid, signal.SIGINT)  # a terminal sends it to the group
    saved = _interrupted(sweep, "SIGINT", 130, 0)

    sweep = Sweep(out, tmpdir_env)
    sweep.wait_busy()
    for i in range(6):
        try:
            os.killpg(sweep.proc.pid, signal.SIGINT)
        except ProcessLookupError:
            break
        time.sleep(0.1 + 0.1 * (i % 4))
    saved = _interrupted(sweep, "SIGINT", 130, saved)

    sweep = Sweep(out, tmpdir_env)
    sweep.wait_busy()
    os.kill(sweep.proc.pid, signal.SIGTERM)
    saved = _interrupted(sweep, "SIGTERM", 128 + signal.SIGTERM, saved)

    sweep = Sweep(out, tmpdir_env)
    workers = sweep.wait_busy()
    workers[0].suspend()
    os.kill(sweep.proc.pid, signal.SIGKILL)
    assert sweep.wait(10) == -signal.SIGKILL
    sweep.assert_all_gone()
    _resume(out, tmpdir_env, reference, _parts_rows(out))


@pytest.mark.slow
def test_sigkill_and_resume(tmp_path, tmpdir_env, reference):
    """kill -9 of the whole group once a part is written; the rerun does only the rest.

    The workers are stopped (SIGSTOP) as soon as they are busy, so the sweep cannot
    end before its first part is written (within a second), however fast the machine.
    """
    sweep = Sweep(tmp_path / "out", tmpdir_env, "--no-progress")
    for worker in sweep.wait_busy():
        worker.suspend()
    parts = tmp_path / "out" / "parts"
    end = time.monotonic() + 30
    while not list(parts.glob("part-*.parquet")) and time.monotonic() < end:
        time.sleep(0.01)
    os.killpg(sweep.proc.pid, signal.SIGKILL)  # the CLI, its fork server and workers
    assert sweep.wait(10) == -signal.SIGKILL
    assert not (tmp_path / "out" / "runs.parquet").exists()
    n_rows = _parts_rows(tmp_path / "out")
    assert 0 < n_rows < N_RUNS
    _resume(tmp_path / "out", tmpdir_env, reference, n_rows)


# ------------------------------------------------------------ lost workers
def test_stopped_worker_times_out(tmp_path, tmpdir_env, reference):
    """A worker stopped (SIGSTOP) mid-run: after --timeout it is killed, its run redone."""
    sweep = Sweep(tmp_path / "out", tmpdir_env, "--timeout", "2")
    workers = sweep.wait_busy()
    workers[0].suspend()
    assert sweep.wait(60) == 0, sweep.err()
    err = sweep.err()
    stopped = f"sweep worker process {workers[0].pid} gave no result within 2 s"
    # stopped in a run (the usual case): that run (and the unfinished others of its group,
    # if any) is redone elsewhere; stopped in the instant between two chunks: the next
    # chunk, not begun, goes to another worker
    redone = ("the run is redone on another worker", "are each redone alone on another worker")
    assert (f"{stopped} in run" in err and any(r in err for r in redone)) or (
        f"{stopped} before it began its next runs; they go to another worker" in err
    ), err
    sweep.assert_all_gone()
    assert_same_table(read_runs(tmp_path / "out"), reference)


@pytest.mark.slow
def test_killed_fork_server(tmp_path, tmpdir_env, reference):
    """The workers die with their server; their runs are redone, the sweep completes."""
    sweep = Sweep(tmp_path / "out", tmpdir_env)
    workers = sweep.wait_busy()
    server = psutil.Process(_ppid(workers[0]))
    server.kill()
    assert sweep.wait(60) == 0, sweep.err()
    err = sweep.err()
    assert "Traceback" not in err and "error" not in err, err
    assert f"sweep worker process {workers[0].pid} died" in err
    sweep.assert_all_gone()
    assert_same_table(read_runs(tmp_path / "out"), reference)


HANG_SCRIPT = """
import time
from quadimpact.simulation import batch

real_prepare, real_run = batch.prepare, batch._run


def tagged(scenario, *args, **kwargs):  # imported again in each worker (forkserver/spawn)
    setup = real_prepare(scenario, *args, **kwargs)
    setup.hangs = scenario.inclination_deg == 7
    return setup


def hanging(setup, buffers):  # a run's compiled loop, as a sweep worker runs it
    if getattr(setup, "hangs", False):
        time.sleep(600)  # never returns in time, on any worker
    return real_run(setup, buffers)


batch.prepare, batch._run = tagged, hanging

if __name__ == "__main__":
    from quadimpact.sweep import SweepSpec, run_sweep

    spec = SweepSpec(base={"final_time_s": 1.0}, grid={"inclination_deg": "0:10:1"})
    run_sweep(spec, "out", workers=2, timeout=1.0)
"""


def test_run_that_times_out_twice_is_failed(tmp_path):
    (tmp_path / "hang.py").write_text(HANG_SCRIPT)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
    proc = subprocess.run(
        [sys.executable, "hang.py"], cwd=tmp_path, env=env, capture_output=True, text=True,
        timeout=120,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    table = read_runs(tmp_path / "out")
    assert list(table.loc[table["status"] == "failed", "inclination_deg"]) == [7.0]
    assert table.loc[7, "reason"] == "no result within 1 s, twice (--timeout 1 s)"
    assert len(table) == 11 and table["delta_init_m"].notna().sum() == 10
    assert proc.stderr.count("gave no result within 1 s in run 7") == 1, proc.stderr
    assert "run 7: no result within 1 s, twice (--timeout 1 s); recorded as failed" in proc.stderr


# --------------------------------------------------------------------- Dask
def _start(log: Path, tmp: Path, *args: str) -> subprocess.Popen:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
    with log.open("w") as out:
        return subprocess.Popen(
            [sys.executable, "-m", *args], cwd=tmp, env=env, stdout=out,
            stderr=subprocess.STDOUT, start_new_session=True,
            preexec_fn=sigint_as_on_a_terminal,
        )  # fmt: skip


def _wait_for_port(port: int, proc: subprocess.Popen, log: Path, limit_s: float = 60.0) -> None:
    """Wait until ``proc`` listens on 127.0.0.1:``port`` (a Dask scheduler takes a few seconds)."""
    end = time.monotonic() + limit_s
    while time.monotonic() < end:
        assert proc.poll() is None, log.read_text()
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=1.0):
                return
        except OSError:
            time.sleep(0.1)
    raise AssertionError(f"nothing listens on port {port} after {limit_s} s:\n{log.read_text()}")


def _group_cpu(proc: subprocess.Popen) -> float:
    try:
        root = psutil.Process(proc.pid)
        return sum(process_cpu_s(p) for p in [root, *root.children(recursive=True)])
    except psutil.Error:
        return 0.0


def _stop_group(proc: subprocess.Popen) -> None:
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    proc.wait(timeout=10)


@pytest.mark.slow
def test_dask_without_workers_says_so(tmp_path, tmpdir_env, reference):
    """Every Dask worker gone mid-sweep: it says what it waits for; Ctrl-C stops it cleanly,
    and with a worker back the rerun completes the reference table."""
    pytest.importorskip("distributed")
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    address = f"tcp://127.0.0.1:{port}"
    worker_args = ("distributed.cli.dask_worker", address, "--nworkers", "1", "--nthreads",
                   "1", "--no-dashboard", "--host", "127.0.0.1",
                   "--local-directory", str(tmp_path))  # fmt: skip
    scheduler = _start(tmp_path / "scheduler.log", tmp_path, "distributed.cli.dask_scheduler",
                       "--host", "127.0.0.1", "--port", str(port), "--no-dashboard")  # fmt: skip
    _wait_for_port(port, scheduler, tmp_path / "scheduler.log")  # the sweep checks it at once
    worker = _start(tmp_path / "worker.log", tmp_path, *worker_args)
    try:
        sweep = Sweep(tmp_path / "out", tmpdir_env, "--scheduler", address, workers=None)
        end = time.monotonic() + 90
        while "runs to do" not in sweep.err() and time.monotonic() < end:  # workers warm
            assert sweep.proc.poll() is None, sweep.err()
            time.sleep(0.02)
        idle = _group_cpu(worker)
        while _group_cpu(worker) < idle + 0.05 and time.monotonic() < end:  # running runs
            assert sweep.proc.poll() is None, sweep.err()
            time.sleep(0.02)
        _stop_group(worker)  # the nanny and its worker: no worker left
        end = time.monotonic() + 30
        while "waiting for Dask workers" not in sweep.err() and time.monotonic() < end:
            time.sleep(0.1)
        assert "quadimpact: waiting for Dask workers: none connected for 5 s" in sweep.err()
        os.killpg(sweep.proc.pid, signal.SIGINT)
        assert sweep.wait(15) == 130
        saved = _saved(sweep.err(), "SIGINT")
        worker = _start(tmp_path / "worker2.log", tmp_path, *worker_args)
        again = Sweep(tmp_path / "out", tmpdir_env, "--scheduler", address, workers=None)
        assert again.wait(120) == 0, again.err()
        assert f"{saved} done before" in again.stdout.read_text() or saved == 0
        assert_same_table(read_runs(tmp_path / "out"), reference)
    finally:
        _stop_group(worker)
        _stop_group(scheduler)
