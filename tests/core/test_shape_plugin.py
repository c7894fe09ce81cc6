"""A plug-in shape component (``examples/shape_template.py``, a capsule) named from a scenario
like a built-in: a caged vehicle hits a long capsule as it hits a cylinder of its radius."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from quadimpact import simulate
from quadimpact.inputs import plugins
from quadimpact.inputs.scenarios import scenario_from_dict

pytestmark = pytest.mark.slow  # compiles a loop around the plug-in (about a minute)

ROOT = Path(__file__).resolve().parents[2]


def _load():
    """Import the template once per process, as ``--plugin`` does (other tests load it so)."""
    plugins.load_plugin(str(ROOT / "examples" / "shape_template.py"))


def test_a_long_capsule_is_a_cylinder_to_a_cage():
    _load()
    base = {
        "kind": "flight",
        "vehicle": str(ROOT / "examples" / "vehicles" / "navi_cage.toml"),
        "controller": "paper",
        "final_time_s": 0.8,
        "velocity_m_s": (1.0, 0.0, 0.0),
    }
    bar = {
        "kind": "capsule",
        "name": "bar",
        "a_m": (0.6, 0.0, -20.0),
        "b_m": (0.6, 0.0, 20.0),
        "radius_m": 0.05,
    }
    pole = {"kind": "cylinder", "name": "bar", "point_m": (0.6, 0.0, -2.0), "radius_m": 0.05}
    a = simulate(scenario_from_dict({**base, "obstacles": [bar]}))
    b = simulate(scenario_from_dict({**base, "obstacles": [pole]}))
    assert len(a.episodes) == len(b.episodes) >= 1
    for col in ("t_start_s", "t_end_s", "peak_delta_m", "peak_force_n"):
        assert np.allclose(a.episodes[col], b.episodes[col], rtol=1e-9, atol=1e-12), col
    assert a.world["surfaces"][0]["kind"] == "capsule"
