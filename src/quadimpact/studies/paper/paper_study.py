"""The paper's study in one call: Figure 4, Table II, Figures 5-6 and a report.

``reproduce(out_dir)`` runs, for both model variants (docs/VARIANTS.md),
the Figure 4 sweep (heading 0 and 45 deg, inclination -20..20 deg in 1-deg
steps, impact speed 0.5, 0.75, 1 m/s: 246 runs each) and the example run
(45 deg, 15 deg, 0.75 m/s), evaluates the paper's findings on each
(:mod:`~quadimpact.studies.paper.findings`), and, to explain where the variants
disagree, repeats the replica with each of its six differences switched off in turn. It writes:

* ``report.md`` (:mod:`~quadimpact.studies.paper.paper_report`): the findings with the
  paper's claim, what each variant measured and the computed verdict; the
  ablation; the figures and Table II;
* ``fig4_<variant>.png``, ``table2_<variant>.png``, ``example-<variant>/``
  (the run's files, Figures 5 and 6);
* ``fig4.parquet`` (every run of every sweep), ``table2.parquet``,
  ``findings.parquet``, ``ablation.parquet``;
* ``sweeps/<name>/``: the resumable sweep folders.

With ``recovery`` (the default) it adds "Beyond the paper: recovery"
(:func:`recovery_part`, docs/RECOVERY.md): the recovery Monte Carlo of the
Navi at :data:`RECOVERY_N` trials in ``default`` and ``recovery-replica``;
the noisy IMU and the Spiri at :data:`RECOVERY_COMPARE_N` trials against
the Navi's first :data:`RECOVERY_COMPARE_N` trials (ideal IMU, default);
the Figure 4 grid with the recovery controller (pre-impact nominal, the
``paper`` controller) against the nominal runs, in both paper variants; and
the seven Table III crashes without the motor power-off, nominal against
recovery; and the estimators (``ideal``, ``complementary``, ``ekf``) on the
same first trials under the IMU's impact disturbance, beside the authors'
figures (:mod:`~quadimpact.studies.paper.estimator_comparison`). It writes ``recovery/<study>/``
(the trials, resumable), ``recovery_trials.parquet``, ``recovery_fig4.parquet``,
``recovery_crashes.parquet``, ``recovery_by_inclination.png`` and
``recovery_estimators_error.png``. It also adds "Beyond the paper: the pole"
(:func:`pole_part`, docs/OBSTACLES.md 3): the authors' pole study on a coarser
grid (:data:`POLE_GRID`: pitch 0 to -45 deg every 5 deg by offsets -0.35 to
0.35 m every 0.05 m, 150 points, both controllers), into ``pole/`` (its
trials, maps and report).
"""

from __future__ import annotations

import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd
from matplotlib.figure import Figure

from quadimpact.inputs.model import MODEL_VARIANTS
from quadimpact.inputs.scenarios import WallApproach
from quadimpact.results import figures, sweep_figures
from quadimpact.results.costs import cost_ratio
from quadimpact.simulation import simulate
from quadimpact.studies.paper.estimator_comparison import COMPARE_N, compare_estimators
from quadimpact.studies.paper.findings import Finding, evaluate, fig4_curves, findings_frame
from quadimpact.studies.paper.paper_report import render_report, type_label
from quadimpact.studies.recovery import recovery_analysis as recovery_analysis
from quadimpact.studies.recovery.baselines import (
    crashes_without_power_off,
    grid_comparison,
    recovery_base,
    saved_by_type,
)
from quadimpact.studies.recovery.recovery_figures import compare_by_bin_figure
from quadimpact.studies.recovery.recovery_study import RecoveryStudy, run_trials
from quadimpact.studies.study_folder import StudyFolder
from quadimpact.sweep import SweepSpec, run_sweep
from quadimpact.sweep.runner import warm_pool
from quadimpact.viz.scene import Scene
from quadimpact.viz.snapshots import write_snapshots

FIG4_GRID: dict[str, list[float]] = {
    "heading_deg": [0.0, 45.0],
    "inclination_deg": [float(i) for i in range(-20, 21)],
    "speed_m_s": [0.5, 0.75, 1.0],
}
EXAMPLE = {"heading_deg": 45.0, "inclination_deg": 15.0, "speed_m_s": 0.75}
VARIANTS = ("paper-replica", "default")
SWITCHES = tuple(
    k
    for k in MODEL_VARIANTS["default"]
    if MODEL_VARIANTS["default"][k] != MODEL_VARIANTS["paper-replica"][k]
    and k != "recovery_law"  # the staged law's tuning: the paper's runs fly no recovery
)  # the paper replica's six differences (its other switches are the default's)
#: Trials of the Navi's recovery Monte Carlo in each variant (reduced from the study's 10,000).
RECOVERY_N = 2_000
#: Trials of the noisy-IMU and Spiri comparisons (the first trials of the same seed).
RECOVERY_COMPARE_N = 1_000
RECOVERY_VARIANTS = ("default", "recovery-replica")


@dataclass
class StudyResult:
    """What ``reproduce`` produced (paths and tables)."""

    out_dir: Path
    report: Path
    tables: dict[str, pd.DataFrame]
    findings: pd.DataFrame
    ablation: pd.DataFrame
    elapsed_s: float
    recovery: RecoveryPart | None = None
    pole: Any = None
    stage_times: list[tuple[str, float]] = field(default_factory=list)
    piece_times: list[tuple[str, float]] = field(default_factory=list)


@dataclass
class RecoveryPart:
    """The recovery part of the study: numbers (``recovery.analysis.summarise``) and tables.

    ``monte_carlo``: variant -> numbers of the Navi's :data:`RECOVERY_N`
    trials; ``compare``: label -> numbers of :data:`RECOVERY_COMPARE_N` trials
    (the Navi's first, ideal IMU; the noisy IMU; the Spiri), default model;
    ``grid``: paper variant -> ``saved_by_type`` of the Figure 4 grid;
    ``crashes``: ``crashes_without_power_off``; ``elapsed_s``: its wall time;
    ``estimators``: estimator -> numbers of the estimators' comparison
    (:mod:`~quadimpact.studies.paper.estimator_comparison`).
    """

    monte_carlo: dict[str, dict]
    compare: dict[str, dict]
    grid: dict[str, pd.DataFrame]
    crashes: pd.DataFrame
    elapsed_s: float
    estimators: dict[str, dict] = field(default_factory=dict)
    cost: dict[str, float] | None = None
    """``results.costs.cost_ratio`` of its trials and its Figure 4 grids."""


class StageClock:
    """Names each stage of the study as it starts and times it (wall clock, s).

    With ``progress`` each stage is named on stderr when it starts and its
    time given when it ends (``reproduce: <stage>: 3.2 s``); ``times`` holds
    (stage, seconds) in order, for the report, and ``pieces`` the same for the
    pieces of a stage that ran on worker processes (their own wall times,
    which overlap). While a stage of pieces runs, one status line (pieces
    done, time so far) is redrawn in place every :attr:`TICK_S` on a terminal;
    when stderr is not a terminal, a line is printed instead after each
    :attr:`HEARTBEAT_S` without one.
    """

    #: Seconds without a line after which a running stage says it is still running
    #: (stderr not a terminal).
    HEARTBEAT_S = 15.0
    #: Seconds between redraws of the status line on a terminal.
    TICK_S = 1.0

    def __init__(self, progress: bool) -> None:
        self.progress = progress
        self.times: list[tuple[str, float]] = []
        self.pieces: list[tuple[str, float]] = []
        self._current: tuple[str, float] | None = None
        self._n_pieces = 0
        self._done_pieces = 0
        self._last_line = time.perf_counter()
        self._beat: threading.Event | None = None
        self._lock = threading.Lock()
        self._status = False  # a status line is drawn (terminal), to be cleared first

    @staticmethod
    def _tty() -> bool:
        isatty = getattr(sys.stderr, "isatty", None)
        try:
            return bool(isatty and isatty())
        except (OSError, ValueError):  # a closed or detached stream
            return False

    def _say(self, line: str) -> None:
        with self._lock:
            self._last_line = time.perf_counter()
            if self.progress:
                clear = "\r\x1b[K" if self._status else ""
                self._status = False
                print(f"{clear}reproduce: {line}", file=sys.stderr, flush=True)

    def _draw(self, stage: tuple[str, float]) -> None:
        """Redraw the status line of ``stage`` in place (a terminal), cut to its width."""
        import shutil

        width = max(shutil.get_terminal_size().columns - 1, 20)
        line = f"reproduce: {self._still_running(*stage, named=False)}"
        if len(line) > width:
            line = line[: width - 3] + "..."
        with self._lock:
            if self._current is not stage:  # the stage ended meanwhile: its line is said
                return
            self._status = True
            sys.stderr.write(f"\r\x1b[K{line}")
            sys.stderr.flush()

    def start(self, text: str, n_pieces: int = 0) -> None:
        """End the running stage (if any) and start the one named ``text``.

        ``n_pieces``: the pieces it runs on worker processes; while they run,
        the stage says it is still running (how many pieces are done, the time
        so far), so that a long stage (a first run also compiles the
        simulator) is never silent: one line redrawn in place on a terminal,
        else a line after each :attr:`HEARTBEAT_S` without one.
        """
        self.stop()
        self._current = (text, time.perf_counter())
        self._n_pieces, self._done_pieces = n_pieces, 0
        self._say(text)
        if self.progress and n_pieces:  # (other stages show their sweeps' progress bars)
            self._beat = threading.Event()
            threading.Thread(target=self._heartbeat, args=(self._beat,), daemon=True).start()

    def _still_running(self, name: str, t0: float, named: bool = True) -> str:
        """The status: pieces done and time so far, after the stage's name (without its
        parenthesis) when ``named`` (a terminal's status line sits under the name)."""
        done = f"{self._done_pieces} of {self._n_pieces} pieces done" if self._n_pieces else ""
        so_far = f"{time.perf_counter() - t0:.0f} s so far"
        compiling = "" if self._done_pieces else "; a first run compiles the simulator first"
        if not named:
            return f"still running: {so_far}{', ' + done if done else ''}{compiling}"
        done = f"{done}, " if done else ""
        return f"{name.split(' (')[0]}: still running ({done}{so_far}{compiling})"

    def _heartbeat(self, stop: threading.Event) -> None:
        tty = self._tty()
        while not stop.wait(self.TICK_S if tty else 1.0):
            current = self._current
            if current is None:
                continue
            if tty:
                self._draw(current)
            elif time.perf_counter() - self._last_line >= self.HEARTBEAT_S:
                self._say(self._still_running(*current))

    def piece(self, text: str, seconds: float) -> None:
        """A piece of the running stage finished (on a worker process) in ``seconds``."""
        self.pieces.append((text, seconds))
        self._done_pieces += 1
        self._say(f"{text}: {seconds:.1f} s")

    def stop(self) -> None:
        """End the running stage (if any) and record its time."""
        if self._beat is not None:
            self._beat.set()
            self._beat = None
        if self._current is None:
            return
        text, t0 = self._current
        self._current = None
        seconds = time.perf_counter() - t0
        self.times.append((text, seconds))
        self._say(f"{text}: {seconds:.1f} s")


def _ablation_name(switch: str) -> str:
    return f"replica-without-{switch}"


def _variant_task(
    name: str, base: dict, out: Path, write_example: bool, sweep_options: dict[str, Any]
) -> tuple[tuple[pd.DataFrame, list[Finding]], float]:
    """One variant's Figure 4 sweep and example run, evaluated: ((its sweep table, its
    findings), wall time in s). With ``write_example`` (a paper variant) the example run's
    folder and the variant's Figure 4 and Table II pictures are written too, here: on a
    worker process, beside the other pieces, rather than at the study's end on one core."""
    start = time.perf_counter()
    table = run_sweep(SweepSpec(base=base, grid=FIG4_GRID), out / "sweeps" / name, **sweep_options)
    example = simulate(WallApproach(**EXAMPLE, **base))
    if write_example:
        example.write(out / f"example-{name}")
        write_snapshots(out / f"example-{name}", scene=Scene.from_result(example))
    found = evaluate(table, (example.summary, example.episodes, example.timeseries))
    if write_example:
        _write_variant_figures(out, table, name)
    return (table, found), time.perf_counter() - start


def _paper_task(kind: str, *args: Any) -> tuple[Any, float]:
    """A piece of the paper's study (``"variant"`` or ``"crash"``), for ``run_tasks``."""
    from quadimpact.studies.table3.table3_study import crash_task

    return _variant_task(*args) if kind == "variant" else crash_task(*args)


def _paper_pieces(
    out: Path,
    options: dict[str, Any],
    ablation: bool,
    crashes: tuple[Path, dict[int, Any]] | None,
) -> list[tuple[str, tuple[Any, ...]]]:
    """The pieces of the paper's part, independent of each other, as (stage name, task of
    :func:`_paper_task`): Figure 4 and the example run in each variant, with ``ablation``
    the replica without each of its differences, with ``crashes`` (the experiments' folder
    and the logs by crash number) the crashes of Table III. ``options``: the pieces' own
    sweeps' options (workers, scheduler, progress)."""
    from quadimpact.experiments.crashes import TABLE3
    from quadimpact.studies.table3.crash_logs import LOG_SENSITIVITY_RUNS
    from quadimpact.studies.table3.table3_study import SENSITIVITY_RUNS

    pieces: list[tuple[str, tuple[Any, ...]]] = [
        (f"Figure 4 sweep and the example run, {v}",
         ("variant", v, {"model": v}, out, True, options))
        for v in VARIANTS
    ]  # fmt: skip
    if ablation:
        for k, switch in enumerate(SWITCHES, 1):
            base = {"model": "paper-replica",
                    "model_options": {switch: MODEL_VARIANTS["default"][switch]}}  # fmt: skip
            task = ("variant", _ablation_name(switch), base, out, False, options)
            pieces.append((f"ablation {k} of {len(SWITCHES)}: the replica without {switch}", task))
    if crashes is not None:
        exp_out, logs = crashes
        pieces += [
            (f"Table III: crash {c.number} of {len(TABLE3)}",
             ("crash", c, logs[c.number], exp_out, SENSITIVITY_RUNS, LOG_SENSITIVITY_RUNS, options))
            for c in TABLE3
        ]  # fmt: skip
    return pieces


def _run_pieces(
    pieces: list[tuple[str, tuple[Any, ...]]], processes: int, clock: StageClock, what: str
) -> list[tuple[Any, float]]:
    """Each piece's (value, wall time in s), in the order of ``pieces``: on ``processes``
    worker processes (the crashes, the longest, first, so that the processes end together;
    one stage of ``clock``, its pieces timed, ``what`` saying what they are) or one after
    the other in this process (one stage each)."""
    from quadimpact.sweep.tasks import run_tasks

    if processes <= 1:
        results = []
        for name, task in pieces:
            clock.start(name)
            results.append(_paper_task(*task))
        return results
    order = sorted(range(len(pieces)), key=lambda i: pieces[i][1][0] != "crash")
    clock.start(f"the paper's runs: {len(pieces)} pieces on {min(processes, len(pieces))} "
                f"processes ({what})", n_pieces=len(pieces))  # fmt: skip

    def done(k: int, result: tuple[Any, float]) -> None:
        clock.piece(pieces[order[k]][0], result[1])

    ran = run_tasks(_paper_task, [pieces[i][1] for i in order], processes, done)
    return [r for _, r in sorted(zip(order, ran, strict=True))]


def _sorted_results(
    pieces: list[tuple[str, tuple[Any, ...]]], results: list[tuple[Any, float]]
) -> tuple[dict[str, pd.DataFrame], dict[str, list[Finding]], pd.DataFrame, list[Any]]:
    """The pieces' values by kind: the Figure 4 tables by sweep name (variants and
    ablations), the findings by paper variant, the ablations' findings (one row per switch
    and finding) and the crashes' rows, in order."""
    tables: dict[str, pd.DataFrame] = {}
    found: dict[str, list[Finding]] = {}
    ablation_rows, crash_rows = [], []
    for (_, task), (value, _seconds) in zip(pieces, results, strict=True):
        if task[0] == "crash":
            crash_rows.append(value)
            continue
        name, (table, fs) = task[1], value
        tables[name] = table
        if task[4]:  # a variant of the paper, not an ablation
            found[name] = fs
        else:
            switch = name.removeprefix(_ablation_name(""))
            ablation_rows += [{"switch": switch, **f.__dict__} for f in fs]
    return tables, found, pd.DataFrame(ablation_rows), crash_rows


def _finish_table3(
    folder: StudyFolder, crash_rows: list[Any], data_dir: str | Path | None
) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
    """Table III from the crashes' rows, written into the experiments' ``folder`` (then
    finished), the source of its logs in its ``attrs["logs"]`` (said in the report); with
    its runs and switch runs as written (``table3_runs``, ``table3_switches``)."""
    from quadimpact.studies.table3.crash_logs import logs_source
    from quadimpact.studies.table3.table3_study import write_table3

    table3 = write_table3(crash_rows, folder.path)
    folder.finish({"crashes": len(crash_rows)})
    table3.attrs["logs"] = logs_source(data_dir)
    runs, switches = (
        pd.read_parquet(folder.path / f"{name}.parquet")
        for name in ("table3_runs", "table3_switches")
    )
    return table3, runs, switches


def _write_paper_tables(
    out: Path, tables: dict[str, pd.DataFrame], findings: pd.DataFrame, ablation: pd.DataFrame
) -> None:
    """The tables behind the report (``fig4.parquet``, ``table2.parquet``,
    ``findings.parquet``, ``ablation.parquet``), into ``out`` (each paper variant's
    Figure 4 and Table II pictures are its piece's: :func:`_write_variant_figures`)."""
    pd.concat([t.assign(variant=v) for v, t in tables.items()]).to_parquet(out / "fig4.parquet")
    table2(tables).to_parquet(out / "table2.parquet")
    findings.to_parquet(out / "findings.parquet")
    ablation.to_parquet(out / "ablation.parquet")


def _write_variant_figures(out: Path, table: pd.DataFrame, variant: str) -> None:
    """A paper variant's Figure 4 and Table II pictures (``fig4_<variant>.png``,
    ``table2_<variant>.png``) from its Figure 4 sweep's ``table``, into ``out``."""
    fig4_figure(table, variant).savefig(out / f"fig4_{variant}.png", dpi=120)
    type_map_figure(table, variant).savefig(out / f"table2_{variant}.png", dpi=120)


def reproduce(
    out_dir: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = False,
    ablation: bool = True,
    experiments: bool = True,
    recovery: bool = True,
    data_dir: str | Path | None = None,
) -> StudyResult:
    """Run the paper's study and write the report folder (see the module docstring).

    With ``experiments`` the seven crashes of Table III are simulated too
    (``studies/table3/table3_study.py``, into ``out_dir/experiments``), compared with
    their logs when ``data_dir`` (or the default data folder) holds them.
    With ``recovery``, "Beyond the paper: recovery" (:func:`recovery_part`).
    """
    from quadimpact.studies.table3.crash_logs import check_data_dir
    from quadimpact.studies.table3.table3_study import prepare_experiments
    from quadimpact.sweep.runner import _resolve_workers

    start = time.perf_counter()
    clock = StageClock(progress)
    folder = study_folder(out_dir, ablation=ablation, experiments=experiments, recovery=recovery)
    folder.check()
    if experiments and data_dir is not None:
        data_dir = check_data_dir(data_dir, "data_dir")
    out = folder.claim()
    warm_pool(workers, scheduler)  # the sweeps below find the pool's server ready
    processes = 1 if scheduler is not None else _resolve_workers(workers)
    here = {"workers": workers, "scheduler": scheduler, "progress": progress}
    inside = {"workers": 1, "scheduler": None, "progress": False}  # a piece's own sweeps
    exp_folder, crashes = None, None
    if experiments:
        exp_folder, logs = prepare_experiments(out / "experiments", data_dir)
        crashes = (exp_folder.path, logs)
    pieces = _paper_pieces(out, inside if processes > 1 else here, ablation, crashes)
    what = ("Figure 4 and the example in both variants" + (", the ablations" if ablation else "")
            + (", the crashes of Table III" if experiments else ""))  # fmt: skip
    tables, found, ablation_df, crash_rows = _sorted_results(
        pieces, _run_pieces(pieces, processes, clock, what)
    )
    findings = findings_frame(found)
    table3, table3_runs, table3_switches = (
        _finish_table3(exp_folder, crash_rows, data_dir) if exp_folder is not None
        else (None, None, None)
    )  # fmt: skip

    part = recovery_part(out, tables, workers, scheduler, progress, clock) if recovery else None
    pole = pole_part(out, workers, scheduler, progress, clock) if recovery else None

    clock.start("figures, tables and the report")
    _write_paper_tables(out, tables, findings, ablation_df)
    clock.stop()
    elapsed = time.perf_counter() - start
    report = folder.finish(
        {"elapsed_s": elapsed},
        render_report(
            tables, findings, ablation_df, elapsed, table3, part, clock.times, clock.pieces,
            pole=pole, table3_runs=table3_runs, table3_switches=table3_switches,
        ),
    )  # fmt: skip
    return StudyResult(
        out, report, tables, findings, ablation_df, elapsed, part, pole, clock.times,
        clock.pieces,
    )  # fmt: skip


def study_folder(
    out_dir: str | Path,
    *,
    ablation: bool = True,
    experiments: bool = True,
    recovery: bool = True,
    where: str = "",
) -> StudyFolder:
    """The study's report folder: which parts it has decides what it runs."""
    identity = {"ablation": ablation, "experiments": experiments, "recovery": recovery}
    flags = {k: f"{k} (--no-{k})" for k in identity}
    return StudyFolder(Path(out_dir), "report", identity, where=where, flags=flags)


#: The pole study's coarser grid in ``reproduce`` (the full one: ``quadimpact pole``).
POLE_GRID = {"pitch_step_deg": 5.0, "offset_step_m": 0.05}


def pole_part(
    out: Path, workers: int | None, scheduler: str | None, progress: bool, clock: StageClock
) -> Any:
    """Beyond the paper: the pole study on :data:`POLE_GRID`, into ``out/pole``."""
    from quadimpact.studies.pole.pole_study import PoleStudy, run_pole_study

    study = PoleStudy(**POLE_GRID)
    n = len(study.pitches()) * len(study.offsets())
    clock.start(f"the pole: {n} grid points, without and with recovery")
    return run_pole_study(
        study, out / "pole", workers=workers, scheduler=scheduler, progress=progress
    )


# ---------------------------------------------------------------- recovery
def recovery_part(
    out: Path,
    tables: dict[str, pd.DataFrame],
    workers: int | None,
    scheduler: str | None,
    progress: bool,
    clock: StageClock | None = None,
) -> RecoveryPart:
    """Beyond the paper: recovery (see the module docstring); ``tables``: the Figure 4 sweeps.

    ``clock`` names and times the stages (default: a new one, with ``progress``).
    """
    start = time.perf_counter()
    clock = clock if clock is not None else StageClock(progress)
    par = {"workers": workers, "scheduler": scheduler, "progress": progress}
    rec = out / "recovery"
    trials: dict[str, pd.DataFrame] = {}
    for v in RECOVERY_VARIANTS:
        clock.start(f"recovery: {RECOVERY_N:,} impact trials of the Navi, {v}")
        trials[f"navi, {v}"] = run_trials(RecoveryStudy(n=RECOVERY_N, model=v),
                                          rec / f"navi-{v}", **par)[1]  # fmt: skip
    m = RECOVERY_COMPARE_N
    clock.start(f"recovery: {m:,} trials with the noisy IMU, {m:,} of the Spiri")
    trials["navi, noisy IMU"] = run_trials(RecoveryStudy(n=m, imu="noisy"), rec / "navi-noisy",
                                           **par)[1]  # fmt: skip
    trials["spiri"] = run_trials(RecoveryStudy(vehicle="spiri", n=m), rec / "spiri", **par)[1]
    first = trials["navi, default"]
    monte_carlo = {v: recovery_analysis.summarise(trials[f"navi, {v}"])
                   for v in RECOVERY_VARIANTS}  # fmt: skip
    compare = {
        f"navi, ideal IMU (the first {m} above)": recovery_analysis.summarise(
            first[first["run_id"] < m]
        ),
        **{k: recovery_analysis.summarise(trials[k]) for k in ("navi, noisy IMU", "spiri")},
    }

    grid, runs, grids = {}, [], []
    for variant in VARIANTS:
        clock.start(f"recovery: the Figure 4 grid with the recovery controller, {variant}")
        table = run_sweep(
            SweepSpec(base=recovery_base({"model": variant}), grid=FIG4_GRID),
            out / "sweeps" / f"recovery-{variant}", **par,
        )  # fmt: skip
        grids.append(table)
        both = grid_comparison(tables[variant], table, list(FIG4_GRID))
        grid[variant] = saved_by_type(both)
        runs.append(both.assign(variant=variant))
    clock.start("recovery: the crashes without their power-off, nominal and recovery")
    crashes = crashes_without_power_off(VARIANTS)
    clock.start(f"recovery: {COMPARE_N:,} trials with each estimator, impact sensors")
    estimators, estimator_trials, _ = compare_estimators(out, par, COMPARE_N)
    trials.update({k: t for k, t in estimator_trials.groupby("study")})

    pd.concat([t.assign(study=k) for k, t in trials.items()]).to_parquet(
        out / "recovery_trials.parquet", index=False
    )
    pd.concat(runs, ignore_index=True).to_parquet(out / "recovery_fig4.parquet", index=False)
    crashes.to_parquet(out / "recovery_crashes.parquet", index=False)
    figures.save_figure(
        compare_by_bin_figure(monte_carlo, "by_inclination",
                              "Navi: success rate by inclination bin, both variants"),
        out / "recovery_by_inclination.png",
    )  # fmt: skip
    cost = cost_ratio(pd.concat([*trials.values(), *grids], ignore_index=True))
    return RecoveryPart(
        monte_carlo, compare, grid, crashes, time.perf_counter() - start, estimators, cost
    )


# ------------------------------------------------------------------ tables
def table2(tables: dict[str, pd.DataFrame]) -> pd.DataFrame:
    """Response type and subsequent-impact count of every Figure 4 run, all sweeps."""
    cols = ["heading_deg", "speed_m_s", "inclination_deg", "response_type", "n_subsequent_impacts"]
    parts = []
    for v, t in tables.items():
        p = t[cols].copy()
        p["label"] = t.apply(type_label, axis=1)
        p["variant"] = v
        parts.append(p)
    return pd.concat(parts, ignore_index=True)


# ------------------------------------------------------------------ figures
def fig4_figure(table: pd.DataFrame, variant: str) -> Figure:
    """Figure 4: delta_init against inclination, one panel per heading, one curve per speed."""
    curves = fig4_curves(table)
    headings = sorted({h for h, _ in curves.columns})
    fig = figures.new_figure(10, 4)
    axes = fig.subplots(1, len(headings), sharey=True, squeeze=False)[0]
    for ax, h in zip(axes, headings, strict=True):
        for v in sorted(curves[h].columns):
            ax.plot(curves.index, curves[h][v] * 1e3, marker=".", label=f"{v:g} m/s")
        ax.axvline(10.0, color="0.6", lw=0.8, ls="--")
        ax.set_title(f"ψ = {h:g}°")
        ax.set_xlabel("inclination (deg)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("δ_init (mm)")
    axes[-1].legend(title="V_c")
    figures.fit_title(fig, f"Figure 4, {variant}: maximum deflection at the initial impact")
    return fig


def type_map_figure(table: pd.DataFrame, variant: str) -> Figure:
    """Table II as a picture: response type over inclination and speed, one panel per heading."""
    return sweep_figures.type_map_figure(
        table, "inclination_deg", "speed_m_s", facet="heading_deg", label=type_label,
        title=f"Table II, {variant}: response type (C/D with the number of subsequent impacts)",
        text_meaning="C3, D4...: the type and the number of subsequent impacts",
    )  # fmt: skip
