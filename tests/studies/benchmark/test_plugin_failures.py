"""Plug-ins fail loudly (issue 55, item 4): checked before any trial, stopped when they raise.

A plug-in with a wrong signature, one that raises at the first tick, one that
returns a value, reads past an array or leaves a command not finite: each is
one line naming the plug-in, its function and the rule, before any trial
(``simulation.plugin_check``). One that raises only at a later trial stops
the benchmark with one line after its cell's sweep, the cells finished kept,
and the same command resumes (``studies.benchmark.plugin_guard``). The step's
compilation is timed apart from the trials' CPU (``compile_cpu_s``).

The pre-flight compiles a step alone (well under a second), and so does a run
(the cached loop calls the step by its address): these tests are fast but
those that fly whole benchmark cells.
"""

from __future__ import annotations

import functools
import json

import numpy as np
import pandas as pd
import pytest
from numba import njit

from quadimpact.core import named
from quadimpact.errors import InputError
from quadimpact.inputs.controllers import register_controller, unregister_controller
from quadimpact.inputs.estimators import register_estimator, unregister_estimator
from quadimpact.inputs.scenarios import ImpactTrial
from quadimpact.simulation.plugin_check import check_plugins
from quadimpact.simulation.plugin_kernel import PluginError, plugin_failure, typing_text
from quadimpact.studies.benchmark import benchmark_study
from quadimpact.studies.benchmark.benchmark_study import BenchmarkStudy, run_benchmark
from quadimpact.studies.benchmark.subject import Subject

from helpers import cli_here


# ------------------------------------------------------------------ the steps
@njit
def hold(t, meas, ctrl, mem, veh, dt, cmd):
    speeds = named.rotor_speeds(meas)
    for j in range(4):
        cmd[j] = speeds[j]


@njit
def six_parameters(t, meas, ctrl, mem, veh, cmd):
    for j in range(4):
        cmd[j] = 0.0


@njit
def raises_at_once(t, meas, ctrl, mem, veh, dt, cmd):
    raise ValueError("no recovery law here")


@njit
def returns_the_command(t, meas, ctrl, mem, veh, dt, cmd):
    speeds = named.rotor_speeds(meas)
    return np.array([speeds[0], speeds[1], speeds[2], speeds[3]])


@njit
def reads_past_its_memory(t, meas, ctrl, mem, veh, dt, cmd):
    for j in range(4):
        cmd[j] = mem[j + 64]  # mem has NMEM = 64 floats


@njit
def indexes_a_number(t, meas, ctrl, mem, veh, dt, cmd):
    cmd[0] = dt[0]


@njit
def leaves_nan(t, meas, ctrl, mem, veh, dt, cmd):
    for j in range(4):
        cmd[j] = np.nan


@njit
def estimator_raises(t, dt, meas, ecfg, est):
    raise RuntimeError("no filter here")


BAD = {
    "t-six-parameters": six_parameters,
    "t-raises-at-once": raises_at_once,
    "t-returns-the-command": returns_the_command,
    "t-reads-past-its-memory": reads_past_its_memory,
    "t-indexes-a-number": indexes_a_number,
    "t-leaves-nan": leaves_nan,
}


@pytest.fixture(scope="module")
def plugins():
    register_controller("t-hold", step=hold, replace=True)
    for name, step in BAD.items():
        register_controller(name, step=step, replace=True)
    register_estimator("t-estimator-raises", step=estimator_raises, replace=True)
    yield
    for name in ("t-hold", *BAD):
        unregister_controller(name)
    unregister_estimator("t-estimator-raises")


def _error(controller: str, estimator: str = "ideal") -> str:
    with pytest.raises(PluginError) as info:
        check_plugins(ImpactTrial(controller=controller, estimator=estimator, final_time_s=0.3))
    text = str(info.value)
    assert "\n" not in text and "Traceback" not in text
    return text


# ------------------------------------------------------------ the pre-flight
def test_a_plugin_that_flies_passes_and_builtins_are_not_checked(plugins):
    checked = check_plugins(ImpactTrial(controller="t-hold", final_time_s=0.3))
    assert [(w.kind, w.name, w.function) for w in checked] == [("controller", "t-hold", "hold")]
    assert check_plugins(ImpactTrial(controller="recovery", final_time_s=0.3)) == []


@pytest.mark.parametrize(
    ("name", "fragments"),
    [
        ("t-six-parameters", ["six_parameters", "takes 7 parameters",
                              "(got six_parameters(t, meas, ctrl, mem, veh, cmd))"]),
        ("t-raises-at-once", ["raises_at_once", "first tick",
                              "raised ValueError: no recovery law here", "must not raise"]),
        ("t-returns-the-command", ["returns_the_command", "returns array(float64",
                                   "returns nothing", "into cmd"]),
        ("t-reads-past-its-memory", ["reads_past_its_memory", "IndexError",
                                     "past the end of an array"]),
        ("t-indexes-a-number", ["indexes_a_number", "does not compile", "getitem(float64",
                                "test_plugin_failures.py, line"]),
        ("t-leaves-nan", ["leaves_nan", "cmd[0] = nan", "must be finite"]),
    ],
)  # fmt: skip
def test_a_bad_plugin_is_one_line_naming_it_its_function_and_the_rule(plugins, name, fragments):
    text = _error(name)
    assert text.startswith(f"controller plug-in {name!r} ("), text
    for fragment in fragments:
        assert fragment in text, (fragment, text)


def test_an_estimator_plugin_is_checked_too(plugins):
    text = _error("recovery", "t-estimator-raises")
    assert text.startswith("estimator plug-in 't-estimator-raises' (estimator_raises)")
    assert "raised RuntimeError: no filter here" in text


def test_a_numba_typing_error_reads_in_one_line():
    @njit
    def bad(x):
        return x.no_such_attribute

    with pytest.raises(Exception) as info:
        bad(1.0)
    text = typing_text(info.value)
    assert "\n" not in text and "no_such_attribute" in text, text
    assert "test_plugin_failures.py, line" in text, text


def test_a_plugins_failed_runs_are_found_and_ordinary_failures_are_not():
    runs = pd.DataFrame({
        "run_id": [0, 1, 2, 3],
        "status": ["completed", "failed", "failed", "failed"],
        "reason": ["", "step size too small", "PluginError: controller plug-in 'x' (f) raised "
                   "ValueError: late", "PluginError: later"],
    })  # fmt: skip
    assert plugin_failure(runs) == (2, "controller plug-in 'x' (f) raised ValueError: late")
    assert plugin_failure(runs.iloc[:2]) is None  # a numerical failure stays a failed run


def _one_error_line(code: int, err: str, *fragments: str) -> str:
    assert code == 2, err
    lines = [ln for ln in err.strip().splitlines() if ln.startswith("quadimpact: error: ")]
    assert len(lines) == 1 and "Traceback" not in err, err
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    return lines[0]


@pytest.mark.parametrize(
    ("name", "fragment"),
    [("t-six-parameters", "takes 7 parameters"), ("t-raises-at-once", "first tick")],
)
def test_the_benchmark_command_refuses_a_bad_plugin_before_any_trial(
    plugins, capsys, tmp_path, name, fragment
):
    out = tmp_path / "bench"
    code, err = cli_here(
        capsys, "benchmark", "--quick", "--controller", name, "--no-references", "--no-cache",
        "--workers", "1", "--no-progress", "--out", str(out),
    )  # fmt: skip
    line = _one_error_line(code, err, f"benchmark: {name} wall/ideal: ", name, fragment)
    assert len(line) < 400, line
    assert not (out / "cells").exists()  # no trial flown


def test_quadimpact_run_refuses_a_bad_plugin_before_it_flies(plugins, capsys, tmp_path):
    out = tmp_path / "run"
    code, err = cli_here(
        capsys, "run", "--controller", "t-reads-past-its-memory", "--final-time", "0.6",
        "--out", str(out),
    )  # fmt: skip
    _one_error_line(code, err, "controller plug-in 't-reads-past-its-memory'", "IndexError")
    assert not out.exists()


@pytest.mark.parametrize(
    "args",
    [
        ("recovery", "--n", "3", "--no-example", "--no-animation"),
        ("pole", "--pitch-step", "15", "--offset-step", "0.35"),
    ],
)
def test_the_studies_refuse_a_bad_estimator_plugin_before_any_trial(
    plugins, capsys, tmp_path, args
):
    out = tmp_path / "study"
    code, err = cli_here(
        capsys, *args, "--estimator", "t-estimator-raises", "--workers", "1", "--no-progress",
        "--out", str(out),
    )  # fmt: skip
    _one_error_line(code, err, "estimator plug-in 't-estimator-raises' (estimator_raises)")
    assert not (out / "runs.parquet").exists() and not (out / "trials.parquet").exists()


# ------------------------------------------------------------ in the loop (slow)
def _raising_from(offset_m: float, name: str) -> None:
    """A plug-in that holds its rotors and raises at the first tick of a trial started at
    an inertial y between ``offset_m`` and -0.1 m: the pole grid's points start at -0.35,
    -0.34, -0.33 m..., the wall's trials at 0."""

    @njit
    def offset_trials_raise(t, meas, ctrl, mem, veh, dt, cmd):
        speeds = named.rotor_speeds(meas)
        for j in range(4):
            cmd[j] = speeds[j]
        if t < 1e-9 and offset_m < named.position(meas)[1] < -0.1:
            raise ValueError("this trial is too far to the side for me")

    register_controller(name, step=offset_trials_raise, replace=True)


@pytest.mark.slow  # three benchmark cells, twice
def test_a_plugin_raising_at_a_later_trial_stops_the_command_and_it_resumes(
    capsys, tmp_path, monkeypatch
):
    """Three trials per cell: the plug-in passes its pre-flight (the first trial of each
    cell) and every wall cell (one per sensor set of the default suite), then raises at the
    pole grid's third point. One line, exit 2; the wall cells kept; fixed, the same command
    resumes without flying them again."""
    from quadimpact.studies.benchmark.suite import SUITE_VERSION, SUITES

    sets = SUITES[SUITE_VERSION].sensor_sets
    name = "t-raises-later"
    _raising_from(-0.335, name)
    try:
        monkeypatch.setattr(
            benchmark_study, "BenchmarkStudy", functools.partial(BenchmarkStudy, limit=3)
        )
        out = tmp_path / "bench"
        args = (
            "benchmark", "--tasks", "wall,pole", "--controller", name, "--no-references",
            "--no-cache", "--workers", "1", "--out", str(out),
        )  # fmt: skip
        code, err = cli_here(capsys, *args)
        _one_error_line(
            code, err, f"benchmark: {name} pole/ideal, run 2: ", "offset_trials_raise",
            "raised ValueError: this trial is too far to the side for me",
            f"the {len(sets)} cells finished are kept", "the same command resumes",
        )  # fmt: skip
        assert f"quadimpact: compiling plug-in {name!r}" in err
        kept = out / "cells" / name
        assert all((kept / f"wall-{s}.parquet").is_file() for s in sets), sorted(kept.iterdir())
        assert not (kept / "pole-ideal.parquet").exists()
        assert (kept / "pole-ideal" / "sweep-failed" / "runs.parquet").is_file()
        assert not (out / "benchmark.csv").exists()
        wall_sweep = kept / "wall-ideal" / "sweep" / "runs.parquet"
        stamp = wall_sweep.stat().st_mtime_ns

        # fixed (never raising): the same command resumes, the wall cells not flown again
        _raising_from(1.0, name)
        code, err = cli_here(capsys, *args)
        assert code == 0, err
        assert wall_sweep.stat().st_mtime_ns == stamp
        t = pd.read_csv(out / "benchmark.csv")
        mine = t[t["row"] == name]
        assert len(mine) == 2 * len(sets), mine
        assert (mine["failed_runs"] == 0).all() and (mine["trials"] == 3).all()
        # the compilation apart: the step's compile in compile_cpu_s, a trial's CPU in ms
        first = mine[(mine["task"] == "wall") & (mine["sensors"] == "ideal")]
        assert float(first["compile_cpu_s"].iloc[0]) > 0.0, mine["compile_cpu_s"]
        assert (mine["cpu_ms_per_trial"] < 500.0).all(), mine["cpu_ms_per_trial"]
        study = json.loads((out / "study.json").read_text())
        assert study["identity"]["limit"] == 3
    finally:
        unregister_controller(name)


def test_run_benchmark_stops_on_a_plugin_raising_in_a_run(tmp_path):
    """The study's own entry: an ``InputError`` of one line, the same as the command's."""
    name = "t-raises-later-2"
    _raising_from(-0.335, name)
    try:
        study = BenchmarkStudy(
            Subject(name, controller=name), tasks=("pole",), references=False, limit=3
        )
        with pytest.raises(InputError) as info:
            run_benchmark(study, tmp_path / "b", workers=1)
        text = str(info.value)
        assert text.startswith(f"benchmark: {name} pole/ideal, run 2: controller plug-in "), text
        assert "the 0 cells finished are kept" in text
    finally:
        unregister_controller(name)


def test_a_plugins_compilation_is_in_its_own_cost_and_in_no_other(caplog, plugins):
    """The first run of a process compiles the plug-in's step (alone: the loop is the cached
    one): its ``compile_cpu_s`` holds it, its kernel and total CPU do not (the second run's
    cost is of the same size as the first's); it is announced once."""
    from quadimpact.simulation.batch import simulate_batch

    name = "t-hold-costs"
    register_controller(name, step=njit(hold.py_func), replace=True)  # new to this process
    try:
        first, second = (
            s["cost"] for s in simulate_batch([ImpactTrial(controller=name, final_time_s=0.3)] * 2)
        )
        assert first["compile_cpu_s"] > 0.0 and second["compile_cpu_s"] == 0.0, (first, second)
        assert first["total_cpu_s"] < 20 * second["total_cpu_s"] + 0.05, (first, second)
        assert first["kernel_cpu_s"] < 20 * second["kernel_cpu_s"] + 0.05, (first, second)
        said = [r.getMessage() for r in caplog.records if "compiling plug-in" in r.getMessage()]
        assert len(said) == 1 and f"plug-in {name!r}" in said[0], said
    finally:
        unregister_controller(name)
