"""``quadimpact train``'s pieces: trials never the benchmark's, the reward the benchmark's
success, a state that resumes to the same optimiser, and flying its policy without any
training library."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from quadimpact.errors import InputError
from quadimpact.studies.training.flying import rewards
from quadimpact.studies.training.trials import (
    PURPOSE_CHECK,
    PURPOSE_SCREEN,
    PURPOSE_TRAIN,
    Problem,
    check_seed,
    held_out_point,
)

cma = pytest.importorskip("cma")


# ------------------------------------------------------------------ the trials
def _benchmark_wall_draws() -> tuple[set, set]:
    """The benchmark's 10,000 wall trials: their (roll, pitch, yaw, speed) and their seeds."""
    from quadimpact.studies.benchmark.subject import Subject
    from quadimpact.studies.benchmark.suite import TASKS, sensor_set
    from quadimpact.sweep.trials import trial_draws

    spec = Subject("x").spec(TASKS["wall"], False, sensor_set("onboard"))
    t = spec.trials
    draws = [trial_draws(t["seed"], i, t["ranges"], "seed") for i in range(t["n"])]
    keys = {tuple(d[k] for k in t["ranges"]) for d in draws}
    return keys, {int(d["seed"]) for d in draws}


def test_training_and_check_wall_trials_are_none_of_the_benchmarks():
    problem = Problem(tasks=("wall",), seed=61)
    keys, seeds = _benchmark_wall_draws()
    ranges = ("roll_deg", "pitch_deg", "yaw_deg", "speed_m_s")
    train = [d for _, d in problem.batch(PURPOSE_TRAIN, 0, 2000)]
    check = [d for _, d in problem.batch(PURPOSE_CHECK, 0, 300)]
    screen = [d for _, d in problem.batch(PURPOSE_SCREEN, 0, 500)]
    mine = {tuple(d[k] for k in ranges) for d in train + check + screen}
    assert len(mine) == 2800  # training, check and screened trials differ among themselves too
    assert not mine & keys
    assert not {int(d["seed"]) for d in train + check + screen} & seeds
    # the same distribution as the benchmark's: every draw inside its ranges
    for d in train:
        assert -15 <= d["roll_deg"] <= 15 and -45 <= d["pitch_deg"] <= 45
        assert 0.5 <= d["speed_m_s"] <= 2.5
        assert d["sensors"] == "onboard" and d["estimator"] == "nav-ekf"
        assert d["final_time_s"] == 4.0 and d["ground"] == "crash"


def test_grid_trials_lie_off_the_benchmark_grid_with_other_sensor_seeds():
    from quadimpact.studies.benchmark.suite import TASKS, sensor_set

    problem = Problem(tasks=("pole", "edge"), seed=61)
    study = TASKS["pole"].grid_study(False, sensor_set("onboard"))
    bench_seeds = set(study.point_seeds())
    lattice = {(round(p, 6), round(o, 6)) for p in study.pitches() for o in study.offsets()}
    trials = problem.batch(PURPOSE_TRAIN, 0, 600) + problem.batch(PURPOSE_CHECK, 0, 100)
    assert {task for task, _ in trials} == {"pole", "edge"}
    for task, d in trials:
        assert (round(d["pitch_deg"], 6), round(d["lateral_offset_m"], 6)) not in lattice
        assert -45 <= d["pitch_deg"] <= 0 and -0.35 <= d["lateral_offset_m"] <= 0.35
        assert int(d["seed"]) not in bench_seeds
        assert d["obstacles"][0]["kind"] == ("cylinder" if task == "pole" else "box")


def test_a_draw_on_the_benchmark_lattice_is_moved_off_it():
    assert held_out_point(-12.0, 0.07) == (-11.5, 0.07)
    assert held_out_point(0.0, -0.35) == (-0.5, -0.35)
    assert held_out_point(-12.25, 0.07) == (-12.25, 0.07)  # off the lattice: unchanged
    assert held_out_point(-12.0, 0.075) == (-12.0, 0.075)


def test_the_benchmarks_seed_and_bad_problems_are_refused():
    with pytest.raises(InputError, match="--seed: 0 is the benchmark's own seed"):
        check_seed(0)
    with pytest.raises(InputError, match="--seed: 0 is the benchmark's own seed"):
        Problem(seed=0)
    with pytest.raises(InputError, match="--tasks: unknown task 'ceiling'"):
        Problem(tasks=("ceiling",))
    with pytest.raises(InputError, match="--sensors: unknown sensor set"):
        Problem(sensors="sonar")
    with pytest.raises(InputError, match="--sensors: unknown sensor set 'sonar'"):
        Problem(sensors="onboard,sonar")
    with pytest.raises(InputError, match="--sensors: name each sensor set once"):
        Problem(sensors="onboard,onboard")


def test_trials_depend_on_the_seed_and_their_index_alone():
    a = Problem(tasks=("wall", "pole"), seed=5)
    b = Problem(tasks=("wall", "pole"), seed=5)
    assert a.batch(PURPOSE_TRAIN, 10, 4) == b.batch(PURPOSE_TRAIN, 0, 14)[10:]
    assert a.batch(PURPOSE_TRAIN, 0, 4) != Problem(tasks=("wall", "pole"), seed=6).batch(
        PURPOSE_TRAIN, 0, 4
    )


def test_several_sensor_sets_fly_the_same_draws_each():
    """``onboard,ideal``: each draw of each task is flown once with each set, paired; the
    first set's trials are the single-set problem's, in a different order."""
    one = Problem(tasks=("wall", "pole"), sensors="onboard", seed=5)
    two = Problem(tasks=("wall", "pole"), sensors=" onboard, ideal", seed=5)
    assert two.sensors == "onboard,ideal" and two.sensor_sets == ("onboard", "ideal")
    assert two.describe()["sensors"] == "onboard,ideal"
    batch = two.batch(PURPOSE_TRAIN, 0, 8)
    assert [t for t, _ in batch] == ["wall", "wall", "pole", "pole"] * 2
    for (ta, a), (tb, b) in zip(batch[0::2], batch[1::2], strict=True):
        assert ta == tb
        assert (a.get("sensors"), a.get("estimator")) == ("onboard", "nav-ekf")
        assert b.get("sensors") is None and b.get("estimator") in (None, "ideal")
        drawn = [k for k in ("roll_deg", "pitch_deg", "yaw_deg", "speed_m_s", "seed",
                             "lateral_offset_m") if k in a]  # fmt: skip
        assert len(drawn) >= 3 and all(a[k] == b[k] for k in drawn), drawn
    assert batch[0::2] == one.batch(PURPOSE_TRAIN, 0, 4)


# ------------------------------------------------------------------ the reward
def _summary(**kw):
    base = {"status": "ok", "reason": "", "bumper_model_valid": True, "held_hover": True,
            "touched_after_hover": False, "min_altitude_m": 4.5, "crash_time_s": None}  # fmt: skip
    return {**base, **kw}


def test_the_reward_is_the_benchmarks_held_hover_success_plus_height_kept():
    cases = [
        (_summary(), True),  # held hover, 0.5 m lost
        (_summary(held_hover=False), False),
        (_summary(min_altitude_m=2.9), False),  # 2.1 m lost
        (_summary(crash_time_s=1.2), False),  # the ground touched
        (_summary(touched_after_hover=True), False),
        (_summary(bumper_model_valid=False), False),  # invalid: scores 0
        (_summary(status="failed", reason="x", held_hover=None), False),  # a numerical failure
        (None, False),  # a trial that could not be prepared
    ]
    r, s = rewards([c[0] for c in cases], [5.0] * len(cases), 0.1)
    assert list(s) == [c[1] for c in cases]
    assert math.isclose(r[0], 1.0 + 0.1 * math.exp(-0.5))
    assert math.isclose(r[1], 0.1 * math.exp(-0.5))
    assert math.isclose(r[2], 0.1 * math.exp(-2.1))
    assert r[5] == 0.0 and r[7] == 0.0
    climb = rewards([_summary(min_altitude_m=5.0)], [5.0], 0.1)[0][0]  # nothing lost
    assert math.isclose(climb, 1.1)  # a climb above the start earns nothing more


def test_a_success_scores_less_by_its_hover_drift_and_a_failure_does_not():
    """With a drift weight w a success scores 1 - w min(drift / 0.1 m, 1): linear in the
    drift, whole at 0.1 m and beyond; a failure's score and w = 0 ignore the drift."""
    cases = [_summary(hover_drift_m=d) for d in (0.0, 0.02, 0.05, 0.1, 0.4)]
    cases.append(_summary(held_hover=False, hover_drift_m=None))
    kept = 0.1 * math.exp(-0.5)
    r, s = rewards(cases, [5.0] * len(cases), 0.1, drift_weight=0.5)
    np.testing.assert_allclose(r, [1 + kept, 0.9 + kept, 0.75 + kept, 0.5 + kept,
                                   0.5 + kept, kept])  # fmt: skip
    assert list(s) == [True] * 5 + [False]  # the success itself is the benchmark's
    r0, _ = rewards(cases, [5.0] * len(cases), 0.1)
    np.testing.assert_allclose(r0, [1 + kept] * 5 + [kept])
    with pytest.raises(ValueError, match="a success without its hover_drift_m"):
        rewards([_summary()], [5.0], 0.1, drift_weight=0.5)  # flown without its rows


def test_hover_drift_is_the_farthest_horizontal_distance_from_the_hover_point():
    """Rows before the hover began do not count, nor does height; after it the CM circles
    the hover point at 3 cm and once reaches 4 cm east and 3 cm north: 5 cm."""
    from quadimpact.core import layout as L
    from quadimpact.core.hover_slots import HH_HELD_X, HH_T_HELD
    from quadimpact.core.recording_slots import NOUT, OUT_T, OUT_X
    from quadimpact.studies.training.flying import hover_drift_m

    t = np.linspace(0.0, 4.0, 4001)
    out = np.zeros((t.size, NOUT))
    out[:, OUT_T] = t
    stats = np.zeros(L.NSTAT)
    stats[L.ST_HELD + HH_T_HELD] = 2.0
    stats[L.ST_HELD + HH_HELD_X : L.ST_HELD + HH_HELD_X + 3] = (1.0, -2.0, 5.0)
    p = OUT_X + L.X_POS
    out[:, p] = 1.0 + 0.03 * np.cos(t)
    out[:, p + 1] = -2.0 + 0.03 * np.sin(t)
    out[:, p + 2] = 5.0 - 3.0 * t  # falling: no horizontal drift
    out[t < 2.0, p] = 50.0  # before the hover: ignored
    assert math.isclose(hover_drift_m(out, stats), 0.03, rel_tol=1e-12)
    out[3500, p : p + 2] = (1.04, -1.97)
    assert math.isclose(hover_drift_m(out, stats), 0.05, rel_tol=1e-12)
    stats[L.ST_HELD + HH_T_HELD] = np.nan
    assert hover_drift_m(out, stats) is None


def test_the_trainers_drift_is_the_time_series_drift_of_the_same_run():
    """One held hover flown by the trainer (its rows) and by ``simulate`` (its table): the
    same farthest distance from where the hover began, to 1e-9 m."""
    from quadimpact import simulate
    from quadimpact.inputs.scenarios import scenario_from_dict
    from quadimpact.studies.training.flying import Flyer, prepare_trial

    trials = _problem().batch(PURPOSE_CHECK, 0, 8)
    flyer = Flyer(drift=True)
    for task, data in trials:
        summary = flyer.fly(prepare_trial(task, data), None)
        if summary["hover_drift_m"] is not None:
            break
    else:
        pytest.fail("no held hover in 8 ideal wall trials")
    r = simulate(scenario_from_dict(data))
    t_h = r.summary["first_contact_s"] + r.summary["time_to_held_hover_s"]
    ts = r.timeseries[r.timeseries["t_s"] >= t_h - 1e-9]
    xy = ts[["x_m", "y_m"]].to_numpy()
    want = float(np.linalg.norm(xy - xy[0], axis=1).max())
    assert 0.0 < summary["hover_drift_m"] < 0.2
    assert math.isclose(summary["hover_drift_m"], want, abs_tol=1e-9)


# ------------------------------------------------------------------ state and resume
_SMALL = dict(hidden=2, popsize=3, batch=2, check=2, check_every=1, sigma=0.5)


def _problem():
    return Problem(tasks=("wall",), sensors="ideal", seed=7)


def test_a_trial_lost_to_the_law_costs_the_loss_weight():
    from quadimpact.studies.training.trainer import candidate_scores

    s = np.array([[1, 1, 0, 0], [1, 0, 1, 0], [1, 1, 1, 0]], dtype=bool)  # law, a, b
    r = s + 0.1
    assert np.allclose(candidate_scores(r, s, 0.0), [0.6, 0.85])
    # a wins trial 2 and loses trial 1 to the law; b loses none
    assert np.allclose(candidate_scores(r, s, 1.0), [0.6 - 0.25, 0.85])
    assert np.allclose(candidate_scores(r, s, 2.0), [0.6 - 0.5, 0.85])


def test_the_screen_keeps_the_trials_the_candidates_split_and_batches_cycle_them():
    """--contested: a trial is kept when the law, the start and its neighbours do not all
    succeed or all fail; generation g's batch continues the cycle where g - 1 stopped."""
    from quadimpact.inputs.policy_file import initial_policy
    from quadimpact.studies.training import trainer
    from quadimpact.studies.training.trainer import Settings, contested_trials, training_batch

    s = np.array([[1, 0, 1, 0, 1], [1, 0, 0, 0, 1], [1, 0, 1, 1, 1]], dtype=bool)
    assert contested_trials(s) == [2, 3]
    settings = Settings(**{**_SMALL, "batch": 3, "contested": 5})
    problem = _problem()
    seen = {}

    def evaluate(trials, blocks, terms):
        seen["trials"], seen["blocks"] = trials, blocks
        return np.zeros(s.shape), s

    state = trainer._new_state(problem, settings)
    trainer._screen(state, problem, settings, evaluate)
    assert state["contested"] == [2, 3]
    assert seen["trials"] == problem.batch(PURPOSE_SCREEN, 0, 5)
    assert seen["blocks"][0] is None and len(seen["blocks"]) == 2 + settings.popsize
    start = initial_policy(2, 0.3, 4.0, 7, 5).block()  # the law's weights: a zero output layer
    np.testing.assert_array_equal(seen["blocks"][1], start)
    assert not np.array_equal(seen["blocks"][2], start)  # a neighbour, sigma away
    pool = problem.batch(PURPOSE_SCREEN, 0, 5)
    assert training_batch(problem, settings, [2, 3], 1) == [pool[2], pool[3], pool[2]]
    assert training_batch(problem, settings, [2, 3], 2) == [pool[3], pool[2], pool[3]]
    fresh = Settings(**_SMALL)
    assert training_batch(problem, fresh, None, 2) == problem.batch(PURPOSE_TRAIN, 2, 2)
    with pytest.raises(InputError, match="--contested: none of the 5 screened trials"):
        trainer._screen(state, problem, settings, lambda *a: (np.zeros(s.shape), s & False))


def test_settings_are_checked_with_one_line():
    from quadimpact.studies.training.trainer import Settings

    with pytest.raises(InputError, match=r"--popsize: must be >= 2 \(got 1\)"):
        Settings(popsize=1)
    with pytest.raises(InputError, match="--stages: must be 4 or 5"):
        Settings(last_stage=3)
    with pytest.raises(InputError, match=r"--loss-weight: must be finite, >= 0 \(got -1.0\)"):
        Settings(loss_weight=-1.0)
    with pytest.raises(InputError, match=r"--contested: must be >= 0 \(got -3\)"):
        Settings(contested=-3)
    with pytest.raises(InputError, match=r"--hover-fade: must be FROM,TO s with 0 <= FROM < TO"):
        Settings(hover_fade_s=(1.5, 1.0))
    with pytest.raises(InputError, match=r"given with --stages 1-5 \(got \(0.5, 1.0\)\)"):
        Settings(last_stage=4, hover_fade_s=(0.5, 1.0))
    assert Settings(hover_fade_s=(1, 2)).hover_fade_s == (1.0, 2.0)


def test_a_start_from_a_policy_of_another_shape_is_refused():
    """--init takes the weights of a policy whose width, scales and stages are the run's
    (learned: 8 hidden units, 0.3 m g, 4 rad/s, stages 1-5); it is recorded by digest."""
    from quadimpact.inputs.policy_file import initial_policy, load_policy
    from quadimpact.studies.training.trainer import Settings, _initial_weights, init_settings

    pol = initial_policy(8, 0.3, 4.0, 1, 5)
    start = _initial_weights(pol, "learned")
    np.testing.assert_array_equal(start.vector(), load_policy("learned").vector())
    with pytest.raises(InputError, match="--init learned: its hidden is 8, the run's 4"):
        _initial_weights(initial_policy(4, 0.3, 4.0, 1, 5), "learned")
    with pytest.raises(InputError, match="--init learned: its stages is 5, the run's 4"):
        _initial_weights(initial_policy(8, 0.3, 4.0, 1, 4), "learned")
    s = init_settings(Settings(init="learned"))
    assert s.init == "learned" and s.init_sha256 == load_policy("learned").sha256
    with pytest.raises(InputError, match="no such file"):
        init_settings(Settings(init="/nonexistent/p.npz"))


@pytest.mark.slow
def test_a_run_started_from_a_policy_keeps_that_policy_until_one_beats_it(tmp_path, monkeypatch):
    """--init: generation 0's best is the starting policy flown on the check set (not the
    law's score under its weights); stopped before generation 1, it is the policy written."""
    from quadimpact.inputs.policy_file import load_policy
    from quadimpact.studies.training import trainer
    from quadimpact.studies.training.trainer import Settings, init_settings, train
    from quadimpact.studies.training.workers import fly_job
    from quadimpact.sweep import SweepInterrupted

    a, b = tmp_path / "a", tmp_path / "b"
    train(_problem(), Settings(**_SMALL), a, None, 2, progress=False)
    start = load_policy(a / "policy.npz")
    settings = init_settings(Settings(**{**_SMALL, "init": str(a / "policy.npz")}))

    def stop(*args, **kwargs):
        raise SweepInterrupted(2)

    monkeypatch.setattr(trainer, "_generation", stop)
    with pytest.raises(SweepInterrupted, match="interrupted at generation 0"):
        train(_problem(), settings, b, None, 3, progress=False)
    written = load_policy(b / "policy.npz")
    np.testing.assert_array_equal(written.vector(), start.vector())
    checks = _problem().batch(PURPOSE_CHECK, 0, settings.check)
    r, _ = fly_job((checks, [None, start.block()], (settings.shaping, 0.0)))
    assert written.meta["check_score_policy"] == float(r[1].mean())
    assert written.meta["check_score_law"] == float(r[0].mean())


@pytest.mark.slow
def test_a_resumed_run_continues_the_same_optimiser(tmp_path):
    """Two generations straight, or one and then a resume to two: the same CMA-ES state,
    the same curve, the same policy; another setting is refused."""
    from quadimpact.inputs.policy_file import load_policy
    from quadimpact.studies.training.trainer import Settings, load_state, train

    settings = Settings(**_SMALL)
    a, b = tmp_path / "a", tmp_path / "b"
    train(_problem(), settings, a, None, 2, progress=False)
    res1 = train(_problem(), settings, b, None, 1, progress=False)
    assert res1.generations == 1 and (b / "policy.npz").is_file()
    res2 = train(_problem(), settings, b, None, 2, progress=False)
    assert res2.resumed_from == 1 and res2.generations == 2
    sa, sb = load_state(a), load_state(b)
    np.testing.assert_array_equal(sa["es"].mean, sb["es"].mean)
    assert sa["es"].sigma == sb["es"].sigma
    strip = [{k: v for k, v in row.items() if k != "minutes"} for row in sa["curve"]]
    assert strip == [{k: v for k, v in row.items() if k != "minutes"} for row in sb["curve"]]
    pa, pb = load_policy(a / "policy.npz"), load_policy(b / "policy.npz")
    assert pa.sha256 == pb.sha256 and pa.last_stage == 5
    assert pa.meta["problem"]["seed"] == 7 and pa.meta["generations"] == 2
    lines = (a / "curve.csv").read_text().splitlines()
    assert lines[0].startswith("generation,runs,minutes") and len(lines) == 4
    assert (a / "curve.png").stat().st_size > 0
    with pytest.raises(InputError, match="holds a training run with other settings: popsize"):
        train(_problem(), Settings(**{**_SMALL, "popsize": 4}), b, None, 3, progress=False)


@pytest.mark.slow
def test_an_interrupt_keeps_the_last_whole_generation_and_resumes(tmp_path, monkeypatch):
    """A stop signal during generation 2 (raised by the evaluator, as the signal handler
    does): generation 1's state, curve and policy are saved; the rerun goes on from 1."""
    from quadimpact.studies.training import trainer
    from quadimpact.studies.training.workers import Evaluator
    from quadimpact.sweep import SweepInterrupted

    settings = trainer.Settings(**_SMALL)
    real = Evaluator.__call__
    calls = {"n": 0}

    def flaky(self, trials, blocks, shaping):
        calls["n"] += 1
        if calls["n"] == 5:  # law check, gen 1 + its check, then gen 2
            raise SweepInterrupted(2)
        return real(self, trials, blocks, shaping)

    monkeypatch.setattr(Evaluator, "__call__", flaky)
    with pytest.raises(SweepInterrupted, match="interrupted at generation 1"):
        trainer.train(_problem(), settings, tmp_path, None, 3, progress=False)
    assert trainer.load_state(tmp_path)["generation"] == 1
    assert (tmp_path / "policy.npz").is_file()
    assert json.loads((tmp_path / "train.json").read_text())["finished"] is False
    monkeypatch.setattr(Evaluator, "__call__", real)
    res = trainer.train(_problem(), settings, tmp_path, None, 3, progress=False)
    assert res.resumed_from == 1 and res.generations == 3 and res.finished


def test_a_folder_of_something_else_is_refused(tmp_path):
    from quadimpact.studies.training.trainer import Settings, train

    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(InputError, match="holds files that are not a training run's"):
        train(_problem(), Settings(**_SMALL), tmp_path, None, 1, progress=False)


# ------------------------------------------------------------------ flying a trained file
def test_a_trained_policy_flies_without_any_training_library(tmp_path):
    """In a fresh interpreter: a policy file of every stage (last_stage 5) flies a trial with
    NumPy and the compiled loop, and neither cma nor torch is imported; importing the
    trainer's module does not import cma either (it is imported when training starts)."""
    from quadimpact.inputs.policy_file import initial_policy, save_policy

    p = initial_policy(8, 0.3, 4.0, seed=3, last_stage=5)
    p = p.with_vector(np.random.default_rng(3).normal(0, 0.3, p.vector().size))
    path = save_policy(p, tmp_path / "policy.npz")
    code = f"""
import json, sys
from quadimpact import ImpactTrial, simulate
import quadimpact.studies.training.trainer
s = ImpactTrial(vehicle="navi", speed_m_s=2.0, pitch_deg=-20.0, pre_impact="spin-down",
                controller_params={{"policy": {str(path)!r}}})
r = simulate(s).summary
print(json.dumps({{"status": r["status"], "detected": r["detected"],
                  "cma": "cma" in sys.modules, "torch": "torch" in sys.modules}}))
"""
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=900)  # fmt: skip
    assert res.returncode == 0, res.stderr
    got = json.loads(res.stdout.strip().splitlines()[-1])
    assert got["status"] != "failed" and got["detected"]
    assert not got["cma"] and not got["torch"]


def test_one_training_run_at_a_time_in_a_folder(tmp_path):
    """A second trainer in a folder another one holds is refused (the lock is released
    when the first ends)."""
    from quadimpact.studies.training import trainer

    with trainer._folder_lock(tmp_path):
        with pytest.raises(InputError, match="another quadimpact train is running in it"):
            trainer.train(_problem(), trainer.Settings(**_SMALL), tmp_path, None, 1,
                          progress=False)  # fmt: skip
    with trainer._folder_lock(tmp_path):
        pass


@pytest.mark.slow
@pytest.mark.parametrize("task_name", ["wall", "pole"])
def test_the_trainers_success_is_the_benchmarks_on_the_same_trials(tmp_path, task_name):
    """The benchmark's first trials of a task, flown by the benchmark's sweep and table
    (cell_table) and by the trainer (fly_job): the same success, trial by trial."""
    from quadimpact.studies.benchmark.cells import cell_table
    from quadimpact.studies.benchmark.subject import Subject
    from quadimpact.studies.benchmark.suite import TASKS, sensor_set
    from quadimpact.studies.training.workers import fly_job
    from quadimpact.sweep import read_runs, run_sweep

    task = TASKS[task_name]
    spec = Subject("default").spec(task, True, sensor_set("lab"), limit=12)
    run_sweep(spec, tmp_path / "sweep", workers=1)
    table = cell_table(read_runs(tmp_path / "sweep"), spec, task)
    trials = [(task_name, spec.scenario_dict(i)) for i in range(spec.n_runs)]
    _, success = fly_job((trials, [None], (0.1, 0.0)))
    want = table.sort_values("run_id")["success"].to_numpy(dtype=bool)
    assert list(success[0]) == list(want)
    assert 0 < want.sum() < len(want)  # successes and failures both compared
