"""Train a recovery policy with PPO on the batched environment, then evaluate it.

Needs the ``rl`` and ``train`` extras and PyTorch (see docs/LEARNING.md section 9)::

    .venv/bin/python examples/train_recovery_ppo.py --out results/train-ppo
    .venv/bin/python examples/train_recovery_ppo.py --steps 200000 --eval 200   # a quick look

What it does:

1. Stable-Baselines3 PPO (MLP policy 128x128) on ``quadimpact/ImpactRecovery-v0``
   batched (64 trials stepped together in compiled code), for a fixed budget of
   environment steps (default 4,000,000: 10-15 minutes on this project's
   2-core machine, one PyTorch thread);
   detection start, collective thrust and body rates (``ctbr``), on-board
   observations (``imu``), the default reward; rewards normalised by
   ``VecNormalize``.
2. The learning curve (mean episode return and success rate per rollout) as
   ``learning_curve.png`` and ``learning_curve.csv``.
3. An evaluation on held-out trials of the authors' distribution (seeded): the
   learned policy (deterministic), the staged controller (``simulate`` of the
   same trials: the numbers ``quadimpact recovery`` reports), hover thrust and
   random actions. Success rate with its 95 % Wilson interval, median time to
   recover and height loss of the recovered trials: ``evaluation.md`` and
   ``evaluation.json``. The model is saved as ``ppo_recovery.zip``.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

import quadimpact.envs as E
from quadimpact.envs.sb3 import SB3BatchedEnv
from quadimpact.simulation.batch import simulate_batch

ENV_KWARGS = {"start": "detection", "action": "ctbr", "observe": "imu"}


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """95 % Wilson score interval of a binomial proportion k/n (docs/RECOVERY.md 8)."""
    if n == 0:
        return math.nan, math.nan
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return centre - half, centre + half


def summarise(name: str, rows: list[dict]) -> dict:
    """Success rate, its interval, and medians of the recovered trials."""
    n = len(rows)
    rec = [r for r in rows if r["recovered"]]
    lo, hi = wilson(len(rec), n)

    def median(key: str) -> float:
        v = [r[key] for r in rec if r[key] is not None]
        return float(np.median(v)) if v else math.nan

    return {
        "policy": name,
        "trials": n,
        "recovered": len(rec),
        "success_rate": len(rec) / n,
        "wilson_95": (lo, hi),
        "median_time_to_recover_s": median("time_to_recover_s"),
        "median_height_loss_m": median("height_loss_m"),
        "median_horizontal_drift_m": median("horizontal_drift_m"),
    }


def after_recovery(rows: list[dict]) -> dict:
    """Of the trials recovered when run to the final time: how many stay inside the envelope
    to the end, and their median speed there."""
    rec = [r for r in rows if r["recovered"]]
    kept = [r for r in rec if r["outcome"] == "time limit"]
    return {
        "recovered": len(rec),
        "inside_envelope_to_the_end": len(kept),
        "median_final_speed_m_s": float(np.median([r["final_speed_m_s"] for r in kept]))
        if kept
        else math.nan,
        "outcomes": {o: sum(r["outcome"] == o for r in rec) for o in {r["outcome"] for r in rec}},
    }


def evaluate_in_env(policy_fn, trials: list, n_envs: int = 50, **changes) -> list[dict]:
    """Episode metrics of a policy on the given trials (batched, no autoreset)."""
    kwargs = {**ENV_KWARGS, **changes}
    venv = E.BatchedImpactRecoveryEnv(n_envs, autoreset_mode="Disabled", **kwargs)
    act = policy_fn(venv)
    rows: list[dict] = []
    for i in range(0, len(trials), n_envs):
        chunk = trials[i : i + n_envs]
        chunk = chunk + [chunk[-1]] * (n_envs - len(chunk))
        obs, _ = venv.reset(options={"trials": chunk})
        ended: dict[int, dict] = {}
        while len(ended) < n_envs:
            obs, _, _, _, info = venv.step(act(obs))
            for k in np.flatnonzero(info.get("_metrics", [])):
                ended[int(k)] = {key: v[k] for key, v in info["metrics"].items()
                                 if not key.startswith("_")}  # fmt: skip
        rows += [ended[k] for k in range(min(n_envs, len(trials) - i))]
    return rows


class Curve:
    """SB3 callback: per rollout, the mean return and success rate of the episodes that ended."""

    def __init__(self) -> None:
        from stable_baselines3.common.callbacks import BaseCallback

        outer = self

        class _CB(BaseCallback):
            def _on_step(self) -> bool:
                for info, done in zip(self.locals["infos"], self.locals["dones"], strict=True):
                    if done and "metrics" in info:
                        outer._ret.append(float(info["metrics"]["episode_return"]))
                        outer._rec.append(bool(info["metrics"]["recovered"]))
                return True

            def _on_rollout_end(self) -> None:
                if outer._ret:
                    outer.rows.append({
                        "timesteps": int(self.num_timesteps),
                        "wall_s": time.perf_counter() - outer.t0,
                        "episodes": len(outer._ret),
                        "mean_return": float(np.mean(outer._ret)),
                        "success_rate": float(np.mean(outer._rec)),
                    })  # fmt: skip
                    outer._ret.clear()
                    outer._rec.clear()

        self.callback = _CB()
        self.rows: list[dict] = []
        self._ret: list[float] = []
        self._rec: list[bool] = []
        self.t0 = time.perf_counter()


def plot_curve(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = np.array([r["timesteps"] for r in rows]) / 1e6
    fig, (a, b) = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
    a.plot(t, [r["mean_return"] for r in rows], lw=1)
    a.set_ylabel("mean episode return")
    a.grid(alpha=0.3)
    b.plot(t, [100 * r["success_rate"] for r in rows], lw=1, color="C2")
    b.set_ylabel("recovered, % of episodes")
    b.set_xlabel("environment steps (millions; 1 step = 5 ms)")
    b.set_ylim(0, 100)
    b.grid(alpha=0.3)
    a.set_title("PPO on quadimpact/ImpactRecovery-v0 (ctbr, imu, 64 trials batched)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--out", default="results/train-ppo", help="output folder")
    ap.add_argument("--steps", type=int, default=4_000_000, help="environment steps to train")
    ap.add_argument("--envs", type=int, default=64, help="trials stepped together")
    ap.add_argument("--eval", type=int, default=500, help="held-out evaluation trials")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument(
        "--run-to-end",
        action="store_true",
        help="train without ending episodes at the recovery (end_on_recovery=False)",
    )
    ap.add_argument(
        "--load", default=None, help="evaluate a saved model (ppo_recovery.zip) instead of training"
    )
    ap.add_argument(
        "--threads",
        type=int,
        default=1,
        help="PyTorch threads (more than 1 is much slower on a busy 2-core machine)",
    )
    args = ap.parse_args()

    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    torch.set_num_threads(args.threads)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    if args.load:
        model = PPO.load(args.load, device="cpu")
        train_s = math.nan
        curve = Curve()
    else:
        env = SB3BatchedEnv(args.envs, **ENV_KWARGS, end_on_recovery=not args.run_to_end)
        env.seed(args.seed)
        venv = VecNormalize(env, norm_obs=False, norm_reward=True, gamma=0.995)
        model = PPO(
            "MlpPolicy", venv, n_steps=128, batch_size=2048, n_epochs=5, learning_rate=3e-4,
            gamma=0.995, gae_lambda=0.95, clip_range=0.2, ent_coef=0.0,
            policy_kwargs={"net_arch": [128, 128], "log_std_init": -0.5}, seed=args.seed,
            verbose=0, device="cpu",
        )  # fmt: skip
        curve = Curve()
        t0 = time.perf_counter()
        model.learn(total_timesteps=args.steps, callback=curve.callback)
        train_s = time.perf_counter() - t0
        model.save(out / "ppo_recovery.zip")
        plot_curve(curve.rows, out / "learning_curve.png")
        with open(out / "learning_curve.csv", "w") as f:
            f.write("timesteps,wall_s,episodes,mean_return,success_rate\n")
            for r in curve.rows:
                f.write(f"{r['timesteps']},{r['wall_s']:.1f},{r['episodes']},"
                        f"{r['mean_return']:.4f},{r['success_rate']:.4f}\n")  # fmt: skip

    # ---- evaluation on held-out trials (a different seed from training's)
    dist = E.TrialDistribution()
    rng = np.random.default_rng(10_000 + args.seed)
    trials = [dist.trial(dist.draw(rng), ground=False, record=False) for _ in range(args.eval)]
    t1 = time.perf_counter()

    def learned(v):
        return lambda obs: model.predict(obs, deterministic=True)[0]

    def staged_observed(v):
        # the staged controller's actions, judged by the observer as any policy is
        pol = E.RecoveryPolicy(v)

        def act(obs):
            a = pol(obs)
            v.report_stages(np.full(v.num_envs, -1.0))
            return a

        return act

    # after the recovery: the same trials run to the final time (no end on recovery)
    after = {
        "PPO (learned)": after_recovery(evaluate_in_env(learned, trials, end_on_recovery=False)),
        "staged controller (rotors)": after_recovery(evaluate_in_env(
            E.RecoveryPolicy, trials, action="rotors", end_on_recovery=False)),
    }  # fmt: skip
    table = [
        summarise("PPO (learned)", evaluate_in_env(learned, trials)),
        summarise("staged controller (simulate: its own stages)", simulate_batch(trials)),
        summarise(
            "staged controller through the env, judged by the observer (rotors)",
            evaluate_in_env(staged_observed, trials, action="rotors"),
        ),
        summarise(
            "hover speeds, no correction (rotors)",
            evaluate_in_env(E.HoverPolicy, trials, action="rotors"),
        ),
        summarise(
            "hover thrust, zero rate references (ctbr)", evaluate_in_env(E.HoverPolicy, trials)
        ),
        summarise(
            "random actions (ctbr)", evaluate_in_env(lambda v: E.RandomPolicy(v, seed=1), trials)
        ),
    ]
    eval_s = time.perf_counter() - t1
    result = {
        "train_steps": args.steps, "train_wall_s": train_s, "eval_wall_s": eval_s,
        "env": ENV_KWARGS, "n_envs": args.envs, "curve_last": curve.rows[-5:], "table": table,
        "model": args.load, "after_recovery": after, "run_to_end": args.run_to_end,
    }  # fmt: skip
    (out / "evaluation.json").write_text(json.dumps(result, indent=2))
    trained = (f"Training: {args.steps:,} steps in {train_s / 60:.1f} min "
               f"({args.steps / train_s:,.0f} steps/s, {args.envs} trials batched). "
               if not args.load else f"Model: {args.load}. ")  # fmt: skip
    lines = [
        trained + f"Evaluation: {args.eval} held-out trials of the authors' distribution "
        f"({eval_s:.0f} s).",
        "",
        "| policy | recovered | success rate (95 % Wilson) | median time to recover (s) "
        "| median height loss (m) |",
        "|---|---|---|---|---|",
    ]
    for r in table:
        lo, hi = r["wilson_95"]
        lines.append(
            f"| {r['policy']} | {r['recovered']}/{r['trials']} | {100 * r['success_rate']:.1f} % "
            f"({100 * lo:.1f}-{100 * hi:.1f}) | {r['median_time_to_recover_s']:.3f} "
            f"| {r['median_height_loss_m']:.3f} |"
        )
    lines += ["", "Run to the final time instead of ending at the recovery (the same trials):", "",
              "| policy | recovered | inside the envelope to 3 s | median speed at 3 s (m/s) |",
              "|---|---|---|---|"]  # fmt: skip
    for name, a in after.items():
        lines.append(f"| {name} | {a['recovered']} | {a['inside_envelope_to_the_end']} "
                     f"| {a['median_final_speed_m_s']:.2f} |")  # fmt: skip
    (out / "evaluation.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
