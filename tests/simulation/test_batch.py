"""simulate_batch gives the summaries of single simulate() calls, bit for bit.

Its runs record no output rows (the loop samples at every output time for its
stats, without writing a row or computing the contact geometry there); nothing
else of a run may change.
"""

from __future__ import annotations

import json
import time

import numpy as np

from quadimpact import FlightScenario, ImpactTrial, WallApproach, simulate
from quadimpact.core import layout as L
from quadimpact.core.kernel import BUILTIN
from quadimpact.core.recording_slots import NOUT, OUT_DELTA, OUT_X
from quadimpact.core.records import new_output
from quadimpact.inputs.world import Cylinder
from quadimpact.simulation.batch import GROUP_MAX, GROUP_S, BatchRunner, simulate_batch
from quadimpact.simulation.setup import prepare

POLE = Cylinder(name="pole", point_m=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0), radius_m=0.1)


def _same(a, b):
    """Equal summaries but for what the runs cost (wall-clock and CPU times)."""
    a, b = dict(a), dict(b)
    a["integrator"].pop("wall_time_s"), b["integrator"].pop("wall_time_s")
    a.pop("cost"), b.pop("cost")
    return json.dumps(a, sort_keys=True, allow_nan=True) == json.dumps(b, sort_keys=True,
                                                                       allow_nan=True)  # fmt: skip


def test_batch_equals_single_runs():
    scenarios = [
        WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75, model="paper-replica"),
        WallApproach(heading_deg=0, inclination_deg=-10, speed_m_s=1.0),  # a shorter output
        WallApproach(heading_deg=45, inclination_deg=20, speed_m_s=0.5),  # a late start
        ImpactTrial(roll_deg=5, pitch_deg=-30, yaw_deg=20, speed_m_s=1.5, imu="noisy", seed=3),
        FlightScenario(final_time_s=4.0),  # longer than the others: the buffers grow
        WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75, model="paper-replica"),
        ImpactTrial(controller="recovery", roll_deg=10, speed_m_s=2.0, obstacles=(POLE,)),
    ]
    batch = simulate_batch(scenarios)
    assert len(batch) == len(scenarios)
    for s, b in zip(scenarios, batch, strict=True):
        assert _same(simulate(s).summary, b)


def test_a_run_that_raises_is_a_failed_summary():
    bad = WallApproach(vehicle_overrides={"thrust_coefficient": 1e-12})  # cannot hover: raises
    good = WallApproach(final_time_s=1.0)
    out = simulate_batch([bad, good])
    assert out[0]["status"] == "failed" and out[0]["reason"]
    assert _same(out[1], simulate(good).summary)


def test_a_group_in_passes_gives_each_run_its_own_summary_and_cost():
    """Runs prepared, then run, then summarised as one group: each summary is its single
    run's, bit for bit, whatever ran before or after it in the group (the same scenario
    twice, a noisy IMU, a pole, a wall approach's late start); a run that raises in its
    preparation is that run's error alone; each cost is the run's own (its loop within it,
    the group's costs within the group's CPU time)."""
    bad = WallApproach(vehicle_overrides={"thrust_coefficient": 1e-12})  # cannot hover
    scenarios = [
        ImpactTrial(controller="recovery", roll_deg=10, pitch_deg=-15, speed_m_s=0.8),
        WallApproach(heading_deg=45, inclination_deg=20, speed_m_s=0.5),  # a late start
        bad,
        ImpactTrial(roll_deg=5, pitch_deg=-30, yaw_deg=20, speed_m_s=1.5, imu="noisy", seed=3),
        ImpactTrial(controller="recovery", roll_deg=10, speed_m_s=2.0, obstacles=(POLE,)),
        ImpactTrial(controller="recovery", roll_deg=10, pitch_deg=-15, speed_m_s=0.8),
    ]
    runner = BatchRunner()
    assert runner.group_size() == 1  # no run measured yet
    looped = []
    cpu = time.thread_time()
    done = runner.run_group([(lambda s=s: s) for s in scenarios], before_loop=looped.append)
    cpu = time.thread_time() - cpu
    assert looped == [0, 1, 3, 4, 5]  # the run that could not be prepared has no loop
    assert done[2].summary is None and "hover" in str(done[2].error)
    for s, d in zip(scenarios, done, strict=True):
        if s is not bad:
            assert d.error is None
            assert d.kernel_s == d.summary["integrator"]["wall_time_s"] < d.wall_s
            cost = d.summary["cost"]
            assert 0.0 < cost["kernel_cpu_s"] < cost["total_cpu_s"] <= d.cpu_s
            assert _same(d.summary, simulate(s).summary)
    assert sum(d.cpu_s for d in done) <= cpu
    # the next group holds about GROUP_S of runs at this group's pace
    pace = runner.run_wall_s
    assert pace is not None and pace > 0.0
    assert runner.group_size() == max(1, min(GROUP_MAX, int(GROUP_S / pace)))
    assert runner.group_size(limit=1) == 1


def test_rows_without_contact_columns_leave_the_run_unchanged():
    """A run into rows of NOUT columns: the same time, state, command and stage in every
    row, the same episodes, IMU samples and stats, bit for bit (a pole, a recovery)."""
    s = ImpactTrial(controller="recovery", roll_deg=10, speed_m_s=2.0, obstacles=(POLE,))
    m = prepare(s).model()
    full = new_output(m, prepare(s).n_imu, 64)
    lean = new_output(m, prepare(s).n_imu, 64, contact_columns=False)
    BUILTIN.run(m, full)
    BUILTIN.run(m, lean)
    assert lean.out.shape[1] == NOUT < full.out.shape[1]
    assert np.any(full.out[:, OUT_DELTA:] != 0.0)  # the contacts were there to skip
    assert np.array_equal(full.out[:, :NOUT], lean.out)
    for a, b in ((full.episodes, lean.episodes), (full.imu, lean.imu), (full.stats, lean.stats)):
        assert np.array_equal(a, b, equal_nan=True)


def test_runs_without_rows_sample_the_same_and_keep_what_the_summary_reads():
    """No output rows: the same episodes, IMU samples and stats, bit for bit, among them
    the count of samples, their attitude excursion and the last sample's state (what
    the summary reads); and those are the rows' (a noisy recovery trial, a pole)."""
    for s in (
        ImpactTrial(controller="recovery", roll_deg=10, pitch_deg=-30, speed_m_s=2.0,
                    imu="noisy", seed=4),
        ImpactTrial(controller="recovery", roll_deg=10, speed_m_s=2.0, obstacles=(POLE,)),
    ):  # fmt: skip
        setup = prepare(s)
        m = setup.model()
        full = new_output(m, setup.n_imu, 64)
        none = new_output(m, setup.n_imu, 64, contact_columns=False, rows=False)
        BUILTIN.run(m, full)
        BUILTIN.run(m, none)
        assert none.out.shape[0] == 0
        for a, b in ((full.episodes, none.episodes), (full.imu, none.imu)):
            assert np.array_equal(a, b, equal_nan=True)
        assert np.array_equal(full.stats, none.stats, equal_nan=True)
        n_out = int(none.stats[L.ST_N_OUT])
        assert n_out == m.t_out.shape[0] or none.stats[L.ST_STATUS] != L.STATUS_COMPLETED
        last = full.out[n_out - 1, OUT_X : OUT_X + L.NX]
        assert np.array_equal(none.stats[L.ST_X_LAST : L.ST_X_LAST + L.NX], last)
