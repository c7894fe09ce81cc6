"""``quadimpact train``: a residual recovery policy trained by CMA-ES, resumable, to a folder.

The policy is the residual network of ``core/controllers/residual.py`` on the
default staged law (docs/LEARNING.md 12 and 14): its weights, a few hundred
numbers, are the optimiser's parameters. They are trained by CMA-ES (the
``cma`` package, Hansen's reference implementation), because

* the reward is episodic and black-box: the benchmark's success of whole
  trials flown in the compiled loop, with no gradient through contacts,
  estimators and stage switches;
* a few hundred parameters are where CMA-ES works well (its covariance is
  a few hundred squared numbers), on a CPU, in minutes;
* its whole state pickles, so an interrupted run resumes where it stopped.

Each generation CMA-ES proposes ``popsize`` candidate weight vectors; each
flies the same ``batch`` fresh training trials (the problem's tasks in turn,
:mod:`quadimpact.studies.training.trials`: never the benchmark's; the law
flies them too, the curve's yardstick) and scores the mean reward
(:func:`quadimpact.studies.training.flying.rewards`: the benchmark's success
plus a little height kept). Every ``check_every``
generations the distribution's mean flies a fixed check set (other trials of
the same problem), and the best on it is the policy written.

With ``contested`` N (``--contested N``), N trials of a third stream are
screened first (:func:`_screen`): the law, the start and ``popsize`` draws
around the start fly them, and the trials on which their successes differ
are kept. The batches then cycle through those, in a fixed order. Most fresh
trials are won, or lost, by every candidate alike and cannot rank them; the
kept ones can, so a batch of the same size carries several times the signal.
The check set stays fresh trials of the whole problem, so the policy kept
is judged on what it is trained for, not on the screened trials.

The folder ``DIR``:

* ``state.pkl``: the optimiser's state after the last whole generation (the
  CMA-ES object, NumPy's global generator, which ``cma`` draws from, the
  curve, the best weights); written atomically after every generation;
* ``curve.csv`` and ``curve.png``: the learning curve;
* ``policy.npz``: the best policy (docs/LEARNING.md 12's file, with
  ``last_stage`` and how it was trained in its ``meta``);
* ``train.json``: the problem, the settings, the times, the result.

Run the same command with the same ``DIR`` to resume after an interrupt: the
problem and the settings must be the same (the budget may change). The
trials of a generation depend on its number alone, and the optimiser's draws
on its saved state, so a resumed run continues the same sequence.
"""

from __future__ import annotations

import contextlib
import json
import math
import pickle
import time
from collections.abc import Iterator
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from quadimpact.errors import InputError
from quadimpact.results.files import atomic_write
from quadimpact.studies.training.curve import Progress, plot_curve, progress_bar, write_curve
from quadimpact.studies.training.settings import Settings, TrainingResult
from quadimpact.studies.training.trials import (
    PURPOSE_CHECK,
    PURPOSE_SCREEN,
    PURPOSE_TRAIN,
    Problem,
)
from quadimpact.studies.training.workers import Evaluator

__all__ = ["STATE_FILE", "Settings", "TrainingResult", "candidate_scores", "load_state", "train"]

STATE_FILE = "state.pkl"
STATE_VERSION = 1
#: The files a training folder holds (a folder with others is refused for a new run).
OWN_FILES = ("state.pkl", "policy.npz", "curve.csv", "curve.png", "train.json", "train.lock")


# ------------------------------------------------------------------ state
def load_state(out: Path) -> dict[str, Any] | None:
    """The saved state of the training run in ``out`` (None: none there).

    Raises InputError for a file that is not a training state of this version.
    """
    path = Path(out) / STATE_FILE
    if not path.is_file():
        return None
    try:
        state = pickle.loads(path.read_bytes())
    except Exception as exc:  # noqa: BLE001 - any unreadable state is the same user error
        raise InputError(f"--out {out}: {STATE_FILE} is not readable ({type(exc).__name__}); "
                         "remove it to start again") from None  # fmt: skip
    if not isinstance(state, dict) or state.get("version") != STATE_VERSION:
        raise InputError(f"--out {out}: {STATE_FILE} is not a training state of this version; "
                         "remove it to start again")  # fmt: skip
    return state


def _save_state(out: Path, state: dict[str, Any]) -> None:
    data = pickle.dumps(state, protocol=pickle.HIGHEST_PROTOCOL)
    atomic_write(out / STATE_FILE, lambda tmp: tmp.write_bytes(data))


def _new_state(problem: Problem, settings: Settings) -> dict[str, Any]:
    import cma

    from quadimpact.inputs.policy_file import initial_policy

    pol = initial_policy(settings.hidden, settings.thrust_scale, settings.rate_scale_rad_s,
                         problem.seed, settings.last_stage,
                         settings.hover_centred)  # fmt: skip
    if settings.init is not None:
        pol = _initial_weights(pol, settings.init)
    if settings.hover_fade_s != (0.0, 0.0):
        pol = pol.with_fade(*settings.hover_fade_s)
    if settings.hover_hand_over:
        pol = pol.with_hand_over()
    opts = {"seed": problem.seed, "popsize": settings.popsize, "verbose": -9}
    es = cma.CMAEvolutionStrategy(pol.vector(), settings.sigma, opts)
    return {
        "version": STATE_VERSION,
        "problem": problem.describe(),
        "settings": asdict(settings),
        "cma_version": cma.__version__,
        "es": es,
        "np_random": np.random.get_state(),  # noqa: NPY002 - cma draws from the legacy global
        "policy": pol,
        "generation": 0,
        "runs": 0,
        "minutes": 0.0,
        "curve": [],
        "law_check": None,
        "best": None,  # (success, score, generation, theta)
        "contested": None,  # the screened trials kept (--contested): their indices
        "sessions": [],
    }


def _initial_weights(pol: Any, init: str) -> Any:
    """``pol`` with the weights of policy ``init``, whose shape and scales must be ``pol``'s."""
    from quadimpact.inputs.policy_file import load_policy

    start = load_policy(init)
    for name, have, want in (
        ("hidden", start.hidden, pol.hidden),
        ("thrust-scale", start.thrust_scale, pol.thrust_scale),
        ("rate-scale", start.rate_scale_rad_s, pol.rate_scale_rad_s),
        ("stages", start.last_stage, pol.last_stage),
    ):
        if have != want:
            raise InputError(f"--init {init}: its {name} is {have}, the run's {want}; "
                             f"give --{name} to match it")  # fmt: skip
    return pol.with_vector(start.vector())


def init_settings(settings: Settings) -> Settings:
    """``settings`` with its ``init`` policy's digest filled in (none: unchanged)."""
    from dataclasses import replace

    from quadimpact.inputs.policy_file import checked_policy

    if settings.init is None:
        return settings
    ref, sha = checked_policy(settings.init)
    return replace(settings, init=ref, init_sha256=sha)


def _same_run(state: dict[str, Any], problem: Problem, settings: Settings, out: Path) -> None:
    """Refuse to resume a run of another problem or other settings (one line naming them)."""
    want = {**problem.describe(), **asdict(settings)}
    # a setting added since the state was written reads as its default
    have = {**asdict(Settings()), **state["problem"], **state["settings"]}
    diff = [k for k in want if want[k] != have.get(k)]
    if diff:
        what = ", ".join(f"{k} {have.get(k)!r} (now {want[k]!r})" for k in diff)
        raise InputError(f"--out {out}: holds a training run with other settings: {what}; "
                         "give the same settings to resume it, or another --out")  # fmt: skip


# ------------------------------------------------------------------ training
def train(
    problem: Problem,
    settings: Settings,
    out: Path,
    minutes: float | None = 10.0,
    generations: int | None = None,
    workers: int = 1,
    progress: bool = True,
    stream: Any = None,
) -> TrainingResult:
    """Train (or resume training) a policy into ``out`` (module docstring).

    ``minutes``: the run's training time in all, resumes included (None: no
    limit); ``generations``: stop after this many in all (None: no limit).
    At least one must be given. Ctrl-C or SIGTERM stops it after saving what
    the last whole generation reached (``policy.npz`` included) and raises
    :class:`quadimpact.sweep.SweepInterrupted` with how to resume.
    """
    if minutes is None and generations is None:
        raise InputError("--minutes or --generations: give a budget")
    if minutes is not None and not (math.isfinite(minutes) and minutes > 0):
        raise InputError(f"--minutes: must be > 0 (got {minutes})")
    if generations is not None and generations < 1:
        raise InputError(f"--generations: must be >= 1 (got {generations})")
    settings = init_settings(settings)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with _folder_lock(out):
        return _train(problem, settings, out, minutes, generations, workers, progress, stream)


@contextlib.contextmanager
def _folder_lock(out: Path) -> Iterator[None]:
    """One training run at a time in a folder (``train.lock``, an advisory lock; none where
    the system has no ``fcntl``)."""
    try:
        import fcntl
    except ImportError:  # not on this system: no lock
        yield
        return
    with open(out / "train.lock", "a") as fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise InputError(f"--out {out}: another quadimpact train is running in it") from None
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def _train(problem, settings, out, minutes, generations, workers, progress, stream):
    """:func:`train` in its folder, locked."""
    from quadimpact.sweep import SweepInterrupted
    from quadimpact.sweep.interrupt import stop_signals

    state = load_state(out)
    if state is None:
        others = sorted(p.name for p in out.iterdir() if p.name not in OWN_FILES)
        if others:
            raise InputError(f"--out {out}: holds files that are not a training run's "
                             f"({', '.join(others[:3])}); give an empty or new folder")  # fmt: skip
        state = _new_state(problem, settings)
    else:
        _same_run(state, problem, settings, out)
    resumed_from = int(state["generation"])
    np.random.set_state(state["np_random"])  # noqa: NPY002 - cma draws from it
    bar = Progress(progress, stream)
    session_start = time.perf_counter()
    spent_before = float(state["minutes"])
    state["sessions"].append({"from_generation": resumed_from, "workers": int(workers)})

    def elapsed() -> float:
        return spent_before + (time.perf_counter() - session_start) / 60.0

    def budget_left() -> bool:
        if generations is not None and state["generation"] >= generations:
            return False
        return not (minutes is not None and elapsed() >= minutes)

    check_trials = problem.batch(PURPOSE_CHECK, 0, settings.check)
    finished = False
    with stop_signals(restore_after_stop=False) as stop:
        evaluate = Evaluator(workers, stop)
        try:
            if state["law_check"] is None:
                # the law, and the start's weights when they are not the law's (--init)
                theta0 = np.array(state["es"].mean, dtype=float)
                blocks = [None]
                if settings.init is not None:
                    blocks.append(state["policy"].with_vector(theta0).block())
                r, s = evaluate(check_trials, blocks, _terms(settings))
                state["runs"] += len(blocks) * len(check_trials)
                state["law_check"] = (float(s[0].mean()), float(r[0].mean()))
                state["best"] = (float(s[-1].mean()), float(r[-1].mean()), 0, theta0)
                state["curve"].append({"generation": 0, "runs": state["runs"],
                                       "minutes": elapsed(),
                                       "check_success": state["law_check"][0],
                                       "check_score": state["law_check"][1]})  # fmt: skip
                state["minutes"] = elapsed()
                state["np_random"] = np.random.get_state()  # noqa: NPY002
                _save_state(out, state)
            if settings.contested and state.get("contested") is None:
                _screen(state, problem, settings, evaluate)
                state["minutes"] = elapsed()
                _save_state(out, state)
            while budget_left():
                _generation(state, problem, settings, evaluate, check_trials, elapsed)
                state["minutes"] = elapsed()
                state["np_random"] = np.random.get_state()  # noqa: NPY002
                _save_state(out, state)
                write_curve(out, state["curve"])
                _show(bar, state, minutes, generations)
            if state["curve"] and state["curve"][-1].get("check_success") is None:
                _check(state, problem, settings, evaluate, check_trials)
                state["minutes"] = elapsed()
                _save_state(out, state)
            finished = True
        except SweepInterrupted as exc:
            evaluate.close(terminate=True)
            bar.end()
            saved = load_state(out)  # the last whole generation, not the one cut short
            if saved is None:
                exc.args = ("training interrupted before its first generation; nothing saved",)
                raise
            result = _finish(out, saved, problem, settings, False, resumed_from)
            exc.args = (
                f"training interrupted at generation {result.generations} ({result.runs} runs, "
                f"{result.minutes:.1f} min): the state of the last whole generation is in "
                f"{out / STATE_FILE} and the best policy so far in {out / 'policy.npz'}; run "
                "the same command again to resume",
            )
            raise
        finally:
            evaluate.close(terminate=not finished)
    bar.end()
    return _finish(out, state, problem, settings, True, resumed_from)


def _generation(state, problem, settings, evaluate, check_trials, elapsed) -> None:
    """One CMA-ES generation: ask, fly the batch, tell; a check every ``check_every``."""
    es = state["es"]
    pol = state["policy"]
    gen = state["generation"] + 1
    xs = es.ask()
    trials = training_batch(problem, settings, state.get("contested"), gen)
    blocks = [None] + [pol.with_vector(x).block() for x in xs]  # the law first: a yardstick
    r, s = evaluate(trials, blocks, _terms(settings))
    law = float(r[0].mean())
    scores = candidate_scores(r, s, settings.loss_weight)
    es.tell(xs, [-float(v) for v in scores])
    state["generation"] = gen
    state["runs"] += len(blocks) * len(trials)
    row = {"generation": gen, "runs": state["runs"], "minutes": elapsed(),
           "batch_mean": float(scores.mean()), "batch_best": float(scores.max()),
           "batch_law": law, "sigma": float(es.sigma)}  # fmt: skip
    state["curve"].append(row)
    if gen % settings.check_every == 0:
        _check(state, problem, settings, evaluate, check_trials)
        row["runs"] = state["runs"]


def training_batch(
    problem: Problem, settings: Settings, kept: list[int] | None, gen: int
) -> list[tuple[str, dict[str, Any]]]:
    """Generation ``gen``'s training trials: fresh ones, or the screened trials ``kept``
    (``--contested``) in turn, from where the last generation stopped."""
    start = (gen - 1) * settings.batch
    if not settings.contested:
        return problem.batch(PURPOSE_TRAIN, start, settings.batch)
    ids = [kept[(start + k) % len(kept)] for k in range(settings.batch)]
    return [problem.batch(PURPOSE_SCREEN, i, 1)[0] for i in ids]


def contested_trials(successes: np.ndarray) -> list[int]:
    """The trials (columns) whose successes differ between the blocks (rows)."""
    s = np.asarray(successes, dtype=bool)
    return [int(i) for i in np.flatnonzero(s.any(axis=0) & ~s.all(axis=0))]


def _screen(state, problem, settings, evaluate) -> None:
    """Fly the screened pool with the law, the start and ``popsize`` draws around it at
    ``sigma`` (a stream of the problem's seed, not CMA-ES's); keep the trials they split."""
    theta0 = np.array(state["es"].mean, dtype=float)
    pol = state["policy"]
    seq = np.random.SeedSequence(problem.seed, spawn_key=(PURPOSE_SCREEN,))
    rng = np.random.Generator(np.random.PCG64(seq))
    thetas = [theta0] + [theta0 + settings.sigma * rng.standard_normal(theta0.size)
                         for _ in range(settings.popsize)]  # fmt: skip
    pool = problem.batch(PURPOSE_SCREEN, 0, settings.contested)
    blocks = [None] + [pol.with_vector(t).block() for t in thetas]
    _, s = evaluate(pool, blocks, _terms(settings))
    state["runs"] += len(blocks) * len(pool)
    kept = contested_trials(s)
    if not kept:
        raise InputError(f"--contested: none of the {settings.contested} screened trials "
                         "separates the start from its neighbours; screen more, or raise "
                         "--sigma")  # fmt: skip
    state["contested"] = kept


def _terms(settings: Settings) -> tuple[float, float]:
    """The reward's terms: (shaping, drift weight)."""
    return (settings.shaping, settings.drift_weight)


def _check_key(got: tuple[float, float], settings: Settings) -> tuple[float, ...]:
    """How the check set ranks (success, mean reward): success first, or, with a drift
    weight, the mean reward, which holds the drift."""
    return (got[1], got[0]) if settings.drift_weight > 0 else got


def candidate_scores(rewards: np.ndarray, successes: np.ndarray, loss_weight: float) -> np.ndarray:
    """Each candidate's score on a batch: its mean reward, less ``loss_weight`` for each
    trial the law (row 0) succeeds in and the candidate fails.

    Parameters
    ----------
    rewards, successes : ndarray, shape (1 + candidates, trials)
        The law's row first, then the candidates'.
    loss_weight : float
        The penalty per trial lost to the law (>= 0).

    Returns
    -------
    ndarray, shape (candidates,)
    """
    lost = successes[0][np.newaxis, :] & ~successes[1:]
    return (rewards[1:] - loss_weight * lost).mean(axis=1)


def _check(state, problem, settings, evaluate, check_trials) -> None:
    """The distribution's mean on the check set; kept as the best if better (success, then
    reward)."""
    theta = np.array(state["es"].mean, dtype=float)
    block = state["policy"].with_vector(theta).block()
    r, s = evaluate(check_trials, [block], _terms(settings))
    state["runs"] += len(check_trials)
    got = (float(s.mean()), float(r.mean()))
    row = state["curve"][-1]
    row["check_success"], row["check_score"] = got
    if _check_key(got, settings) > _check_key(state["best"][:2], settings):
        state["best"] = (*got, state["generation"], theta.copy())


def _show(bar: Progress, state: dict[str, Any], minutes: float | None,
          generations: int | None) -> None:  # fmt: skip
    row = state["curve"][-1]
    if generations is not None:
        done, total, unit = state["generation"], generations, f"/{generations} gen."
    else:
        done, total, unit = state["minutes"], float(minutes), f"/{minutes:g} min"
    law = state["law_check"][0]
    best = state["best"]
    checked = row.get("check_success") is not None
    text = (f"train {progress_bar(done, total)} gen {state['generation']} ({state['minutes']:.1f}"
            f"{unit if generations is None else ' min, ' + str(done) + unit}), "
            f"{state['runs']} runs, batch {row['batch_mean']:.3f}, check best {best[0]:.3f} "
            f"(law {law:.3f})")  # fmt: skip
    bar.show(text, checked)


def _finish(out: Path, state: dict[str, Any], problem: Problem, settings: Settings,
            finished: bool, resumed_from: int) -> TrainingResult:  # fmt: skip
    """Write policy.npz (the best so far), curve.csv and .png and train.json."""
    import cma

    from quadimpact.inputs.policy_file import save_policy

    write_curve(out, state["curve"])
    if state["best"] is None:
        return TrainingResult(out, 0, state["runs"], state["minutes"], math.nan, math.nan, 0,
                              finished, resumed_from)  # fmt: skip
    plot_curve(out / "curve.csv", out / "curve.png")
    best_success, best_score, best_gen, theta = state["best"]
    law_success, law_score = state["law_check"]
    meta = {
        "method": f"CMA-ES (cma {cma.__version__}), residual on the default staged law",
        "command": "quadimpact train",
        "problem": problem.describe(),
        "settings": asdict(settings),
        "trials": "held-out: streams SeedSequence(seed, spawn_key=(task, purpose, index)), "
        "grid points off the benchmark's lattice (docs/LEARNING.md 14)",
        "generations": state["generation"],
        "best_generation": best_gen,
        "contested_kept": len(state.get("contested") or []),
        "runs": state["runs"],
        "minutes": round(state["minutes"], 2),
        "check_success_law": law_success,
        "check_success_policy": best_success,
        "check_score_law": law_score,
        "check_score_policy": best_score,
        "finished": finished,
    }
    save_policy(state["policy"].with_vector(theta, **meta), out / "policy.npz")
    text = json.dumps({**meta, "sessions": state["sessions"],
                       "files": list(OWN_FILES)},
                      indent=1) + "\n"  # fmt: skip
    atomic_write(out / "train.json", lambda tmp: tmp.write_text(text, encoding="utf-8"))
    return TrainingResult(out, state["generation"], state["runs"], state["minutes"],
                          law_success, best_success, best_gen, finished, resumed_from)  # fmt: skip
