"""One schema: every summary a run produces has exactly the schema's keys; the docs list them."""

from __future__ import annotations

from pathlib import Path

import pytest

from quadimpact import FlightScenario, ImpactTrial, WallApproach, simulate
from quadimpact.results.schema import SUMMARY_KEYS, TIMESERIES_COLUMNS
from quadimpact.results.summary_record import markdown_table, optional_keys
from quadimpact.sweep.store import SUMMARY_COLUMNS, flatten_summary

DOCS = Path(__file__).resolve().parents[2] / "docs" / "RESULTS.md"
SCHEMA = {k.name for k in SUMMARY_KEYS}


def _flat(summary, prefix=""):
    keys = set()
    for k, v in summary.items():
        name = f"{prefix}__{k}" if prefix else k
        if isinstance(v, dict):
            keys |= _flat(v, name)
        else:
            keys.add(name)
    return keys


SCENARIOS = {
    "wall-approach": WallApproach(heading_deg=45, inclination_deg=15, final_time_s=1.5),
    "wall-approach, recovery": WallApproach(
        heading_deg=45, inclination_deg=15, final_time_s=1.5, controller="recovery"
    ),  # fmt: skip
    "flight": FlightScenario(
        final_time_s=0.5,
        surfaces=({"name": "slope", "point_m": (0.3, 0, 0), "normal": (-1, 0, -0.5)},),
    ),  # fmt: skip
    "impact-trial": ImpactTrial(roll_deg=5, pitch_deg=-30, yaw_deg=20, speed_m_s=1.5),
}


@pytest.mark.parametrize("name", list(SCENARIOS))
def test_summaries_have_only_schema_keys(name):
    summary = simulate(SCENARIOS[name]).summary
    keys = _flat(summary)
    assert keys <= SCHEMA, f"summary keys missing from the schema: {sorted(keys - SCHEMA)}"
    # what is always there: everything but the kind-specific tables
    optional = optional_keys() - {k for k in SCHEMA if k.startswith("attitude_excursion__")}
    assert optional == {k for k in SCHEMA if k.split("__")[0] in ("approach", "requested")} | {
        "wall_distance_m", "crash_distance_from_wall_m"
    }  # fmt: skip
    absent = sorted(SCHEMA - optional - keys)
    assert not absent, f"schema keys not produced: {absent}"
    row = flatten_summary(summary)
    assert row["summary_extra"] is None


def test_sweep_columns_derive_from_the_schema():
    names = [k.name for k in SUMMARY_KEYS if k.name != "integrator__wall_time_s"]
    assert [c for c, _ in SUMMARY_COLUMNS] == [*names, "summary_extra"]
    assert {kind for _, kind in SUMMARY_COLUMNS} <= set("fibsj")


def test_results_doc_lists_every_key_and_column():
    text = DOCS.read_text(encoding="utf-8")
    missing = [k.name for k in SUMMARY_KEYS if f"`{k.name}`" not in text]
    # per-bumper columns are written as ranges (`delta1_m`..`delta4_m`): the ends suffice
    missing += [c for c in TIMESERIES_COLUMNS if f"`{c}`" not in text and not any(
        d in c for d in "23")]  # fmt: skip
    assert not missing, f"docs/RESULTS.md does not describe: {missing}"


def test_the_docs_table_of_the_summary_is_generated_from_the_typed_summary():
    """docs/RESULTS.md's table is ``python -m quadimpact.results.summary_record``'s output:
    a key declared in the typed summary is documented with its kind, unit and meaning."""
    text = DOCS.read_text(encoding="utf-8")
    start = text.index("| key | kind | unit | meaning |")
    table = text[start : text.index("\n\n", start)]
    assert table == markdown_table()
