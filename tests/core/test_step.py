"""A run advanced one control interval at a time is the run advanced at once, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from quadimpact import WallApproach
from quadimpact.core import layout as L
from quadimpact.core.kernel import execute
from quadimpact.core.records import new_data, new_output
from quadimpact.core.sensors import detection as DET
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.core.step import advance, start
from quadimpact.simulation.setup import prepare


@pytest.mark.parametrize("model", ["paper-replica", "default"])
@pytest.mark.parametrize("controller", ["paper", "cascade-pid"])
def test_tick_by_tick_equals_the_whole_run(model, controller):
    s = WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75, model=model,
                     controller=controller)  # fmt: skip
    setup = prepare(s)
    scfg = np.zeros(IMS.NSCFG)
    scfg[IMS.SC_RATE] = 200.0
    scfg[DET.SC_DET_THRESHOLD] = 0.5 * 9.81
    m = setup.model(scfg=scfg, noise=np.zeros((0, 6)))
    whole = execute(m, n_imu=1000, max_episodes=64)
    d = new_data(m)
    o = new_output(m, 1000, 64)
    start(m, d, o)
    ticks = 0
    while d.ls[L.LS_DONE] < 0.5:
        ticks += advance(1, m, d, o)
    assert ticks == int(whole.stats[L.ST_N_TICKS])
    np.testing.assert_array_equal(o.stats, whole.stats)
    n_out = int(whole.stats[L.ST_N_OUT])
    np.testing.assert_array_equal(o.out[:n_out], whole.out)
    np.testing.assert_array_equal(o.episodes[: len(whole.episodes)], whole.episodes)
    np.testing.assert_array_equal(o.imu[: len(whole.imu)], whole.imu)
    assert len(whole.episodes) >= 2 and not np.isnan(whole.stats[L.ST_T_DETECT])
