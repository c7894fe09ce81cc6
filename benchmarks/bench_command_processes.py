"""Where a study command's time goes, process by process: CPU of each and the wall time.

Run: ``python benchmarks/bench_command_processes.py [--repeat 2] -- recovery --n 2000
--workers 2 [--no-example]`` (any ``quadimpact`` command; ``--out`` is added, a
temporary folder).

The command runs in a child process whose whole tree is polled every 20 ms
(``psutil``): each process's CPU time (user + system) as last seen, when it
was first and last seen, and its role: the command itself, the pool's fork
server, multiprocessing's resource tracker, the processes forked from the
server (the sweep's workers; the one that started ffmpeg is the recovery
study's example trial), ffmpeg. A process that ends between two polls loses at
most its last 20 ms. Where the command writes a table with
``cost__kernel_cpu_s`` (``trials.parquet`` or ``runs.parquet``), the sum of
the runs' compiled-loop CPU time is given too, and the wall time over half of
it (the measure of issue 21 on 2 cores) and the CPU of all processes over it.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import psutil


def _role(proc: dict[str, Any], server: int | None, ffmpeg_parents: set[int]) -> str:
    cmd = proc["cmd"]
    if proc["depth"] == 0:
        return "the command"
    if "resource_tracker" in cmd:
        return "resource tracker"
    if "forkserver" in cmd and proc["pid"] == server:
        return "the pool's fork server"
    if "ffmpeg" in cmd:
        return "ffmpeg"
    if proc["ppid"] == server:
        return "example trial" if proc["pid"] in ffmpeg_parents else "sweep worker"
    return "other"


def measure(args: list[str]) -> dict[str, Any]:
    """Run ``quadimpact ARGS --out TMP``; per-process CPU, wall time and the table's kernel sum."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out"
        command = [sys.executable, "-m", "quadimpact.cli", *args, "--out", str(out)]
        start = time.perf_counter()
        child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        root = psutil.Process(child.pid)
        seen: dict[int, dict[str, Any]] = {}
        while child.poll() is None:
            try:
                tree = [(root, 0)] + [(p, 1) for p in root.children(recursive=True)]
            except psutil.Error:
                break
            now = time.perf_counter() - start
            for p, depth in tree:
                try:
                    cpu = p.cpu_times()
                    if p.pid not in seen:
                        seen[p.pid] = {"pid": p.pid, "ppid": p.ppid(), "depth": depth,
                                       "cmd": " ".join(p.cmdline()), "first_s": now}  # fmt: skip
                    seen[p.pid]["cpu_s"] = cpu.user + cpu.system
                    seen[p.pid]["last_s"] = now
                except psutil.Error:
                    pass
            time.sleep(0.02)
        wall = time.perf_counter() - start
        err = child.stderr.read().decode(errors="replace") if child.stderr else ""
        if child.returncode != 0:
            raise RuntimeError(f"quadimpact {' '.join(args)} failed:\n{err[-2000:]}")
        kernel = None
        for name in ("trials.parquet", "runs.parquet"):
            if (out / name).is_file():
                import pyarrow.parquet as pq

                table = pq.read_table(out / name)
                if "cost__kernel_cpu_s" in table.column_names:
                    kernel = float(sum(v for v in table.column("cost__kernel_cpu_s").to_pylist()
                                       if v))  # fmt: skip
                break
    servers = [p["pid"] for p in seen.values() if "forkserver" in p["cmd"]]
    server = servers[0] if servers else None
    ffmpeg_parents = {p["ppid"] for p in seen.values() if "ffmpeg" in p["cmd"]}
    procs = sorted(seen.values(), key=lambda p: p["first_s"])
    for p in procs:
        p["role"] = _role(p, server, ffmpeg_parents)
    return {"wall_s": wall, "kernel_cpu_s": kernel, "processes": procs}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("command", nargs=argparse.REMAINDER, help="-- then the command's arguments")
    args = parser.parse_args(argv)
    command = [a for a in args.command if a != "--"] or ["recovery", "--n", "2000", "--workers",
                                                         "2", "--no-progress"]  # fmt: skip
    for k in range(args.repeat):
        r = measure(command)
        total = sum(p.get("cpu_s", 0.0) for p in r["processes"])
        print(f"quadimpact {' '.join(command)} (run {k + 1}): wall {r['wall_s']:.2f} s, "
              f"CPU of all processes {total:.2f} s")  # fmt: skip
        by_role: dict[str, list[float]] = {}
        for p in r["processes"]:
            by_role.setdefault(p["role"], []).append(p.get("cpu_s", 0.0))
            print(f"  {p['role']:<24} CPU {p.get('cpu_s', 0.0):6.2f} s, "
                  f"seen {p['first_s']:6.2f}-{p.get('last_s', p['first_s']):6.2f} s")  # fmt: skip
        kernel = r["kernel_cpu_s"]
        if kernel:
            ratio = r["wall_s"] / (kernel / 2)
            print(f"  the runs' compiled loops: {kernel:.2f} s of CPU; wall / (loops / 2) "
                  f"{ratio:.2f}, CPU / loops {total / kernel:.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
