"""``quadimpact benchmark``: the recovery benchmark to a folder (``studies/benchmark/``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from quadimpact.cli.options import (
    allow_large_option,
    out_option,
    parallel_options,
    plugin_option,
    stoppable,
)
from quadimpact.errors import InputError

__all__ = ["benchmark", "subject_from_options"]

_CONTROLLER_FLAGS = ("controller", "model", "params")


def subject_from_options(
    *,
    name: str | None = None,
    controller: str | None = None,
    model: str | None = None,
    params: dict[str, Any] | None = None,
    estimator: str | None = None,
    policy: str | None = None,
) -> Any:
    """The thing benchmarked, from the command's options (see ``quadimpact benchmark --help``).

    Its kind: ``policy`` with a policy; ``controller`` with a controller,
    model or parameters (or nothing: the default law); ``estimator`` with an
    estimator alone. Its name, unless given: the policy's, the plug-in
    controller's, the model's (with ``+params`` when parameters are set), or
    ``default + <estimator>``.

    Raises
    ------
    InputError
        An unknown controller, model, estimator or policy, a bad parameter, or a
        name that a reference row has but that flies something else.
    """
    from quadimpact.inputs.controllers import validate_params
    from quadimpact.studies.benchmark.subject import REFERENCES, Subject
    from quadimpact.studies.benchmark.suite import DEFAULT_ESTIMATOR

    params = dict(params or {})
    if policy is not None and (controller is not None or params):
        raise InputError("--policy: a policy flies itself; give no --controller or --param")
    kind = (
        "policy" if policy is not None
        else "controller" if controller is not None or model is not None or params
        else "estimator" if estimator is not None
        else "controller"
    )  # fmt: skip
    controller = controller or "recovery"
    if params:
        try:
            validate_params(controller, params)
        except InputError as exc:
            raise InputError(f"--param: {str(exc).removeprefix('controller_params.')}") from None
    if name is None:
        if kind == "policy":
            name = f"policy {policy}"
        elif kind == "estimator":
            name = f"default + {estimator}"
        else:
            name = model or "default" if controller == "recovery" else controller
            name += " +params" if params else ""
    try:
        subject = Subject(
            name, kind=kind, controller=controller, model=model or "default", params=params,
            estimator=estimator or DEFAULT_ESTIMATOR, policy=policy,
        )  # fmt: skip
    except InputError as exc:  # "controller: ..." -> "--controller: ..."
        text = str(exc)
        field = text.partition(":")[0]
        raise InputError(f"--{text}" if field in ("controller", "estimator") else text) from None
    for ref in REFERENCES:
        same = {k: v for k, v in ref.describe().items() if k not in ("role", "note", "kind")}
        mine = {k: v for k, v in subject.describe().items() if k not in ("role", "note", "kind")}
        if ref.name == subject.name and same != mine:
            raise InputError(f"--name: {name!r} is a reference row's; name what you benchmark "
                             "otherwise")  # fmt: skip
    return subject


@click.command("benchmark")
@out_option(
    "results/benchmark",
    "Benchmark folder: benchmark.csv and .parquet, report.md, leaderboard.png, cells/ (every "
    "cell's trials, and the sweeps run here: run the same command again to resume).",
)
@click.option(
    "--quick", is_flag=True,
    help="The quick suite: the wall's first 1,000 trials, the grids' every 3rd pitch and every "
    "5th offset (240 points).",
)  # fmt: skip
@click.option(
    "--tasks", metavar="wall,pole,edge",
    help="The tasks to fly, comma-separated. [default: all three]",
)  # fmt: skip
@click.option(
    "--controller", metavar="NAME",
    help="The controller benchmarked: recovery (the staged law, in --model) or a registered "
    "plug-in (see --plugin). [default: recovery]",
)  # fmt: skip
@click.option(
    "--model", metavar="VARIANT",
    help="The model variant the recovery law flies (docs/VARIANTS.md): default, classic, "
    "recovery-replica, pole-replica... [default: default]",
)  # fmt: skip
@click.option(
    "--param", "params", multiple=True, metavar="NAME=VALUE",
    help="A parameter of the controller (repeatable), as [controller_params] of a scenario "
    "file, e.g. --param a_mag_m_s2=4.8.",
)  # fmt: skip
@click.option(
    "--estimator", metavar="NAME",
    help="The state estimator of the impact sensor set: ekf, complementary or a registered "
    "one. Alone (without --controller, --model, --param) it is what is benchmarked, with the "
    "default law. [default: ekf]",
)  # fmt: skip
@click.option(
    "--policy", metavar="learned|learned-imu|FILE",
    help="A learned policy flown by the recovery controller: learned = the residual on the "
    "staged law shipped with quadimpact (docs/LEARNING.md 15; learned-imu: the one before "
    "it), or a .npz policy file of your "
    "own; or a policy registered with quadimpact.studies.benchmark.subject.register_policy.",
)  # fmt: skip
@click.option(
    "--suite", "suite_version", default=None, metavar="VERSION",
    help="The suite's version: 3 (the default: success is a held hover, sensor sets ideal, "
    "lab and onboard), 2 (the same without onboard) or 1 (the published criteria, sensor "
    "sets ideal and impact; its numbers unchanged).",
)  # fmt: skip
@click.option(
    "--sensors", metavar="ideal,lab,...",
    help="The sensor sets to fly, comma-separated: the suite's own by default; suites 2 and 3 "
    "also fly impact (an IMU alone) when named.",
)  # fmt: skip
@click.option("--name", metavar="NAME", help="The benchmarked row's name in every output.")
@click.option(
    "--no-references", is_flag=True,
    help="Fly only the thing benchmarked (no reference rows; the authors' published figures "
    "are still shown).",
)  # fmt: skip
@click.option(
    "--cache", type=click.Path(file_okay=False, path_type=Path), metavar="DIR",
    help="The cache of the built-in rows' cells, keyed by suite, quadimpact version and runs. "
    "[default: $QUADIMPACT_BENCHMARK_CACHE, else ~/.cache/quadimpact/benchmark]",
)  # fmt: skip
@click.option("--no-cache", is_flag=True, help="Neither read nor keep cached cells.")
@allow_large_option
@parallel_options
@plugin_option
def benchmark(
    out: Path,
    quick: bool,
    tasks: str | None,
    controller: str | None,
    model: str | None,
    params: tuple[str, ...],
    estimator: str | None,
    policy: str | None,
    suite_version: str | None,
    sensors: str | None,
    name: str | None,
    no_references: bool,
    cache: Path | None,
    no_cache: bool,
    allow_large: bool,
    workers: int | None,
    scheduler: str | None,
    no_progress: bool,
) -> None:
    """The recovery benchmark: a controller or an estimator ranked on a fixed suite.

    Flies the suite's seeded tasks (docs/BENCHMARK.md): wall, the authors'
    Monte Carlo of wall impacts (10,000 trials; --quick 1,000); pole, the
    authors' pole grid (3,266 points; --quick 240); edge, the same grid against
    the vertical edge of a 1 m x 1 m pillar; each with the ideal sensors,
    with the lab sensors (an IMU, a magnetometer, motion capture) and a state
    estimator (ekf unless --estimator), and with the onboard sensors (flow,
    range, barometer, magnetometer, IMU) and the nav-ekf navigation filter.
    Success (suites 2 and 3) is a held hover:
    slow, level, not turning and touching nothing for 0.5 s, with less than
    2 m of height lost and the ground untouched.
    The thing benchmarked (by default the default law) flies beside the
    reference rows (the default law, classic, recovery-replica, pole-replica,
    the baseline without recovery; read from the cache when computed before
    by this version) and the authors' published figures. Writes
    DIR/benchmark.csv (and .parquet): per row, task and sensor set the
    success with its 95 % interval, its paired difference to the default row,
    the published criterion, the time and distance to the hover, the height
    lost (p50, p90), missed and false detections and the CPU time;
    DIR/report.md with the leaderboard; DIR/leaderboard.png.
    The suite's version is in every output. Resumable and distributed like
    every sweep.

    \b
    Examples:
      quadimpact benchmark --quick --out results/bench-quick
      quadimpact benchmark --out results/bench
      quadimpact benchmark --quick --model pole-replica --out results/bench-pole-law
      quadimpact benchmark --quick --param a_mag_m_s2=4.8 --out results/bench-amag
      quadimpact benchmark --quick --estimator complementary --out results/bench-cf
      quadimpact benchmark --quick --policy learned --out results/bench-learned
      quadimpact benchmark --quick --plugin my_law.py --controller my-law --out results/mine
    """
    if scheduler is not None and workers is not None:
        raise InputError("--workers and --scheduler: give one or the other")
    if cache is not None and no_cache:
        raise InputError("--cache and --no-cache: give one or the other")
    from quadimpact.cli.run_command import _parse_options
    from quadimpact.studies.benchmark.benchmark_study import (
        BenchmarkStudy,
        run_benchmark,
        study_folder,
    )
    from quadimpact.studies.benchmark.cells import default_cache
    from quadimpact.studies.benchmark.suite import SUITE_VERSION, parse_sensor_sets, parse_tasks

    subject = subject_from_options(
        name=name, controller=controller, model=model,
        params=_parse_options(params, "--param") if params else None, estimator=estimator,
        policy=policy,
    )  # fmt: skip
    version = suite_version or SUITE_VERSION
    sets = None if sensors is None else parse_sensor_sets(sensors, version)
    study = BenchmarkStudy(
        subject=subject, quick=quick, tasks=parse_tasks(tasks), references=not no_references,
        suite=version, sensors=sets,
    )  # fmt: skip
    study_folder(study, out).check()  # another benchmark, or other options: refused at once
    from quadimpact.sweep.runner import warm_pool

    warm_pool(workers, scheduler)  # the pool's server warms up while the benchmark loads
    with stoppable(out):
        result = run_benchmark(
            study, out, workers=workers, scheduler=scheduler, progress=not no_progress,
            cache=None if no_cache else (cache or default_cache()), allow_large=allow_large,
        )  # fmt: skip
    click.echo(_summary(result))


def _summary(result: Any) -> str:
    from quadimpact.studies.statistics import percent

    t = result.table
    mine = t[t["row"] == result.cells[0]["row"]]
    rows = []
    for _, line in mine.iterrows():
        rows.append(
            f"{line['task']:<5} {line['sensors']:<7} {percent(line['success'])} "
            f"[{percent(line['success_low'])}, {percent(line['success_high'])}] "
            f"({int(line['success_k'])} / {int(line['valid'])})"
        )
    n_run = sum(c["source"] == "run" for c in result.cells)
    return "\n".join([
        f"benchmarked {result.cells[0]['row']} (suite {t['suite_version'].iloc[0]}):",
        *rows,
        f"cells     {len(result.cells)} ({n_run} run now, the others from the cache or shared)",
        f"table     {result.out_dir / 'benchmark.csv'}",
        f"report    {result.report}",
        f"time      {result.elapsed_s:.1f} s",
    ])  # fmt: skip
