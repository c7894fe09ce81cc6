"""The first use's compilation is said once, where it happens, and only after the inputs
are checked: the commands, the Python entry points, the learning environments, the
workers (silent: the process they work for says it) and ``quadimpact compile``.

A cold cache is an empty ``NUMBA_CACHE_DIR`` (``core.cache_is_warm`` looks there);
the loop this process already loaded is not compiled again, so these runs stay fast.
"""

from __future__ import annotations

import logging
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

import quadimpact.core as core
from quadimpact.cli import main

from helpers import cli_here

NOTICE = "quadimpact: compiling the simulator (first use only"


@pytest.fixture
def cold_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty Numba cache for ``cache_is_warm``, and a process that has said nothing yet."""
    cache = tmp_path / "numba-cache"
    cache.mkdir()
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(cache))
    monkeypatch.setattr(core, "_checked", set())
    assert not core.cache_is_warm()
    return cache


@pytest.fixture
def notices() -> Iterator[list[str]]:
    """What the ``quadimpact`` logger says (whatever handlers a command installed)."""
    said: list[str] = []

    class Keep(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            said.append(record.getMessage())

    logger = logging.getLogger("quadimpact")
    keep = Keep(logging.WARNING)
    logger.addHandler(keep)
    yield said
    logger.removeHandler(keep)


INVALID = [
    ["run", "--speed", "50"],
    ["sweep", "--grid", "speed_m_s=0.5,50"],
    ["recovery", "--vehicle", "nope", "--workers", "1"],
    ["pole", "--speed", "50", "--workers", "1"],
    ["experiments", "--data", "no-such-folder", "--workers", "1"],
    ["reproduce", "--data", "no-such-folder", "--workers", "1"],
]


@pytest.mark.parametrize("args", INVALID, ids=[a[0] for a in INVALID])
def test_an_invalid_input_is_refused_before_any_compile_notice(
    args: list[str], cold_cache: Path, tmp_path: Path, monkeypatch, capsys
) -> None:
    monkeypatch.chdir(tmp_path)
    code, err = cli_here(capsys, *args, "--out", "o")
    assert code == 2, err
    assert err.startswith("quadimpact: error: ") and "compiling" not in err, err


def test_an_invalid_sweep_with_an_empty_cache_prints_no_compile_notice(tmp_path: Path) -> None:
    """The issue's case, in a process of its own with a really empty Numba cache."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    proc = subprocess.run(
        [sys.executable, "-m", "quadimpact.cli", "sweep", "--grid", "speed_m_s=0.5,50",
         "--out", str(tmp_path / "o")],
        capture_output=True, text=True, timeout=120, env=env,
    )  # fmt: skip
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr == (
        "quadimpact: error: sweep: run 1 (speed_m_s=50.0): speed_m_s: must be <= 20 (got 50.0)\n"
    )


def test_a_sweep_says_it_compiles_once_before_its_runs_and_not_when_nothing_is_left(
    cold_cache: Path, tmp_path: Path, monkeypatch, capsys
) -> None:
    monkeypatch.chdir(tmp_path)
    args = ["sweep", "--grid", "inclination_deg=0,5,10", "--workers", "1", "--no-plots"]
    code, err = cli_here(capsys, *args, "--out", "o")
    assert code == 0, err
    lines = err.splitlines()
    assert sum(NOTICE in line for line in lines) == 1, err
    assert lines[0].startswith(NOTICE) and "`quadimpact compile`" in lines[0], err
    monkeypatch.setattr(core, "_checked", set())  # a new process, the same cold cache
    code, err = cli_here(capsys, *args, "--out", "o")
    assert code == 0 and "compiling" not in err, err


def test_the_python_entry_points_say_it_once_per_process(cold_cache: Path, notices) -> None:
    from quadimpact import ImpactTrial, Simulation, WallApproach, simulate, simulate_batch

    simulate(ImpactTrial(final_time_s=0.05))
    assert len(notices) == 1 and notices[0].startswith(NOTICE), notices
    Simulation(ImpactTrial(final_time_s=0.05))
    simulate_batch([WallApproach(final_time_s=0.6)])
    assert len(notices) == 1, notices
    core._checked.clear()  # another process
    simulate_batch([ImpactTrial(final_time_s=0.05)])
    assert len(notices) == 2, notices


def test_nothing_is_said_with_a_warm_cache_or_in_a_worker(
    cold_cache: Path, notices, monkeypatch
) -> None:
    from quadimpact import ImpactTrial, simulate

    core.silence_compilation_notice()  # what the sweeps' and studies' workers do
    simulate(ImpactTrial(final_time_s=0.05))
    assert notices == []
    monkeypatch.delenv("NUMBA_CACHE_DIR")  # this checkout's own cache: warm
    core._checked.clear()
    assert core.cache_is_warm()
    simulate(ImpactTrial(final_time_s=0.05))
    assert notices == []


def test_the_learning_environments_name_what_they_compile(cold_cache: Path, notices) -> None:
    pytest.importorskip("gymnasium")
    from numba.core.caching import UserProvidedCacheLocator

    from quadimpact.envs.single import ImpactRecoveryEnv

    ImpactRecoveryEnv()
    assert len(notices) == 1, notices
    seconds = sum(core.COMPILED_PARTS[p][2] for p in ("simulator", "environments"))
    assert notices[0].startswith(
        "quadimpact: compiling the simulator and the learning environments' loop (first use "
        f"only: about {seconds} s of CPU"
    ), notices
    # the simulator in the cache (its index file where Numba puts it), theirs not
    kernel_py = str(Path(core.__file__).parent / "kernel.py")
    where = cold_cache / UserProvidedCacheLocator.get_suitable_cache_subpath(kernel_py)
    where.mkdir(parents=True)
    (where / "step.advance-48.py311.nbi").write_bytes(b"")
    core._checked.clear()
    ImpactRecoveryEnv()
    assert len(notices) == 2 and notices[1].startswith(
        "quadimpact: compiling the learning environments' loop (first use only: about "
        f"{core.COMPILED_PARTS['environments'][2]} s"
    ), notices


def test_compile_says_what_it_found_in_the_cache(capsys) -> None:
    """This checkout's simulator is in the cache (the suite compiled it first): it is loaded."""
    try:
        main(["compile", "--no-environments"])
    except SystemExit as exc:
        assert not exc.code
    out = capsys.readouterr()
    assert out.out.startswith("simulator     loaded from the cache in "), out
    assert len(out.out.splitlines()) == 1 and out.err == "", out
