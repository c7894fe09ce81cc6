"""A run advanced one control interval at a time is the run advanced at once, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from quadimpact import WallApproach
from quadimpact.core import layout as L
from quadimpact.core.run import execute_record
from quadimpact.core.step import advance, start
from quadimpact.simulation.setup import prepare


def _arrays(setup, scfg):
    nc = 4 * setup.surf.shape[0]
    t_out = setup.output_times()
    return dict(
        x=setup.x0.copy(), ls=np.zeros(L.NLS), cs=np.zeros((nc, L.NCS)), rin=np.zeros(L.NRIN),
        mem=np.zeros(L.NMEM), meas=np.zeros(L.NMEAS), sst=np.zeros(L.NSST), t_out=t_out,
        out=np.zeros((len(t_out), L.NOUT)), imu_out=np.zeros((1000, L.NIMU)),
        episodes=np.zeros((64, L.NEP)), stats=np.zeros(L.NSTAT), scfg=scfg,
    )  # fmt: skip


@pytest.mark.parametrize("model", ["paper-replica", "default"])
@pytest.mark.parametrize("controller", ["paper", "cascade-pid"])
def test_tick_by_tick_equals_the_whole_run(model, controller):
    s = WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75, model=model,
                     controller=controller)  # fmt: skip
    setup = prepare(s)
    scfg = np.zeros(L.NSCFG)
    scfg[L.SC_RATE] = 200.0
    scfg[L.SC_DET_THRESHOLD] = 0.5 * 9.81
    sched = setup.schedule()
    whole = execute_record(setup.x0, setup.t0, setup.tf, setup.veh, setup.surf, setup.opts,
                           setup.ctrl, setup.output_times(), max_episodes=64, scfg=scfg,
                           n_imu=1000, **sched)  # fmt: skip
    a = _arrays(setup, scfg)
    start(a["x"], setup.t0, setup.tf, a["ls"], a["cs"], a["rin"], a["mem"], a["meas"], a["sst"],
          setup.veh, setup.surf, setup.opts, scfg, np.zeros((0, 6)), a["t_out"], a["out"],
          a["imu_out"], a["stats"])  # fmt: skip
    ticks = 0
    while a["ls"][L.LS_DONE] < 0.5:
        ticks += advance(1, a["x"], a["ls"], a["cs"], a["rin"], a["mem"], a["meas"], a["sst"],
                         setup.veh, setup.surf, setup.opts, setup.ctrl, scfg, sched["sched_t"],
                         sched["sched_rate"], sched["sched_stop"], np.zeros((0, 6)), a["t_out"],
                         a["out"], a["imu_out"], a["episodes"], a["stats"])  # fmt: skip
    assert ticks == int(whole.stats[L.ST_N_TICKS])
    np.testing.assert_array_equal(a["stats"], whole.stats)
    n_out = int(whole.stats[L.ST_N_OUT])
    np.testing.assert_array_equal(a["out"][:n_out], whole.out)
    np.testing.assert_array_equal(a["episodes"][: len(whole.episodes)], whole.episodes)
    np.testing.assert_array_equal(a["imu_out"][: len(whole.imu)], whole.imu)
    assert len(whole.episodes) >= 2 and not np.isnan(whole.stats[L.ST_T_DETECT])
