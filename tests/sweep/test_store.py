"""The sweep store on resume: a damaged part or table (flipped bytes in a data page, a
missing column) is found, named in a warning, and its runs are redone, so that the
folder always completes to the same table; the merge names a file it cannot read."""

from __future__ import annotations

import shutil
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq
import pytest

from quadimpact.sweep import SweepSpec, read_runs, run_sweep
from quadimpact.sweep.store import PartWriter, consolidate, schema_of

from helpers import assert_same_table

SPEC = SweepSpec(base={"final_time_s": 1.0}, grid={"heading_deg": "0:70:10"})  # 8 runs


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> pd.DataFrame:
    return run_sweep(SPEC, tmp_path_factory.mktemp("ref") / "out", workers=1)


@pytest.fixture
def unfinished(reference: pd.DataFrame, tmp_path: Path) -> Path:
    """A folder as a killed sweep leaves it: sweep.json and two parts of four runs."""
    out = tmp_path / "out"
    shutil.copytree(Path(reference.attrs["sweep"]["out_dir"]), out)
    table = pq.read_table(out / "runs.parquet")
    (out / "runs.parquet").unlink()
    writer = PartWriter(out / "parts", schema_of(SPEC), 0)
    for lo in (0, 4):
        writer.write(table.slice(lo, 4))
    return out


def _parts(out: Path) -> list[Path]:
    return sorted((out / "parts").glob("part-*.parquet"))


def _flip_column_bytes(path: Path, column: str, row_group: int = 0) -> None:
    """Invert 8 bytes inside one column's data; the footer and other columns still read."""
    meta = pq.ParquetFile(path).metadata.row_group(row_group)
    names = [meta.column(i).path_in_schema for i in range(meta.num_columns)]
    chunk = meta.column(names.index(column))
    start = chunk.data_page_offset + chunk.total_compressed_size // 2
    data = bytearray(path.read_bytes())
    data[start : start + 8] = bytes(b ^ 0xFF for b in data[start : start + 8])
    path.write_bytes(bytes(data))
    assert pq.read_table(path, columns=["run_id"]).num_rows  # run_id still reads


def _resume(out: Path, capsys: pytest.CaptureFixture[str], reference: pd.DataFrame) -> str:
    table = run_sweep(SPEC, out, workers=1)
    assert_same_table(table, reference)
    assert not list((out / "parts").iterdir())
    return capsys.readouterr().err


def test_resume_from_good_parts(unfinished, capsys, reference):
    assert _resume(unfinished, capsys, reference) == ""
    assert run_sweep(SPEC, unfinished, workers=1).attrs["sweep"]["n_ran"] == 0


def test_part_with_flipped_bytes_is_redone(unfinished, capsys, reference):
    bad = _parts(unfinished)[1]
    _flip_column_bytes(bad, "peak_force_n")
    err = _resume(unfinished, capsys, reference)
    assert f"quadimpact: warning: {bad}: its checksum does not match its content; " in err
    assert "its runs will be redone" in err


@pytest.mark.parametrize("change", ["drop", "retype"])
def test_part_with_another_schema_is_redone(unfinished, capsys, reference, change):
    """A part in the old naming (no checksum) without a column, or with one of another type."""
    good = _parts(unfinished)[0]
    table = pq.read_table(good)
    i = table.schema.get_field_index("peak_force_n")
    if change == "drop":
        table = table.drop_columns(["peak_force_n"])
        why = "column 'peak_force_n' missing"
    else:
        table = table.set_column(i, "peak_force_n", table.column(i).cast("float32"))
        why = "column 'peak_force_n' is float, expected double"
    legacy = good.with_name("part-000001.parquet")
    good.unlink()
    pq.write_table(table, legacy)
    err = _resume(unfinished, capsys, reference)
    assert f"quadimpact: warning: {legacy}: {why}; its runs will be redone" in err


def test_table_with_flipped_bytes_is_redone(reference, tmp_path, capsys):
    """runs.parquet (Parquet's page checksums) damaged in a data page: its runs are redone."""
    out = tmp_path / "out"
    shutil.copytree(Path(reference.attrs["sweep"]["out_dir"]), out)
    _flip_column_bytes(out / "runs.parquet", "peak_force_n")
    err = _resume(out, capsys, reference)
    assert f"quadimpact: warning: {out / 'runs.parquet'}: row group 0: " in err
    assert "its 8 missing runs will be redone" in err


def test_table_keeps_its_good_row_groups(reference, tmp_path, capsys):
    """A table of several row groups with one damaged: only that group's runs are redone."""
    out = tmp_path / "out"
    shutil.copytree(Path(reference.attrs["sweep"]["out_dir"]), out)
    table = pq.read_table(out / "runs.parquet")
    pq.write_table(table, out / "runs.parquet", row_group_size=3)
    _flip_column_bytes(out / "runs.parquet", "peak_force_n", row_group=1)
    resumed = run_sweep(SPEC, out, workers=1)
    assert resumed.attrs["sweep"]["n_ran"] == 3
    assert_same_table(resumed, reference)
    err = capsys.readouterr().err
    assert "row group 1: " in err and "its 3 missing runs will be redone" in err
    assert "(the 5 readable ones are kept)" in err


@pytest.mark.parametrize("damage", ["empty", "truncated", "garbage"])
def test_a_damaged_merged_table_is_replaced_on_resume(reference, tmp_path, capsys, damage):
    """Issue 20 item 4: an emptied or truncated runs.parquet no longer blocks every rerun."""
    out = tmp_path / "out"
    shutil.copytree(Path(reference.attrs["sweep"]["out_dir"]), out)
    path = out / "runs.parquet"
    data = path.read_bytes()
    path.write_bytes({"empty": b"", "truncated": data[: len(data) // 2],
                      "garbage": b"PAR1" + bytes(100) + b"PAR1"}[damage])  # fmt: skip
    err = _resume(out, capsys, reference)
    assert f"quadimpact: warning: {path}: " in err and "its 8 missing runs will be redone" in err
    # and the rerun after it has nothing to do
    assert run_sweep(SPEC, out, workers=1).attrs["sweep"]["n_ran"] == 0


def test_merge_names_an_unreadable_file(unfinished):
    """A part damaged after the check (between the resume's scan and the merge)."""
    bad = _parts(unfinished)[0]
    bad.write_bytes(b"PAR1" + bytes(100) + b"PAR1")
    with pytest.raises(RuntimeError, match=rf"{bad}: unreadable .*run the sweep again"):
        consolidate(unfinished, schema_of(SPEC), SPEC.n_runs)
    table = run_sweep(SPEC, unfinished, workers=1)  # the rerun repairs it
    assert len(read_runs(unfinished)) == len(table) == SPEC.n_runs
