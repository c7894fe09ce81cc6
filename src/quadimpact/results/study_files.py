"""What every Monte Carlo study folder holds beside its sweep: ``study.json`` and ``report.md``.

The recovery study and the pole study write the same two files the same way:
``study.json`` (what the study was, every invocation that ran trials of it,
its numbers) and ``report.md``, each atomically.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from quadimpact.results.files import atomic_write, to_jsonable

__all__ = ["REPORT_MD", "STUDY_JSON", "sweep_history", "write_report", "write_study_json"]

STUDY_JSON = "study.json"
REPORT_MD = "report.md"


def sweep_history(out: Path, run: dict[str, Any]) -> list[dict[str, Any]]:
    """The invocations that ran trials of this study: ``study.json``'s, then this one's.

    ``run`` holds this invocation's ``n_already_done``, ``n_ran``, ``sweep_s``
    (s) and ``backend``; an invocation that ran nothing adds nothing.
    """
    history: list[dict[str, Any]] = []
    path = out / STUDY_JSON
    if run["n_already_done"] and path.is_file():
        try:
            history = list(json.loads(path.read_text(encoding="utf-8")).get("sweeps") or [])
        except (OSError, ValueError):
            history = []
    if run["n_ran"]:
        history.append({k: run[k] for k in ("n_ran", "sweep_s", "backend")})
    return history


def write_study_json(out: Path, description: dict[str, Any]) -> Path:
    """Write ``description`` to ``out/study.json`` (sorted keys, NumPy values as plain)."""
    text = json.dumps(description, indent=1, sort_keys=True, default=to_jsonable) + "\n"
    return atomic_write(out / STUDY_JSON, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def write_report(out: Path, markdown: str) -> Path:
    """Write the study's ``out/report.md``."""
    return atomic_write(out / REPORT_MD, lambda tmp: tmp.write_text(markdown, encoding="utf-8"))
