"""Lines that several commands print after a sweep or a study: what ran, and where its files are."""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["file_lines", "ran_text"]


def ran_text(info: dict[str, Any]) -> str:
    """What a sweep ran now, from its run information ``info`` (``run_sweep``'s): its runs
    with their time (s) and where they went, and those done before; or that it had nothing
    left to run."""
    if info["n_ran"] == 0:
        return "all done before, nothing to run"
    before = f", {info['n_already_done']} done before" if info["n_already_done"] else ""
    return f"{info['n_ran']} run now in {info['elapsed_s']:.1f} s, {info['backend']}{before}"


def file_lines(table: Path, report: Path, elapsed_s: float) -> list[str]:
    """A study's closing lines: its table, its report and the time it took (s)."""
    return [
        f"table     {table}",
        f"report    {report}",
        f"time      {elapsed_s:.1f} s",
    ]
