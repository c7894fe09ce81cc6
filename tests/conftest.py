"""Test markers (registered in pyproject.toml; the default run runs them all).

``slow``: more than about 5 s; ``data``: needs the shared flight data (skipped,
saying so, when it is absent); ``browser``: needs headless Chromium (skipped,
saying so, when it is absent; see ``tests/viz/test_viz.py``). Deselect with
e.g. ``pytest -m "not slow and not data"``.
"""

from __future__ import annotations

import signal
import warnings
from collections.abc import Iterator
from pathlib import Path

import pytest

from quadimpact.experiments.logs import DATA_ENV_VAR, data_dir

from helpers import short_tmpdir

DATA_MISSING = (
    f"shared crash data absent (set {DATA_ENV_VAR} to the folder holding "
    "spiri-crash-set-1/ and spiri_crash_set_1.toml, or put it in ../shared/data)"
)


def pytest_sessionstart(session: pytest.Session) -> None:
    """Compile the simulator once, in this process, before any test.

    On a fresh checkout Numba's cache is cold: the first test to simulate would
    compile the loop (about 2 min of CPU on 2 cores), and a command-line test
    doing it in a subprocess would run past its time limit. Compiled here, the
    on-disk cache serves every later process.
    """
    from quadimpact import ImpactTrial, WallApproach, simulate

    simulate(WallApproach(final_time_s=0.6))
    simulate(ImpactTrial(final_time_s=0.05))


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if data_dir() is not None:
        return
    skip = pytest.mark.skip(reason=DATA_MISSING)
    for item in items:
        if item.get_closest_marker("data") is not None:
            item.add_marker(skip)


@pytest.fixture(autouse=True)
def stop_signal_handlers_restored(request: pytest.FixtureRequest) -> Iterator[None]:
    """Each test leaves SIGINT and SIGTERM handled as it found them.

    A sweep handles these signals only where Python's defaults are in place
    (``sweep/interrupt.py``); a handler left behind by one test (a library's,
    or ``SIG_IGN``) would make a later stop-signal test's sweep ignore its
    signal and run on. A test that leaves one behind is named in a warning.
    """
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    yield
    for signum, handler in before.items():
        now = signal.getsignal(signum)
        if now is not handler:
            signal.signal(signum, handler)
            warnings.warn(
                f"{request.node.nodeid} left the {signal.Signals(signum).name} handler {now!r}",
                stacklevel=1,
            )


@pytest.fixture
def python_sigint() -> Iterator[None]:
    """Python's own SIGINT handler during the test (a test that interrupts itself).

    The tests may run where SIGINT is ignored (started in the background by a
    non-interactive shell, or under ``nohup``: Python then keeps ignoring it),
    and a sweep handles only what Python installs by default
    (``sweep/interrupt.py``): the test gets what a terminal's foreground job has.
    """
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, before)


@pytest.fixture
def tmpdir_env() -> Iterator[Path]:
    """A short private folder for a command's ``TMPDIR`` (``helpers.short_tmpdir``)."""
    with short_tmpdir() as path:
        yield path
