"""Table III's switch runs: the scenario changes each crash is run again with.

At the matched conditions every crash is run again with one change at a time
(:func:`switch_changes`), to show what each changes: the motor schedule read
the earlier way (a zero rate holds the motor's speed: :func:`zero_rate_held`),
each switch-off moved to the end of its log segment
(:func:`offs_within_segment`), and, by variant, the default model's own
approach, the mirrored heading, and the replica without each of its crash-run
switches (crash I-03 also with the authors' hand modification). The rows they
give are written by :func:`quadimpact.studies.table3.table3_study.switch_records`.
"""

from __future__ import annotations

import math
from typing import Any

from quadimpact.experiments.crashes import (
    HAND_MODIFICATION,
    MATCHED_APPROACH_OPTIONS,
    REPLICA_CRASH_SWITCHES,
    SWITCH_CHANGES,
    Crash,
)

__all__ = [
    "HELD_RATE_RPM_PER_S",
    "HELD_STALL_RPM_PER_S",
    "offs_within_segment",
    "switch_changes",
    "zero_rate_held",
]

#: The earlier reading of the schedules: a motor whose rates never exceed this
#: (rpm/s) stalled at the impact; any other zero rate held the motor's speed.
HELD_STALL_RPM_PER_S = 100.0


def zero_rate_held(scenario: Any) -> Any:
    """The scenario with its schedule read the earlier way: a zero rate holds the motor's
    speed, and a motor whose rates never exceed ``HELD_STALL_RPM_PER_S`` stops at the
    trigger (``stopped_motors``), unless the run cuts it at the next tick
    (``cut_step_motors``: the cut is the switch's, not the reading's)."""
    po = scenario.power_off
    rates = po.rates_rpm_per_s
    cut = scenario.resolved_model_options().cut_step_motors
    quiet = [all(abs(r[j]) <= HELD_STALL_RPM_PER_S for r in rates) for j in range(4)]
    stalled = tuple(j + 1 for j in range(4) if quiet[j] and j + 1 not in cut)
    held = po.model_copy(update={"zero_rate": "hold", "stopped_motors": stalled})
    return scenario.model_copy(update={"power_off": held})


#: A held rate in :func:`offs_within_segment`: not exactly 0, so not a switch-off.
HELD_RATE_RPM_PER_S = 1e-12


def offs_within_segment(power_off: Any, fraction: float) -> Any:
    """The schedule with each switch-off after the contact moved inside its segment.

    A motor's first zero rate in a segment ``k > 0`` switches it off from the
    segment's start (the authors' reading). The segment runs from one of the
    log's motor samples, the motor still running, to the next, which reads it
    off, so the log puts the switch-off anywhere in it. Here the motor keeps
    its speed over ``fraction`` of that segment (the last segment: of 0.1 s)
    and is off after it: 0 is the schedule as given, 1 the latest switch-off
    the log allows. Zero rates from the first segment (off from the contact)
    and the other rates are kept; the segments are split where needed.
    """
    starts, rates = list(power_off.segment_start_s), power_off.rates_rpm_per_s
    n = len(starts)
    off: dict[tuple[int, int], float] = {}  # (motor, its first zero segment) -> switch-off
    for j in range(4):
        for k in range(1, n):
            if rates[k][j] == 0.0 and rates[k - 1][j] != 0.0:
                end = starts[k + 1] if k + 1 < n else starts[k] + 0.1
                off[(j, k)] = starts[k] + fraction * (end - starts[k])
    cuts = sorted(set(starts) | set(off.values()))
    new = []
    for t in cuts:
        k = max(i for i in range(n) if starts[i] <= t)
        row = []
        for j in range(4):
            r = rates[k][j]
            first = k
            while r == 0.0 and first > 0 and rates[first - 1][j] == 0.0:
                first -= 1
            if r == 0.0 and t < off.get((j, first), -math.inf):
                r = HELD_RATE_RPM_PER_S
            row.append(r)
        new.append(tuple(row))
    return power_off.model_copy(
        update={"segment_start_s": tuple(cuts), "rates_rpm_per_s": tuple(new)}
    )


def switch_changes(crash: Crash, model: str) -> list[tuple[str, Any]]:
    """The switch runs of a crash in a variant (matched conditions): (change, scenario).

    The changes are those of :data:`SWITCH_CHANGES` that apply to the variant.
    """
    base = crash.scenario(model, "matched")
    options = base.model_options.model_dump(exclude_none=True)

    def changed(**fields: Any) -> Any:  # validated again
        return type(base).model_validate({**base.model_dump(exclude_unset=True), **fields})

    mirrored = changed(heading_deg=180.0 - crash.matched.yaw_from_wall_normal_deg)
    late = base.model_copy(update={"power_off": offs_within_segment(base.power_off, 1.0)})
    changes: list[tuple[str, Any]] = [
        ("zero rate held", zero_rate_held(base)),
        ("offs at the segment's end", late),
    ]
    if model == "default":
        own = {k: v for k, v in options.items() if k not in MATCHED_APPROACH_OPTIONS}
        changes += [
            ("late start", changed(model_options=own)),
            ("heading 180 - yaw", mirrored),
            ("with motor2_cut_step", crash.scenario(model, "matched", ["motor2_cut_step"])),
            ("with thrust_coefficient", crash.scenario(model, "matched", ["thrust_coefficient"])),
        ]
    else:
        changes.append(("heading 180 - yaw", mirrored))
        for switch in REPLICA_CRASH_SWITCHES:
            others = [k for k in REPLICA_CRASH_SWITCHES if k != switch]
            changes.append((f"without {switch}", crash.scenario(model, "matched", others)))
        if crash.number == 1:
            with_hand = [*REPLICA_CRASH_SWITCHES, HAND_MODIFICATION]
            changes.append((f"with {HAND_MODIFICATION}",
                            crash.scenario(model, "matched", with_hand)))  # fmt: skip
    assert all(name in SWITCH_CHANGES for name, _ in changes)
    return changes
