"""Input files: the one TOML reader, the vehicle-beside-the-file rule, overrides."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import pytest

from quadimpact.errors import InputError
from quadimpact.inputs.toml_files import apply_overrides, locate_vehicle, read_toml_file


def test_reader_names_the_file_or_the_given_place(tmp_path: Path) -> None:
    (tmp_path / "a.toml").write_text("x = 1\n")
    assert read_toml_file(tmp_path / "a.toml") == {"x": 1}
    assert read_toml_file(str(tmp_path / "a.toml")) == {"x": 1}
    with pytest.raises(InputError, match=r"^vehicle b.toml: file not found$"):
        read_toml_file(tmp_path / "b.toml", "vehicle b.toml")
    with pytest.raises(InputError, match="is a directory, not a file"):
        read_toml_file(tmp_path)
    (tmp_path / "bad.toml").write_text("x = = 1\n")
    with pytest.raises(InputError, match=r"bad.toml( \(\d+ characters\))?: invalid TOML: .*line 1"):
        read_toml_file(tmp_path / "bad.toml")


def test_reader_reads_packaged_resources() -> None:
    spiri = resources.files("quadimpact.inputs").joinpath("vehicles", "spiri.toml")
    assert read_toml_file(spiri, "vehicle spiri.toml")["name"] == "spiri"


def test_relative_vehicle_path_is_looked_up_beside_the_file(tmp_path: Path) -> None:
    (tmp_path / "heavy.toml").write_text("")
    found = locate_vehicle({"vehicle": "heavy.toml", "speed_m_s": 1.0}, tmp_path)
    assert found == {"vehicle": str((tmp_path / "heavy.toml").resolve()), "speed_m_s": 1.0}
    for kept in ("spiri", "missing.toml", str(tmp_path / "heavy.toml")):
        assert locate_vehicle({"vehicle": kept}, tmp_path) == {"vehicle": kept}
    assert locate_vehicle({}, tmp_path) == {}


def test_overrides_go_on_top_and_vehicle_fields_to_vehicle_overrides() -> None:
    base = {"speed_m_s": 0.5, "model": "default", "vehicle_overrides": {"restitution": 0.5}}
    out = apply_overrides(base, {"speed_m_s": 1.0, "mass_kg": 1.2}, vehicle_fields=["mass_kg"])
    assert out == {
        "speed_m_s": 1.0,
        "model": "default",
        "vehicle_overrides": {"restitution": 0.5, "mass_kg": 1.2},
    }
    assert base["vehicle_overrides"] == {"restitution": 0.5}  # the base is not changed
    replaced = apply_overrides(base, {"vehicle_overrides": {"contact_stiffness": 80.0}})
    assert replaced["vehicle_overrides"] == {"contact_stiffness": 80.0}
