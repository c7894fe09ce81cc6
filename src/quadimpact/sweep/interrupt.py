"""Stopping a sweep: Ctrl-C (SIGINT) and SIGTERM, however often they come.

While a sweep runs, :func:`stop_signals` replaces the default handlers of
SIGINT and SIGTERM. The first signal stops the sweep: in-process runs raise
:class:`SweepInterrupted` at once, the pool and Dask loops (which poll the
:class:`StopFlag` a few times a second) stop at their next look; every later
signal is only counted, so that the clean-up (stopping the workers, writing
the finished runs) is never cut short by a second Ctrl-C. A handler the
program installed itself (anything but Python's defaults) is left alone.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from types import FrameType

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class SweepInterrupted(KeyboardInterrupt):
    """A sweep stopped by SIGINT or SIGTERM; its finished runs are saved.

    Parameters
    ----------
    signum : int
        The signal that stopped it.
    message : str, optional
        What was saved and how to resume (set by ``run_sweep``).
    """

    def __init__(self, signum: int, message: str = "") -> None:
        super().__init__(message or f"sweep interrupted by {signal_name(signum)}")
        self.signum = signum

    @property
    def exit_code(self) -> int:
        """The shell's status for a program ended by this signal: 128 + the signal number."""
        return 128 + int(self.signum)


def signal_name(signum: int) -> str:
    """``SIGINT``, ``SIGTERM``... (the number for an unknown signal)."""
    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"


class StopFlag:
    """Whether a stop signal came (``signum``), and whether the next one raises at once.

    ``raising`` is True where the sweep's own code cannot poll (runs in this
    process); the pool and Dask loops set it to False and call :meth:`check`.
    """

    def __init__(self) -> None:
        self.signum: int | None = None
        self.count = 0
        self.raising = True

    def check(self) -> None:
        """Raise :class:`SweepInterrupted` if a stop signal came."""
        if self.signum is not None:
            raise SweepInterrupted(self.signum)

    @contextlib.contextmanager
    def polled(self) -> Iterator[None]:
        """Within this block a signal only sets the flag (the caller polls it)."""
        before, self.raising = self.raising, False
        try:
            yield
        finally:
            self.raising = before

    def _handle(self, signum: int, _frame: FrameType | None) -> None:
        self.count += 1
        if self.signum is not None:
            return  # already stopping: the clean-up runs to its end
        self.signum = signum
        if self.raising:
            raise SweepInterrupted(signum)


@contextlib.contextmanager
def stop_signals(restore_after_stop: bool = True) -> Iterator[StopFlag]:
    """Handle SIGINT and SIGTERM as a request to stop the sweep (see the module).

    Only in the main thread (elsewhere Python cannot install handlers: the
    flag is then never set) and only for signals whose handler is Python's
    default (``default_int_handler`` for SIGINT, ``SIG_DFL`` for SIGTERM).
    Inside another ``stop_signals`` block it shares that block's flag. The
    previous handlers are restored on exit, unless a signal came and
    ``restore_after_stop`` is False: a program about to end (the command
    line) then ignores these signals (``SIG_IGN``) until it has exited.
    """
    current = signal.getsignal(signal.SIGINT)
    outer = getattr(current, "__self__", None)
    if isinstance(outer, StopFlag):
        yield outer
        return
    flag = StopFlag()
    if threading.current_thread() is not threading.main_thread():
        yield flag
        return
    defaults = {signal.SIGINT: signal.default_int_handler, signal.SIGTERM: signal.SIG_DFL}
    previous = {}
    try:
        for signum in STOP_SIGNALS:
            if signal.getsignal(signum) is defaults[signum]:
                previous[signum] = signal.signal(signum, flag._handle)
        yield flag
    finally:
        for signum, handler in previous.items():
            if flag.signum is not None and not restore_after_stop:
                handler = signal.SIG_IGN  # (a Python handler would not outlive finalisation)
            signal.signal(signum, handler)
