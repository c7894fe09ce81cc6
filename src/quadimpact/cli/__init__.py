"""Command-line interface: the ``quadimpact`` group, one module per command.

* :mod:`~quadimpact.cli.run_command`: ``quadimpact run``;
* :mod:`~quadimpact.cli.sweep_command`: ``quadimpact sweep``;
* :mod:`~quadimpact.cli.reproduce_command`: ``quadimpact reproduce``;
* :mod:`~quadimpact.cli.experiments_command`: ``quadimpact experiments``;
* :mod:`~quadimpact.cli.recovery_command`: ``quadimpact recovery``;
* :mod:`~quadimpact.cli.pole_command`: ``quadimpact pole``;
* :mod:`~quadimpact.cli.estimators_command`: ``quadimpact estimators``;
* :mod:`~quadimpact.cli.benchmark_command`: ``quadimpact benchmark``;
* :mod:`~quadimpact.cli.train_command`: ``quadimpact train``;
* :mod:`~quadimpact.cli.viz_commands`: ``quadimpact animate``, ``snapshots``, ``view``;
* :mod:`~quadimpact.cli.compile_command`: ``quadimpact compile``;
* :mod:`~quadimpact.cli.options`: options shared by several commands.

Heavy modules (pydantic, NumPy, the compiled core) are imported inside the
commands, so that ``quadimpact --help`` answers at once. Every input problem
ends the program with one line on stderr, ``quadimpact: error: ...``, and
exit status 2; set ``QUADIMPACT_DEBUG=1`` to see tracebacks. ``quadimpact
run`` exits with status 3 when the run failed numerically (its status is
``"failed"``).
"""

from __future__ import annotations

import logging
import os
import sys
import traceback
import warnings
from typing import Any

import click

from quadimpact.cli.benchmark_command import benchmark
from quadimpact.cli.compile_command import compile_command
from quadimpact.cli.estimators_command import estimators
from quadimpact.cli.experiments_command import experiments
from quadimpact.cli.pole_command import pole
from quadimpact.cli.recovery_command import recovery
from quadimpact.cli.reproduce_command import reproduce
from quadimpact.cli.run_command import build_scenario, format_summary, run
from quadimpact.cli.sweep_command import sweep
from quadimpact.cli.train_command import train
from quadimpact.cli.viz_commands import animate, snapshots, view
from quadimpact.errors import InputError, input_error_from_validation, one_line

__all__ = ["build_scenario", "cli", "format_summary", "main"]


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("quadimpact")
    except PackageNotFoundError:
        return str(getattr(sys.modules.get("quadimpact"), "__version__", "unknown"))


def _print_version(ctx: click.Context, _param: click.Parameter, value: bool) -> None:
    if value and not ctx.resilient_parsing:
        click.echo(f"quadimpact {_version()}")
        ctx.exit(0)


@click.group(context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100})
@click.option(
    "--version",
    is_flag=True,
    expose_value=False,
    is_eager=True,
    callback=_print_version,
    help="Print the version and exit.",
)
def cli() -> None:
    """Simulate a bumper-protected quadrotor colliding with its surroundings.

    quadimpact implements the model of "Dynamics of a quadrotor undergoing
    impact with a wall" (the Spiri quadrotor, Hunt-Crossley bumper contact,
    the authors' PID controller) with a physically consistent default model
    and a "paper-replica" variant that reproduces the authors' simulator;
    and what the paper was for: an IMU, impact detection and a staged
    recovery controller (the Navi quadrotor, 'quadimpact recovery', the
    "recovery-replica" variant of the authors' later simulator, and the
    "pole-replica" variant: their staged law as retuned for the pole study).

    Frames: inertial NED (X toward the wall, Y right, Z down; altitude = -Z),
    body FRD (x forward, y right, z down). Units: SI, angles in degrees.

    Exit status: 0 success; 1 an unexpected error (one line; set
    QUADIMPACT_DEBUG=1 for the traceback); 2 bad input (one line naming the
    flag, file or field); 3 'quadimpact run' of a run that failed numerically.

    Start with:  quadimpact run --help
    """


# ---- the commands, each in its own module: one registration line each ----
_COMMANDS = (
    run,
    animate,
    snapshots,
    view,
    sweep,
    reproduce,
    experiments,
    recovery,
    pole,
    estimators,
    benchmark,
    train,
)
for _command in (*_COMMANDS, compile_command):
    cli.add_command(_command)


def _fail(message: str, code: int) -> None:
    click.echo(f"quadimpact: error: {one_line(message)}", err=True)
    sys.exit(code)


def _show_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: Any = None,
    line: str | None = None,
) -> None:
    """A Python warning (NumPy, Matplotlib...) as one line, without its source line."""
    where = f"{os.path.basename(filename)}:{lineno}"
    click.echo(
        f"quadimpact: warning: {one_line(str(message))} ({category.__name__} at {where})",
        err=True,
    )


class _Notices(logging.Handler):
    """The ``quadimpact`` logger's notices (a first run's compilation) as lines on stderr."""

    def emit(self, record: logging.LogRecord) -> None:
        click.echo(one_line(record.getMessage()), err=True)


def _show_notices() -> None:
    logger = logging.getLogger("quadimpact")
    if not any(isinstance(h, _Notices) for h in logger.handlers):
        logger.addHandler(_Notices(logging.WARNING))
        logger.propagate = False


def main(argv: list[str] | None = None) -> None:
    """Entry point of the ``quadimpact`` command.

    Input errors (bad flag, value, file) print one line and exit with status 2;
    unexpected failures print one line and exit with status 1 (set
    ``QUADIMPACT_DEBUG=1`` for the traceback). A Python warning from a library
    (NumPy, Matplotlib) is printed as one line too, without its source line.

    Parameters
    ----------
    argv : list of str, optional
        Arguments; default ``sys.argv[1:]``.
    """
    debug = os.environ.get("QUADIMPACT_DEBUG", "") not in ("", "0")
    if not debug:
        warnings.showwarning = _show_warning
    _show_notices()
    try:
        code = cli.main(args=argv, prog_name="quadimpact", standalone_mode=False)
    except click.exceptions.NoArgsIsHelpError as exc:
        click.echo(exc.ctx.get_help() if exc.ctx else "quadimpact --help")
        code = 0
    except click.exceptions.UsageError as exc:
        if debug:
            traceback.print_exc()
        where = exc.ctx.command_path if exc.ctx else "quadimpact"
        _fail(f"{exc.format_message()} (see '{where} --help')", 2)
    except click.exceptions.Abort:
        _fail("aborted", 130)
    except click.ClickException as exc:
        _fail(exc.format_message(), exc.exit_code)
    except InputError as exc:
        if debug:
            traceback.print_exc()
        _fail(str(exc), 2)
    except KeyboardInterrupt:
        _fail("interrupted", 130)
    except Exception as exc:  # the last line of defence: one line, no traceback
        if debug:
            traceback.print_exc()
        pydantic = sys.modules.get("pydantic")
        if pydantic is not None and isinstance(exc, pydantic.ValidationError):
            _fail(str(input_error_from_validation(exc)), 2)
        _fail(
            f"unexpected {type(exc).__name__}: {exc} (set QUADIMPACT_DEBUG=1 to see the traceback)",
            1,
        )
    sys.exit(code if isinstance(code, int) else 0)
