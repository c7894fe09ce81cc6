"""A million-trial recovery study: its planning memory and how soon it shows progress.

Run: ``python benchmarks/bench_large_study.py [--n 1000000] [--seconds 20] [--workers 2]``

Starts ``quadimpact recovery --n N --allow-large`` into a temporary folder,
polls the memory (resident set) of the command and of every process it
starts every 50 ms for ``--seconds`` s, then stops it with SIGINT (the study
resumes from there) and reports:

* the command's largest resident memory while it planned and started the
  trials (target: under 200 MB for 10^6 trials: the trials are drawn when
  they run, never all at once);
* the time to its first line of progress on stderr (target: within a second
  of the command's own imports);
* how many trials were saved when it was stopped, and that no process
  outlived the command.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import psutil


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, default=1_000_000)
    p.add_argument("--seconds", type=float, default=20.0)
    p.add_argument("--workers", type=int, default=2)
    a = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "big"
        cmd = [sys.executable, "-m", "quadimpact.cli", "recovery", "--n", str(a.n),
               "--allow-large", "--no-example", "--workers", str(a.workers),
               "--out", str(out)]  # fmt: skip
        start = time.perf_counter()
        proc = subprocess.Popen(cmd, stderr=subprocess.PIPE)
        fd = proc.stderr.fileno()
        os.set_blocking(fd, False)
        me = psutil.Process(proc.pid)
        peak_cmd = peak_all = 0
        first_line = None
        lines: list[str] = []
        children: set[int] = set()
        while time.perf_counter() - start < a.seconds and proc.poll() is None:
            try:
                rss = me.memory_info().rss
                kids = me.children(recursive=True)
                children |= {k.pid for k in kids}
                total = rss + sum(_rss(k) for k in kids)
            except psutil.NoSuchProcess:
                break
            peak_cmd, peak_all = max(peak_cmd, rss), max(peak_all, total)
            try:
                chunk = os.read(fd, 1 << 16).decode(errors="replace")
            except BlockingIOError:
                chunk = ""
            if chunk:
                lines += chunk.splitlines()
                if first_line is None:
                    first_line = time.perf_counter() - start
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        _, tail = proc.communicate(timeout=120)
        lines += (tail or b"").decode(errors="replace").splitlines()
        gone_by = time.perf_counter() + 10.0  # processes ended by the command have gone by then
        alive = [pid for pid in children if psutil.pid_exists(pid)]
        while alive and time.perf_counter() < gone_by:
            time.sleep(0.1)
            alive = [pid for pid in alive if _running(pid)]
        print(
            f"trials                 {a.n:,} on {a.workers} workers, stopped after {a.seconds:g} s"
        )
        mb_cmd, mb_all = peak_cmd / 1e6, peak_all / 1e6
        print(f"command's memory peak  {mb_cmd:.0f} MB (with its workers {mb_all:.0f} MB)")
        print(f"first progress line    {first_line:.2f} s" if first_line else "no progress line")
        print(f"exit status            {proc.returncode}")
        print(f"last line              {lines[-1] if lines else ''}")
        print(f"processes left         {len(alive)} (10 s after the command ended)")


def _running(pid: int) -> bool:
    try:
        return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


def _rss(p: psutil.Process) -> int:
    try:
        return p.memory_info().rss
    except psutil.NoSuchProcess:
        return 0


if __name__ == "__main__":
    main()
