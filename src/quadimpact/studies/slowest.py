"""A study's slowest trials: what each cost and why (steps, rejected steps, contact onsets).

Every study reports its slowest trials (issue 59), so that a trial costing many times the
median is seen, with what the integrator did: its accepted and rejected steps and its contact
onsets (the episodes). A trial that would exceed the kernel's step budget ends as ``failed``
with the reason "step budget exhausted" (docs/NUMERICS.md, "Step budget"); one whose contact
chatters (more than 64 events in a control interval) ends sooner, failed as an "event storm"
(docs/NUMERICS.md, "Event budget").
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import pandas as pd  # loaded by the functions that take a table: not at import

__all__ = ["SLOWEST_N", "slowest_lines", "slowest_trials"]

#: How many of the slowest trials a report lists.
SLOWEST_N = 5
# the compiled loop's CPU first (the total adds the scenario's preparation and summary)
_CPU = ("cost__kernel_cpu_s", "cost__total_cpu_s")  # the first the table has
_COUNTS = {
    "steps": "integrator__steps",
    "rejected_steps": "integrator__rejected_steps",
    "contact_onsets": "n_episodes",
}


def _number(value: Any) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        return float("nan")


def slowest_trials(
    table: pd.DataFrame, ids: Sequence[str] = ("run_id",), n: int = SLOWEST_N
) -> dict[str, Any] | None:
    """The ``n`` trials of ``table`` (one row a trial) that cost the most CPU.

    Parameters
    ----------
    table : DataFrame
        A sweep's rows: the CPU columns (``cost__kernel_cpu_s``, the
        compiled loop's, else ``cost__total_cpu_s``, s), and where present the step counts
        (``integrator__steps``, ``integrator__rejected_steps``), the contact
        onsets (``n_episodes``), ``status`` and ``reason``.
    ids : sequence of str
        The columns naming a trial (those present are kept).
    n : int
        How many trials.

    Returns
    -------
    dict or None
        ``{"cpu_column", "median_cpu_ms", "trials": [...]}``, each trial its ids,
        ``cpu_ms``, ``times_median``, ``steps``, ``rejected_steps``,
        ``contact_onsets``, ``status`` and ``reason`` (JSON-able); ``None``
        when the table has no CPU column or no row.
    """
    import pandas as pd

    column = next((c for c in _CPU if c in table.columns), None)
    if column is None or len(table) == 0:
        return None
    cpu = pd.to_numeric(table[column], errors="coerce").to_numpy(dtype=float)
    if not np.isfinite(cpu).any():
        return None
    median = float(np.nanmedian(cpu))
    order = np.argsort(-np.nan_to_num(cpu, nan=-np.inf), kind="stable")[:n]
    trials = []
    for i in order:
        row = table.iloc[int(i)]
        trial: dict[str, Any] = {k: row[k].item() if hasattr(row[k], "item") else row[k]
                                 for k in ids if k in table.columns}  # fmt: skip
        trial["cpu_ms"] = 1e3 * float(cpu[i])
        trial["times_median"] = float(cpu[i] / median) if median > 0.0 else float("nan")
        for key, col in _COUNTS.items():
            value = _number(row[col]) if col in table.columns else float("nan")
            trial[key] = int(value) if np.isfinite(value) else None
        for key in ("status", "reason"):
            trial[key] = str(row[key]) if key in table.columns and pd.notna(row[key]) else ""
        trials.append(trial)
    return {"cpu_column": column, "median_cpu_ms": 1e3 * median, "trials": trials}


def _cell(value: Any) -> str:
    if value is None:
        return "–"
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def slowest_lines(slowest: dict[str, Any] | None, title: str = "## Slowest trials") -> list[str]:
    """The Markdown section of :func:`slowest_trials` (none when ``slowest`` is ``None``)."""
    if not slowest or not slowest["trials"]:
        return []
    trials = slowest["trials"]
    ids = [k for k in trials[0] if k not in _TRIAL_KEYS]
    lines = [
        title,
        "",
        f"CPU per trial ({slowest['cpu_column']}): median {slowest['median_cpu_ms']:.1f} ms. "
        "Steps: accepted and rejected integration steps. Onsets: contact onsets (episodes). "
        "Each process loads the compiled code before its first trial, apart from the trials.",
        "",
        "| " + " | ".join([*ids, "CPU (ms)", "x median", "steps", "rejected", "onsets",
                          "status"]) + " |",
        "|" + "---|" * (len(ids) + 6),
    ]  # fmt: skip
    for t in trials:
        status = t["status"] + (f" ({t['reason']})" if t["reason"] else "")
        cells = [*(_cell(t[k]) for k in ids), f"{t['cpu_ms']:.1f}", f"{t['times_median']:.1f}",
                 _cell(t["steps"]), _cell(t["rejected_steps"]), _cell(t["contact_onsets"]),
                 status]  # fmt: skip
        lines.append("| " + " | ".join(cells) + " |")
    lines.append("")
    return lines


_TRIAL_KEYS = ("cpu_ms", "times_median", *_COUNTS, "status", "reason")
