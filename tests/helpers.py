"""Shared test helpers: run packed setups through the compiled kernel."""

from __future__ import annotations

import importlib.util
import shutil
import signal
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import psutil

import quadimpact
from quadimpact.core import layout as L
from quadimpact.core.kernel import execute
from quadimpact.core.recording_slots import OUT_X
from quadimpact.simulation.setup import RunSetup

#: The repository's examples folder.
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

#: The bundled Spiri's parameter file.
SPIRI_TOML = Path(quadimpact.__file__).resolve().parent / "inputs" / "vehicles" / "spiri.toml"


def run_packed(setup: RunSetup, **changes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Run ``setup`` (with some fields of its model replaced) on its output grid.

    No IMU and no power-off schedule unless ``changes`` give them; returns
    ``(out, episodes, stats)``.
    """
    fields: dict[str, np.ndarray | None] = dict.fromkeys(
        ("scfg", "noise", "sched_t", "sched_rate", "sched_stop")
    )
    fields.update(changes)
    rec = execute(setup.model(**fields))
    return rec.out, rec.episodes, rec.stats


def states(out: np.ndarray) -> np.ndarray:
    """The NX state columns of an output array."""
    return out[:, OUT_X : OUT_X + L.NX]


def run_cli(*args: str, cwd, timeout: float = 120, env: dict | None = None, umask=None):
    """Run ``python -m quadimpact.cli ARGS`` in a subprocess (the installed or the src package).

    ``env``: variables set on top of this process's; ``umask``: the child's umask.
    """
    import os
    import subprocess
    import sys
    from pathlib import Path

    import quadimpact

    src = Path(quadimpact.__file__).resolve().parents[1]
    env = {**os.environ, **(env or {})}
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(src), env.get("PYTHONPATH")]))
    env.pop("QUADIMPACT_DEBUG", None)
    return subprocess.run(
        [sys.executable, "-m", "quadimpact.cli", *args],
        cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout,
        preexec_fn=None if umask is None else (lambda: os.umask(umask)),
    )  # fmt: skip


def cli_here(capsys, *args: str) -> tuple[int, str]:
    """``quadimpact ARGS`` in this process (``quadimpact.cli.main``): (exit status, stderr).

    Python's warning printer, which the command replaces, is put back after it.
    """
    import warnings

    from quadimpact.cli import main

    shown = warnings.showwarning
    try:
        main(list(args))
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    finally:
        warnings.showwarning = shown
    return code, capsys.readouterr().err


# ------------------------------------------------------------- processes
def process_cpu_s(p: psutil.Process) -> float:
    """CPU time (user + system, s) a process has used; 0 when it is gone."""
    try:
        t = p.cpu_times()
        return t.user + t.system
    except psutil.Error:
        return 0.0


def process_alive(p: psutil.Process) -> bool:
    """Whether a process still runs (a zombie, waiting to be reaped, does not)."""
    try:
        return p.is_running() and p.status() != psutil.STATUS_ZOMBIE
    except psutil.Error:
        return False


@contextmanager
def short_tmpdir() -> Iterator[Path]:
    """A short private folder for a command's ``TMPDIR`` (a Unix socket's path must stay
    under 108 bytes, and multiprocessing's ``pymp-*`` folders of that command land in it)."""
    path = Path(tempfile.mkdtemp(prefix="qi-"))
    try:
        yield path
    finally:
        shutil.rmtree(path, ignore_errors=True)


def assert_all_gone(procs: list[psutil.Process], tmp: Path, within_s: float = 5.0) -> None:
    """No process of ``procs`` is alive within ``within_s`` (those left are killed, and the
    assertion names them); no multiprocessing ``pymp-*`` folder is left in ``tmp``."""
    end = time.monotonic() + within_s
    alive = list(procs)
    while alive and time.monotonic() < end:
        alive = [p for p in alive if process_alive(p)]
        time.sleep(0.05)
    names = [(p.pid, " ".join(p.cmdline())[-60:]) for p in alive if process_alive(p)]
    for p in alive:
        p.kill()
    assert not names, f"left running: {names}"
    assert not list(tmp.glob("pymp-*")), list(tmp.iterdir())


def assert_same_table(a, b) -> None:
    """Two sweep tables (pandas) equal bit for bit, but for what their runs cost.

    The cost columns (``quadimpact.sweep.COST_COLUMNS``: CPU time where each run
    ran) are the only ones that differ between two runs of the same sweep.
    """
    import pandas as pd

    from quadimpact.sweep import without_costs

    pd.testing.assert_frame_equal(without_costs(a), without_costs(b))


def sigint_as_on_a_terminal() -> None:
    """``preexec_fn`` of a command a test stops with SIGINT: SIGINT's default action in it.

    A process started in the background by a non-interactive shell (``cmd &``,
    ``nohup``) ignores SIGINT, and its children inherit that; Python then
    keeps ignoring it, and so does a sweep (it leaves a handler it did not
    expect alone, ``sweep/interrupt.py``). The command under test gets the
    disposition of a terminal's foreground job, wherever the tests run.
    """
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def load_example(filename: str):
    """Import ``examples/<filename>`` as a module (what it registers is then registered).

    The module is put in ``sys.modules`` under its stem first: pydantic resolves the
    annotations of the models it defines there.
    """
    spec = importlib.util.spec_from_file_location(Path(filename).stem, EXAMPLES / filename)
    assert spec is not None and spec.loader is not None, filename
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module
