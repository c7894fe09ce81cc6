"""``quadimpact sweep``: many runs to one table (``quadimpact.sweep``).

Registered on the group in :mod:`quadimpact.cli`. Heavy modules are
imported inside the command, so that ``quadimpact --help`` stays fast.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from quadimpact.cli.command_output import ran_text
from quadimpact.cli.options import (
    file_argument,
    max_record_option,
    parallel_options,
    plugin_option,
    stoppable,
)
from quadimpact.errors import InputError

__all__ = ["sweep"]


def _parse_grid(options: tuple[str, ...]) -> dict[str, list]:
    from quadimpact.sweep import parse_values

    grid: dict[str, list] = {}
    for option in options:
        field, sep, values = option.partition("=")
        field = field.strip()
        if not sep or not field:
            raise InputError(
                f"--grid: must be FIELD=VALUES, e.g. inclination_deg=-20:20:1 (got {option!r})"
            )
        if field in grid:
            raise InputError(f"--grid: {field}: given twice")
        grid[field] = parse_values(values, f"--grid {field}")
    return grid


@click.command("sweep")
@file_argument("sweep_file", "[SWEEP.toml]")
@click.option(
    "--grid",
    "grid",
    multiple=True,
    metavar="FIELD=VALUES",
    help="Sweep a scenario or vehicle field (heading_deg, inclination_deg, speed_m_s, "
    "restitution, contact_stiffness, mass_kg, model...) over VALUES: a comma list (0,45) "
    "or an inclusive range start:stop:step (-20:20:1). Repeat for a grid over several "
    "fields; replaces or extends the sweep file's grid.",
)
@click.option(
    "--out",
    "out",
    required=True,
    metavar="DIR",
    type=click.Path(file_okay=False, path_type=Path),
    help="Output folder: runs.parquet (one row per run), sweep.json, plots/. Run the same "
    "command again to resume an interrupted sweep.",
)
@parallel_options
@click.option(
    "--timeout",
    type=click.FloatRange(min=0, min_open=True),
    metavar="SECONDS",
    help="Longest time one run may take on a worker process or Dask; a run over it has "
    "its worker stopped and is redone once on another worker, then recorded as failed. "
    "[default: 60 s, more for long scenarios: 4 x the time the kernel's step budget "
    "(2e6 steps per simulated second) takes at the measured cost of a step]",
)
@click.option(
    "--allow-large",
    is_flag=True,
    help="Allow a sweep of more than 1,000,000 runs (refused otherwise).",
)
@max_record_option(
    "Largest record (time series and IMU samples) one run may allocate; a run above "
    "it is refused before any starts."
)
@click.option("--no-plots", is_flag=True, help="Do not write plots/.")
@plugin_option
def sweep(
    sweep_file: Path | None,
    grid: tuple[str, ...],
    out: Path,
    workers: int | None,
    scheduler: str | None,
    no_progress: bool,
    timeout: float | None,
    allow_large: bool,
    max_record_mb: float,
    no_plots: bool,
) -> None:
    """Run a sweep: one base scenario over a grid, a list or a random sample.

    SWEEP.toml names the base scenario (a [base] table of scenario-file keys,
    or base = "scenario.toml") and the runs ([grid], [[runs]] or [sample]);
    without it the base is the paper's wall approach with its defaults and
    the runs are the --grid. Every run is validated before any starts.

    Ctrl-C (any number of times) or SIGTERM stops the sweep at once and keeps
    every finished run (exit status 130, 143 for SIGTERM); run the same
    command again to resume: only the missing runs are done, and parts found
    damaged are checked and redone. A worker process that dies or exceeds
    --timeout costs only the run it was on, which is redone once elsewhere.

    Writes DIR/runs.parquet: one row per run with the swept inputs, the
    summary fields of `quadimpact run`, response_type (A, B, C, D, Other),
    n_subsequent_impacts and status (a run that fails numerically is a row
    with status "failed" and its reason). The table is the same whatever the
    number of workers or the cluster. Plots of delta_init and of the response
    types go to DIR/plots/ when the grid has one to three varied fields.

    \b
    Examples:
      quadimpact sweep --grid heading_deg=0,45 --grid inclination_deg=-20:20:1 \\
          --grid speed_m_s=0.5,0.75,1.0 --grid model=paper-replica --out fig4
      quadimpact sweep study.toml --grid restitution=0.2:0.8:0.1 --out restitution
    """
    from quadimpact.results.files import check_out_dir

    check_out_dir(out, "sweep")
    extra = _parse_grid(grid)
    if sweep_file is None and not extra:
        raise InputError("sweep: give a sweep file or at least one --grid FIELD=VALUES")
    _warm_up(out, workers, no_plots)
    from quadimpact.sweep import run_sweep

    spec = _sweep_spec(sweep_file, extra)
    # once stopped by a signal, every later one is ignored until the program has ended
    with stoppable():
        info = run_sweep(
            spec,
            out,
            workers=workers,
            scheduler=scheduler,
            progress=not no_progress,
            load=False,
            timeout=timeout,
            allow_large=allow_large,
            max_record_mb=max_record_mb,
        )
    plots = [] if no_plots else _plots(out, spec)
    click.echo(_report(out, plots, info))


def _warm_up(out: Path, workers: int | None, no_plots: bool) -> None:
    """With N workers given (N > 1) and runs left in ``out``: start the pool's fork server
    now, and load the plotting here meanwhile (unless ``no_plots``)."""
    from quadimpact.sweep.store import finished_before

    if workers is not None and workers > 1 and not finished_before(out):
        from quadimpact.sweep.runner import warm_pool

        # N workers from the start (unless every run is done already): the fork server
        # imports the simulator and loads the kernel on another core meanwhile
        warm_pool(workers)
        if not no_plots:  # and this process loads the plotting (Matplotlib) on this one
            import quadimpact.sweep.plots  # noqa: F401


def _sweep_spec(sweep_file: Path | None, extra: dict[str, list]) -> Any:
    """The sweep: the file's, its grid replaced or extended by the ``--grid`` fields
    (``extra``); without a file, the default base over those fields."""
    from quadimpact.sweep import SweepSpec, load_sweep_file

    if sweep_file is None:
        return SweepSpec(grid=extra, where="sweep")
    spec = load_sweep_file(sweep_file)
    return spec.with_grid(extra) if extra else spec


def _plots(out: Path, spec: Any) -> list[Path]:
    """The sweep's plots in ``out/plots`` (``sweep.plot_plan``): those drawn before from
    this very table (a rerun) kept, else drawn now; a failure only warns (the table stays)."""
    from quadimpact.sweep.plot_plan import drawn_plots, plot_plan

    names = plot_plan(spec)[1]
    drawn = drawn_plots(out, names) if names else []
    if drawn is not None:  # drawn before from this very table (a rerun): kept
        return drawn
    from quadimpact.sweep.plots import auto_plots

    try:
        return auto_plots(out, spec)
    except Exception as exc:  # plots never lose the table
        click.echo(f"quadimpact: warning: plots not written: {exc}", err=True)
        return []


def _report(out: Path, plots: list[Path], info: dict) -> str:
    import pyarrow.parquet as pq

    from quadimpact.results.costs import COST_KEYS, cost_ratio, cost_text

    path = out / "runs.parquet"
    columns = ["status", "response_type", "bumper_model_valid", *COST_KEYS]
    t = pq.read_table(path, columns=columns).to_pandas()
    n = len(t)
    status = t["status"].value_counts()
    types = t["response_type"].value_counts()
    status_text = ", ".join(
        f"{k} {int(status.get(k, 0))}" for k in ("completed", "crashed", "failed")
    )
    type_text = ", ".join(f"{k} {int(types.get(k, 0))}" for k in ("A", "B", "C", "D", "Other"))
    lines = [
        f"runs    {n} ({int(status.get('failed', 0))} failed, "
        f"{int(t['bumper_model_valid'].eq(False).sum())} deeper than the bumper radius; "
        f"{ran_text(info)})",
        f"status  {status_text}",
        f"types   {type_text}",
        f"cost    {cost_text(cost_ratio(t))}",
        f"table   {path}",
    ]
    if plots:
        lines.append(f"plots   {out / 'plots'} ({', '.join(p.name for p in plots)})")
    return "\n".join(lines)
