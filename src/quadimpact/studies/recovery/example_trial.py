"""The recovery study's example trial: one trial run again with its files, figure,
viewer and animation (``DIR/example/``; docs/RECOVERY.md 8).

The trial nearest the median conditions (``analysis.example_trial``) depends
on the trials' inputs only, so where the trials run on other processes (a
pool or Dask) it is made beside them, on a process of its own
(:class:`EarlyExample`), and otherwise after them, here (:func:`write_example`).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from quadimpact.inputs.scenarios import ImpactTrial, scenario_from_dict
from quadimpact.sweep import SweepSpec

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["EXAMPLE_DIR", "EarlyExample", "beside", "check_example", "write_example"]

EXAMPLE_DIR = "example"


def beside(workers: int | None, scheduler: Any) -> bool:
    """Whether the example trial runs beside the trials: they run on other processes.

    ``workers=None`` is the sweep's default (:func:`quadimpact.sweep.runner.default_workers`):
    a pool when this process may use more than one core.
    """
    if scheduler is not None:
        return True
    if workers is None:
        from quadimpact.sweep.runner import default_workers

        workers = default_workers()
    return int(workers) > 1


def check_example(run_id: int, recovered: bool, table: pd.DataFrame) -> None:
    """Raise if the example run of trial ``run_id`` did not recover as its table row says."""
    row = table.loc[table["run_id"] == run_id].iloc[0]
    if bool(recovered) != bool(row["recovered"]):  # pragma: no cover
        raise RuntimeError(f"trial {run_id}: the example run does not repeat its table row")


class EarlyExample:
    """The example trial written on a process of its own while the trials run.

    The trial nearest the median conditions (``analysis.example_trial``) is
    known from the sweep's inputs before any trial runs, so its files,
    figure, viewer and animation (about as much CPU time as 1,000 trials) are
    made beside the sweep, on a process forked from the sweep's warm fork
    server, instead of after it.
    """

    def __init__(self, run_id: int, executor: Any, future: Any, out: Path) -> None:
        self.run_id = run_id
        self._executor = executor
        self._future = future
        self._out = out

    @classmethod
    def start(
        cls, scenario_data: dict[str, Any], run_id: int, out: Path, animation: bool
    ) -> EarlyExample | None:
        """Start writing trial ``run_id`` (its scenario mapping) into ``out/example``.

        None where processes are not forked from a warm server (the example is
        then written after the trials).
        """
        from concurrent.futures import ProcessPoolExecutor

        from quadimpact.sweep.pool import pool_context, start_server
        from quadimpact.sweep.tasks import _start_task_worker

        ctx = pool_context()
        if ctx.get_start_method() != "forkserver":
            return None  # a spawned process would import everything again: after the trials
        start_server(ctx)
        executor = ProcessPoolExecutor(1, mp_context=ctx, initializer=_start_task_worker)
        future = executor.submit(_example_task, scenario_data, run_id, out, animation)
        return cls(run_id, executor, future, out)

    def result(self) -> tuple[Path, tuple[list[Path], list[str]], bool]:
        """Wait for the example (Ctrl-C and SIGTERM stop it); its folder, files, warnings."""
        from concurrent.futures import wait

        from quadimpact.sweep.interrupt import stop_signals

        try:
            with stop_signals() as stop, stop.polled():
                while not wait([self._future], timeout=0.2).done:
                    stop.check()
            d, paths, warnings, recovered = self._future.result()
        except BaseException:
            self.cancel()
            raise
        self._executor.shutdown(wait=True)
        self._executor = None
        return d, (paths, warnings), recovered

    def submit(self, fn: Any, *args: Any) -> Any:
        """A future of ``fn(*args)`` on the example's process once the example is done
        (it is then idle, with Matplotlib loaded); None before, or without the process."""
        if self._executor is None or not self._future.done():
            return None
        try:
            return self._executor.submit(fn, *args)
        except Exception:  # a broken executor: the caller does the work itself
            return None

    def cancel(self) -> None:
        """Stop the example's process at once and remove its unfinished folder."""
        import shutil

        from quadimpact.sweep.tasks import _kill_workers

        if self._executor is None:
            return
        pids = list(getattr(self._executor, "_processes", None) or {})
        _kill_workers(self._executor)
        self._executor.shutdown(wait=True, cancel_futures=True)
        for pid in pids:
            for stage in self._out.glob(f".{EXAMPLE_DIR}.partial-{pid}-*"):
                shutil.rmtree(stage, ignore_errors=True)
        self._executor = None


def _example_task(
    scenario_data: dict[str, Any], run_id: int, out: Path, animation: bool
) -> tuple[Path, list[Path], list[str], bool]:
    """The example trial's folder on a process of its own (see :class:`EarlyExample`)."""
    scenario = scenario_from_dict(scenario_data, where=f"run {run_id}")
    d, (paths, warnings), recovered = _example_files(scenario, run_id, out, animation)
    return d, paths, warnings, recovered


def write_example(
    spec: SweepSpec, run_id: int, table: pd.DataFrame, out: Path, animation: bool
) -> tuple[Path, tuple[list[Path], list[str]]]:
    """Run trial ``run_id`` again into ``out/example`` with its figure, viewer and animation."""
    scenario = scenario_from_dict(spec.scenario_dict(run_id), where=f"run {run_id}")
    d, more, recovered = _example_files(scenario, run_id, out, animation)
    check_example(run_id, recovered, table)
    return d, more


def _example_files(
    scenario: ImpactTrial, run_id: int, out: Path, animation: bool
) -> tuple[Path, tuple[list[Path], list[str]], bool]:
    from quadimpact.simulation import simulate
    from quadimpact.studies.recovery import recovery_figures as figures
    from quadimpact.viz.scene import Scene
    from quadimpact.viz.viewer import write_viewer

    result = simulate(scenario)
    d = out / EXAMPLE_DIR
    result.write(d)
    paths = [figures.write_example(result, d / "recovery.png", run_id)]
    warnings: list[str] = []
    scene = Scene.from_result(result, vehicle=scenario.build_vehicle())
    paths.append(write_viewer(d, scene=scene))
    if animation:
        try:
            from quadimpact.viz.animation import write_animation

            movie = write_animation(d, scene=scene).mp4
            if movie is not None:
                paths.append(Path(movie))
        except Exception as exc:  # no ffmpeg (the viz extra): the study stands without it
            warnings.append(f"example animation not written: {type(exc).__name__}: {exc}")
    return d, (paths, warnings), bool(result.summary["recovered"])
