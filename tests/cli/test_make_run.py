"""``make run DATA=DIR`` reaches ``quadimpact reproduce --data DIR`` (issue 60, item 3).

``make -n`` prints the commands without running them, so this costs nothing.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.skipif(shutil.which("make") is None, reason="no make on this machine")


def reproduce_line(*args: str, env: dict[str, str] | None = None) -> str:
    """The ``quadimpact reproduce`` command line ``make -n run ARGS`` would run."""
    environ = {k: v for k, v in os.environ.items() if k not in ("DATA", "MAKEFLAGS")}
    environ.update(env or {})
    done = subprocess.run(
        ["make", "-n", "-C", str(ROOT), "run", *args],
        capture_output=True, text=True, env=environ, check=True,
    )  # fmt: skip
    lines = [line for line in done.stdout.splitlines() if "quadimpact reproduce" in line]
    assert len(lines) == 1, done.stdout
    return lines[0]


def test_make_run_data_becomes_reproduces_data_option():
    assert reproduce_line("DATA=/some/logs").endswith('--out results/paper --data "/some/logs"')
    assert reproduce_line("DATA=/with space").endswith('--data "/with space"')


def test_make_run_without_data_leaves_the_search_to_reproduce():
    assert "--data" not in reproduce_line()
    # A DATA of the environment is too common a name to be read; QUADIMPACT_DATA is its route.
    assert "--data" not in reproduce_line(env={"DATA": "/elsewhere"})
