"""Suite 2 cannot be gamed: a law that climbs away, or one that does nothing, ranks last.

Suite 1's survival criteria (less than 2 m lost on the grids, a declared
stage 4 on the wall) were topped by a law that levels and climbs away for
ever. Suite 2 counts a held hover. The fast tests check the criterion on
trial rows; the slow one flies the two plug-ins of ``examples/gaming_controllers.py``
on the quick suite beside the default law.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from quadimpact.studies.benchmark.cells import held_hover_success

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"


def _rows(**columns):
    n = len(next(iter(columns.values())))
    base = {
        "valid": [True] * n,
        "held_hover": [True] * n,
        "touched_after_hover": [False] * n,
        "height_lost_m": [0.5] * n,
        "crash_time_s": [math.nan] * n,
    }
    base.update(columns)
    return pd.DataFrame(base)


def test_a_climb_away_without_a_hover_is_no_success():
    """Levelled and climbing (no held hover), nothing lost: suite 1 would count it; suite 2
    does not."""
    t = _rows(held_hover=[False], height_lost_m=[-3.0])
    assert not held_hover_success(t)[0]


def test_each_condition_of_the_held_hover_criterion_is_needed():
    t = _rows(
        held_hover=[True, True, True, True, True, False],
        touched_after_hover=[False, True, False, False, False, False],
        height_lost_m=[0.5, 0.5, 2.0, 0.5, 0.5, 0.5],
        crash_time_s=[math.nan, math.nan, math.nan, 1.2, math.nan, math.nan],
        valid=[True, True, True, True, False, True],
    )
    assert held_hover_success(t).tolist() == [True, False, False, False, False, False]


def test_a_run_that_ran_out_of_steps_is_no_success_even_after_a_held_hover():
    """The step budget exhausted after the hover was held: the run failed (it did not fly
    its length), so it counts as a failure, not a success and not excluded."""
    t = _rows(
        held_hover=[True, True],
        status=["failed", "completed"],
        reason=["step budget exhausted", ""],
    )
    assert held_hover_success(t).tolist() == [False, True]


@pytest.mark.slow  # two plug-in loops compiled, ~9,000 trials: a few minutes on 2 cores
def test_climbing_away_and_doing_nothing_rank_below_the_default_law(tmp_path):
    """On every task and sensor set of suite 2's quick suite, both gaming plug-ins score
    below the default law (and the climb would have topped suite 1's grid criterion)."""
    from click.testing import CliRunner

    from quadimpact.cli import cli

    plugin = str(EXAMPLES / "gaming_controllers.py")
    tables = {}
    for controller in ("recovery", "climb-away", "do-nothing"):
        out = tmp_path / controller
        result = CliRunner().invoke(cli, [
            "benchmark", "--quick", "--plugin", plugin, "--controller", controller,
            "--no-references", "--no-cache", "--out", str(out), "--no-progress",
        ])  # fmt: skip
        assert result.exit_code == 0, result.output
        tables[controller] = pd.read_csv(out / "benchmark.csv")
    default = tables.pop("recovery")
    default = default[default["row"] == "default"].set_index(["task", "sensors"])
    sets = default.index.get_level_values("sensors").unique()
    assert len(default) == 3 * len(sets) and len(sets) >= 2  # every task with every set
    for controller, t in tables.items():
        mine = t[t["row"] == controller].set_index(["task", "sensors"])
        assert set(mine.index) == set(default.index)
        for key, line in mine.iterrows():
            assert line["success"] < default.loc[key, "success"], (controller, key)
    climb = tables["climb-away"]
    climb = climb[climb["row"] == "climb-away"].set_index(["task", "sensors"])
    grids = climb.loc[[("pole", "ideal"), ("edge", "ideal")]]
    assert (grids["success"] < 0.05).all()
    assert np.isfinite(grids["published_success"]).all()
