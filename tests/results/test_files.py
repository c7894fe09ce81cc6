"""Result folder: writers, readers and SimulationResult.write."""

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from quadimpact.core.recording_slots import (
    E_FEATURE,
    E_OPEN,
    E_PEAK_DELTA,
    E_PEAK_FORCE,
    E_SHAPE,
    E_T_END,
    E_T_START,
    E_V_I,
    NEP,
)
from quadimpact.results.files import (
    EPISODES_LEADING_COLUMNS,
    TIMESERIES_COLUMNS,
    UNITS_METADATA_KEY,
    column_unit,
    read_timeseries_units,
    to_jsonable,
    write_episodes_csv,
    write_summary_json,
    write_timeseries_parquet,
)
from quadimpact.results.result import SimulationResult, read_result
from quadimpact.simulation.tables import episodes_frame


def make_timeseries(n: int = 50) -> pd.DataFrame:
    t = np.linspace(0.0, 1.0, n)
    data = {c: np.zeros(n) for c in TIMESERIES_COLUMNS}
    data["t_s"] = t
    data["x_m"] = 1.2 + 0.1 * t
    data["altitude_m"] = 2.0 - 0.5 * t**2
    data["z_m"] = -data["altitude_m"]
    data["q0"] = np.ones(n)
    data["yaw_deg"] = 45.0 + 10.0 * np.sin(6.0 * t)
    data["delta4_m"] = np.clip(0.03 * np.sin(20.0 * (t - 0.5)), 0.0, None)
    return pd.DataFrame(data)


def make_episodes() -> pd.DataFrame:
    raw = np.zeros((3, NEP))
    raw[0, [E_FEATURE, E_SHAPE, E_T_START, E_T_END]] = [3, 0, 0.5, 0.52]
    raw[0, [E_V_I, E_PEAK_DELTA, E_PEAK_FORCE]] = [0.75, 0.0312345678901234, 50.5]
    raw[1, [E_FEATURE, E_SHAPE, E_T_START, E_T_END, E_OPEN]] = [1, 1, 0.9, 1.0, 1]
    raw[1, E_V_I] = np.nan
    return episodes_frame(raw, 2, ["wall", "ground"])


def make_result(**kw: object) -> SimulationResult:
    summary = {
        "status": "completed",
        "delta_init_m": np.float64(0.0312345678901234),
        "crash_time_s": float("nan"),
        "n_episodes": np.int64(2),
        "leading_bumpers": [4],
        "flags": np.array([True, False]),
    }
    refs = {"roll_rad": 0.1, "pitch_rad": -0.2, "yaw_rad": math.pi / 4, "altitude_m": 2.0}
    args = {
        "summary": summary,
        "episodes": make_episodes(),
        "timeseries": make_timeseries(),
        "references": refs,
        "scenario": None,
        "stats": {"n_steps": np.int64(1234), "n_rejected": 5},
    }
    args.update(kw)
    return SimulationResult(**args)  # type: ignore[arg-type]


def test_summary_json_nan_to_null_and_numpy_scalars(tmp_path: Path) -> None:
    p = write_summary_json(
        {"a": np.float64("nan"), "b": np.int32(3), "c": [1.5, float("inf")], "d": np.bool_(True)},
        tmp_path / "summary.json",
    )
    text = p.read_text()
    assert "NaN" not in text and "Infinity" not in text
    assert json.loads(text) == {"a": None, "b": 3, "c": [1.5, None], "d": True}
    assert text.startswith("{\n  ")  # indent 2
    assert [f.name for f in tmp_path.iterdir()] == ["summary.json"]  # no temp file left


def test_summary_json_rejects_unknown_objects(tmp_path: Path) -> None:
    with pytest.raises(TypeError, match="object"):
        write_summary_json({"x": object()}, tmp_path / "s.json")
    assert not (tmp_path / "s.json").exists()
    assert list(tmp_path.iterdir()) == []


def test_to_jsonable_nested() -> None:
    assert to_jsonable({"a": (np.float32(0.5), {1, 2}), 3: np.arange(2)}) == {
        "a": [0.5, [1, 2]],
        "3": [0, 1],
    }


def test_episodes_csv_column_order(tmp_path: Path) -> None:
    df = make_episodes()[["open", "t_peak_force_s", *reversed(EPISODES_LEADING_COLUMNS)]]
    write_episodes_csv(df, tmp_path / "e.csv")
    header = (tmp_path / "e.csv").read_text().splitlines()[0].split(",")
    assert header[:8] == list(EPISODES_LEADING_COLUMNS)
    assert header[8:] == ["open", "t_peak_force_s"]


def test_column_units() -> None:
    assert column_unit("t_s") == "s"
    assert column_unit("x_m") == "m"
    assert column_unit("vx_m_s") == "m/s"
    assert column_unit("p_rad_s") == "rad/s"
    assert column_unit("omega_cmd1_rad_s") == "rad/s"
    assert column_unit("force3_n") == "N"
    assert column_unit("roll_deg") == "deg"
    assert column_unit("q0") == "1"
    assert column_unit("q_rad_s") == "rad/s"


def test_parquet_units_metadata(tmp_path: Path) -> None:
    ts = make_timeseries(10)
    p = write_timeseries_parquet(ts, tmp_path / "ts.parquet")
    meta = pq.read_schema(p).metadata
    units = json.loads(meta[UNITS_METADATA_KEY.encode()])
    assert set(units) == set(TIMESERIES_COLUMNS)
    assert units["t_s"] == "s" and units["vz_m_s"] == "m/s" and units["force2_n"] == "N"
    assert read_timeseries_units(p) == units


def test_write_read_round_trip(tmp_path: Path) -> None:
    res = make_result()
    out = res.write(tmp_path / "run")
    names = {f.name for f in out.iterdir()}
    assert names == {"summary.json", "episodes.csv", "timeseries.parquet", "fig5.png", "fig6.png"}
    back = read_result(out)
    assert back.scenario is None
    assert back.summary["delta_init_m"] == 0.0312345678901234
    assert back.summary["crash_time_s"] is None  # NaN -> null
    assert back.summary["n_episodes"] == 2
    assert back.summary["flags"] == [True, False]
    assert "plot_errors" not in back.summary
    assert back.references == pytest.approx(res.references)
    assert back.stats == {"n_steps": 1234, "n_rejected": 5}
    pd.testing.assert_frame_equal(back.timeseries, res.timeseries)
    pd.testing.assert_frame_equal(back.episodes, res.episodes, check_dtype=False)
    assert back.episodes["bumper"].tolist() == [4, 2]
    assert back.episodes["open"].tolist() == [False, True]
    assert math.isnan(back.episodes["v_i_m_s"].iloc[1])
    # The read-back result can be written again (re-plot a folder).
    again = back.write(tmp_path / "again")
    assert (again / "fig6.png").stat().st_size > 10_000


def test_round_trip_without_episodes(tmp_path: Path) -> None:
    res = make_result(episodes=episodes_frame(np.zeros((1, NEP)), 0, ["wall"]))
    back = read_result(res.write(tmp_path))
    assert len(back.episodes) == 0
    assert list(back.episodes.columns) == list(res.episodes.columns)


def test_plot_failure_keeps_data_and_is_reported(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ts = make_timeseries().drop(columns=["delta3_m"])  # Figure 5 cannot be drawn
    (tmp_path / "fig5.png").write_bytes(b"stale")
    res = make_result(timeseries=ts)
    out = res.write(tmp_path)
    err = capsys.readouterr().err
    assert "warning" in err and "fig5.png" in err and "delta3_m" in err
    assert len(err.strip().splitlines()) == 1
    assert not (out / "fig5.png").exists()  # stale figure removed
    assert (out / "fig6.png").exists()
    summary = json.loads((out / "summary.json").read_text())
    assert len(summary["plot_errors"]) == 1 and "KeyError" in summary["plot_errors"][0]
    assert res.summary["plot_errors"] == summary["plot_errors"]
    from quadimpact.errors import InputError
    from quadimpact.results.files import read_episodes_csv, read_timeseries_parquet

    pd.testing.assert_frame_equal(read_timeseries_parquet(out / "timeseries.parquet"), ts)
    assert len(read_episodes_csv(out / "episodes.csv")) == 2
    with pytest.raises(InputError, match="timeseries.parquet: missing column.s. delta3_m"):
        read_result(out)  # a series that cannot be drawn is refused when read back


def test_read_result_missing_folder(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError):
        read_result(tmp_path / "nope")


def test_to_jsonable_keeps_nan_and_unknown_values_when_asked() -> None:
    marker = object()
    value = {"a": np.float64("nan"), "b": (np.int64(2), marker)}
    out = to_jsonable(value, finite=False, strict=False)
    assert math.isnan(out["a"]) and out["b"] == [2, marker]


def test_atomic_write_leaves_the_old_file_on_failure(tmp_path: Path) -> None:
    from quadimpact.results.files import atomic_write

    target = tmp_path / "table.bin"
    atomic_write(target, lambda tmp: tmp.write_bytes(b"old"), durable=True)

    def fail(tmp: Path) -> None:
        assert tmp.name.endswith(".mp4") and tmp.parent == tmp_path
        tmp.write_bytes(b"half")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError, match="disk full"):
        atomic_write(target, fail, suffix=".mp4")
    assert target.read_bytes() == b"old" and [p.name for p in tmp_path.iterdir()] == ["table.bin"]


# ------------------------------------------------------------------ the folder as a whole
def _disk_full(*_args: object, **_kwargs: object) -> None:
    import errno

    raise OSError(errno.ENOSPC, "No space left on device")


def test_a_failed_write_leaves_no_half_folder(tmp_path: Path, monkeypatch) -> None:
    """Disk full while writing the time series: no folder with summary.json but no data."""
    import quadimpact.results.files as files

    monkeypatch.setattr(files, "write_timeseries_parquet", _disk_full)
    with pytest.raises(OSError, match="No space left"):
        make_result().write(tmp_path / "run")
    assert list(tmp_path.iterdir()) == []  # neither the folder nor its hidden stage
    # an existing run folder is left exactly as it was
    monkeypatch.undo()
    old = make_result().write(tmp_path / "old")
    before = {p.name: p.read_bytes() for p in old.iterdir()}
    monkeypatch.setattr(files, "write_timeseries_parquet", _disk_full)
    with pytest.raises(OSError):
        make_result(summary={"status": "crashed"}).write(old)
    assert {p.name: p.read_bytes() for p in old.iterdir()} == before
    assert [p.name for p in tmp_path.iterdir()] == ["old"]


def test_a_run_written_over_a_run_replaces_it_and_its_pictures(tmp_path: Path) -> None:
    from quadimpact.results.files import DERIVED_FILES

    out = make_result().write(tmp_path / "run")
    (out / "imu.parquet").write_bytes(b"old run's IMU")  # the new run has none
    for name in ("animation.mp4", "viewer.html", "snapshots.png", "snapshots.pdf"):
        (out / name).write_bytes(b"picture of the old run")
    (out / "notes.txt").write_text("mine")
    make_result(summary={"status": "crashed"}).write(out)
    names = {p.name for p in out.iterdir()}
    assert names == {"summary.json", "episodes.csv", "timeseries.parquet", "fig5.png",
                     "fig6.png", "notes.txt"}  # fmt: skip
    assert not names & set(DERIVED_FILES)
    assert json.loads((out / "summary.json").read_text())["status"] == "crashed"
    assert [p.name for p in tmp_path.iterdir()] == ["run"]


def test_drawing_commands_write_only_listed_derived_files() -> None:
    """What a new run removes from a run folder names every picture the viz commands write."""
    from quadimpact.experiments.logs_compare import COMPARE_CSV, COMPARE_PNG
    from quadimpact.results.files import DERIVED_FILES, RUN_FILES
    from quadimpact.results.result import FIG5_PNG, FIG6_PNG, IMU_PNG
    from quadimpact.viz.animation import ANIMATION_GIF, ANIMATION_MP4
    from quadimpact.viz.snapshots import SNAPSHOTS_PDF, SNAPSHOTS_PNG
    from quadimpact.viz.viewer import VIEWER_HTML

    assert {ANIMATION_GIF, ANIMATION_MP4, SNAPSHOTS_PDF, SNAPSHOTS_PNG, VIEWER_HTML,
            COMPARE_CSV, COMPARE_PNG} == set(DERIVED_FILES)  # fmt: skip
    assert {FIG5_PNG, FIG6_PNG, IMU_PNG} < set(RUN_FILES)


@pytest.mark.parametrize(
    ("names", "kind", "fragment"),
    [
        (["sweep.json", "runs.parquet"], "a sweep", "sweep.json, runs.parquet"),
        (["report.md"], "a study report", "report.md"),
        (["table3.csv"], "the crash experiments", "table3.csv"),
        (["thesis.tex"], "files that are not quadimpact's", "thesis.tex"),
    ],
)
def test_a_run_refuses_a_folder_of_another_kind(
    tmp_path: Path, names: list[str], kind: str, fragment: str
) -> None:
    from quadimpact.errors import InputError

    for name in names:
        (tmp_path / name).write_text("x")
    with pytest.raises(InputError, match=f"holds {kind} \\({fragment}\\); use a new or empty"):
        make_result().write(tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(names)


def test_check_out_dir_says_what_is_wrong_in_one_line(tmp_path: Path) -> None:
    from quadimpact.errors import InputError
    from quadimpact.results.files import check_out_dir, folder_kind

    (tmp_path / "file").write_text("x")
    cases = [
        (tmp_path / "file" / "sub", "cannot be created: "),
        (tmp_path / "file", "is a file, not a folder"),
        (tmp_path / ("a" * 5000), "path too long"),
        (tmp_path / ("b" * 300) / "c", "longer than 255 bytes|path too long"),
    ]
    for path, rule in cases:
        with pytest.raises(InputError, match=rule) as info:
            check_out_dir(path, "run")
        assert "\n" not in str(info.value) and len(str(info.value)) < 300
    assert check_out_dir(tmp_path / "new" / "run", "run") == tmp_path / "new" / "run"
    assert not (tmp_path / "new").exists()  # checking makes nothing
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / ".hidden").write_text("x")
    assert folder_kind(tmp_path / "run") == (None, [])
    (tmp_path / "run" / "summary.json").write_text("{}")
    assert folder_kind(tmp_path / "run") == ("run", ["summary.json"])
    with pytest.raises(InputError, match="holds a run .*this sweep's own folder"):
        check_out_dir(tmp_path / "run", "sweep")
    # one rule for every kind (issue 20 item 8): no output among files that are not quadimpact's
    for kind in ("sweep", "recovery", "report", "experiments", "run"):
        with pytest.raises(InputError, match="holds files that are not quadimpact's"):
            check_out_dir(tmp_path, kind)


def test_a_one_sample_run_is_plotted_without_warnings(tmp_path: Path) -> None:
    """A run of one sample: its figures, and no Matplotlib warning about singular limits."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = make_result(timeseries=make_timeseries(1)).write(tmp_path / "one")
    assert (out / "fig5.png").is_file() and (out / "fig6.png").is_file()


def test_summary_json_holds_the_integrator_counters_once(tmp_path: Path) -> None:
    """No "stats" copy of "integrator" in the file; older folders with only "stats" still read."""
    out = make_result().write(tmp_path / "run")
    summary = json.loads((out / "summary.json").read_text())
    assert "stats" not in summary and summary["integrator"] == {"n_steps": 1234, "n_rejected": 5}
    assert read_result(out).stats == {"n_steps": 1234, "n_rejected": 5}
    old = dict(summary)
    old["stats"] = old.pop("integrator")  # as older versions wrote it
    (out / "summary.json").write_text(json.dumps(old))
    back = read_result(out)
    assert back.stats == {"n_steps": 1234, "n_rejected": 5} and "stats" not in back.summary
