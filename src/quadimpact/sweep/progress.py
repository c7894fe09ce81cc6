"""The sweep's progress bar on stderr."""

from __future__ import annotations

import contextlib
import math
import sys
import time
from typing import Any


# --------------------------------------------------------------- progress
class Progress:
    """Runs done / total, rate and time left, on stderr.

    On a terminal one line is redrawn in place (at most 10 times a second);
    otherwise at most five lines are printed (start, 25/50/75 % and the end;
    a resumed sweep skips the marks it had passed before). The rate and the
    time left count only the runs done since the bar started: until one is
    done they are unknown (``--``), not zero.
    """

    def __init__(self, total: int, done: int = 0, enabled: bool = True, stream: Any = None):
        self.stream = stream if stream is not None else sys.stderr
        self.total, self.done, self.start_done = total, done, done
        self.enabled = enabled and total > done
        isatty = getattr(self.stream, "isatty", None)
        self.tty = bool(isatty and isatty())
        self.t0 = time.monotonic()
        self.last = 0.0
        self.next_mark = 1  # the first of the 25/50/75 % marks not yet passed
        while self.next_mark <= 3 and done * 4 >= self.next_mark * total:
            self.next_mark += 1
        self.drawn = -1
        if self.enabled and self.tty:
            self._draw()
        if self.enabled and not self.tty:
            resumed = f", {done} already done" if done else ""
            todo = total - done
            self._print(f"sweep: {todo} run{'s' if todo != 1 else ''} to do{resumed}\n")

    def _print(self, text: str) -> None:
        with contextlib.suppress(Exception):
            self.stream.write(text)
            self.stream.flush()

    def _line(self) -> str:
        elapsed = time.monotonic() - self.t0
        ran = self.done - self.start_done
        rate = ran / elapsed if elapsed > 0 and ran > 0 else math.nan
        left = (self.total - self.done) / rate if rate > 0 else math.nan
        eta = "--:--" if math.isnan(left) else _clock(left)
        speed = "    --" if math.isnan(rate) else f"{rate:6.1f}"
        pct = 100.0 * self.done / self.total if self.total else 100.0
        return (
            f"sweep {self.done}/{self.total} runs ({pct:3.0f}%)  {speed} runs/s  "
            f"elapsed {_clock(elapsed)}  left {eta}"
        )

    def update(self, n: int) -> None:
        self.done += n
        if not self.enabled:
            return
        now = time.monotonic()
        if self.tty:
            if now - self.last >= 0.1 or self.done >= self.total:
                self.last = now
                self._draw()
        else:
            while self.next_mark <= 3 and self.done * 4 >= self.next_mark * self.total:
                self.next_mark += 1
                if self.done < self.total:
                    self._print(self._line() + "\n")

    def note(self, line: str) -> None:
        """Print a message line on the stream (even when the bar is off), then the bar again."""
        if self.enabled and self.tty:
            self._print("\r\x1b[K" + line + "\n")
            self._draw()
        else:
            self._print(line + "\n")

    def _draw(self) -> None:
        self.drawn = self.done
        self._print("\r" + self._line() + "\x1b[K")

    def close(self) -> None:
        if not self.enabled:
            return
        if not self.tty:
            self._print(self._line() + "\n")
        elif self.drawn == self.done:
            self._print("\n")
        else:
            self._print("\r" + self._line() + "\x1b[K\n")
        self.enabled = False


def _clock(seconds: float) -> str:
    s = int(round(seconds))
    h, rem = divmod(s, 3600)
    m, s = divmod(rem, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"
