"""Throughput of the impact-recovery environments against the compiled trials they step.

    .venv/bin/python benchmarks/bench_env.py [--trials 256] [--json PATH] [--no-rotorpy]

On the same impact trials (``--trials`` drawn from the authors' distribution,
seeded) it measures:

1. the reference: control ticks per second of the compiled recovery trials,
   ``simulate(ImpactTrial(...))``'s kernel (``summary["integrator"]``: ticks /
   kernel wall time), with simulate's default 1-kHz output and with the
   environments' output (start and end rows only);
2. the same ticks through the environments: each trial from t = 0 to its final
   time (``start="trial"``, ``rotor_floor="zero"``, ``end_on_recovery=False``,
   no envelope), driven by the staged controller's commands recorded once
   through ``RecoveryPolicy`` and replayed (so the policy's cost is not timed
   and the physics is the kernel's, contacts included; the replay is checked
   to give the recorded metrics). Environment steps per second and their
   ratio to (1): the single env (direct, and through ``gym.make``'s
   wrappers) and the batched env at N = 64 and 256, resets included;
3. default episodes (detection start, end on recovery) with ``RecoveryPolicy``
   acting live (its cost included): steps per second, single and batched;
4. for comparison, RotorPy's batched ``QuadrotorEnv`` (PyTorch, one thread;
   no contacts) at N = 1, 64 and 256 with random motor-speed actions, when it
   is installed.

Wall-clock times on a shared machine: compare within one run.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time

import gymnasium as gym
import numpy as np

import quadimpact.envs as E
from quadimpact import simulate
from quadimpact.core.kernel import BUILTIN
from quadimpact.core.records import new_output
from quadimpact.simulation.setup import prepare

SAME_TICKS = {
    "start": "trial",
    "rotor_floor": "zero",
    "end_on_recovery": False,
    "envelope": E.Envelope(180.0, 1e12, 1e12, 1e12),
}


PHYSICS_KEYS = ("min_altitude_m", "final_speed_m_s", "impacts_after_detection", "t_detect_s")


def draw_trials(n: int, seed: int) -> list:
    d = E.TrialDistribution()
    rng = np.random.default_rng(seed)
    return [d.trial(d.draw(rng), ground=False, record=True) for _ in range(n)]


def kernel_rate(trials: list) -> dict:
    """Ticks per second of simulate()'s kernel (1-kHz output) and of the kernel alone with
    the environments' output grid."""
    simulate(trials[0])
    ticks = wall = 0.0
    for t in trials:
        s = simulate(t).summary["integrator"]
        ticks += s["control_ticks"]
        wall += s["wall_time_s"]
    env_ticks = env_wall = 0.0
    d = E.TrialDistribution()
    from quadimpact.core import layout as L

    for t in trials:
        lean = d.trial(t.model_dump(include={"roll_deg", "pitch_deg", "yaw_deg", "speed_m_s",
                                             "seed"}), ground=False, record=False)  # fmt: skip
        m = prepare(lean).model()
        o = new_output(m, 0, 256)  # no IMU record, as the environments
        t0 = time.perf_counter()
        BUILTIN.run(m, o)
        env_wall += time.perf_counter() - t0
        env_ticks += o.stats[L.ST_N_TICKS]
    return {"ticks": ticks, "ticks_per_s": ticks / wall, "lean_ticks_per_s": env_ticks / env_wall}


def record_actions(trials: list) -> tuple[list[np.ndarray], list[dict]]:
    env = E.ImpactRecoveryEnv(**SAME_TICKS)
    pol = E.RecoveryPolicy(env)
    actions, metrics = [], []
    for t in trials:
        obs, _ = env.reset(options={"trial": t})
        a, done = [], False
        while not done:
            u = pol(obs)
            a.append(u)
            obs, _, term, trunc, info = env.step(u)
            done = term or trunc
        actions.append(np.array(a))
        metrics.append(info["metrics"])
    return actions, metrics


def replay_single(env, trials, actions, metrics) -> float:
    steps = 0
    t0 = time.perf_counter()
    for t, a in zip(trials, actions, strict=True):
        env.reset(options={"trial": t})
        for u in a:
            _, _, term, trunc, info = env.step(u)
        steps += len(a)
    wall = time.perf_counter() - t0
    assert term or trunc
    for key in PHYSICS_KEYS:  # the replay is the recorded run (stage times are the observer's)
        assert info["metrics"][key] == metrics[-1][key]
    return steps / wall


def replay_batched(n, trials, actions, metrics) -> float:
    venv = E.BatchedImpactRecoveryEnv(n, autoreset_mode="Disabled", **SAME_TICKS)
    lengths = {len(a) for a in actions}
    assert len(lengths) == 1, "same-ticks episodes all run to the final time"
    steps = 0
    t0 = time.perf_counter()
    for i in range(0, len(trials) - n + 1, n):
        venv.reset(options={"trials": trials[i : i + n]})
        acts = np.stack(actions[i : i + n], axis=1)
        for u in acts:
            _, _, term, trunc, info = venv.step(u)
        steps += acts.shape[0] * n
        for key in PHYSICS_KEYS:
            want = [m[key] for m in metrics[i : i + n]]
            assert list(info["metrics"][key]) == want, "the replay reproduces the recorded runs"
    return steps / (time.perf_counter() - t0)


def default_single(trials) -> float:
    env = E.ImpactRecoveryEnv()
    pol = E.RecoveryPolicy(env)
    steps = 0
    t0 = time.perf_counter()
    for t in trials:
        fields = {k: getattr(t, k) for k in ("roll_deg", "pitch_deg", "yaw_deg", "speed_m_s")}
        obs, _ = env.reset(options={"trial": fields})
        done = False
        while not done:
            obs, _, term, trunc, _ = env.step(pol(obs))
            steps += 1
            done = term or trunc
    return steps / (time.perf_counter() - t0)


def default_batched(n: int, steps: int) -> float:
    venv = E.BatchedImpactRecoveryEnv(n)
    pol = E.RecoveryPolicy(venv)
    obs, _ = venv.reset(seed=1)
    t0 = time.perf_counter()
    for _ in range(steps):
        obs, *_ = venv.step(pol(obs))
    return steps * n / (time.perf_counter() - t0)


def rotorpy_rates(sizes=(1, 64, 256), steps=300) -> dict:
    try:
        import torch
        from rotorpy.learning.quadrotor_environments import QuadrotorEnv
        from rotorpy.vehicles.crazyflie_params import quad_params
    except Exception as exc:  # not installed: say why
        return {"error": f"{type(exc).__name__}: {exc}"}
    torch.set_num_threads(1)
    out = {}
    for n in sizes:
        w = 1.0 * np.sqrt(quad_params["mass"] * 9.81 / (4 * quad_params["k_eta"]))
        init = {
            "x": torch.zeros(n, 3).double(), "v": torch.zeros(n, 3).double(),
            "q": torch.tensor([0, 0, 0, 1.0]).repeat(n, 1).double(),
            "w": torch.zeros(n, 3).double(), "wind": torch.zeros(n, 3).double(),
            "rotor_speeds": torch.full((n, 4), w).double(),
        }  # fmt: skip
        env = QuadrotorEnv(n, initial_states=init, control_mode="cmd_motor_speeds",
                           quad_params=dict(quad_params), sim_rate=200, max_time=3)  # fmt: skip
        env.reset()
        rng = np.random.default_rng(0)
        acts = rng.uniform(-1, 1, size=(steps, n, 4))
        env.step(acts[0])
        t0 = time.perf_counter()
        for a in acts:
            env.step(a)
        out[n] = steps * n / (time.perf_counter() - t0)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--trials", type=int, default=256)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--json", default=None)
    ap.add_argument("--no-rotorpy", action="store_true")
    args = ap.parse_args()
    print(f"# machine: {os.cpu_count()} CPUs, affinity {len(os.sched_getaffinity(0))}, "
          f"Python {platform.python_version()}, NumPy {np.__version__}, "
          f"Gymnasium {gym.__version__}")  # fmt: skip
    trials = draw_trials(args.trials, args.seed)
    ref = kernel_rate(trials)
    actions, metrics = record_actions(trials)
    rows = {}
    rows["single env (ImpactRecoveryEnv)"] = replay_single(
        E.ImpactRecoveryEnv(**SAME_TICKS), trials, actions, metrics
    )
    rows["single env via gym.make (wrappers)"] = replay_single(
        gym.make(E.ENV_ID, **SAME_TICKS), trials, actions, metrics
    )
    for n in (64, 256):
        if n <= len(trials):
            rows[f"batched env, N = {n}"] = replay_batched(n, trials, actions, metrics)
    live = {
        "single env, RecoveryPolicy live": default_single(trials[:64]),
        "batched env N = 64, RecoveryPolicy live": default_batched(64, 400),
        "batched env N = 256, RecoveryPolicy live": default_batched(256, 200),
    }
    rp = {} if args.no_rotorpy else rotorpy_rates()

    k = ref["ticks_per_s"]
    print(f"\nreference: simulate(ImpactTrial)'s kernel, {len(trials)} trials, {ref['ticks']:.0f} "
          f"ticks: {k:,.0f} ticks/s (1-kHz output); kernel with the envs' output grid: "
          f"{ref['lean_ticks_per_s']:,.0f} ticks/s")  # fmt: skip
    print("\n| same ticks (whole trials, replayed commands) | steps/s | ratio | ratio (lean) |")
    print("|---|---|---|---|")
    for name, v in rows.items():
        print(f"| {name} | {v:,.0f} | {v / k:.2f} | {v / ref['lean_ticks_per_s']:.2f} |")
    print("\n| default episodes (detection start, end on recovery) | steps/s | ratio |")
    print("|---|---|---|")
    for name, v in live.items():
        print(f"| {name} | {v:,.0f} | {v / k:.2f} |")
    if rp:
        print("\n| RotorPy QuadrotorEnv (torch, 1 thread, random motor speeds) | steps/s | ratio |")
        print("|---|---|---|")
        if "error" in rp:
            print(f"| not measured: {rp['error']} | | |")
        else:
            for n, v in rp.items():
                print(f"| N = {n} | {v:,.0f} | {v / k:.2f} |")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"reference": ref, "same_ticks": rows, "default": live,
                       "rotorpy": {str(a): b for a, b in rp.items()}}, f, indent=2)  # fmt: skip


if __name__ == "__main__":
    main()
