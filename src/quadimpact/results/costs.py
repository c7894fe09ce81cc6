"""What a run cost: CPU time in the compiled loop and in the whole run.

Every summary carries a ``cost`` table (docs/RESULTS.md): ``kernel_cpu_s``,
the CPU time the run spent in compiled loops (its main run and, for a wall
approach, the approach's shooting runs), and ``total_cpu_s``, the CPU time of
the whole run from its scenario to its summary (a sweep's run: to its table
row). Both are CPU time of the thread that ran the run (``time.thread_time``),
so they measure the work, not how busy the machine was; they are the only
numbers of a summary or a sweep table that differ from one run of the same
scenario to the next. :func:`cost_ratio` is the ratio studies print: the
whole runs' CPU time over their compiled loops'.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from time import thread_time
from typing import Any

__all__ = ["COST_KEYS", "CpuClock", "cost_ratio", "cost_text", "cpu_time"]

cpu_time = thread_time
"""CPU time of this thread, s (what every cost is measured with)."""

COST_KEYS = ("cost__kernel_cpu_s", "cost__total_cpu_s")
"""The flattened summary keys (and sweep table columns) of a run's cost."""


class CpuClock:
    """Adds up the CPU time (of this thread) of the blocks it times: ``with clock: ...``."""

    __slots__ = ("total", "_start")

    def __init__(self) -> None:
        self.total = 0.0
        self._start = 0.0

    def __enter__(self) -> CpuClock:
        self._start = thread_time()
        return self

    def __exit__(self, *exc: object) -> None:
        self.total += thread_time() - self._start


def _column_sum(values: Iterable[Any]) -> tuple[float, int]:
    total, n = 0.0, 0
    for v in values:
        if v is not None and v == v:  # neither null nor NaN
            total += float(v)
            n += 1
    return total, n


def cost_ratio(table: Any) -> dict[str, float]:
    """The CPU time of a table's runs (a sweep's or a study's), whole and in the compiled loop.

    Parameters
    ----------
    table : pandas.DataFrame or mapping of columns
        With the columns :data:`COST_KEYS` (rows without them, failed runs
        for instance, are left out).

    Returns
    -------
    dict
        ``runs`` (the runs measured), ``kernel_cpu_s`` and ``total_cpu_s``
        (their sums, s) and ``ratio`` (total / kernel; NaN without any
        kernel time).
    """
    kernel_col, total_col = (table[k] if k in table else () for k in COST_KEYS)
    pairs = [
        (k, t)
        for k, t in zip(kernel_col, total_col, strict=False)
        if k is not None and t is not None and k == k and t == t
    ]
    kernel, n = _column_sum(k for k, _ in pairs)
    total, _ = _column_sum(t for _, t in pairs)
    return {
        "runs": n,
        "kernel_cpu_s": kernel,
        "total_cpu_s": total,
        "ratio": total / kernel if kernel > 0 else math.nan,
    }


def cost_text(cost: dict[str, float]) -> str:
    """One line on a table's CPU time (:func:`cost_ratio`) for reports."""
    if not cost["runs"]:
        return "no run measured"
    per_run = 1e3 * cost["total_cpu_s"] / cost["runs"]
    return (
        f"{cost['total_cpu_s']:.1f} s of CPU in {cost['runs']} runs ({per_run:.1f} ms each), "
        f"{cost['ratio']:.2f}x their compiled loop's {cost['kernel_cpu_s']:.1f} s"
    )
