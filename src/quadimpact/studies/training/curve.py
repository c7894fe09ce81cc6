"""The learning curve of a training run (``curve.csv``, ``curve.png``) and its progress line."""

from __future__ import annotations

import csv
import io
import sys
from pathlib import Path
from typing import Any

from quadimpact.results.files import atomic_write

__all__ = ["CURVE_COLUMNS", "Progress", "plot_curve", "progress_bar", "write_curve"]

CURVE_COLUMNS = ("generation", "runs", "minutes", "batch_mean", "batch_best", "batch_law",
                 "sigma", "check_success", "check_score")  # fmt: skip


def write_curve(out: Path, curve: list[dict[str, Any]]) -> None:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CURVE_COLUMNS)
    for row in curve:
        w.writerow(["" if row.get(c) is None else _fmt(row[c]) for c in CURVE_COLUMNS])
    text = buf.getvalue()
    atomic_write(out / "curve.csv", lambda tmp: tmp.write_text(text, encoding="utf-8"))


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def plot_curve(curve_csv: Path, png: Path) -> Path:
    """The learning curve as a figure: above, the check set's success of the distribution's
    mean against the law's (generation 0); below, each generation's mean candidate reward
    minus the law's on the same training trials, and its 5-generation mean."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import pandas as pd

    c = pd.read_csv(curve_csv)
    fig, (top, low) = plt.subplots(2, 1, figsize=(7.0, 5.2), sharex=True,
                                   constrained_layout=True)  # fmt: skip
    check = c.dropna(subset=["check_success"])
    if len(check):
        top.plot(check["generation"], check["check_success"], "o-", color="C0", ms=3,
                 label="the policy (CMA-ES's mean): success on the check set")  # fmt: skip
        top.axhline(check["check_success"].iloc[0], color="C3", ls="--", lw=1,
                    label="the staged law on the check set")  # fmt: skip
    top.set_ylabel("benchmark success")
    top.legend(fontsize=8, loc="best", framealpha=0.8)
    top.grid(alpha=0.3)
    batch = c.dropna(subset=["batch_mean"])
    gain = batch["batch_mean"] - batch["batch_law"]
    low.plot(batch["generation"], gain, ".-", color="0.7", lw=0.8, ms=3,
             label="mean candidate minus the law, same trials")  # fmt: skip
    low.plot(batch["generation"], gain.rolling(5, min_periods=1).mean(), color="0.2", lw=1.5,
             label="the same, 5-generation mean")  # fmt: skip
    low.axhline(0.0, color="C3", ls="--", lw=1)
    low.set_xlabel("generation")
    low.set_ylabel("training reward\nminus the law's")
    low.legend(fontsize=8, loc="best", framealpha=0.8)
    low.grid(alpha=0.3)
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return png


class Progress:
    """One line on stderr: redrawn in place on a terminal, printed at each check otherwise."""

    def __init__(self, enabled: bool, stream: Any = None) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = enabled
        isatty = getattr(self.stream, "isatty", None)
        self.tty = bool(isatty and isatty())

    def show(self, text: str, checked: bool) -> None:
        if not self.enabled:
            return
        if self.tty:
            self.stream.write("\r" + text.ljust(110)[:110])
        elif checked:
            self.stream.write(text + "\n")
        self.stream.flush()

    def end(self) -> None:
        if self.enabled and self.tty:
            self.stream.write("\n")
            self.stream.flush()


def progress_bar(done: float, total: float, width: int = 20) -> str:
    k = int(width * min(max(done / total, 0.0), 1.0)) if total > 0 else width
    return "[" + "#" * k + "." * (width - k) + "]"
