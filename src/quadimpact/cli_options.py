"""Command-line options shared by the commands that run sweeps."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import click


def parallel_options(command: Callable[..., Any]) -> Callable[..., Any]:
    """Add ``--workers N``, ``--scheduler tcp://HOST:PORT`` and ``--no-progress``."""
    options = [
        click.option(
            "--workers",
            type=click.IntRange(min=1),
            metavar="N",
            help="Local worker processes (1: in this process). [default: all cores]",
        ),
        click.option(
            "--scheduler",
            metavar="tcp://HOST:PORT",
            help="Run on an existing Dask cluster instead of local processes "
            "(needs pip install 'quadimpact[distributed]').",
        ),
        click.option("--no-progress", is_flag=True, help="Do not show the progress bar."),
    ]
    for option in reversed(options):
        command = option(command)
    return command
