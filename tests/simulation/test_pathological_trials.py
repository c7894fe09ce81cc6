"""Trials that cost a thousand times their task's median (issue 59) now take a bounded step count.

Both were ring contacts whose contact point jumped between evaluations of the right-hand
side, so the contact moment was discontinuous and the integrator rejected step after step
(docs/NUMERICS.md, "Pathological trials"):

* the ``pole-replica`` row's edge trial (pitch -42 deg, offset 0.2 m, ideal sensors): a
  bumper ring across the pillar's vertical edge, its two crossings of the edge equally deep;
  the deepest point jumped from one to the other (18 cm apart) and the run chattered between
  them: 536,608 steps (377,431 rejected), 9 s of CPU; now 7,031;
* the pole trial at pitch -30 deg, offset 0, with the plug-in of
  ``examples/benchmark_controller.py`` and the ``impact`` sensors: two rings around the pole,
  whose deepest points the branch and bound gave only to about 1e-6 rad: 84,866 steps
  (27,543 rejected), 14 s of CPU; now 14,265.

The bounds count steps (accepted and rejected), not time. The runs' physics is checked
elsewhere (tests/simulation/test_obstacles.py); here they complete within a few times their
present count, far below the step budget.
"""

from __future__ import annotations

import pytest

from quadimpact import simulate
from quadimpact.inputs.scenarios import scenario_from_dict
from quadimpact.studies.benchmark.subject import Subject
from quadimpact.studies.benchmark.suite import sensor_set, task

from helpers import load_example


def _trial(
    subject: Subject,
    task_name: str,
    sensors: str,
    pitch_deg: float,
    offset_m: float,
    version: str = "1",
):
    """The quick suite's grid trial at (pitch, offset), as the benchmark (suite ``version``)
    builds it."""
    spec = subject.spec(task(task_name), True, sensor_set(sensors), version=version)
    for i in range(spec.n_runs):
        v = spec.inputs(i)
        if v["pitch_deg"] == pitch_deg and abs(v["lateral_offset_m"] - offset_m) < 1e-9:
            return scenario_from_dict(spec.scenario_dict(i))
    raise AssertionError(f"no point ({pitch_deg}, {offset_m}) in the {task_name} grid")


def _steps(summary) -> int:
    counters = summary["integrator"]
    return int(counters["steps"]) + int(counters["rejected_steps"])


def test_the_pole_replicas_edge_trial_takes_a_bounded_step_count():
    """The hoop across the pillar's edge: 536,608 steps before the fix, 7,031 after."""
    subject = Subject("pole-replica", model="pole-replica")
    summary = simulate(_trial(subject, "edge", "ideal", -42.0, 0.2)).summary
    assert summary["status"] == "completed"
    assert _steps(summary) < 20_000


@pytest.mark.slow
def test_the_example_plug_ins_pole_trial_takes_a_bounded_step_count():
    """Two rings around the pole: 84,866 steps before the fix, 14,265 after (the plug-in's
    loop compiles first: about 30 s)."""
    from quadimpact.inputs.controllers import unregister_controller

    load_example("benchmark_controller.py")  # registers "level-first"
    try:
        subject = Subject("level-first", controller="level-first")
        summary = simulate(_trial(subject, "pole", "impact", -30.0, 0.0)).summary
    finally:
        unregister_controller("level-first")
    assert summary["status"] == "completed"
    assert _steps(summary) < 30_000


def _level_first_trial(task_name: str, sensors: str, pitch_deg: float, offset_m: float):
    """The example plug-in's quick-suite trial (suite 3)."""
    subject = Subject("level-first", controller="level-first")
    return _trial(subject, task_name, sensors, pitch_deg, offset_m, version="3")


@pytest.fixture(scope="module")
def level_first():
    """The example plug-in registered (its step compiles alone: a few s of CPU)."""
    from quadimpact.inputs.controllers import unregister_controller

    load_example("benchmark_controller.py")  # registers "level-first"
    yield
    unregister_controller("level-first")


@pytest.mark.slow
def test_a_vehicle_pinned_to_the_pole_by_friction_takes_steps_for_its_physics(level_first):
    """The plain law pins the vehicle against the pole from 0.73 s to the end, four rings in
    contact. The tolerance sets the step there: about five steps a 5-ms tick (one of them
    rejected) for 3.3 s, 5,635 steps with 20 contact onsets. Chattering between onset and
    release would count hundreds of onsets; an event storm, tens of thousands of steps
    (docs/NUMERICS.md, "A sustained contact")."""
    summary = simulate(_level_first_trial("pole", "ideal", -30.0, 0.0)).summary
    assert summary["status"] == "completed"
    assert summary["n_episodes"] <= 40
    assert _steps(summary) < 10_000


@pytest.mark.slow
def test_a_trial_over_the_step_budget_fails_and_is_no_success(level_first):
    """The same trial with a budget of 2,000 steps (it needs 5,635): it ends at the budget,
    failed with the reason, and the benchmark counts it as no success."""
    import pandas as pd

    from quadimpact.core import layout as L
    from quadimpact.simulation.setup import prepare
    from quadimpact.simulation.simulate import run_setup
    from quadimpact.studies.benchmark.cells import held_hover_success

    scenario = _level_first_trial("pole", "ideal", -30.0, 0.0)
    setup = prepare(scenario)
    setup.opts[L.O_MAX_STEPS] = 2_000
    summary = run_setup(setup, scenario).summary
    assert (summary["status"], summary["reason"]) == ("failed", "step budget exhausted")
    assert _steps(summary) <= 2_000
    row = pd.DataFrame([{"status": summary["status"], "valid": True, "held_hover": True,
                         "touched_after_hover": False, "height_lost_m": 0.0,
                         "crash_time_s": None}])  # fmt: skip
    assert not held_hover_success(row)[0]


def test_a_vehicle_chattering_at_the_recovery_replicas_contact_gate_fails_as_an_event_storm():
    """Run 5797 of the whole wall task (``recovery-replica`` row, ideal sensors) leans on the
    wall at the replica's contact gate: the bumper's force switches on and off in episodes of
    ~70 us, up to 100 onsets per 5-ms tick. The step budget ended it at 80,000 steps; the
    event budget ends it after a few thousand, failed with its own reason (docs/NUMERICS.md,
    "Event budget"). The count is of steps, not time."""
    from quadimpact.core.layout import MAX_INTERVAL_EVENTS, REASON_EVENT_STORM, REASON_TEXT

    subject = Subject("recovery-replica", model="recovery-replica")
    spec = subject.spec(task("wall"), False, sensor_set("ideal"))
    summary = simulate(scenario_from_dict(spec.scenario_dict(5797))).summary
    assert summary["status"] == "failed"
    assert summary["reason"] == REASON_TEXT[REASON_EVENT_STORM]
    assert f"more than {MAX_INTERVAL_EVENTS} events" in summary["reason"]
    assert _steps(summary) < 8_000  # 3,057 with the event budget; 80,000 without
    assert summary["n_episodes"] > MAX_INTERVAL_EVENTS // 2
