"""examples/ has a scenario file of every kind, each runs, and the flight's fields are the
ones docs/STUDIES.md 7 documents (issue 20 item 18)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from quadimpact import simulate
from quadimpact.inputs.scenarios import _KINDS, FlightScenario, load_scenario_file

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.toml"))


def test_there_is_an_example_of_every_scenario_kind() -> None:
    kinds = {load_scenario_file(path).kind for path in EXAMPLES}
    assert kinds == set(_KINDS), kinds


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_every_example_runs(path: Path) -> None:
    scenario = load_scenario_file(path)
    summary = simulate(scenario).summary
    assert summary["status"] in ("completed", "crashed"), summary["reason"]
    assert summary["delta_init_m"] is not None  # each example hits its obstacle
    assert not [w for w in summary["warnings"] if "IMU" in w or "penetration" in w]


def test_the_flight_fields_are_documented() -> None:
    text = (ROOT / "docs/STUDIES.md").read_text(encoding="utf-8")
    section = text[text.index("## 7. Flights"):]
    table = set(re.findall(r"^\| `\[*(\w+)\]*` \|", section, flags=re.M))
    own = set(FlightScenario.model_fields) - set(FlightScenario.__mro__[1].model_fields)
    assert own <= table | {"kind"}, own - table
    settings = set(FlightScenario.__mro__[1].model_fields)
    named = set(re.findall(r"`\[?(\w+)\]?`", section))
    assert settings <= named, settings - named
