"""``examples/benchmark_controller.py`` states its time as measured (issue 60 item 6): the
wall time of a run, cold (the reference rows computed too) and warm, with the machine it
ran on, not an estimate."""

from __future__ import annotations

import ast
import re
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "benchmark_controller.py"


def test_the_benchmark_example_states_its_time_as_measured() -> None:
    doc = ast.get_docstring(ast.parse(EXAMPLE.read_text(encoding="utf-8"))) or ""
    text = " ".join(doc.split())
    assert "Measured" in text, text
    times = re.findall(r"(\d[\d,]*) s \(", text)  # "1,079 s (18 min ...)"
    assert len(times) >= 2, text  # the first run and a run with the references cached
    assert "2-core" in text and "load average" in text
    assert not re.search(r"\babout (two|\d+) (minutes|s)\b", text), text  # no guesses
