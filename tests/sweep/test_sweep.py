"""Sweeps: value parsing, spec validation, identical tables on every backend
(in-process, local processes, a real Dask cluster on loopback), resume, failed
runs as rows, the command line and the plots (signals, kills and lost workers:
``test_processes.py``; damaged parts: ``test_store.py``)."""

from __future__ import annotations

import json
import os
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

import quadimpact
from quadimpact.errors import InputError, short_path
from quadimpact.sweep import (
    SUMMARY_COLUMNS,
    SweepSpec,
    flatten_summary,
    load_sweep_file,
    parse_values,
    read_runs,
    run_sweep,
)

from helpers import assert_same_table

SRC = Path(quadimpact.__file__).resolve().parents[1]
BASE = {"model": "paper-replica", "final_time_s": 1.0}
SMALL_GRID = {"heading_deg": [0, 45], "inclination_deg": [-5, 10], "speed_m_s": [0.75]}


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
    env.pop("QUADIMPACT_DEBUG", None)
    return env


def _cli(*args: str, cwd: Path, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "quadimpact.cli", *args],
        cwd=cwd,
        env=_env(),
        capture_output=True,
        text=True,
        timeout=timeout,
    )


# ------------------------------------------------------------------ values
@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("0,45", [0, 45]),
        ("-20:20:1", list(range(-20, 21))),
        ("0:0.3:0.1", [0.0, 0.1, 0.2, 0.3]),
        ("0.5:1:0.25", [0.5, 0.75, 1.0]),
        ("1:0:-0.5", [1.0, 0.5, 0.0]),
        ("0:1:0.3", [0.0, 0.3, 0.6, 0.9]),
        ("-20:-10:5, 0, 10:20:10", [-20, -15, -10, 0, 10, 20]),
        ("1e-3,2.5", [0.001, 2.5]),
        ("paper-replica,default", ["paper-replica", "default"]),
        ("true", [True]),
        ("45", [45]),
    ],
)
def test_parse_values(text, expected):
    values = parse_values(text)
    assert values == expected
    assert [type(v) for v in values] == [type(v) for v in expected]


def test_parse_values_no_float_drift():
    values = parse_values("-2:2:0.1")
    assert len(values) == 41
    assert values == [round(-2 + 0.1 * k, 10) for k in range(41)]
    assert values[-1] == 2.0 and values[23] == 0.3  # exact decimals, not 0.30000000000000004


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("", "empty value"),
        ("0,,45", "empty value"),
        ("1:2", "start:stop:step"),
        ("a:b:c", "must be numbers"),
        ("0:10:0", "step must not be 0"),
        ("10:0:1", "empty range"),
    ],
)
def test_parse_values_errors(text, fragment):
    with pytest.raises(InputError, match=fragment):
        parse_values(text, "inclination_deg")


# ------------------------------------------------------------------- specs
def test_spec_enumeration_and_vehicle_fields():
    spec = SweepSpec(
        base={"vehicle_overrides": {"mass_kg": 1.0}},
        grid={"heading_deg": [0, 45], "inclination_deg": "-1:1:1", "restitution": [0.5]},
    )
    assert spec.n_runs == 6
    assert spec.inputs(0) == {"heading_deg": 0.0, "inclination_deg": -1.0, "restitution": 0.5}
    assert spec.inputs(4) == {"heading_deg": 45.0, "inclination_deg": 0.0, "restitution": 0.5}
    data = spec.scenario_dict(4)
    assert data["vehicle_overrides"] == {"mass_kg": 1.0, "restitution": 0.5}
    assert "restitution" not in data
    assert spec.columns == {"heading_deg": "f", "inclination_deg": "f", "restitution": "f"}
    spec.validate()
    # grid x runs: every grid point with every run
    spec = SweepSpec(grid={"heading_deg": [0, 45]}, runs=[{"speed_m_s": 1}, {"model": "default"}])
    assert spec.n_runs == 4
    assert spec.inputs(3) == {"heading_deg": 45.0, "model": "default"}
    assert spec.input_columns(spec.inputs(3)) == {
        "heading_deg": 45.0,
        "speed_m_s": None,
        "model": "default",
    }


def test_sample_is_seeded():
    def make(seed):
        return SweepSpec(
            sample={
                "n": 50,
                "seed": seed,
                "ranges": {"inclination_deg": [-20, 20]},
                "choices": {"heading_deg": [0, 45]},
            }
        )

    a, b, c = make(3), make(3), make(4)
    assert [a.inputs(i) for i in range(50)] == [b.inputs(i) for i in range(50)]
    assert a.fingerprint() == b.fingerprint() != c.fingerprint()
    values = [a.inputs(i)["inclination_deg"] for i in range(50)]
    assert all(-20 <= v <= 20 for v in values) and len(set(values)) == 50
    assert {a.inputs(i)["heading_deg"] for i in range(50)} == {0.0, 45.0}


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"grid": {"headng_deg": [0]}}, "headng_deg: unknown field.*did you mean 'heading_deg'"),
        ({"grid": {"inclination_deg": "-20:20:0"}}, "inclination_deg: range step must not be 0"),
        ({"grid": {"inclination_deg": "20:-20:1"}}, "empty range"),
        ({"grid": {}}, "empty sweep"),
        ({"grid": {"heading_deg": []}}, "heading_deg: no values"),
        ({"grid": {"heading_deg": [0, 0.0]}}, "listed twice"),
        ({"grid": {"kind": ["flight"]}}, "kind: cannot be swept"),
        (
            {"grid": {"heading_deg": [0]}, "runs": [{"heading_deg": 1}]},
            "both in the grid and in runs",
        ),
        ({"sample": {"n": 0, "ranges": {"heading_deg": [0, 1]}}}, r"n: must be an integer"),
        ({"sample": {"n": 5, "ranges": {"heading_deg": [1, 0]}}}, "low < high"),
        ({"base": {"modle": "default"}, "grid": {"heading_deg": [0]}}, "base: modle: unknown key"),
    ],
)
def test_spec_errors(kwargs, fragment):
    with pytest.raises(InputError, match=fragment) as info:
        SweepSpec(**kwargs).validate()
    assert "\n" not in str(info.value)


def test_long_grids_are_checked_in_linear_time():
    """100,001 values: the duplicate check was quadratic (about 90 s), now well under 1 s."""
    start = time.perf_counter()
    spec = SweepSpec(grid={"heading_deg": "0:100000:1"})
    assert time.perf_counter() - start < 10
    assert spec.n_runs == 100_001 and spec.grid["heading_deg"][-1] == 100_000.0
    with pytest.raises(InputError, match="value 7 is listed twice"):
        SweepSpec(grid={"heading_deg": [*range(100_000), 7]})
    with pytest.raises(InputError, match="value 'a' is listed twice"):
        SweepSpec(grid={"model": ["a", "b", "a"]})
    assert SweepSpec(grid={"heading_deg": [0.0, -0.0]}).n_runs == 2  # as canonical JSON


def test_large_sweeps_need_confirmation(tmp_path):
    grid = {"inclination_deg": [70.5, *range(999)], "heading_deg": "0:1:0.001"}  # 1,001,000 runs
    with pytest.raises(InputError, match=r"1001000 runs, more than 1000000: confirm with "
                       r"--allow-large \(allow_large=True\)"):  # fmt: skip
        run_sweep(SweepSpec(grid=grid), tmp_path / "o", workers=1)
    with pytest.raises(InputError, match="run 0 .*inclination_deg: must be <= 60"):
        run_sweep(SweepSpec(grid=grid), tmp_path / "o", workers=1, allow_large=True)
    assert not (tmp_path / "o").exists()
    proc = _cli("sweep", "--grid=heading_deg=0:1000:1", "--grid=speed_m_s=0.5:1.5:0.001",
                "--out", "o", cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert "1002001 runs, more than 1000000: confirm with --allow-large" in proc.stderr
    assert not (tmp_path / "o").exists()


def test_bad_values_rejected_before_anything_runs(tmp_path):
    spec = SweepSpec(grid={"inclination_deg": [0, 70]})
    with pytest.raises(
        InputError, match=r"run 1 \(inclination_deg=70.0\): inclination_deg: must be <= 60"
    ):
        run_sweep(spec, tmp_path / "out", workers=1)
    spec = SweepSpec(grid={"restitution": [0.5, 1.5]})
    with pytest.raises(InputError, match=r"vehicle_overrides.restitution: must be <= 1"):
        run_sweep(spec, tmp_path / "out", workers=1)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("[grid\nheading_deg = [0]\n", "invalid TOML"),
        ("[grd]\nheading_deg = [0]\n", "grd: unknown key; did you mean 'grid'"),
        ("[grid]\nheading_deg = '0:10:0'\n", "range step must not be 0"),
        ("[grid]\nspeed_m_s = [0.5, 'fast']\n", r"speed_m_s: must be a number"),
        (
            "base = 'missing.toml'\n[grid]\nheading_deg = [0]\n",
            r"missing.toml( \(\d+ characters\))?: file not found",  # a long path is cut
        ),
        ("[sample]\nn = 5\n", "give ranges and/or choices"),
    ],
)
def test_bad_sweep_files(tmp_path, text, fragment):
    path = tmp_path / "sweep.toml"
    path.write_text(text)
    with pytest.raises(InputError, match=fragment) as info:
        run_sweep(load_sweep_file(path), tmp_path / "out", workers=1)
    # the file is named first, whole or (a long path) cut in the middle
    named = (str(path), short_path(path)) if "missing" not in text else ""
    assert str(info.value).startswith(named)
    assert not (tmp_path / "out").exists()


def test_sweep_file(tmp_path):
    (tmp_path / "base.toml").write_text('model = "paper-replica"\nfinal_time_s = 1.0\n')
    path = tmp_path / "sweep.toml"
    path.write_text(
        'base = "base.toml"\n[grid]\nheading_deg = "0,45"\ninclination_deg = [-5, 10]\n'
        "speed_m_s = 0.75\n"
    )
    spec = load_sweep_file(path)
    assert spec == SweepSpec(base=BASE, grid=SMALL_GRID)
    assert spec.with_grid({"speed_m_s": [1.0]}).inputs(0)["speed_m_s"] == 1.0


def test_flatten_covers_the_summary():
    """Every key of a real summary has its column (update SUMMARY_COLUMNS otherwise)."""
    summary = quadimpact.simulate(
        quadimpact.WallApproach(heading_deg=45, inclination_deg=15, final_time_s=1.5)
    ).summary
    row = flatten_summary(summary)
    assert row["summary_extra"] is None, f"summary keys without a column: {row['summary_extra']}"
    assert "integrator__wall_time_s" not in row
    assert set(row) == {name for name, _ in SUMMARY_COLUMNS}
    assert json.loads(row["leading_bumpers"]) == summary["leading_bumpers"]
    assert row["approach__start_time_s"] == summary["approach"]["start_time_s"]


def test_a_row_has_every_column_once_typed_and_in_the_tables_order():
    """A hand-made summary: nested tables joined with ``__``, lists as JSON, timings
    dropped, inputs skipped, unknown keys in summary_extra, missing columns null,
    ints given for floats as floats; and the row is the same built twice (its kept
    template is not changed by a row)."""
    summary = {
        "status": "completed",
        "delta_init_m": 1,  # an int for a float column
        "peak_force_n": float("nan"),
        "leading_bumpers": [1, 2],
        "n_episodes": 3,
        "bumper_model_valid": True,
        "integrator": {"steps": 10, "wall_time_s": 0.5},
        "model_options": {"bumper_force_scale": [1.0, 1.0, 1.0, 1.0]},
        "speed_m_s": 0.75,  # an input: skipped
        "not_a_column": {"a": 1},
    }
    skip = {"speed_m_s": 0.75}
    row = flatten_summary(summary, skip=skip)
    names = [name for name, _ in SUMMARY_COLUMNS if name not in skip]
    assert list(row) == names
    assert row["status"] == "completed" and row["n_episodes"] == 3
    assert row["delta_init_m"] == 1.0 and type(row["delta_init_m"]) is float
    assert row["peak_force_n"] is None
    assert row["leading_bumpers"] == "[1,2]"
    assert row["integrator__steps"] == 10 and "integrator__wall_time_s" not in row
    assert row["model_options__bumper_force_scale"] == "[1.0,1.0,1.0,1.0]"
    assert json.loads(row["summary_extra"]) == {"not_a_column__a": 1}
    assert row["response_type"] is None  # not in the summary: null
    assert flatten_summary(summary, skip=skip) == row
    assert flatten_summary({}, skip=skip)["status"] is None


def test_tuples_kept_between_rows_are_typed_as_their_own_values():
    """The JSON text of a tuple is kept from row to row: tuples equal under ``==`` but
    written differently (1 and 1.0, 0.0 and -0.0, True and 1) each keep their own text,
    as they were before they were kept (a NaN as NaN, as in a list)."""
    texts = []
    for value in [(1, 2), (1.0, 2.0), (0.0,), (-0.0,), (True,), (1,), (1, 2), (float("nan"),)]:
        row = flatten_summary({"model_options": {"bumper_force_scale": value}})
        texts.append(row["model_options__bumper_force_scale"])
    assert texts == ["[1,2]", "[1.0,2.0]", "[0.0]", "[-0.0]", "[true]", "[1]", "[1,2]", "[NaN]"]
    nested = ((1.0, 2.0), [3.0])
    row = flatten_summary({"model_options": {"cut_step_motors": nested}})
    assert row["model_options__cut_step_motors"] == "[[1.0,2.0],[3.0]]"


def test_a_chunk_runs_in_groups_with_the_rows_of_runs_alone(monkeypatch):
    """A worker runs a chunk in groups (prepare all, run all, summarise all): the first
    group alone (nothing measured yet), then groups of several; it says each group's
    size and each loop's start; the rows are those of the runs done one by one, bit for
    bit but for their costs, and each cost is the run's own."""
    from quadimpact.sweep import worker
    from quadimpact.sweep.backends import make_chunks
    from quadimpact.sweep.worker import run_item, run_items

    monkeypatch.setattr(worker, "_RUNNER", None)  # a worker's first chunk: nothing measured
    spec = SweepSpec(base=BASE, grid={"inclination_deg": "-10:13:1"})
    spec.validate()
    (chunk,) = list(make_chunks(spec, range(spec.n_runs), 32))
    events: list[tuple[str, int]] = []
    done = list(
        run_items(
            chunk,
            on_group=lambda n: events.append(("group", n)),
            on_loop=lambda k: events.append(("loop", k)),
        )
    )
    sizes = [n for kind, n in events if kind == "group"]
    assert sum(sizes) == len(chunk) == 24 and sizes[0] == 1 and max(sizes) > 1
    at = 0
    for n in sizes:  # each group: its size, then its loops in order
        assert events[at] == ("group", n) and events[at + 1 : at + 1 + n] == [
            ("loop", k) for k in range(n)
        ]
        at += 1 + n
    from quadimpact.sweep.store import COST_COLUMNS as costs

    for item, (row, cost) in zip(chunk, done, strict=True):
        alone, _ = run_item(item)
        assert {k: v for k, v in row.items() if k not in costs} == {
            k: v for k, v in alone.items() if k not in costs
        }
        assert 0.0 < row["cost__kernel_cpu_s"] < row["cost__total_cpu_s"]
        assert 0.0 < cost.kernel_s < cost.wall_s and cost.steps > 0


# ------------------------------------------------------------- backends
@pytest.fixture(scope="module")
def serial_table(tmp_path_factory):
    out = tmp_path_factory.mktemp("serial")
    return run_sweep(SweepSpec(base=BASE, grid=SMALL_GRID), out, workers=1)


def test_serial_table(serial_table):
    t = serial_table
    assert list(t["run_id"]) == [0, 1, 2, 3]
    assert list(t.columns[:4]) == ["run_id", "heading_deg", "inclination_deg", "speed_m_s"]
    assert list(t["heading_deg"]) == [0.0, 0.0, 45.0, 45.0]
    assert list(t["inclination_deg"]) == [-5.0, 10.0, -5.0, 10.0]
    assert set(t["status"]) <= {"completed", "crashed"}
    assert set(t["response_type"]) <= {"A", "B", "C", "D", "Other"}
    assert t["delta_init_m"].between(0.005, 0.1).all()
    assert str(t["n_subsequent_impacts"].dtype) == "Int64"
    assert "integrator__wall_time_s" not in t.columns


def test_parallel_table_is_identical(serial_table, tmp_path):
    table = run_sweep(SweepSpec(base=BASE, grid=SMALL_GRID), tmp_path / "p", workers=2)
    assert table.attrs["sweep"]["backend"] == "2 processes"
    assert_same_table(table, serial_table)


def test_trials_run_here_leave_what_the_process_held_out_of_its_collections(monkeypatch, tmp_path):
    """Python's full collection walks every object of the process and is paid by whichever
    trial triggers it: 80 to 110 ms in a study's process, over 20 times a wall trial. The
    trials a sweep runs in its own process run with the process's objects frozen (left
    out of the collector's scans), and the sweep gives them back when it ends."""
    import gc

    import quadimpact.sweep.runner as run_module

    frozen: list[int] = []
    real = run_module.run_serial

    def spy(chunks, sink):
        frozen.append(gc.get_freeze_count())
        return real(chunks, sink)

    monkeypatch.setattr(run_module, "run_serial", spy)
    assert gc.get_freeze_count() == 0
    run_sweep(SweepSpec(base=BASE, grid=SMALL_GRID), tmp_path / "o", workers=1)
    assert frozen and min(frozen) > 10_000  # the imports' objects, at least
    assert gc.get_freeze_count() == 0


def _children() -> set[int]:
    import psutil

    return {p.pid for p in psutil.Process().children(recursive=True)}


def test_default_small_sweep_runs_in_process(serial_table, tmp_path):
    """By default, runs that would take under a second here start no process at all."""
    before = _children()
    placed: list[int] = []
    out = tmp_path / "s"
    table = run_sweep(
        SweepSpec(base=BASE, grid=SMALL_GRID), out, on_placed=lambda: placed.append(_rows(out))
    )
    assert table.attrs["sweep"]["backend"] == "serial"
    assert not _children() - before
    assert_same_table(table, serial_table)
    # told once that the runs stay here, before the last of them was written
    assert len(placed) == 1 and placed[0] < len(table)


def _rows(out: Path) -> int:
    """Rows written to a sweep folder's parts so far."""
    import pyarrow.parquet as pq

    return sum(pq.read_metadata(p).num_rows for p in (out / "parts").glob("part-*.parquet"))


def test_on_placed_is_called_once_whatever_the_backend(serial_table, tmp_path):
    """Given workers, in this process or a pool: one call, before any run was written; in a
    folder with nothing left to run: one call too."""
    spec = SweepSpec(base=BASE, grid=SMALL_GRID)
    for workers, out in ((1, tmp_path / "one"), (2, tmp_path / "two")):
        placed: list[int] = []
        run_sweep(spec, out, workers=workers, on_placed=lambda o=out, p=placed: p.append(_rows(o)))
        assert placed == [0]
    placed = []
    info = run_sweep(spec, tmp_path / "two", load=False, on_placed=lambda: placed.append(0))
    assert info["n_ran"] == 0 and placed == [0]


def test_default_hands_over_to_the_pool(monkeypatch, tmp_path):
    """By default the first runs are done here, then (if other cores are idle) the pool does
    the rest once its server is warm; one table, the same as in-process."""
    import quadimpact.sweep.runner as run_module
    from quadimpact.sweep.pool import pool_context, server_ready, start_server

    spec = SweepSpec(base=BASE, grid={"heading_deg": [0, 45], "inclination_deg": "-4:10:2"})
    reference = run_sweep(spec, tmp_path / "ref", workers=1)
    start_server(pool_context())
    end = time.monotonic() + 60
    while not server_ready(pool_context()) and time.monotonic() < end:
        time.sleep(0.05)
    monkeypatch.setattr(run_module, "FINISH_HERE_S", 0.0)  # never "too little left"
    monkeypatch.setattr(run_module, "MEASURE_S", 0.0)  # decide after the first run
    monkeypatch.setattr(run_module, "WARM_HANDOVER_RUNS", 10**9)  # time runs here first
    placed: list[str] = []
    table = run_sweep(spec, tmp_path / "d", on_placed=lambda: placed.append("placed"))
    assert placed == ["placed"]
    backend = table.attrs["sweep"]["backend"]
    # the pool, unless the other cores were measured busy
    handed_over = re.fullmatch(r"\d processes, the first [12] runs in this one", backend)
    assert backend == "serial" or handed_over, backend
    assert_same_table(table, reference)
    # from WARM_HANDOVER_RUNS runs on, a warm server takes every run (none here) when
    # another core is idle; the same table. The idle cores measured as 2 (the measure
    # itself, over MEASURE_S = 0 here, would be one jiffy of /proc/stat or none)
    monkeypatch.setattr(run_module, "WARM_HANDOVER_RUNS", 2)
    monkeypatch.setattr(run_module, "_warm_pool_size", lambda cores: 2)
    placed.clear()
    table = run_sweep(spec, tmp_path / "w", on_placed=lambda: placed.append("placed"))
    backend = table.attrs["sweep"]["backend"]
    assert placed == ["placed"]
    assert backend == "2 processes", backend
    assert_same_table(table, reference)


@pytest.mark.parametrize(
    ("idle", "cores", "workers"),
    [(None, 4, 4), (0.0, 2, 1), (0.4, 2, 1), (0.5, 2, 2), (0.95, 2, 2), (6.7, 8, 8), (2.2, 8, 3)],
)
def test_default_pool_size(idle, cores, workers):
    from quadimpact.sweep.runner import pool_size

    assert pool_size(idle, cores) == workers


@pytest.mark.parametrize(
    ("idle", "before", "after", "window", "expected"),
    [(0.2, 1.0, 1.2, 0.25, 1.0), (0.2, None, 1.2, 0.25, 0.2), (None, 1.0, 1.2, 0.25, None),
     (1.0, 1.0, 1.0, 0.25, 1.0), (0.3, 2.0, 1.9, 0.25, 0.3)],
)  # fmt: skip
def test_own_server_counts_as_idle(idle, before, after, window, expected):
    """The CPU the sweep's own warming fork server used is idle for the pool's size."""
    from quadimpact.sweep.runner import own_server_idle, pool_size

    got = own_server_idle(idle, before, after, window)
    assert got == pytest.approx(expected) if expected is not None else got is None
    if expected is not None:
        assert pool_size(got, 2) == pool_size(expected, 2)


@pytest.mark.parametrize(("idle", "workers"), [(2.0, 2), (1.6, 2), (1.3, 1), (1.0, 1), (None, 2)])
def test_warm_pool_size_takes_this_waiting_core_off(monkeypatch, idle, workers):
    """Measured while this process waits, its own core is idle too: only the others count."""
    import quadimpact.sweep.runner as run_module

    monkeypatch.setattr(run_module, "MEASURE_S", 0.0)
    monkeypatch.setattr(run_module, "idle_cores", lambda before, after: idle)
    assert run_module._warm_pool_size(2) == workers


@pytest.mark.parametrize(
    ("idle", "own_s", "age_s", "workers", "waits"),
    [(1.0, 1.0, 1.0, 2, False), (0.2, 1.0, 1.0, 1, False), (1.0, 0.0, 1.0, 1, False),
     (2.0, 0.0, 60.0, 2, True)],
)  # fmt: skip
def test_warm_pool_size_measures_from_the_last_sweep_end(
    monkeypatch, idle, own_s, age_s, workers, waits
):
    """A study's next sweep measures the idle cores from its last sweep's end: it waits
    only for what is left of MEASURE_S, and this process's own work in the window counts
    as idle (it stops when the pool starts). An end too long ago is not used."""
    import quadimpact.sweep.runner as run_module

    slept: list[float] = []
    monkeypatch.setattr(run_module.time, "sleep", slept.append)
    monkeypatch.setattr(run_module, "idle_cores", lambda before, after: idle)
    monkeypatch.setattr(run_module, "cpu_sample", lambda: {0: (0, 0)})
    end = (time.perf_counter() - age_s, {0: (0, 0)}, time.process_time() - own_s)
    monkeypatch.setattr(run_module, "_last_sweep_end", end)
    assert run_module._warm_pool_size(2) == workers
    assert (slept == [pytest.approx(run_module.MEASURE_S, abs=0.01)]) if waits else not slept


def test_process_cpu_time_read_from_proc():
    """A process's CPU time from /proc agrees with its own clock to a few ticks."""
    import os
    import time

    from quadimpact.sweep.pool import process_cpu_s

    first = process_cpu_s(os.getpid())
    if first is None:
        pytest.skip("no /proc here")
    end = time.process_time() + 0.2
    while time.process_time() < end:  # burn 0.2 s of CPU
        pass
    tick = 1.0 / os.sysconf("SC_CLK_TCK")
    assert process_cpu_s(os.getpid()) == pytest.approx(time.process_time(), abs=3 * tick)
    assert process_cpu_s(2**22 + 12345) is None  # no such process


def test_idle_cores_measured():
    """While this process burns CPU, at most the other cores are idle."""
    from quadimpact.sweep.runner import cpu_sample, default_workers, idle_cores

    before = cpu_sample()
    if before is None:
        pytest.skip("no /proc/stat")
    end = time.perf_counter() + 0.3
    while time.perf_counter() < end:
        pass
    idle = idle_cores(before, cpu_sample())
    assert idle is not None and 0.0 <= idle <= default_workers() - 0.5


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _stop(procs: list[subprocess.Popen]) -> None:
    for p in procs:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGTERM)
    for p in procs:
        try:
            p.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait(timeout=10)


@pytest.fixture(scope="module")
def dask_cluster(tmp_path_factory):
    """A real scheduler and two one-thread workers, separate processes on loopback."""
    distributed = pytest.importorskip("distributed")
    tmp = tmp_path_factory.mktemp("dask")
    address = f"tcp://127.0.0.1:{_free_port()}"
    procs: list[subprocess.Popen] = []

    def start(name: str, *args: str) -> None:
        log = open(tmp / f"{name}.log", "w")  # noqa: SIM115 - closed with the process
        procs.append(
            subprocess.Popen(
                [sys.executable, "-m", *args],
                cwd=tmp,
                env=_env(),
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
        )

    try:
        port = address.rsplit(":", 1)[1]
        start(
            "scheduler",
            "distributed.cli.dask_scheduler",
            "--host",
            "127.0.0.1",
            "--port",
            port,
            "--no-dashboard",
        )
        for i in range(2):
            start(
                f"worker{i}",
                "distributed.cli.dask_worker",
                address,
                "--nworkers",
                "1",
                "--nthreads",
                "1",
                "--no-dashboard",
                "--host",
                "127.0.0.1",
                "--local-directory",
                str(tmp),
            )
        with distributed.Client(address, timeout="30s", set_as_default=False) as client:
            client.wait_for_workers(2, timeout=60)
        yield address
    finally:
        _stop(procs)


def test_dask_table_is_identical(serial_table, dask_cluster, tmp_path):
    table = run_sweep(SweepSpec(base=BASE, grid=SMALL_GRID), tmp_path / "d", scheduler=dask_cluster)
    assert table.attrs["sweep"]["backend"].startswith("dask")
    assert_same_table(table, serial_table)


def test_a_dask_result_lost_with_its_worker_is_awaited_again_without_blocking():
    """A chunk finished, but its worker went before its rows were fetched: Dask computes it
    again (its client logs "Couldn't gather ... rescheduling"). The sweep waits for it at most
    DASK_GATHER_S (doubled at each new try) and awaits it again, so its loop goes on meanwhile
    (it used to block in the fetch until a worker came back: no "waiting for Dask workers"
    note)."""
    from quadimpact.sweep.backends import DASK_GATHER_S, _Dask, _DaskTask

    class LostResult:
        status = "finished"

        def __init__(self) -> None:
            self.timeouts: list[float | None] = []
            self.callbacks: list = []

        def result(self, timeout: float | None = None):
            self.timeouts.append(timeout)
            raise TimeoutError

        def add_done_callback(self, fn) -> None:
            self.callbacks.append(fn)

    rows: list = []
    loop = _Dask(None, limits=None, sink=rows.extend, note=lambda message: None)
    fut, task = LostResult(), _DaskTask([(0, None, {})])
    loop.finished(fut, task)
    assert fut.timeouts == [DASK_GATHER_S] and loop.pending == {fut: task}
    assert fut.callbacks == [loop.done.put] and rows == [] and not loop.retry
    for _ in range(8):  # each new try waits twice as long, up to 64 times the first
        loop.finished(fut, loop.pending.pop(fut))
    assert fut.timeouts == [DASK_GATHER_S * 2**k for k in (0, 1, 2, 3, 4, 5, 6, 6, 6)]
    assert loop.pending == {fut: task} and len(fut.callbacks) == 9


def test_bad_scheduler(tmp_path):
    pytest.importorskip("distributed")
    with pytest.raises(InputError, match="must be an address like tcp://HOST:PORT"):
        run_sweep(SweepSpec(grid={"heading_deg": [0]}), tmp_path / "o", scheduler="nowhere")
    assert not (tmp_path / "o").exists()


# ------------------------------------------------------ failures, resume
def test_impossible_run_is_a_failed_row(serial_table, tmp_path):
    """A bumper so stiff that the step size collapses (k = 1e20 N/m^n; 1e15 still runs,
    in about 800 steps): those runs are failed rows with the kernel's reason; the sweep
    goes on."""
    spec = SweepSpec(
        base=BASE,
        grid={"heading_deg": [0, 45], "inclination_deg": [-5], "contact_stiffness": [40.0, 1e20]},
    )
    table = run_sweep(spec, tmp_path / "f", workers=2)
    assert len(table) == 4
    failed = table[table["status"] == "failed"]
    assert list(failed["run_id"]) == [1, 3]  # stiffness 1e20, both headings
    assert set(failed["reason"]) == {"step size fell below the floor (stiff or singular dynamics)"}
    assert failed["response_type"].isna().all()
    ok = table.drop(index=failed.index)
    assert set(ok["status"]) <= {"completed", "crashed"} and ok["reason"].eq("").all()
    # the unchanged runs have the same numbers as in the other sweep
    ref = serial_table[serial_table["inclination_deg"] == -5.0]
    assert list(table.loc[table["contact_stiffness"] == 40.0, "delta_init_m"]) == list(
        ref["delta_init_m"]
    )
    common = [c for c in serial_table.columns if c in table.columns]
    assert (table.dtypes[common] == serial_table.dtypes[common]).all()


def test_exception_in_a_run_is_a_failed_row(monkeypatch, serial_table, tmp_path):
    import quadimpact.simulation.batch as batch

    real = batch.prepare

    def fake(scenario, **kwargs):
        if scenario.inclination_deg == 10:
            raise RuntimeError("approach shooting run failed: test")
        return real(scenario, **kwargs)

    monkeypatch.setattr(batch, "prepare", fake)
    table = run_sweep(SweepSpec(base=BASE, grid=SMALL_GRID), tmp_path / "x", workers=1)
    bad = table[table["inclination_deg"] == 10.0]
    assert list(bad["status"]) == ["failed", "failed"]
    assert list(bad["reason"]) == ["RuntimeError: approach shooting run failed: test"] * 2
    assert bad["delta_init_m"].isna().all() and bad["n_episodes"].isna().all()
    good = table[table["inclination_deg"] == -5.0]
    assert_same_table(good, serial_table[serial_table["inclination_deg"] == -5.0])
    assert (table.dtypes == serial_table.dtypes).all()


CRASH_SCRIPT = """
import os
import quadimpact.simulation.batch as batch

real = batch.prepare


def crashing(scenario, **kwargs):  # imported again in each worker (forkserver/spawn)
    if scenario.inclination_deg == 7:
        os._exit(3)  # the worker dies, as in a crash in native code
    return real(scenario, **kwargs)


batch.prepare = crashing

if __name__ == "__main__":
    from quadimpact.sweep import SweepSpec, run_sweep

    spec = SweepSpec(base={"final_time_s": 1.0}, grid={"inclination_deg": "0:10:1"})
    run_sweep(spec, "out", workers=2)
"""


def _run_script(folder: Path, text: str, timeout: float = 120) -> subprocess.CompletedProcess:
    """Run ``text`` as the main script ``script.py`` in ``folder`` (worker processes import it)."""
    (folder / "script.py").write_text(text)
    return subprocess.run(
        [sys.executable, "script.py"], cwd=folder, env=_env(), capture_output=True, text=True,
        timeout=timeout,
    )  # fmt: skip


def test_worker_crash_is_a_failed_row(tmp_path):
    """A run that kills its worker process: that run failed, every other run done."""
    proc = _run_script(tmp_path, CRASH_SCRIPT)
    assert proc.returncode == 0, proc.stderr
    table = read_runs(tmp_path / "out")
    assert list(table.loc[table["status"] == "failed", "inclination_deg"]) == [7.0]
    assert table.loc[7, "reason"].startswith("worker process died")
    assert len(table) == 11 and table["delta_init_m"].notna().sum() == 10


UNGUARDED_SCRIPT = """
from quadimpact.sweep import run_sweep

run_sweep({"grid": {"speed_m_s": [0.5, 1.0], "inclination_deg": [0, 5]}}, "out", workers=2)
"""


def test_a_script_without_the_main_guard_is_told_so_first(tmp_path):
    """Workers re-run an unguarded script: the first line says what to do, no worker traceback."""
    proc = _run_script(tmp_path, UNGUARDED_SCRIPT, timeout=300)
    assert proc.returncode != 0
    lines = proc.stderr.strip().splitlines()
    assert lines[0].startswith("quadimpact: error: a sweep worker, starting up, ran the script")
    assert 'if __name__ == "__main__":' in lines[0]
    assert "multiprocessing" not in proc.stderr and len(lines) < 20, proc.stderr


def test_rerun_and_other_sweep_in_the_folder(serial_table, tmp_path):
    out = tmp_path / "r"
    spec = SweepSpec(base=BASE, grid=SMALL_GRID)
    run_sweep(spec, out, workers=1)
    again = run_sweep(spec, out, workers=1)
    assert again.attrs["sweep"]["n_ran"] == 0
    assert_same_table(again, serial_table)
    # an interrupted sweep: drop two rows, the rerun does only those
    full = read_runs(out)
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pq.read_table(out / "runs.parquet")
    pq.write_table(table.filter(pa.array([True, False, True, False])), out / "runs.parquet")
    resumed = run_sweep(spec, out, workers=1)
    assert resumed.attrs["sweep"]["n_ran"] == 2
    assert_same_table(resumed, full)
    with pytest.raises(InputError, match="holds a different sweep.*grid"):
        run_sweep(SweepSpec(base=BASE, grid={"heading_deg": [0]}), out, workers=1)


# -------------------------------------------------------------------- CLI
def test_cli_sweep(tmp_path):
    proc = _cli(
        "sweep",
        "--grid", "heading_deg=0,45", "--grid", "inclination_deg=-5,0,10",
        "--grid", "final_time_s=1", "--grid", "model=paper-replica",
        "--out", "o", "--workers", "1", "--no-progress",
        cwd=tmp_path,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "runs    6 (0 failed, 0 deeper than the bumper radius; " in proc.stdout
    assert "types   A" in proc.stdout
    table = read_runs(tmp_path / "o")
    assert len(table) == 6 and table["final_time_s"].eq(1.0).all()
    plots = sorted(p.name for p in (tmp_path / "o" / "plots").iterdir())
    assert plots == [".drawn.json", "delta_init_m_vs_inclination_deg.png",
                     "types_inclination_deg_heading_deg.png"]  # fmt: skip


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--grid", "headng_deg=0"], "headng_deg: unknown field"),
        (["--grid", "inclination_deg=0:1"], "start:stop:step"),
        (["--grid", "inclination"], "must be FIELD=VALUES"),
        ([], "give a sweep file or at least one --grid"),
        (["missing.toml"], "missing.toml: file not found"),
    ],
)
def test_cli_sweep_errors(tmp_path, args, fragment):
    proc = _cli("sweep", *args, "--out", "o", cwd=tmp_path)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("quadimpact: error:"), proc.stderr
    assert fragment in lines[0]
    assert not (tmp_path / "o").exists()


# ------------------------------------------------------------------ plots
def test_plots(serial_table, tmp_path):
    from quadimpact.sweep.plots import choose_plot_fields, plot_metric, plot_type_map

    fig = plot_metric(serial_table, "inclination_deg", by="heading_deg", path=tmp_path / "m.png")
    assert len(fig.axes) == 1 and len(fig.axes[0].lines) == 2
    fig = plot_metric(serial_table, "inclination_deg", facet="heading_deg")
    assert len(fig.axes) == 2
    fig = plot_type_map(
        serial_table, "inclination_deg", "speed_m_s", path=tmp_path / "t.png", facet="heading_deg"
    )
    assert len(fig.axes) == 2
    assert len(fig.axes[0].texts) == 2  # n_subsequent_impacts in each cell
    assert (tmp_path / "m.png").stat().st_size > 0 and (tmp_path / "t.png").stat().st_size > 0
    with pytest.raises(InputError, match="nope: no such column"):
        plot_metric(serial_table, "nope")
    fig4 = {"heading_deg": [0, 45], "inclination_deg": list(range(-20, 21)), "speed_m_s": [1, 2, 3]}
    kinds = dict.fromkeys(fig4, "f")
    assert choose_plot_fields(kinds, fig4) == ("inclination_deg", "speed_m_s", "heading_deg")


def test_plots_say_what_they_show(serial_table):
    """Units in the labels, the fixed parameters in the title, the cells' numbers in the
    legend, runs deeper than the bumper radius marked."""
    from quadimpact.sweep.plots import fixed_parameters, plot_metric, plot_type_map

    spec = SweepSpec(base={**BASE, "vehicle_overrides": {"restitution": 0.7}}, grid=SMALL_GRID)
    fixed = fixed_parameters(spec)
    assert fixed == ("model paper-replica, controller paper, vehicle spiri, impact speed V_c = "
                     "0.75 m/s, ground crash, final time = 1 s, restitution = 0.7")  # fmt: skip
    table = serial_table.copy()
    table.loc[table.index[0], "bumper_model_valid"] = False
    fig = plot_metric(table, "inclination_deg", by="heading_deg", title=fixed)
    ax = fig.axes[0]
    assert ax.get_xlabel() == "inclination ι (deg)" and ax.get_ylabel() == "δ_init (mm)"
    labels = [line.get_label() for line in ax.lines]
    assert labels == [
        "heading ψ = 0 deg",
        "heading ψ = 45 deg",
        "run deeper than the bumper radius (the bumper model does not hold)",
    ]
    assert fig.get_suptitle().replace("\n", " ") == fixed  # wrapped to the figure's width
    fig = plot_type_map(table, "inclination_deg", "heading_deg", title=fixed)
    names = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "number: subsequent impacts" in names
    assert "run deeper than the bumper radius (the bumper model does not hold)" in names
    assert fig.axes[0].get_ylabel() == "heading ψ (deg)"
    assert sum(p.get_hatch() == "//" for p in fig.axes[0].patches) == 1


def test_a_rerun_with_nothing_to_do_keeps_the_plots_drawn_from_the_same_table(tmp_path):
    """No Matplotlib, no drawing: the plots drawn from this very table are kept (issue 46);
    a table written again, or a plot gone, draws them again."""
    import json
    import os
    import subprocess
    import sys

    args = ["sweep", "--grid", "inclination_deg=0,10", "--grid", "speed_m_s=0.5,1.0",
            "--workers", "1", "--no-progress", "--out", "o"]  # fmt: skip
    code = (
        "import json, sys\n"
        "from quadimpact.cli import main\n"
        "try:\n"
        f"    main({args!r})\n"
        "except SystemExit as exc:\n"
        "    assert not exc.code, exc.code\n"
        "print(json.dumps('matplotlib' in sys.modules))\n"
    )

    def run() -> tuple[bool, str]:
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                              cwd=tmp_path, timeout=120)  # fmt: skip
        assert proc.returncode == 0, proc.stderr
        *out, drew = proc.stdout.strip().splitlines()
        return json.loads(drew), "\n".join(out)

    def mtimes() -> dict[str, int]:
        return {p.name: p.stat().st_mtime_ns for p in (tmp_path / "o" / "plots").glob("*.png")}

    drew, out = run()
    first = mtimes()
    assert drew and sorted(first) == [
        "delta_init_m_vs_inclination_deg.png", "types_inclination_deg_speed_m_s.png"
    ]  # fmt: skip
    drew, again = run()
    assert not drew and mtimes() == first and again.splitlines()[-1] == out.splitlines()[-1]
    assert "all done before, nothing to run" in again
    # what draws them again: a table written anew, a plot gone
    from quadimpact.sweep.plot_plan import drawn_plots

    names = sorted(first)
    assert drawn_plots(tmp_path / "o", names) == [tmp_path / "o" / "plots" / n for n in names]
    table = tmp_path / "o" / "runs.parquet"
    os.utime(table, ns=(table.stat().st_atime_ns, table.stat().st_mtime_ns + 1_000_000))
    assert drawn_plots(tmp_path / "o", names) is None
    drew, _ = run()
    assert drew and all(mtimes()[name] > first[name] for name in first)
    assert drawn_plots(tmp_path / "o", names) is not None
    (tmp_path / "o" / "plots" / names[0]).unlink()
    assert drawn_plots(tmp_path / "o", names) is None
