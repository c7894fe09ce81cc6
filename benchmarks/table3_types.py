"""What the types of Table III's crashes hinge on, at the authors' matched conditions.

    .venv/bin/python benchmarks/table3_types.py [--crashes 1 5 6] [--csv PATH]

For each crash and variant (``default``, ``paper-replica`` with its crash-run
switches) it runs the matched scenario as made, then one change at a time:

* ``hold motor J``: motor J's zero rates read as holding its speed (its other
  motors still switched off at their zero rates; motor 2 of the crash runs is
  cut as made);
* ``schedule +/-S ms``: the power-off schedule started S ms after (before)
  the first contact (a fixed trigger time instead of the contact);
* ``offs at F of the segment``: every motor the schedule switches off after
  the contact (its first zero rate, in segment k > 0) held at its speed over
  the fraction F of that segment and off after it, instead of off from the
  segment's start (F = 0, the authors' reading). A segment runs from one of
  the log's motor samples, the motor still running, to the next, which reads
  it off: the log puts the switch-off anywhere in the segment, F = 1 being
  the latest (``experiments.switch_runs.offs_within_segment``);
* ``roll/pitch/heading +/-D deg``, ``speed +/-0.1 m/s``: the matched
  conditions moved (the heading as ``yaw_from_wall_normal_deg``).

and prints the type, the bumpers of the initial and subsequent impacts,
δ_init, the crash time after the contact and the chaining margin (ms: how
far the closest episode is from joining or leaving the impact before it;
negative: joined). docs/EXPERIMENTS.md quotes its results.
"""

from __future__ import annotations

import argparse
import dataclasses
import math

import pandas as pd

from quadimpact import simulate
from quadimpact.experiments.crashes import MATCHED_CONTACT_TIME_S, TABLE3, Crash
from quadimpact.simulation.response_types import closest_chaining
from quadimpact.studies.table3.switch_runs import offs_within_segment

VARIANTS = ("default", "paper-replica")


def _changed(base, **fields):
    return type(base).model_validate({**base.model_dump(exclude_unset=True), **fields})


def changes(crash: Crash, model: str) -> list[tuple[str, object]]:
    """(name, scenario) of the runs of one crash in one variant."""
    base = crash.scenario(model, "matched")
    po = base.power_off
    out: list[tuple[str, object]] = [("as made", base)]
    for j in range(4):
        if not any(r[j] == 0.0 for r in po.rates_rpm_per_s):
            continue
        rates = [tuple(1e-12 if (k == j and r == 0.0) else r for k, r in enumerate(row))
                 for row in po.rates_rpm_per_s]  # fmt: skip
        held = {**po.model_dump(), "rates_rpm_per_s": rates}
        out.append((f"hold motor {j + 1}", _changed(base, power_off=held)))
    for ms in (-10, 5, 10, 20):
        later = {**po.model_dump(), "trigger": MATCHED_CONTACT_TIME_S + ms / 1e3}
        out.append((f"schedule {ms:+d} ms", _changed(base, power_off=later)))
    for fraction in (0.5, 0.75, 1.0):
        moved = offs_within_segment(po, fraction).model_dump()
        out.append((f"offs at {fraction:g} of the segment", _changed(base, power_off=moved)))
    m = crash.matched
    for name, field, delta in (("roll", "roll_deg", 2.0), ("pitch", "pitch_deg", 2.0),
                               ("heading", "yaw_from_wall_normal_deg", 3.0)):  # fmt: skip
        for sign in (-1.0, 1.0):
            moved = dataclasses.replace(m, **{field: getattr(m, field) + sign * delta})
            keep = ("heading_deg", "roll_deg", "pitch_deg", "inclination_deg")
            fields = {k: v for k, v in moved.fields().items() if k in keep}
            out.append((f"{name} {sign * delta:+g} deg", _changed(base, **fields)))
    for dv in (-0.1, 0.1):
        out.append((f"speed {dv:+g} m/s", _changed(base, speed_m_s=m.speed_m_s + dv)))
    return out


def row(crash: Crash, model: str, name: str, scenario) -> dict[str, object]:
    r = simulate(scenario)
    s = r.summary
    crash_t, contact = s["crash_time_s"], s["first_contact_s"]
    chain = closest_chaining(r.episodes, crash_t is not None)
    return {
        "crash": crash.number,
        "model": model,
        "change": name,
        "type": s["response_type"],
        "type_experiment": crash.type_experiment,
        "leading": s["leading_bumpers"],
        "subsequent": s["subsequent_impacts"],
        "delta_init_mm": math.nan if s["delta_init_m"] is None else 1e3 * s["delta_init_m"],
        "crash_after_contact_s": math.nan if crash_t is None else crash_t - contact,
        "chaining_margin_ms": math.nan if chain is None else 1e3 * chain["margin_s"],
        "chaining_bumper": None if chain is None else chain["bumper"],
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--crashes", type=int, nargs="+", default=[1, 5, 6])
    p.add_argument("--csv", default=None)
    a = p.parse_args()
    rows = [row(TABLE3[n - 1], model, name, sc)
            for n in a.crashes for model in VARIANTS
            for name, sc in changes(TABLE3[n - 1], model)]  # fmt: skip
    table = pd.DataFrame(rows)
    with pd.option_context("display.width", 200, "display.max_rows", 500):
        print(table.round(2).to_string(index=False))
    if a.csv:
        table.to_csv(a.csv, index=False)


if __name__ == "__main__":
    main()
