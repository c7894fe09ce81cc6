"""A study's independent tasks on local processes: results in task order, errors raised
here, a stop signal or an error kills every worker at once."""

from __future__ import annotations

import os
import signal
import threading
import time
from pathlib import Path

import psutil
import pytest

from quadimpact.sweep import SweepInterrupted
from quadimpact.sweep.tasks import run_tasks


def _square_later(k: int, delay_s: float) -> tuple[int, int]:
    time.sleep(delay_s)
    return k * k, os.getpid()


def _fail_on(k: int, bad: int) -> int:
    if k == bad:
        raise ValueError(f"task {k} fails")
    time.sleep(0.05)
    return k


def _note_and_sleep(folder: str, k: int) -> int:
    Path(folder, f"{k}.pid").write_text(str(os.getpid()))
    time.sleep(60)
    return k


def _gone(pids: list[int], within_s: float = 5.0) -> bool:
    end = time.monotonic() + within_s
    while time.monotonic() < end:
        alive = []
        for pid in pids:
            try:
                if psutil.Process(pid).status() != psutil.STATUS_ZOMBIE:
                    alive.append(pid)
            except psutil.NoSuchProcess:
                pass
        if not alive:
            return True
        time.sleep(0.05)
    return False


def test_results_come_in_task_order_whatever_finishes_first():
    # the first task takes long: the other process does all the others meanwhile
    tasks = [(k, 2.0 if k == 0 else 0.01) for k in range(6)]
    finished: list[int] = []
    got = run_tasks(_square_later, tasks, 2, lambda i, _r: finished.append(i))
    assert [r[0] for r in got] == [k * k for k in range(6)]
    assert finished == [1, 2, 3, 4, 5, 0]
    assert len({r[1] for r in got}) == 2 and os.getpid() not in {r[1] for r in got}
    assert _gone([r[1] for r in got])  # the workers end with the call
    here = run_tasks(_square_later, tasks, 1)  # one process: here, in order
    assert [r[0] for r in here] == [r[0] for r in got] and {r[1] for r in here} == {os.getpid()}


def test_an_error_in_a_task_is_raised_here_and_stops_the_others():
    with pytest.raises(ValueError, match="task 3 fails"):
        run_tasks(_fail_on, [(k, 3) for k in range(40)], 2)


def _interrupt_when_running(folder: Path, n: int, sent: list[float]) -> None:
    """Send this process SIGINT once ``n`` tasks have noted their pid (not at a fixed time:
    on a loaded machine the workers may take seconds to start); note when."""
    end = time.monotonic() + 120.0
    while len(list(folder.glob("*.pid"))) < n and time.monotonic() < end:
        time.sleep(0.02)
    sent.append(time.monotonic())
    os.kill(os.getpid(), signal.SIGINT)


def test_a_stop_signal_kills_the_workers_at_once(tmp_path, python_sigint):
    sent: list[float] = []
    watcher = threading.Thread(
        target=_interrupt_when_running, args=(tmp_path, 2, sent), daemon=True
    )
    watcher.start()
    with pytest.raises(SweepInterrupted):
        run_tasks(_note_and_sleep, [(str(tmp_path), k) for k in range(4)], 2)
    assert time.monotonic() - sent[0] < 10.0  # at once, not after the tasks' 60 s
    watcher.join()
    pids = [int(p.read_text()) for p in tmp_path.glob("*.pid")]
    assert len(pids) == 2  # two were running, the other two never started
    assert _gone(pids)
