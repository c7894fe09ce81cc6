"""The pole study flies a plug-in shape (``examples/shape_template.py``, a capsule) that its
``--obstacle`` file names, registered from ``--plugin`` like a built-in: a long vertical
capsule is a pole of its radius to a caged vehicle, so the study's table is the pole's. A
trial that would start inside the plug-in shape is refused as one inside a built-in is."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from quadimpact.errors import InputError
from quadimpact.inputs import plugins

from helpers import cli_here

pytestmark = pytest.mark.slow  # compiles a loop around the plug-in shape (about 2 min of CPU)

ROOT = Path(__file__).resolve().parents[3]
TEMPLATE = ROOT / "examples" / "shape_template.py"
CAGE = ROOT / "examples" / "vehicles" / "navi_cage.toml"  # a cage of radius 0.33 m
CAPSULE = {"kind": "capsule", "name": "bar", "a_m": [0.0, 0.0, -20.0], "b_m": [0.0, 0.0, 20.0],
           "radius_m": 0.1}  # fmt: skip
POLE = {"kind": "cylinder", "name": "bar", "point_m": [0.0, 0.0, 0.0], "axis": [0.0, 0.0, 1.0],
        "radius_m": 0.1}  # fmt: skip


def _toml(obstacle: dict) -> str:
    def value(v: object) -> str:
        return f'"{v}"' if isinstance(v, str) else str(v)

    return "[[obstacles]]\n" + "".join(f"{k} = {value(v)}\n" for k, v in obstacle.items())


def _study(capsys, tmp_path: Path, name: str, obstacle: dict, *extra: str) -> pd.DataFrame:
    path = tmp_path / f"{name}.toml"
    path.write_text(_toml(obstacle))
    small_cage = tmp_path / "small_cage.toml"  # 0.22 m: 8 cm clear of the bar at the start
    small_cage.write_text(CAGE.read_text().replace("radius_m = 0.33", "radius_m = 0.22"))
    out = tmp_path / name
    grid = ("--pitch-max", "20", "--pitch-step", "20", "--offset-max", "0.1", "--offset-step",
            "0.1", "--vehicle", str(small_cage), "--workers", "1", "--no-progress")  # fmt: skip
    code, err = cli_here(capsys, "pole", *extra, "--obstacle", str(path), *grid, "--out", str(out))
    assert code == 0, err
    return pd.read_parquet(out / "trials.parquet")


def test_the_pole_study_flies_a_plugin_capsule_as_a_pole_of_its_radius(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.delenv(plugins.PLUGINS_ENV, raising=False)
    capsule = _study(capsys, tmp_path, "capsule", CAPSULE, "--plugin", str(TEMPLATE))
    pole = _study(capsys, tmp_path, "pole", POLE)
    assert len(capsule) == len(pole) == 2 * 2 * 3  # two arms, two pitches, three offsets
    assert set(capsule["status"]) == {"completed"} and (capsule["n_episodes"] >= 1).all()
    assert list(capsule["success"]) == list(pole["success"])
    np.testing.assert_allclose(capsule["height_lost_m"], pole["height_lost_m"], atol=1e-6)


def test_a_trial_starting_inside_a_plugin_shape_is_refused_as_inside_a_pole(monkeypatch):
    from quadimpact.inputs.scenarios import scenario_from_dict
    from quadimpact.simulation.setup import prepare

    monkeypatch.delenv(plugins.PLUGINS_ENV, raising=False)
    plugins.load_plugin(str(TEMPLATE))
    base = {"kind": "impact-trial", "vehicle": str(CAGE), "start_distance_m": 0.3}
    said = []
    for obstacle in (CAPSULE, POLE):  # the 0.33-m cage starts 3 cm into either
        with pytest.raises(InputError, match="starts in contact") as exc:
            prepare(scenario_from_dict({**base, "obstacles": [obstacle]}))
        said.append(str(exc.value))
    assert said[0] == said[1]  # the same depth, said the same way
