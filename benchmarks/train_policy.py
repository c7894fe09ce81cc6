"""Train the learned recovery policy: a residual on the staged law, by evolution strategies.

Run: ``python benchmarks/train_policy.py --out DIR [--minutes 35] [--workers 2]``; then
``cp DIR/policy.npz src/quadimpact/inputs/policies/learned.npz`` to ship it
(docs/LEARNING.md 12 has how the shipped one was made and what it does).

The policy (``core/controllers/residual.py``) corrects the default law's
thrust and roll and pitch rate references after the detection from on-board
quantities only: the EKF's estimate under the ``impact`` sensors, the
accelerometer, the estimated rates, the detector's wall normal and time, the
law's stage. It starts as the law itself (output layer zero) and is trained
with antithetic evolution strategies (OpenAI-ES: Salimans et al. 2017):

* each generation draws a batch of training trials (2/3 wall, 1/3 pole) from
  held-out pools (``policy_trials.py``: wall seed 4747, the pole grid's
  half-degree, odd-half-centimetre points with sensors seeded 4748; never the
  benchmark's trials), flies ``2 x pairs`` perturbed policies
  ``theta +- sigma eps`` on all of them, and scores each by its mean reward:
  1 for a success (the studies' criterion) plus ``0.1 exp(-lost/1 m)`` of
  height kept, 0 for an invalid trial;
* the scores' centred ranks give the gradient estimate
  ``sum (r+ - r-) eps / (2 pairs sigma)``, followed with Adam;
* every ``--check-every`` generations the current policy flies a fixed check
  set (wall seed 4749, pole points with sensors seeded 4750), and the best on
  it is kept: ``DIR/policy.npz``.

Writes ``DIR/curve.csv`` (the learning curve: generation, runs, minutes, the
batch's mean score, the check set's success), ``DIR/train.json`` (the
settings, seeds, times, the law's and the best policy's check success) and
``DIR/policy.npz`` (with the same in its ``meta``). Every seed is fixed: the
same command gives the same policy on the same machine (up to the time limit:
``--generations`` instead of ``--minutes`` for an exact rerun).
"""

from __future__ import annotations

import argparse
import csv
import json
import multiprocessing as mp
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import policy_trials as PT  # noqa: E402

ES_SEED = 47
INIT_SEED = 47
CHECK_WALL_SEED = 4749
CHECK_POLE_SEED = 4750
N_TRAIN_WALL = 6000

_W: dict[str, Any] = {}


def _pools() -> dict[str, list[dict[str, Any]]]:
    return {
        "wall": PT.wall_dicts(N_TRAIN_WALL, PT.TRAIN_WALL_SEED),
        "pole": PT.grid_dicts("pole", True, PT.TRAIN_POLE_SEED),
    }


def _check_dicts(n_wall: int, n_pole: int) -> list[tuple[str, dict[str, Any]]]:
    wall = PT.wall_dicts(n_wall, CHECK_WALL_SEED)
    pole = PT.grid_dicts("pole", True, CHECK_POLE_SEED)
    pick = np.random.default_rng(CHECK_POLE_SEED).choice(len(pole), n_pole, replace=False)
    return [("wall", d) for d in wall] + [("pole", pole[int(i)]) for i in sorted(pick)]


def _init_worker(n_wall: int, n_pole: int) -> None:
    _W["pools"] = _pools()
    _W["check"] = _check_dicts(n_wall, n_pole)
    _W["flyer"] = PT.Flyer()


def _reward(trial: PT.Trial, summary: dict[str, Any]) -> tuple[float, bool, bool]:
    valid, ok, lost = PT.outcome(trial, summary)
    if not valid:
        return 0.0, False, False
    kept = 0.1 * float(np.exp(-max(lost, 0.0))) if np.isfinite(lost) else 0.0
    return (1.0 if ok else 0.0) + kept, ok, True


def _score(job: tuple[list[tuple[str, int]], list[np.ndarray]]) -> list[float]:
    """Mean reward of each block on the trials ``picks`` ((pool, index) pairs)."""
    picks, blocks = job
    trials = []
    for pool, i in picks:
        t = PT.prepare_trial(pool, i, _W["pools"][pool][i])
        if t is not None:
            trials.append(t)
    out = []
    for b in blocks:
        r = [_reward(t, _W["flyer"].fly(t, b))[0] for t in trials]
        out.append(float(np.mean(r)) if r else 0.0)
    return out


def _check(job: tuple[list[int], np.ndarray | None]) -> tuple[int, int]:
    """Successes and valid trials of ``block`` on the check trials ``indices``."""
    indices, block = job
    k = n = 0
    for i in indices:
        task, data = _W["check"][i]
        t = PT.prepare_trial(task, i, data)
        if t is None:
            continue
        _, ok, valid = _reward(t, _W["flyer"].fly(t, block))
        k += ok
        n += valid
    return k, n


def plot_curve(curve_csv: Path, png: Path) -> Path:
    """The learning curve as a figure: the batch's mean score per generation and the check
    set's success (the law's at generation 0), against training minutes."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import pandas as pd

    c = pd.read_csv(curve_csv)
    fig, ax = plt.subplots(figsize=(7.0, 3.6), constrained_layout=True)
    batch = c.dropna(subset=["batch_score"])
    label = "training batch: mean score, 1 a success + 0.1 exp(-lost/m) (10-gen. mean)"
    score = batch["batch_score"].rolling(10, min_periods=1).mean()
    ax.plot(batch["generation"], score, color="0.6", lw=1, label=label)
    check = c.dropna(subset=["check_success"])
    ax.plot(check["generation"], check["check_success"], "o-", color="C0", ms=3,
            label="check set (600 trials): success")  # fmt: skip
    ax.axhline(check["check_success"].iloc[0], color="C3", ls="--", lw=1,
               label="the staged law on the check set")  # fmt: skip
    ax.set_xlabel("generation (1,024 trials each)")
    ax.set_ylabel("share")
    ax.legend(fontsize=8, loc="lower right")
    ax.grid(alpha=0.3)
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return png


def main() -> None:
    from quadimpact.inputs.policy_file import initial_policy, save_policy

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--minutes", type=float, default=35.0, help="Training time limit.")
    ap.add_argument("--generations", type=int, default=0, help="Stop after this many (0: time).")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--batch", type=int, default=64, help="Training trials per generation.")
    ap.add_argument("--pairs", type=int, default=8, help="Antithetic pairs per generation.")
    ap.add_argument("--sigma", type=float, default=0.05)
    ap.add_argument("--lr", type=float, default=0.02)
    ap.add_argument("--hidden", type=int, default=16)
    ap.add_argument("--thrust-scale", type=float, default=0.3)
    ap.add_argument("--rate-scale", type=float, default=4.0, help="rad/s")
    ap.add_argument("--check", type=int, default=600, help="Check trials (2/3 wall).")
    ap.add_argument("--check-every", type=int, default=20)
    a = ap.parse_args()
    a.out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    n_cw = round(a.check * 2 / 3)
    n_cp = a.check - n_cw
    pol = initial_policy(a.hidden, a.thrust_scale, a.rate_scale, INIT_SEED)
    theta = pol.vector()
    rng = np.random.default_rng(ES_SEED)
    m = np.zeros_like(theta)
    v = np.zeros_like(theta)
    b1, b2, eps_adam = 0.9, 0.999, 1e-8
    _init_worker(n_cw, n_cp)  # here first: a pool restarts a worker whose initializer fails
    ctx = mp.get_context("spawn")
    pool = ctx.Pool(a.workers, initializer=_init_worker, initargs=(n_cw, n_cp))
    n_wall_pool, n_pole_pool = N_TRAIN_WALL, 45 * 70
    runs = 0

    def check(block: np.ndarray | None) -> float:
        nonlocal runs
        idx = list(range(a.check))
        parts = [idx[w :: a.workers] for w in range(a.workers)]
        res = pool.map(_check, [(p, block) for p in parts])
        runs += a.check
        k = sum(r[0] for r in res)
        n = sum(r[1] for r in res)
        return k / max(n, 1)

    curve_path = a.out / "curve.csv"
    with curve_path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["generation", "runs", "minutes", "batch_score", "check_success"])
        law = check(None)
        best, best_theta, best_gen = law, theta.copy(), 0
        w.writerow([0, runs, f"{(time.perf_counter() - started) / 60:.2f}", "", f"{law:.4f}"])
        print(f"law on the check set: {law:.4f}", flush=True)
        gen = 0
        while True:
            gen += 1
            n_w = round(a.batch * 2 / 3)
            picks = [("wall", int(i)) for i in rng.choice(n_wall_pool, n_w, replace=False)]
            picks += [
                ("pole", int(i)) for i in rng.choice(n_pole_pool, a.batch - n_w, replace=False)
            ]
            eps = rng.standard_normal((a.pairs, theta.size))
            cands = [pol.with_vector(theta + s * a.sigma * e).block()
                     for e in eps for s in (1.0, -1.0)]  # fmt: skip
            chunks = [cands[k :: a.workers] for k in range(a.workers)]
            res = pool.map(_score, [(picks, c) for c in chunks])
            scores = np.empty(len(cands))
            for k, r in enumerate(res):
                scores[k :: a.workers] = r
            runs += len(cands) * a.batch
            ranks = np.empty(len(scores))
            ranks[np.argsort(scores, kind="stable")] = np.arange(len(scores))
            ranks = ranks / (len(scores) - 1) - 0.5
            grad = ((ranks[0::2] - ranks[1::2])[:, None] * eps).sum(0) / (2 * a.pairs * a.sigma)
            m = b1 * m + (1 - b1) * grad
            v = b2 * v + (1 - b2) * grad * grad
            step = a.lr * (m / (1 - b1**gen)) / (np.sqrt(v / (1 - b2**gen)) + eps_adam)
            theta = theta + step
            minutes = (time.perf_counter() - started) / 60
            row = [gen, runs, f"{minutes:.2f}", f"{scores.mean():.4f}", ""]
            done = (a.generations and gen >= a.generations) or (
                not a.generations and minutes >= a.minutes
            )
            if gen % a.check_every == 0 or done:
                c = check(pol.with_vector(theta).block())
                row[1], row[4] = runs, f"{c:.4f}"
                if c > best:
                    best, best_theta, best_gen = c, theta.copy(), gen
                print(f"gen {gen} ({minutes:.1f} min, {runs} runs): check {c:.4f} "
                      f"(best {best:.4f} at {best_gen})", flush=True)  # fmt: skip
            w.writerow(row)
            fh.flush()
            if done:
                break
    pool.close()
    pool.join()
    minutes = (time.perf_counter() - started) / 60
    meta = {
        "method": "antithetic evolution strategies (centred ranks, Adam), residual on the "
        "default staged law",
        "script": "benchmarks/train_policy.py",
        "sensing": "impact sensors, ekf",
        "train_trials": {"wall_seed": PT.TRAIN_WALL_SEED, "wall_n": N_TRAIN_WALL,
                         "pole": "held-out grid (45 x 70)", "pole_sensor_seed": PT.TRAIN_POLE_SEED},
        "check_trials": {"wall_seed": CHECK_WALL_SEED, "wall_n": n_cw,
                         "pole_sensor_seed": CHECK_POLE_SEED, "pole_n": n_cp},
        "es_seed": ES_SEED, "init_seed": INIT_SEED, "batch": a.batch, "pairs": a.pairs,
        "sigma": a.sigma, "lr": a.lr, "hidden": a.hidden, "generations": gen,
        "best_generation": best_gen, "runs": runs, "minutes": round(minutes, 2),
        "check_success_law": law, "check_success_policy": best, "workers": a.workers,
    }  # fmt: skip
    save_policy(pol.with_vector(best_theta, **meta), a.out / "policy.npz")
    (a.out / "train.json").write_text(json.dumps(meta, indent=1) + "\n")
    plot_curve(curve_path, a.out / "curve.png")
    print(f"wrote {a.out / 'policy.npz'}: check {best:.4f} (law {law:.4f}), "
          f"{gen} generations, {runs} runs, {minutes:.1f} min", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
