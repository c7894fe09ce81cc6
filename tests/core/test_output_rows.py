"""The loop's output rows (``core/recording.py``): each feature's deflection column is the
contact geometry's depth at the row's state, bit for bit, however the row computes it."""

from __future__ import annotations

import numpy as np
import pytest

from quadimpact import WallApproach
from quadimpact.core import layout as L
from quadimpact.core.geometry import PR_FEATURE, PR_GEOMETRY
from quadimpact.core.kernel import execute
from quadimpact.core.recording_slots import OUT_DELTA, OUT_X
from quadimpact.simulation.approach import pair_depths_at
from quadimpact.simulation.setup import prepare


@pytest.mark.parametrize("model", ["default", "paper-replica"])
def test_a_rows_deflection_is_the_deepest_pair_at_its_state(model):
    """A ring out of contact with a plane adds its depth alone (the closed form inlined in
    the row); a pair in contact its whole record. Either way the row's deflection of
    feature ``f`` is ``max(0, depth of every pair of f)`` at the row's state, the depths
    from the contact geometry's own call (``core.geometry.pair_depths``). The wall and
    the ground are contact surfaces: rows before, during and after contacts with both."""
    setup = prepare(
        WallApproach(
            heading_deg=45.0, inclination_deg=15.0, speed_m_s=0.75, model=model, ground="contact"
        )
    )
    rec = execute(setup.model(), n_imu=setup.n_imu, kernel=setup.kernel)
    rows = rec.out
    nf = setup.feat.shape[0]
    pairs = setup.pair_table()
    touching = 0
    for row in rows:
        x = np.ascontiguousarray(row[OUT_X : OUT_X + L.NX])
        depths = pair_depths_at(x, setup.feat, setup.shapes, pairs)
        for f in range(nf):
            deepest = max(0.0, *depths[pairs[:, PR_FEATURE] == f])
            assert row[OUT_DELTA + f] == deepest  # the same bits
            touching += deepest > 0.0
    assert touching > 10  # rows in contact were checked too
    assert (pairs[:, PR_GEOMETRY] == 0).all()  # every pair a ring against a plane
