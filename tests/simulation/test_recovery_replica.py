"""Each switch of the recovery replica changes exactly what it names (docs/VARIANTS.md 5)."""

from __future__ import annotations

import numpy as np
import pytest

from quadimpact import ImpactTrial, simulate
from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.controllers import recovery as CL
from quadimpact.core.rotors import rotor_wrench
from quadimpact.inputs.model import MODEL_VARIANTS, resolve_model_options
from quadimpact.simulation.setup import prepare

TRIAL = dict(roll_deg=5.0, pitch_deg=-30.0, yaw_deg=20.0, speed_m_s=1.5)
SWITCHES = ("yaw_reaction", "spinup_reaction", "detection_tick_reference", "contact_gate_m",
            "pre_impact")  # fmt: skip


def test_the_replica_is_this_set_of_switches():
    rep = MODEL_VARIANTS["recovery-replica"]
    default = MODEL_VARIANTS["default"]
    differ = {k for k in default if default[k] != rep[k]}
    # and the staged law the default had before the benchmark (issue #45), the classic law
    assert rep["recovery_law"] == MODEL_VARIANTS["classic"]["recovery_law"] == "classic"
    differ.discard("recovery_law")
    assert differ == {"yaw_reaction", "detection_tick_reference", "contact_gate_m", "pre_impact"}
    assert rep["spinup_reaction"] == "physical"  # the recovery code had the spin sign
    assert (rep["yaw_reaction"], rep["detection_tick_reference"], rep["contact_gate_m"],
            rep["pre_impact"]) == ("paper", "level", 0.30, "spin-down")  # fmt: skip
    classic = MODEL_VARIANTS["classic"]
    every = {**classic, **{k: rep[k] for k in differ}}
    assert resolve_model_options("classic", {k: rep[k] for k in differ}).model_dump() == every


@pytest.mark.parametrize(("drag", "spinup"), [(False, False), (True, False), (False, True),
                                               (True, True)])  # fmt: skip
def test_drag_and_spinup_senses_are_separate(drag, spinup):
    setup = prepare(ImpactTrial(**TRIAL))
    veh = setup.veh
    x = setup.x0.copy()
    w = np.array([500.0, 520.0, 540.0, 560.0])
    wdot = np.array([1000.0, -2000.0, 3000.0, -4000.0])
    x[L.X_ROTOR : L.X_ROTOR + 4] = w
    x[L.X_OMEGA : L.X_OMEGA + 3] = 0.0
    mz = rotor_wrench(x, wdot, veh, drag, spinup)[3]
    s = veh[VS.V_SPIN : VS.V_SPIN + 4]
    dt, jr = veh[VS.V_DT], veh[VS.V_JR]
    drag_term = (1.0 if drag else -1.0) * np.sum(s * dt * w**2)
    spin_term = -jr * np.sum(wdot) if spinup else -jr * np.sum(s * wdot)
    assert mz == pytest.approx(drag_term + spin_term, rel=1e-13)
    # the options pack each switch into its own slot
    o = {"yaw_reaction": "paper" if drag else "physical",
         "spinup_reaction": "paper" if spinup else "physical"}  # fmt: skip
    opts = prepare(ImpactTrial(**TRIAL, model_options=o)).opts
    assert (opts[L.O_YAW_REACTION_PAPER], opts[L.O_SPINUP_PAPER]) == (float(drag), float(spinup))


def test_yaw_reaction_flips_the_allocation_yaw_row():
    phys = prepare(ImpactTrial(**TRIAL))
    paper = prepare(ImpactTrial(**TRIAL, model_options={"yaw_reaction": "paper"}))
    a = np.linalg.inv(phys.ctrl[CTL.C_ALLOC_INV : CTL.C_ALLOC_INV + 16].reshape(4, 4))
    b = np.linalg.inv(paper.ctrl[CTL.C_ALLOC_INV : CTL.C_ALLOC_INV + 16].reshape(4, 4))
    np.testing.assert_allclose(a[:3], b[:3], rtol=1e-12)
    np.testing.assert_allclose(a[3], -b[3], rtol=1e-12)


def _run(**options):
    return simulate(ImpactTrial(**TRIAL, model_options=options))


def test_level_target_at_the_detection_tick_only():
    # rotors held and no slew limit, so that the commands show the law itself; pitched 45 deg
    # toward the wall, so that stage 1 outlasts the detection tick (|q_e,y| = 0.38 > 0.3)
    # (the classic law: the default's lean cut would idle the rotors of both at this lean)
    free = dict(TRIAL, pitch_deg=-45.0, pre_impact="hold", rotor_slew_limit_rad_s2=None,
                model="classic")  # fmt: skip
    base = simulate(ImpactTrial(**free))
    level = simulate(ImpactTrial(**free, model_options={"detection_tick_reference": "level"}))
    t_d = base.summary["t_detect_s"]
    assert t_d == level.summary["t_detect_s"]
    ts_a, ts_b = base.timeseries, level.timeseries
    before = ts_a["t_s"] <= t_d + 1e-12
    cmd = [f"omega_cmd{j}_rad_s" for j in (1, 2, 3, 4)]
    assert ts_a[before].equals(ts_b[before])  # identical until the detection tick
    # at the detection tick: the law with a level target, i.e. stage 1 with no push
    no_push = simulate(ImpactTrial(**free, controller_params={"a_mag_m_s2": 0.0}))
    first = (ts_a["t_s"] > t_d + 1e-12) & (ts_a["t_s"] <= t_d + 0.005 + 1e-12)
    np.testing.assert_array_equal(ts_b[first][cmd].to_numpy()[0],
                                  no_push.timeseries[first][cmd].to_numpy()[0])  # fmt: skip
    assert not np.allclose(ts_a[first][cmd].to_numpy()[0], ts_b[first][cmd].to_numpy()[0])
    # from the next tick on, the push away from the wall applies in both
    second = (ts_a["t_s"] > t_d + 0.005 + 1e-12) & (ts_a["t_s"] <= t_d + 0.010 + 1e-12)
    assert not np.allclose(no_push.timeseries[second][cmd].to_numpy()[0],
                           ts_b[second][cmd].to_numpy()[0])  # fmt: skip


def test_contact_gate_switches_the_force_on_at_0_30_m():
    # yawed 45 deg: a bumper points at the wall and reaches it 0.316 m ahead of the CM
    yawed = dict(roll_deg=0.0, pitch_deg=0.0, yaw_deg=45.0, speed_m_s=1.0)
    base = simulate(ImpactTrial(**yawed))
    gated = simulate(ImpactTrial(**yawed, model_options={"contact_gate_m": 0.30}))
    eb, eg = base.episodes, gated.episodes
    # the gate delays the first episode until the CM is 0.30 m from the wall
    onset_x = gated.timeseries.set_index("t_s")
    t_gate = gated.summary["first_contact_s"]
    assert t_gate > base.summary["first_contact_s"]
    x_at = np.interp(t_gate, onset_x.index.to_numpy(), onset_x["x_m"].to_numpy())
    assert x_at == pytest.approx(-0.30, abs=2e-4)  # (interpolated at 1 kHz)
    # the bumper is already well into the wall when its force switches on
    first = eg.sort_values("t_start_s").iloc[0]
    ts = gated.timeseries
    j = int(first["bumper"])
    i0 = np.searchsorted(ts["t_s"].to_numpy(), first["t_start_s"])
    assert ts[f"delta{j}_m"].iloc[i0] > 5e-3
    assert ts[f"force{j}_n"].iloc[max(i0 - 1, 0)] == 0.0
    # before any contact the two runs are the same run
    t0 = base.summary["first_contact_s"]
    before = base.timeseries["t_s"] < t0
    assert base.timeseries[before].equals(gated.timeseries[before])
    assert len(eb) and len(eg)


def test_pre_impact_spin_down_overrides_the_scenario():
    hold = prepare(ImpactTrial(**TRIAL, pre_impact="hold"))
    forced = prepare(ImpactTrial(**TRIAL, pre_impact="hold",
                                 model_options={"pre_impact": "spin-down"}))  # fmt: skip

    assert hold.ctrl[CTL.C_PARAMS + CL.R_PRE_IMPACT] == CL.PRE_HOLD
    assert forced.ctrl[CTL.C_PARAMS + CL.R_PRE_IMPACT] == CL.PRE_SPIN_DOWN
    pre = CTL.C_PARAMS + CL.R_PRE_IMPACT
    np.testing.assert_array_equal(np.delete(hold.ctrl, pre), np.delete(forced.ctrl, pre))
    np.testing.assert_array_equal(hold.opts, forced.opts)
    # and in the run: the first interval runs at the trimmed speed minus one slew step
    r = simulate(ImpactTrial(**TRIAL, pre_impact="hold", model_options={"pre_impact": "spin-down"}))
    ts = r.timeseries
    slew = 70_000 * np.pi / 30 * 0.005
    w0 = hold.x0[L.X_ROTOR : L.X_ROTOR + 4]
    np.testing.assert_allclose(ts[[f"omega{j}_rad_s" for j in (1, 2, 3, 4)]].iloc[1], w0 - slew)
