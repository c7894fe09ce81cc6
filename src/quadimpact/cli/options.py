"""Command-line options shared by several commands."""

from __future__ import annotations

import contextlib
import functools
import math
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import click

from quadimpact.errors import InputError, format_value


def allow_large_option(command: Callable[..., Any]) -> Callable[..., Any]:
    """Add ``--allow-large``: confirm more than a million runs (checked before any planning)."""
    from quadimpact.sweep.values import LARGE_RUNS

    return click.option(
        "--allow-large",
        is_flag=True,
        help=f"Confirm a study of more than {LARGE_RUNS:,} runs (refused otherwise, at once).",
    )(command)


SENSORS_HELP = (
    "A preset of sensors: impact = the noisy IMU with the impact disturbance and a gyro bias "
    "walk; indoor = impact + magnetometer + pose sensor; onboard = impact + magnetometer, "
    "barometer, rangefinder, optical flow; or a preset a plug-in registers (--plugin)."
)


def sensing_options(estimator_help: str, sensors_help: str = SENSORS_HELP) -> Decorator:
    """Add ``--estimator NAME`` (a built-in or registered one) and ``--sensors PRESET``
    (the studies' presets of sensors); both default to None (not given)."""
    from quadimpact.studies.recovery import ESTIMATORS, SENSORS

    # a name, checked by the study once the plug-ins (--plugin) have registered theirs
    def add(command: Callable[..., Any]) -> Callable[..., Any]:
        command = click.option("--sensors", metavar="|".join(SENSORS), help=sensors_help)(command)
        return click.option("--estimator", metavar="|".join(ESTIMATORS), help=estimator_help)(
            command
        )

    return add


def plugin_option(command: Callable[..., Any]) -> Callable[..., Any]:
    """Add ``--plugin FILE.py|MODULE`` (repeatable), imported before the command runs.

    A plug-in registers controllers, estimators, sensor components, presets of
    sensors or obstacle shapes (docs/howto). Each is imported in this process
    and named in ``QUADIMPACT_PLUGINS`` so that the worker processes of the
    command's sweeps import it too. A file that is missing or raises on import
    is refused in one line (exit status 2).
    """

    @functools.wraps(command)
    def loaded(*args: Any, **kwargs: Any) -> Any:
        refs = kwargs.pop("plugins", ()) or ()
        if refs:
            from quadimpact.inputs.plugins import add_to_env, load_plugin

            for ref in refs:  # before anything names what they register
                load_plugin(ref)
                add_to_env(ref)
        return command(*args, **kwargs)

    return click.option(
        "--plugin",
        "plugins",
        multiple=True,
        metavar="FILE.py|MODULE",
        help="Import this file or module first (repeatable): what it registers (a controller, "
        "an estimator, a sensor, a preset of sensors, an obstacle shape) can then be named, "
        "in this process and in the sweeps' worker processes.",
    )(loaded)


def policy_option(command: Callable[..., Any]) -> Callable[..., Any]:
    """Add ``--policy learned|FILE``: a learned residual on the recovery law (None: not given)."""
    return click.option(
        "--policy",
        metavar="learned|learned-imu|FILE",
        help="Fly the recovery law with a learned residual (docs/LEARNING.md 15): learned = "
        "the policy shipped with quadimpact (learned-imu: the one before it, docs/LEARNING.md "
        "12), or a .npz policy file of your own. The study "
        "records the policy and its weights' SHA-256. [default: the law alone]",
    )(command)


def parallel_options(command: Callable[..., Any]) -> Callable[..., Any]:
    """Add ``--workers N``, ``--scheduler tcp://HOST:PORT`` and ``--no-progress``.

    Both are checked before the command starts any work: ``--workers`` and
    ``--scheduler`` together are refused, and a scheduler address must be
    ``SCHEME://HOST:PORT``; a ``tcp://`` one must accept a connection.
    ``--workers`` above 4 per core is capped there, with a warning.
    """

    @functools.wraps(command)
    def checked(*args: Any, **kwargs: Any) -> Any:
        scheduler = kwargs.get("scheduler")
        if scheduler is not None:
            if kwargs.get("workers") is not None:
                raise InputError("--workers and --scheduler: give one or the other")
            check_scheduler(scheduler)
        if kwargs.get("workers") is not None:
            from quadimpact.sweep.runner import cap_workers

            kwargs["workers"], note = cap_workers(kwargs["workers"])
            if note:
                click.echo(f"quadimpact: warning: {note}", err=True)
        return command(*args, **kwargs)

    options = [
        click.option(
            "--workers",
            type=click.IntRange(min=1),
            metavar="N",
            help="Local worker processes (1: in this process; at most 4 per core, more is "
            "capped). [default: all cores, after a start in this process; a sweep that takes "
            "under a second stays in it]",
        ),
        click.option(
            "--scheduler",
            metavar="tcp://HOST:PORT",
            help="Run on an existing Dask cluster instead of local processes "
            "(needs pip install 'quadimpact[distributed]').",
        ),
        click.option("--no-progress", is_flag=True, help="Do not show the progress bar."),
    ]
    wrapped: Callable[..., Any] = checked
    for option in reversed(options):
        wrapped = option(wrapped)
    return wrapped


#: Default of --max-record-mb (``simulation.checks.MAX_RECORD_MB``, kept here so that
#: ``--help`` imports nothing heavy; a test checks that the two agree).
MAX_RECORD_MB = 1024.0


def max_record_option(help: str) -> Decorator:
    """``--max-record-mb MB``: the largest record a run may allocate (``run``, ``sweep``)."""
    return click.option(
        "--max-record-mb",
        type=FiniteFloat(min=0, min_open=True),
        default=MAX_RECORD_MB,
        show_default=True,
        metavar="MB",
        help=help,
    )


def check_scheduler(address: str, timeout_s: float = 5.0) -> None:
    """Refuse a Dask scheduler address that is malformed or (``tcp://``) not listening.

    Raises
    ------
    InputError
        One line naming ``--scheduler`` and what is wrong.
    """
    import socket
    from urllib.parse import urlsplit

    form = "must be an address like tcp://HOST:PORT"
    try:
        parts = urlsplit(address)
        port = parts.port
    except ValueError:
        parts, port = None, None
    if parts is None or not parts.scheme or not parts.hostname or port is None:
        raise InputError(f"--scheduler: {form} (got {format_value(address)})")
    if parts.scheme != "tcp":
        return
    try:
        socket.create_connection((parts.hostname, port), timeout=timeout_s).close()
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise InputError(
            f"--scheduler {address}: no Dask scheduler answers there ({reason})"
        ) from None


Decorator = Callable[[Callable[..., Any]], Callable[..., Any]]


class FiniteFloat(click.FloatRange):
    """A number that must be finite (``nan`` and ``inf`` refused), optionally in a range.

    Parameters are those of :class:`click.FloatRange` (no range by default).
    Every numeric flag of the commands takes this type, so that no NaN reaches
    a camera, a clock or a scenario.
    """

    name = "number"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        number = super().convert(value, param, ctx)  # the range check (NaN passes it)
        if not math.isfinite(number):
            self.fail(f"{format_value(str(value))} is not a finite number", param, ctx)
        return number

    def _describe_range(self) -> str:
        """The range shown in ``--help`` (nothing without one)."""
        if self.min is None and self.max is None:
            return ""
        return super()._describe_range()

    def __repr__(self) -> str:
        return "FiniteFloat" if self.min is None and self.max is None else super().__repr__()


FINITE = FiniteFloat()


class Count(click.ParamType):
    """A whole number from ``min`` to ``max`` (``250``, or ``1e3`` written as a number).

    Anything else, ``1e12`` beyond the limit included, is quadimpact's own
    one-line input error naming the flag, the rule and the limit (not Click's
    "not a valid integer range").

    Parameters
    ----------
    min, max : int
        The range, both included.
    unit : str
        What is counted, for the message (``"trials"``).
    """

    name = "integer"

    def __init__(self, min: int, max: int, unit: str) -> None:
        self.min, self.max, self.unit = min, max, unit

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        if isinstance(value, int) and not isinstance(value, bool):
            n: int | None = value
        else:
            n = _whole(str(value).strip())
        if n is None or not self.min <= n <= self.max:
            flag = param.opts[0] if param is not None and param.opts else "value"
            raise InputError(
                f"{flag}: must be a whole number of {self.unit} from {self.min:,} to "
                f"{self.max:,} (got {format_value(str(value))})"
            )
        return n


def _whole(text: str) -> int | None:
    """``text`` as a whole number (``"1e3"``: 1000), None if it is not one."""
    try:
        return int(text)
    except ValueError:
        pass
    try:
        x = float(text)
    except ValueError:
        return None
    return int(x) if math.isfinite(x) and x == int(x) else None


def number_option(
    flag: str, metavar: str | None, help: str, type: Any = FINITE, *, alias: str | None = None
) -> Decorator:
    """``FLAG NUMBER`` without a default: ``None`` when not given (the help says the default).

    ``alias``: a second name of the flag (``--heading-deg`` beside ``--heading``);
    the value keeps the name of ``flag``.
    """
    name = flag.lstrip("-").replace("-", "_")
    decls = (flag, alias, name) if alias else (flag, name)
    return click.option(*decls, type=type, metavar=metavar, help=help)


def defaulted_option(flag: str, type: Any, default: Any, help: str) -> Decorator:
    """``FLAG VALUE`` with a default shown in ``--help``."""
    return click.option(flag, type=type, default=default, show_default=True, help=help)


def file_argument(name: str, metavar: str) -> Decorator:
    """An optional input file argument (``SCENARIO.toml``, ``SWEEP.toml``)."""
    return click.argument(
        name, required=False, metavar=metavar, type=click.Path(dir_okay=False, path_type=Path)
    )


def result_dir_argument(command: Callable[..., Any]) -> Callable[..., Any]:
    """The ``RESULT_DIR`` argument: a folder written by ``quadimpact run``."""
    return click.argument("result_dir", metavar="RESULT_DIR", type=click.Path(path_type=Path))(
        command
    )


data_option: Decorator = click.option(
    "--data",
    type=click.Path(file_okay=False, path_type=Path),
    help="Folder of the crash set's data (spiri-crash-set-1/crash_N.mat); a folder given here "
    "must hold the logs. [default: $QUADIMPACT_DATA when set (then only it), else "
    "shared/data or ../shared/data under the working folder, else ../shared/data beside "
    "the source checkout; without logs the comparisons with them are left out] The folder "
    "used is printed.",
)
"""``--data FOLDER``: the crash set's flight data (``experiments``, ``reproduce``)."""


def out_option(default: str, help: str) -> Decorator:
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


# ---------------------------------------------------------- stopping a study
RESUME = "run the same command again to resume"


def stopped(exc: BaseException, out: Path | None = None) -> int:
    """Say why a study stopped, what is saved, that a rerun resumes; return the exit status.

    ``exc``: a ``SweepInterrupted`` (Ctrl-C: 130, SIGTERM: 143) or a
    ``WorkerError`` (1). A sweep's interruption knows how many runs it saved
    and where; any other part of a study (a crash run on a worker, the
    report) says that the finished sweeps are kept in ``out``.
    """
    from quadimpact.sweep import SweepInterrupted
    from quadimpact.sweep.interrupt import signal_name

    if out is not None:
        from quadimpact.results.files import remove_stale_temporaries

        remove_stale_temporaries(out)  # a worker stopped while writing leaves none behind
    if getattr(exc, "saved", None) is not None:
        resume = f"{exc.saved} of {exc.n_runs} runs saved in {exc.out_dir}; {RESUME}"
    elif out is not None and out.is_dir() and any(out.iterdir()):
        resume = f"every finished sweep is saved in {out}; {RESUME}"
    elif out is not None:
        resume = f"nothing was saved yet ({out} was not written)"
    else:
        resume = RESUME
    if isinstance(exc, SweepInterrupted):
        click.echo(f"quadimpact: interrupted by {signal_name(exc.signum)}: {resume}", err=True)
        return exc.exit_code
    click.echo(f"quadimpact: error: {getattr(exc, 'cause', exc)}; {resume}", err=True)
    return 1


@contextlib.contextmanager
def stoppable(out: Path | None = None) -> Iterator[None]:
    """Ctrl-C and SIGTERM stop a study command as they stop ``quadimpact sweep``.

    The first signal stops the work at once (every finished run kept), later
    ones are ignored until the program has ended; the command then says what
    was saved and how to resume, and exits with 130 (Ctrl-C) or 143
    (SIGTERM); a worker that failed the study exits with 1.
    """
    from quadimpact.sweep import SweepInterrupted, WorkerError
    from quadimpact.sweep.interrupt import stop_signals

    with stop_signals(restore_after_stop=False):
        try:
            yield
        except (SweepInterrupted, WorkerError) as exc:
            raise click.exceptions.Exit(stopped(exc, out)) from None
