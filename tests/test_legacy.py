"""The old flat module paths still import: the new module itself, with a DeprecationWarning."""

from __future__ import annotations

import importlib
import importlib.resources
import subprocess
import sys

import pytest

import quadimpact
from quadimpact._legacy import MOVED


def _forget(monkeypatch: pytest.MonkeyPatch, old: str) -> None:
    """Make the next import of ``old`` go through the finder again."""
    monkeypatch.delitem(sys.modules, old, raising=False)
    monkeypatch.delattr(quadimpact, old.rpartition(".")[2], raising=False)


@pytest.mark.parametrize("old", sorted(MOVED))
def test_old_path_is_the_new_module_and_warns(monkeypatch: pytest.MonkeyPatch, old: str) -> None:
    new_name = MOVED[old]
    new = importlib.import_module(new_name)
    spec = new.__spec__
    _forget(monkeypatch, old)
    with pytest.warns(DeprecationWarning, match=rf"{old} is deprecated: import {new_name}"):
        module = importlib.import_module(old)
    assert module is new
    assert new.__spec__ is spec and new.__name__ == new_name  # the new module is untouched
    assert getattr(quadimpact, old.rpartition(".")[2]) is new


def test_the_same_objects_under_both_names(monkeypatch: pytest.MonkeyPatch) -> None:
    _forget(monkeypatch, "quadimpact.config")
    with pytest.warns(DeprecationWarning):
        from quadimpact.config import WallApproach, load_scenario_file

    from quadimpact.inputs import scenarios

    assert WallApproach is scenarios.WallApproach
    assert load_scenario_file is scenarios.load_scenario_file
    import quadimpact.config  # imported once: no second warning

    assert quadimpact.config.WallApproach is scenarios.WallApproach


def test_unknown_names_are_not_found() -> None:
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("quadimpact.no_such_module")


def test_no_files_at_the_old_paths() -> None:
    root = importlib.resources.files("quadimpact")
    for old in MOVED:
        name = old.rpartition(".")[2]
        assert not root.joinpath(f"{name}.py").is_file(), name


def test_a_fresh_interpreter_warns_at_the_users_line() -> None:
    code = "import warnings; warnings.simplefilter('always')\nimport quadimpact.frames\n"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "<string>:2: DeprecationWarning: quadimpact.frames is deprecated" in proc.stderr
    assert "import quadimpact.rotations instead" in proc.stderr
