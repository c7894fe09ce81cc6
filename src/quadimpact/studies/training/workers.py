"""Flying a generation's trials: in this process or in a pool of spawned workers.

A job is a list of trials, the candidates' policy blocks (``None``: the law)
and the reward's terms; its answer is every block's reward and success on
every trial (:mod:`quadimpact.studies.training.flying`).
"""

from __future__ import annotations

import multiprocessing as mp
import signal
from typing import Any

import numpy as np

from quadimpact.studies.training.flying import Flyer, prepare_trial, rewards

__all__ = ["Evaluator", "fly_job"]

_WORKER: dict[str, Any] = {}


def _worker_init() -> None:
    """A pool worker: Ctrl-C is the parent's to handle (it stops the pool)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def fly_job(job: tuple[list[tuple[str, dict[str, Any]]], list[np.ndarray | None], tuple]) -> tuple:
    """Fly every block on every trial of ``job``: (rewards, successes), each (blocks, trials).

    The job's third part is the reward's terms, ``(shaping, drift_weight)``.
    """
    trials_data, blocks, (shaping, drift_weight) = job
    key = f"flyer-{drift_weight > 0}"
    flyer = _WORKER.get(key)
    if flyer is None:
        flyer = _WORKER[key] = Flyer(drift=drift_weight > 0)
    prepared = [prepare_trial(task, data) for task, data in trials_data]
    altitudes = [float(d.get("altitude_m", 5.0)) if p is None else p.altitude_m
                 for p, (_, d) in zip(prepared, trials_data, strict=True)]  # fmt: skip
    r = np.zeros((len(blocks), len(prepared)))
    s = np.zeros((len(blocks), len(prepared)), dtype=bool)
    for b, block in enumerate(blocks):
        summaries = [None if p is None else flyer.fly(p, block) for p in prepared]
        r[b], s[b] = rewards(summaries, altitudes, shaping, drift_weight)
    return r, s


class Evaluator:
    """Flies blocks on trials in this process (1 worker) or in a pool of spawned workers."""

    def __init__(self, workers: int, stop: Any) -> None:
        self.workers = max(1, int(workers))
        self.stop = stop
        self.pool = None
        if self.workers > 1:
            self.pool = mp.get_context("spawn").Pool(self.workers, initializer=_worker_init)

    def __call__(self, trials: list, blocks: list, terms: tuple[float, float]) -> tuple:
        if self.pool is None:
            return fly_job((trials, blocks, terms))
        parts = [trials[w :: self.workers] for w in range(self.workers)]
        jobs = [(p, blocks, terms) for p in parts if p]
        with self.stop.polled():
            pending = self.pool.map_async(fly_job, jobs)
            while not pending.ready():
                pending.wait(0.2)
                self.stop.check()
        res = pending.get()
        r = np.zeros((len(blocks), len(trials)))
        s = np.zeros((len(blocks), len(trials)), dtype=bool)
        for w, (rw, sw) in enumerate(res):
            r[:, w :: self.workers], s[:, w :: self.workers] = rw, sw
        return r, s

    def close(self, terminate: bool = False) -> None:
        if self.pool is not None:
            (self.pool.terminate if terminate else self.pool.close)()
            self.pool.join()
            self.pool = None
