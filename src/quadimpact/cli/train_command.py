"""``quadimpact train``: train a recovery policy by CMA-ES (``quadimpact.studies.training``)."""

from __future__ import annotations

from pathlib import Path

import click

from quadimpact.cli.options import out_option
from quadimpact.errors import InputError

__all__ = ["train"]


@click.command("train")
@out_option(
    "results/train",
    "Training folder: policy.npz, curve.csv, curve.png, train.json and state.pkl (run the "
    "same command again to resume).",
)
@click.option(
    "--vehicle", default="navi", show_default=True, metavar="navi|spiri|FILE",
    help="Bundled vehicle name or a vehicle TOML file.",
)  # fmt: skip
@click.option(
    "--tasks", default="wall,pole,edge", show_default=True, metavar="wall,pole,edge",
    help="The benchmark's tasks to train on (docs/BENCHMARK.md 1), taken in turn.",
)  # fmt: skip
@click.option(
    "--sensors", default="onboard", show_default=True, metavar="onboard|lab|impact|ideal[,...]",
    help="The benchmark's sensor set the policy flies with (its sensors and estimator); "
    "several, comma-separated, fly every trial with each (onboard,ideal: learn from the "
    "onboard set without losing with ideal sensing).",
)  # fmt: skip
@click.option(
    "--seed", type=int, default=61, show_default=True,
    help="Seed of the training and check trials (not 0, the benchmark's), of the first "
    "layer's draw and of CMA-ES.",
)  # fmt: skip
@click.option(
    "--minutes", type=float, default=10.0, show_default=True,
    help="Training time in all, resumes included (a rerun with more continues).",
)  # fmt: skip
@click.option(
    "--generations", type=int, default=None,
    help="Stop after this many generations in all instead (exactly reproducible).",
)  # fmt: skip
@click.option("--hidden", type=int, default=8, show_default=True, help="Hidden units (1-32).")
@click.option(
    "--popsize", type=int, default=12, show_default=True, help="CMA-ES candidates per generation."
)
@click.option(
    "--batch", type=int, default=24, show_default=True,
    help="Training trials per generation, each flown by every candidate.",
)  # fmt: skip
@click.option(
    "--sigma", type=float, default=0.05, show_default=True, help="CMA-ES's initial step size."
)
@click.option(
    "--thrust-scale", type=float, default=0.3, show_default=True,
    help="Largest thrust correction, a fraction of m g.",
)  # fmt: skip
@click.option(
    "--rate-scale", "rate_scale_rad_s", type=float, default=4.0, show_default=True,
    metavar="RAD/S", help="Largest roll and pitch rate-reference correction.",
)  # fmt: skip
@click.option(
    "--stages", type=click.Choice(("1-5", "1-4")), default="1-5", show_default=True,
    help="The law's stages the policy corrects: every stage from the detection, the hover "
    "included (1-5), or up to the recovery (1-4, the shipped policy's).",
)  # fmt: skip
@click.option(
    "--hover-centred", is_flag=True,
    help="In the hover stage, correct by the network's outputs minus those at the hover "
    "itself (level, at rest), so that the law's hover stays where it is.",
)  # fmt: skip
@click.option(
    "--hover-hand-over", is_flag=True,
    help="In the hover stage, act only while the law brakes: once the law has captured the "
    "point it holds, the law alone holds it.",
)  # fmt: skip
@click.option(
    "--hover-fade", default=None, metavar="FROM,TO",
    help="In the hover stage, fade the correction linearly to zero between FROM and TO "
    "seconds after the detection (0 <= FROM < TO <= 2), so the law alone holds the hover.",
)  # fmt: skip
@click.option(
    "--init", "init", default=None, metavar="learned|FILE",
    help="Start from this policy's weights instead of the law (its width, scales and "
    "stages must be the run's).",
)  # fmt: skip
@click.option(
    "--shaping", type=float, default=0.1, show_default=True,
    help="Weight of the height-kept term added to the benchmark's success in the reward.",
)  # fmt: skip
@click.option(
    "--drift-weight", type=float, default=0.0, show_default=True,
    help="Weight of the held hover's drift in the reward: a success scores 1 - W min(drift / "
    "0.1 m, 1), the drift being the CM's farthest from the hover point (0: none).",
)  # fmt: skip
@click.option(
    "--loss-weight", type=float, default=0.0, show_default=True,
    help="Penalty in the reward for each trial the law succeeds in and the candidate fails "
    "(0: none).",
)  # fmt: skip
@click.option(
    "--contested", type=int, default=0, show_default=True, metavar="N",
    help="Screen N training trials first (the law, the start and a generation's draws around "
    "it fly them) and train on those their successes split, in turn (0: fresh trials).",
)  # fmt: skip
@click.option("--check", type=int, default=60, show_default=True, help="Trials of the check set.")
@click.option(
    "--check-every", type=int, default=5, show_default=True,
    help="Generations between two flights of the check set (the best is kept).",
)  # fmt: skip
@click.option(
    "--workers", type=int, default=1, show_default=True,
    help="Processes flying the trials (each compiles nothing: the disk cache is shared).",
)  # fmt: skip
@click.option("--no-progress", is_flag=True, help="No progress line on stderr.")
def train(
    out: Path,
    vehicle: str,
    tasks: str,
    sensors: str,
    seed: int,
    minutes: float,
    generations: int | None,
    hidden: int,
    popsize: int,
    batch: int,
    sigma: float,
    thrust_scale: float,
    rate_scale_rad_s: float,
    stages: str,
    hover_centred: bool,
    hover_hand_over: bool,
    hover_fade: str | None,
    init: str | None,
    shaping: float,
    drift_weight: float,
    loss_weight: float,
    contested: int,
    check: int,
    check_every: int,
    workers: int,
    no_progress: bool,
) -> None:
    """Train a recovery policy for a vehicle, obstacles and sensors, by CMA-ES.

    The policy is a small network that corrects the default staged law's
    thrust and roll and pitch rates (docs/LEARNING.md 12), in every stage
    from the detection on. Its reward is the benchmark's success (a held
    hover reached, less than 2 m lost, no ground). It trains on trials of the
    benchmark's tasks drawn from streams of their own, never the
    benchmark's. Writes DIR/policy.npz, which --policy FILE flies in run,
    recovery, pole, benchmark and the Gymnasium environment; DIR/curve.csv
    and curve.png, the learning curve; DIR/train.json. Ctrl-C saves the
    state; the same command resumes it. Needs the `cma` package
    (pip install 'quadimpact[cma]'); flying the policy does not.

    \b
    Examples:
      quadimpact train --minutes 20 --out results/train
      quadimpact train --tasks wall --sensors lab --minutes 5 --out results/train-wall
      quadimpact train --sensors onboard,ideal --loss-weight 1 --out results/train-both
      quadimpact benchmark --quick --policy results/train/policy.npz --out results/bench
    """
    from quadimpact.studies.benchmark.suite import parse_tasks

    try:
        import cma  # noqa: F401
    except ImportError:
        raise InputError(
            "train: needs the cma package (pip install 'quadimpact[cma]', or pip install cma)"
        ) from None
    from quadimpact.studies.training.trainer import Settings
    from quadimpact.studies.training.trainer import train as run_training
    from quadimpact.studies.training.trials import Problem
    from quadimpact.sweep import SweepInterrupted

    fade = (0.0, 0.0)
    if hover_fade is not None:
        parts = hover_fade.split(",")
        try:
            if len(parts) != 2:
                raise ValueError
            fade = (float(parts[0]), float(parts[1]))
        except ValueError:
            raise InputError(
                f"--hover-fade: must be two numbers FROM,TO in s (got {hover_fade!r})"
            ) from None
    problem = Problem(vehicle=vehicle, tasks=parse_tasks(tasks), sensors=sensors, seed=seed)
    settings = Settings(
        hidden=hidden, popsize=popsize, batch=batch, sigma=sigma, thrust_scale=thrust_scale,
        rate_scale_rad_s=rate_scale_rad_s, last_stage=5 if stages == "1-5" else 4,
        shaping=shaping, drift_weight=drift_weight, loss_weight=loss_weight, check=check,
        contested=contested,
        check_every=check_every, hover_centred=hover_centred, hover_fade_s=fade, init=init,
        hover_hand_over=hover_hand_over,
    )  # fmt: skip
    if workers < 1:
        raise InputError(f"--workers: must be >= 1 (got {workers})")
    budget = None if generations is not None else minutes
    try:
        res = run_training(problem, settings, out, budget, generations, workers,
                           progress=not no_progress)  # fmt: skip
    except SweepInterrupted as exc:
        click.echo(f"quadimpact: {exc}", err=True)
        raise click.exceptions.Exit(exc.exit_code) from None
    again = f" (resumed at generation {res.resumed_from})" if res.resumed_from else ""
    click.echo(
        f"wrote {out / 'policy.npz'}: check-set success {100 * res.best_check:.1f} % "
        f"(generation {res.best_generation}; the law {100 * res.law_check:.1f} %), "
        f"{res.generations} generation{'s' if res.generations != 1 else ''}{again}, "
        f"{res.runs} runs, {res.minutes:.1f} min"
    )
    click.echo(f"fly it: quadimpact benchmark --quick --policy {out / 'policy.npz'}")
