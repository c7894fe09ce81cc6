"""A recovery study on a Dask cluster: trials/s per core, memory over time, resume, same table.

Run: ``python benchmarks/bench_dask_recovery.py [--n 5000] [--workers 2] [--stop-at 0.4]
[--check 200] [--json PATH]``

The recipe of docs/RECOVERY.md ("A million trials on a Dask cluster") at a size
that fits a small machine, on a ``distributed.LocalCluster`` of ``--workers``
single-threaded worker processes started here:

1. **Interrupted**: the study's trials (``quadimpact.studies.recovery.recovery_study.run_trials``
   with ``scheduler=``) run in a child process that gets SIGINT once
   ``--stop-at`` of the trials are in the sweep's parts (as Ctrl-C would);
2. **Resumed**: the same call again, in this process, to the end: it must
   find the finished trials and run only the rest;
3. **The same table**: the first ``--check`` trials of the study (trial ``i``
   depends on the seed and ``i`` only) are run again on one core
   (``workers=1``), and their rows must equal the Dask table's bit for bit
   (cost columns aside).

Every second the resident memory (RSS) of this process (the client) and of
each Dask worker process is sampled; the report gives it at each tenth of the
resumed pass (flat memory: no growth with the trials done), the trials/s of
the resumed pass per worker core, and the client's RSS per trial of the study.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import psutil

CHILD = r"""
import sys
from dask.distributed import Client
from quadimpact.studies.recovery.recovery_study import RecoveryStudy, run_trials
from quadimpact.sweep import SweepInterrupted
address, n, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
client = Client(address)
try:
    run_trials(RecoveryStudy(n=n), out, scheduler=client)
except (SweepInterrupted, KeyboardInterrupt, SystemExit) as exc:
    print("stopped:", type(exc).__name__)
"""


def rss_mb(pid: int) -> float:
    try:
        return psutil.Process(pid).memory_info().rss / 2**20
    except psutil.Error:
        return float("nan")


class Sampler(threading.Thread):
    """RSS of the client and of the workers (MB), and the trials in the sweep's parts."""

    def __init__(self, worker_pids: list[int], parts: Path, log: Path | None = None) -> None:
        super().__init__(daemon=True)
        self.worker_pids = worker_pids
        self.parts = parts
        self.log = log
        self.samples: list[dict] = []
        self.stop = threading.Event()

    def run(self) -> None:
        t0 = time.perf_counter()
        while not self.stop.wait(1.0):
            sample = {
                "t_s": time.perf_counter() - t0,
                "client_mb": rss_mb(os.getpid()),
                "workers_mb": [rss_mb(p) for p in self.worker_pids],
                "parts_rows": parts_rows(self.parts),
            }
            self.samples.append(sample)
            if self.log is not None:  # as it goes: a long run stopped early keeps its record
                with self.log.open("a", encoding="utf-8") as f:
                    f.write(json.dumps(sample) + "\n")


def _sigint_default() -> None:
    """In the child before it runs: Ctrl-C's default action, as on a terminal (a benchmark
    started in the background, ``cmd &`` or ``nohup``, ignores SIGINT, and so would the
    child, which Python keeps: the study would then never stop)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


_PART_ROWS: dict[str, int] = {}  # part name -> rows (a part is written once, atomically)


def parts_rows(parts: Path) -> int:
    """Trials in the sweep's parts; each part's metadata read once (a 10^6-trial study
    writes thousands of parts: reading them all every second would load the client)."""
    import pyarrow.parquet as pq

    total = 0
    if parts.is_dir():
        for p in parts.glob("part-*.parquet"):
            rows = _PART_ROWS.get(p.name)
            if rows is None:
                try:
                    rows = _PART_ROWS[p.name] = pq.read_metadata(p).num_rows
                except Exception:
                    rows = 0
            total += rows
    return total


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=5000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--stop-at", type=float, default=0.4)
    parser.add_argument("--check", type=int, default=200)
    parser.add_argument("--json", type=Path)
    parser.add_argument(
        "--samples",
        type=Path,
        help="Append each memory sample to this JSON-lines file as it is taken.",
    )
    args = parser.parse_args(argv)

    import pandas as pd
    from dask.distributed import Client, LocalCluster

    from quadimpact.studies.recovery.recovery_study import (
        SWEEP_DIR,
        TRIALS_PARQUET,
        RecoveryStudy,
        run_trials,
    )
    from quadimpact.sweep import without_costs

    report: dict = {"n": args.n, "workers": args.workers, "cpu_count": os.cpu_count(),
                    "load_average_start": os.getloadavg()}  # fmt: skip
    with (
        tempfile.TemporaryDirectory() as tmp,
        LocalCluster(
            n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        Client(cluster) as client,
    ):
        out = Path(tmp) / "study"
        parts = out / SWEEP_DIR / "parts"
        worker_pids = list(client.run(os.getpid).values())
        client.run(lambda: __import__("quadimpact.sweep.worker").sweep.worker.warm_up())

        # 1. interrupted: a child process, SIGINT once --stop-at of the trials are done
        env = dict(os.environ)
        child = subprocess.Popen(
            [sys.executable, "-c", CHILD, cluster.scheduler_address, str(args.n), str(out)],
            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
            preexec_fn=_sigint_default,
        )  # fmt: skip
        t0 = time.perf_counter()
        while child.poll() is None and parts_rows(parts) < args.stop_at * args.n:
            time.sleep(0.5)
        child.send_signal(signal.SIGINT)
        stdout, stderr = child.communicate(timeout=300)
        done_before = parts_rows(parts)
        report["interrupted"] = {"after_s": time.perf_counter() - t0, "rows_kept": done_before,
                                 "returncode": child.returncode,
                                 "stderr_tail": stderr.strip().splitlines()[-2:]}  # fmt: skip
        print(f"interrupted after {report['interrupted']['after_s']:.1f} s with "
              f"{done_before} trials kept", flush=True)  # fmt: skip

        # 2. resumed here, memory sampled
        sampler = Sampler(worker_pids, parts, args.samples)
        sampler.start()
        t = time.perf_counter()
        cpu = time.process_time()
        _spec, table, info = run_trials(RecoveryStudy(n=args.n), out, scheduler=client)
        wall = time.perf_counter() - t
        client_cpu = time.process_time() - cpu
        sampler.stop.set()
        sampler.join()
        report["resumed"] = {
            "wall_s": wall, "client_cpu_s": client_cpu, "n_already_done": info["n_already_done"],
            "n_ran": info["n_ran"], "backend": info["backend"],
            "trials_per_s": info["n_ran"] / wall,
            "trials_per_s_per_core": info["n_ran"] / wall / args.workers,
            "kernel_cpu_s_per_trial": float(table["cost__kernel_cpu_s"].mean()),
            "total_cpu_s_per_trial": float(table["cost__total_cpu_s"].mean()),
        }  # fmt: skip
        assert info["n_already_done"] >= done_before > 0, (
            f"the resumed pass found {info['n_already_done']} trials done, {done_before} kept; "
            f"child: {stdout[-2000:]} {stderr[-2000:]}"
        )
        assert len(table) == args.n and table["run_id"].tolist() == list(range(args.n))
        # each tenth of the study by run_id: the loop's and the whole trial's CPU per trial
        # (a rate that changes over a long pass: the trials' own cost, or the machine?)
        tenth = (table["run_id"] * 10 // args.n).rename("tenth")
        costs = table.groupby(tenth)[["cost__kernel_cpu_s", "cost__total_cpu_s"]].mean()
        report["cost_by_tenth_ms"] = [
            {"tenth": int(k), "kernel": 1e3 * float(r.iloc[0]), "total": 1e3 * float(r.iloc[1])}
            for k, r in costs.iterrows()
        ]
        s = sampler.samples
        picks = [s[min(len(s) - 1, int(k * len(s) / 10))] for k in range(11)] if s else []
        report["memory"] = picks
        report["client_mb_per_trial_of_study"] = (
            (max(x["client_mb"] for x in s) - s[0]["client_mb"]) / args.n if s else None
        )

        # 3. the same table on one core (the first --check trials)
        check = min(args.check, args.n)
        with tempfile.TemporaryDirectory() as tmp1:
            _s, one, _i = run_trials(RecoveryStudy(n=check), Path(tmp1) / "one", workers=1)
        dask_rows = pd.read_parquet(out / TRIALS_PARQUET).iloc[:check].reset_index(drop=True)
        # the bins' labels, not their category lists: a study's bins span the range of
        # its own trials, so a study of fewer trials may have fewer bins
        pd.testing.assert_frame_equal(
            without_costs(dask_rows),
            without_costs(one.reset_index(drop=True)),
            check_categorical=False,
        )
        report["same_table_first_trials"] = check

    r = report["resumed"]
    print(f"resumed: {r['n_ran']} trials in {r['wall_s']:.1f} s ({r['n_already_done']} done "
          f"before): {r['trials_per_s_per_core']:.1f} trials/s per core; kernel "
          f"{1e3 * r['kernel_cpu_s_per_trial']:.1f} ms, whole trial "
          f"{1e3 * r['total_cpu_s_per_trial']:.1f} ms CPU each")  # fmt: skip
    print("memory (MB) over the resumed pass: t_s, trials in parts, client, workers")
    for x in report["memory"]:
        workers = ", ".join(f"{w:.0f}" for w in x["workers_mb"])
        print(f"  {x['t_s']:6.1f} {x['parts_rows']:8d} {x['client_mb']:8.0f}   {workers}")
    print("CPU per trial (ms) by tenth of the study: loop / whole trial")
    for x in report["cost_by_tenth_ms"]:
        print(f"  {x['tenth']}: {x['kernel']:.2f} / {x['total']:.2f}")
    print(f"the first {check} trials: the same rows on one core (bit for bit, costs aside)")
    if args.json:
        args.json.write_text(json.dumps(report, indent=1, default=str))


if __name__ == "__main__":
    main()
