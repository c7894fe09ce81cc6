"""Command-line options shared by several commands."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import click


def parallel_options(command: Callable[..., Any]) -> Callable[..., Any]:
    """Add ``--workers N``, ``--scheduler tcp://HOST:PORT`` and ``--no-progress``."""
    options = [
        click.option(
            "--workers",
            type=click.IntRange(min=1),
            metavar="N",
            help="Local worker processes (1: in this process). [default: all cores, after "
            "a start in this process; a sweep that takes under a second stays in it]",
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


def out_option(default: str, help: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """``--out FOLDER`` with a default folder (shown in ``--help``)."""
    return click.option(
        "--out",
        type=click.Path(file_okay=False, path_type=Path),
        default=Path(default),
        show_default=True,
        help=help,
    )


class RegistryChoice(click.ParamType):
    """A choice among names known only when the simulator is loaded (validated lazily).

    ``names`` is called when a value is converted or the help is shown, so a
    controller registered at run time (``quadimpact.inputs.controllers``) is a
    valid choice, and ``quadimpact --help`` imports nothing heavy.
    """

    def __init__(self, what: str, names: Callable[[], tuple[str, ...]]) -> None:
        self.name = what
        self._names = names

    def get_metavar(self, param: click.Parameter, ctx: click.Context | None = None) -> str:
        return "[" + "|".join(self._names()) + "]"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        names = self._names()
        if value in names:
            return value
        from quadimpact.errors import near_miss

        close = near_miss(str(value), names)
        hint = f"; did you mean {close!r}?" if close else ""
        known = ", ".join(repr(n) for n in names)
        self.fail(f"{value!r} is not one of {known}{hint}", param, ctx)


def controller_names() -> tuple[str, ...]:
    """Every registered controller (the registry is imported here, lazily)."""
    from quadimpact.inputs.controllers import controller_names as names

    return names()


def model_names() -> tuple[str, ...]:
    """Every model variant."""
    from quadimpact.inputs.model import MODEL_VARIANTS

    return tuple(MODEL_VARIANTS)


CONTROLLER = RegistryChoice("controller", controller_names)
MODEL = RegistryChoice("model", model_names)
