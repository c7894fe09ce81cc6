"""The learned residual on the recovery law: its features in the right frames, its network
the same compiled as in NumPy, its correction bounded, zero weights flying the law exactly,
its files checked, and the shipped policy flown with NumPy alone."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys

import numpy as np
import pytest

from quadimpact import ImpactTrial, simulate
from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.controllers import residual as RES
from quadimpact.core.controllers.residual import features, residual_references
from quadimpact.core.sensors import measurement_slots as MSS
from quadimpact.errors import InputError
from quadimpact.inputs.policy_file import (
    PolicyWeights,
    initial_policy,
    load_policy,
    policy_path,
    save_policy,
)
from quadimpact.rotations import euler_zyx_to_quat, quat_to_matrix

NAVI_MASS_KG, G = 1.095, 9.81


def _veh() -> np.ndarray:
    veh = np.zeros(VS.NVEH)
    veh[VS.V_MASS] = NAVI_MASS_KG
    veh[VS.V_GRAVITY] = G
    return veh


def _meas(q: np.ndarray, normal=(-1.0, 0.0, 0.0), t_detect: float = 0.1) -> np.ndarray:
    meas = np.zeros(MSS.NMEAS)
    meas[MSS.MS_X + L.X_QUAT : MSS.MS_X + L.X_QUAT + 4] = q
    meas[MSS.MS_X + L.X_VEL : MSS.MS_X + L.X_VEL + 3] = (1.0, -0.5, 0.25)
    meas[MSS.MS_W_HAT : MSS.MS_W_HAT + 3] = (4.0, -2.0, 1.0)
    meas[MSS.MS_IMU_F : MSS.MS_IMU_F + 3] = (3.0, 0.0, -9.0)
    meas[MSS.MS_NORMAL : MSS.MS_NORMAL + 3] = normal
    meas[MSS.MS_T_DETECT] = t_detect
    return meas


def _random_policy(
    seed: int, hidden: int = 8, scale: float = 1.0, last_stage: int = 4, centred: bool = False
) -> PolicyWeights:
    p = initial_policy(hidden, 0.3, 4.0, seed, last_stage, centred)
    rng = np.random.default_rng(seed + 1)
    return p.with_vector(rng.normal(0.0, scale, p.vector().size))


def _ctrl(p: PolicyWeights) -> np.ndarray:
    ctrl = np.zeros(CTL.NCTRL)
    block = p.block()
    ctrl[CTL.C_POLICY : CTL.C_POLICY + block.size] = block
    return ctrl


@pytest.mark.parametrize(
    "euler_deg", [(0.0, 0.0, 0.0), (30.0, -20.0, 75.0), (-100.0, 60.0, -150.0)]
)
def test_features_are_gravity_and_the_wall_normal_in_body_axes(euler_deg):
    """Features 0-2 are C^T e_Z (gravity's direction in body FRD), 3-5 are C^T n."""
    q = euler_zyx_to_quat(*np.radians(euler_deg))
    c = quat_to_matrix(q)
    n = np.array([-0.6, 0.8, 0.0])
    f = features(0.3, 2, (10.0, 1.0, -2.0), _meas(q, n), _veh())
    np.testing.assert_allclose(f[0:3], c.T @ np.array([0.0, 0.0, 1.0]), atol=1e-12)
    np.testing.assert_allclose(f[3:6], c.T @ n, atol=1e-12)
    assert math.isclose(f[15], 0.2, abs_tol=1e-12)  # time since detection, s
    assert list(f[16:21]) == [0, 1, 0, 0, 0]  # stage 2, one-hot
    assert math.isclose(f[21], 10.0 / (NAVI_MASS_KG * G) - 1.0)


def test_features_read_non_finite_inputs_as_zero_and_cap_the_time():
    q = np.array([1.0, 0.0, 0.0, 0.0])
    meas = _meas(q, (math.nan, math.nan, math.nan), t_detect=math.nan)
    f = features(5.0, 1, (math.inf, 0.0, 0.0), meas, _veh())
    assert np.all(np.isfinite(f))
    assert f[3] == f[4] == f[5] == f[15] == f[21] == 0.0
    f = features(5.0, 1, (5.0, 0.0, 0.0), _meas(q, t_detect=1.0), _veh())
    assert f[15] == 2.0  # capped at 2 s


def test_the_compiled_network_is_the_numpy_network():
    """residual_references (compiled) == PolicyWeights.outputs (NumPy) on the same features."""
    rng = np.random.default_rng(3)
    for k in range(20):
        p = _random_policy(k, hidden=int(rng.integers(1, 33)))
        q = euler_zyx_to_quat(*rng.uniform(-1.0, 1.0, 3))
        meas = _meas(q, (-1.0, 0.0, 0.0))
        refs = (float(rng.uniform(0, 20)), float(rng.normal()), float(rng.normal()))
        stage = int(rng.integers(1, 6))
        got = residual_references(0.5, stage, refs, meas, _ctrl(p), _veh())
        o = p.outputs(features(0.5, stage, refs, meas, _veh()))
        want = (
            max(0.0, refs[0] + p.thrust_scale * NAVI_MASS_KG * G * o[0]),
            refs[1] + p.rate_scale_rad_s * o[1],
            refs[2] + p.rate_scale_rad_s * o[2],
        )
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)


def _hover_meas(yaw_rad: float, normal=(-1.0, 0.0, 0.0)) -> np.ndarray:
    """The measurement of a vehicle level and at rest, heading ``yaw_rad``: the
    accelerometer reads -g along body z (FRD), the rates are zero."""
    meas = _meas(euler_zyx_to_quat(0.0, 0.0, yaw_rad), normal)
    meas[MSS.MS_X + L.X_VEL : MSS.MS_X + L.X_VEL + 3] = 0.0
    meas[MSS.MS_W_HAT : MSS.MS_W_HAT + 3] = 0.0
    meas[MSS.MS_IMU_F : MSS.MS_IMU_F + 3] = (0.0, 0.0, -G)
    return meas


def test_a_hover_centred_policy_does_not_move_the_hover():
    """At the hover itself (level, at rest, the law at m g and zero rate references) a
    hover-centred policy corrects nothing in stage 5, whatever its weights, the heading,
    the wall normal and the time; one that is not centred does (a bias the law's hover
    must then fight), and off the hover both correct."""
    hover = (NAVI_MASS_KG * G, 0.0, 0.0)
    for k in range(20):
        centred = _random_policy(k, scale=2.0, last_stage=5, centred=True)
        plain = _random_policy(k, scale=2.0, last_stage=5)
        yaw = 0.3 * k - 3.0
        normal = (math.cos(yaw), math.sin(yaw), 0.0)
        meas = _hover_meas(yaw, normal)
        t = 0.1 + 0.15 * k
        got = residual_references(t, 5, hover, meas, _ctrl(centred), _veh())
        np.testing.assert_allclose(got, hover, rtol=0.0, atol=1e-12)  # round-off of |q| = 1
        off = np.subtract(residual_references(t, 5, hover, meas, _ctrl(plain), _veh()), hover)
        assert np.max(np.abs(off)) > 1e-3
        moved = meas.copy()
        moved[MSS.MS_X + L.X_VEL] = 0.5  # moving at 0.5 m/s: a correction again
        off = np.subtract(residual_references(t, 5, hover, moved, _ctrl(centred), _veh()), hover)
        assert np.max(np.abs(off)) > 1e-6  # far above the round-off at the hover


@pytest.mark.parametrize("stage", [1, 2, 3, 4])
def test_hover_centring_leaves_the_stages_before_the_hover_alone(stage):
    """Before stage 5, a hover-centred policy is the same network as one that is not."""
    q = euler_zyx_to_quat(0.2, -0.4, 1.0)
    refs = (9.0, 0.7, -1.2)
    for k in range(5):
        centred = _ctrl(_random_policy(k, 8, 2.0, 5, True))
        plain = _ctrl(_random_policy(k, 8, 2.0, 5))
        a = residual_references(0.4, stage, refs, _meas(q), centred, _veh())
        b = residual_references(0.4, stage, refs, _meas(q), plain, _veh())
        assert a == b


def test_the_compiled_hover_centred_network_is_the_numpy_one():
    """residual_references == PolicyWeights.outputs (NumPy) for hover-centred policies, in
    every stage; in stage 5 each correction is bounded by twice its scale."""
    rng = np.random.default_rng(4)
    for k in range(20):
        p = _random_policy(k, hidden=int(rng.integers(1, 33)), scale=2.0, last_stage=5,
                           centred=True)  # fmt: skip
        q = euler_zyx_to_quat(*rng.uniform(-1.0, 1.0, 3))
        meas = _meas(q, (-1.0, 0.0, 0.0))
        refs = (float(rng.uniform(0, 20)), float(rng.normal()), float(rng.normal()))
        stage = 5 if k % 2 else int(rng.integers(1, 5))
        got = residual_references(0.5, stage, refs, meas, _ctrl(p), _veh())
        o = p.outputs(features(0.5, stage, refs, meas, _veh()), gravity_m_s2=G)
        want = (
            max(0.0, refs[0] + p.thrust_scale * NAVI_MASS_KG * G * o[0]),
            refs[1] + p.rate_scale_rad_s * o[1],
            refs[2] + p.rate_scale_rad_s * o[2],
        )
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)
        assert np.all(np.abs(o) < 2.0)


def test_hover_centring_round_trips_and_is_part_of_the_identity(tmp_path):
    """Saved and read back; a file without it reads as not centred, with its old digest."""
    plain = _random_policy(8, last_stage=5)
    centred = _random_policy(8, last_stage=5, centred=True)
    assert centred.sha256 != plain.sha256
    q = load_policy(save_policy(centred, tmp_path / "c.npz"))
    assert q.hover_centred and q.sha256 == centred.sha256
    assert q.block()[RES.PB_HOVER_CENTRED] == 1.0 and plain.block()[RES.PB_HOVER_CENTRED] == 0.0
    assert load_policy("learned").hover_centred is False


def _faded(p: PolicyWeights, a: float, b: float) -> PolicyWeights:
    return p.with_fade(a, b)


def test_a_fading_policy_hands_the_hover_back_to_the_law():
    """In stage 5 a fading policy's correction is the unfaded one's until ``from`` s after
    the detection, then shrinks linearly (half of it midway) and is exactly zero from
    ``to`` on: the law alone then holds its hover. Stages 1-4 are never faded."""
    q = euler_zyx_to_quat(0.2, -0.4, 1.0)
    refs = (9.0, 0.7, -1.2)
    for k in range(10):
        plain = _random_policy(k, 8, 2.0, 5, centred=bool(k % 2))
        fading = _faded(plain, 0.5, 1.5)
        for since, weight in ((0.2, 1.0), (0.5, 1.0), (1.0, 0.5), (1.25, 0.25), (1.5, 0.0),
                              (3.0, 0.0)):  # fmt: skip
            meas = _meas(q, t_detect=0.1)
            t = 0.1 + since
            full = np.subtract(residual_references(t, 5, refs, meas, _ctrl(plain), _veh()), refs)
            got = np.subtract(residual_references(t, 5, refs, meas, _ctrl(fading), _veh()), refs)
            # thrust is clipped at 0 after the correction; these refs keep it positive
            np.testing.assert_allclose(got, weight * full, rtol=1e-12, atol=1e-12)
            if weight == 0.0:
                assert np.all(got == 0.0)
            for stage in (1, 2, 3, 4):
                a = residual_references(t, stage, refs, meas, _ctrl(plain), _veh())
                b = residual_references(t, stage, refs, meas, _ctrl(fading), _veh())
                assert a == b


def test_the_compiled_fade_is_the_numpy_one():
    """residual_references == PolicyWeights.outputs (NumPy) for fading policies."""
    rng = np.random.default_rng(7)
    for k in range(20):
        p = _faded(_random_policy(k, 8, 2.0, 5, centred=bool(k % 3 == 0)), 0.3, 1.7)
        q = euler_zyx_to_quat(*rng.uniform(-1.0, 1.0, 3))
        meas = _meas(q, t_detect=0.1)
        t = 0.1 + float(rng.uniform(0.0, 2.5))
        refs = (float(rng.uniform(0, 20)), float(rng.normal()), float(rng.normal()))
        stage = 5 if k % 2 else int(rng.integers(1, 5))
        got = residual_references(t, stage, refs, meas, _ctrl(p), _veh())
        o = p.outputs(features(t, stage, refs, meas, _veh()), gravity_m_s2=G)
        want = (
            max(0.0, refs[0] + p.thrust_scale * NAVI_MASS_KG * G * o[0]),
            refs[1] + p.rate_scale_rad_s * o[1],
            refs[2] + p.rate_scale_rad_s * o[2],
        )
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)


def test_the_fade_round_trips_and_is_part_of_the_identity(tmp_path):
    """Saved and read back; a file without it reads as no fade, with its old digest."""
    plain = _random_policy(9, last_stage=5)
    fading = _faded(plain, 1.0, 1.5)
    assert fading.sha256 != plain.sha256
    q = load_policy(save_policy(fading, tmp_path / "f.npz"))
    assert q.hover_fade_s == (1.0, 1.5) and q.sha256 == fading.sha256
    assert q.block()[RES.PB_FADE_TO_S] == 1.5 and plain.block()[RES.PB_FADE_TO_S] == 0.0
    assert load_policy("learned").hover_fade_s == (0.0, 0.0)
    assert load_policy("learned").sha256.startswith("3992ef0a")


def test_the_correction_is_bounded_whatever_the_weights():
    """|dT| <= s_T m g and |dp|, |dq| <= s_w, even for weights of size 1000."""
    q = np.array([1.0, 0.0, 0.0, 0.0])
    for k in range(30):
        p = _random_policy(k, scale=1000.0)
        refs = (12.0, 0.5, -0.5)
        t, pd, qd = residual_references(0.2, 1, refs, _meas(q), _ctrl(p), _veh())
        assert abs(t - refs[0]) <= 0.3 * NAVI_MASS_KG * G + 1e-9 and t >= 0.0
        assert abs(pd - refs[1]) <= 4.0 + 1e-12 and abs(qd - refs[2]) <= 4.0 + 1e-12


def _trial(**fields) -> ImpactTrial:
    return ImpactTrial(
        vehicle="navi", speed_m_s=2.0, roll_deg=5.0, pitch_deg=-25.0, yaw_deg=10.0,
        pre_impact="spin-down", sensors="impact", estimator="ekf", seed=11, final_time_s=2.5,
        **fields,
    )  # fmt: skip


def test_a_policy_with_a_zero_output_layer_flies_the_law_bit_for_bit(tmp_path):
    path = save_policy(initial_policy(16, 0.3, 4.0, seed=5), tmp_path / "zero.npz")
    law = simulate(_trial())
    res = simulate(_trial(controller_params={"policy": str(path)}))
    assert law.summary["recovered"] and res.summary["detected"]
    cols = [c for c in law.timeseries.columns if c != "wall_time_s"]
    assert law.timeseries[cols].equals(res.timeseries[cols])


def test_a_policy_changes_the_flight_only_after_the_detection(tmp_path):
    """A strong random policy: the same flight up to the detection tick, another after."""
    path = save_policy(_random_policy(9, hidden=16, scale=2.0), tmp_path / "p.npz")
    law = simulate(_trial()).timeseries
    res = simulate(_trial(controller_params={"policy": str(path)})).timeseries
    stage = law["stage"].to_numpy()
    before = stage == 0
    cols = ["x_m", "y_m", "z_m", "q0", "q1", "q2", "q3"]
    assert law.loc[before, cols].equals(res.loc[before, cols])
    assert not law[cols].equals(res[cols])


def _tick_commands(policy: PolicyWeights | None, stage: int, hold_set: float) -> np.ndarray:
    """One tick of recovery_step in ``stage`` (the law's hold point captured or not), moving
    at (0.5, 0, 0.3) m/s after a detection on a wall of normal -x: the rotor speeds, rad/s."""
    from quadimpact.core.controllers import recovery as CL
    from quadimpact.core.controllers.recovery import recovery_step
    from quadimpact.simulation.setup import prepare

    setup = prepare(_trial())
    ctrl = setup.ctrl.copy()
    if policy is not None:
        block = policy.block()
        ctrl[CTL.C_POLICY : CTL.C_POLICY + block.size] = block
    meas = np.zeros(MSS.NMEAS)
    meas[MSS.MS_X : MSS.MS_X + L.NX] = setup.x0
    meas[MSS.MS_X + L.X_VEL : MSS.MS_X + L.X_VEL + 3] = (0.5, 0.0, 0.3)
    meas[MSS.MS_DETECTED] = 1.0
    meas[MSS.MS_T_DETECT] = 0.1
    meas[MSS.MS_NORMAL : MSS.MS_NORMAL + 3] = (-1.0, 0.0, 0.0)
    mem = np.zeros(L.NMEM)
    mem[L.MEM_STAGE] = stage
    mem[CL.RM_HOLD_SET] = hold_set
    cmd = np.zeros(4)
    recovery_step(0.3, meas, ctrl, mem, setup.veh, 0.005, cmd)
    return cmd


@pytest.mark.parametrize(
    ("stage", "last_stage", "acts"),
    [(1, 4, True), (3, 4, True), (5, 4, False), (1, 5, True), (4, 5, True), (5, 5, True)],
)
def test_the_residual_acts_in_its_stages_and_leaves_the_others_to_the_law(stage, last_stage, acts):
    """One tick of recovery_step in a stage, with and without a strong policy: the commands
    differ in stages 1-4, and in stage 5 (the law's return to hover) only for a policy whose
    last stage is 5."""
    policy = _random_policy(7, hidden=16, scale=3.0, last_stage=last_stage)
    law, corrected = _tick_commands(None, stage, 1.0), _tick_commands(policy, stage, 1.0)
    assert (not np.array_equal(law, corrected)) == acts


@pytest.mark.parametrize(("hold_set", "acts"), [(0.0, True), (1.0, False)])
def test_a_hand_over_policy_leaves_the_held_point_to_the_law(hold_set, acts):
    """In stage 5 a hand-over policy corrects the law while it brakes (its hold point not
    yet captured) and not once the point is captured: then the commands are the law's
    alone, to the bit. Before stage 5 it acts as any policy."""
    policy = _random_policy(7, 16, 3.0, 5).with_hand_over()
    for stage in (3, 5):
        law = _tick_commands(None, stage, hold_set)
        corrected = _tick_commands(policy, stage, hold_set)
        assert (not np.array_equal(law, corrected)) == (acts or stage < 5)


def test_hand_over_round_trips_and_is_part_of_the_identity(tmp_path):
    """Saved and read back; a file without it reads as no hand-over, with its old digest."""
    plain = _random_policy(10, last_stage=5)
    handing = plain.with_hand_over()
    assert handing.sha256 != plain.sha256 and handing.with_hand_over(False).sha256 == plain.sha256
    q = load_policy(save_policy(handing, tmp_path / "h.npz"))
    assert q.hover_hand_over and q.sha256 == handing.sha256
    assert q.block()[RES.PB_HAND_OVER] == 1.0 and plain.block()[RES.PB_HAND_OVER] == 0.0


def test_packing_writes_the_files_block(tmp_path):
    from quadimpact.simulation.setup import prepare

    p = _random_policy(2)
    path = save_policy(p, tmp_path / "p.npz")
    ctrl = prepare(_trial(controller_params={"policy": str(path)})).ctrl
    block = p.block()
    np.testing.assert_array_equal(ctrl[CTL.C_POLICY : CTL.C_POLICY + block.size], block)
    assert not ctrl[CTL.C_POLICY + block.size : CTL.C_POLICY + CTL.NPOLICY].any()
    assert not prepare(_trial()).ctrl[CTL.C_POLICY : CTL.C_POLICY + CTL.NPOLICY].any()
    assert int(ctrl[CTL.C_POLICY + RES.PB_HIDDEN]) == p.hidden


def test_a_policy_file_round_trips_with_its_digest(tmp_path):
    p = _random_policy(4).with_vector(_random_policy(4).vector(), note="x")
    q = load_policy(save_policy(p, tmp_path / "p.npz"))
    np.testing.assert_array_equal(q.vector(), p.vector())
    assert q.sha256 == p.sha256 and len(q.sha256) == 64 and q.meta["note"] == "x"
    assert _random_policy(5).sha256 != p.sha256


def test_the_last_stage_round_trips_and_is_part_of_the_identity(tmp_path):
    """A file without ``last_stage`` (every file before it existed) reads as 4, with the
    digest it always had; 5 is saved, read back, and makes another policy."""
    p4 = _random_policy(6)
    p5 = _random_policy(6, last_stage=5)
    np.testing.assert_array_equal(p4.vector(), p5.vector())
    assert p4.sha256 != p5.sha256
    q5 = load_policy(save_policy(p5, tmp_path / "p5.npz"))
    assert q5.last_stage == 5 and q5.sha256 == p5.sha256
    assert q5.block()[RES.PB_LAST_STAGE] == 5.0 and p4.block()[RES.PB_LAST_STAGE] == 4.0
    old = {"w1": p4.w1, "b1": p4.b1, "w2": p4.w2, "b2": p4.b2,
           "thrust_scale": np.float64(0.3), "rate_scale_rad_s": np.float64(4.0)}  # fmt: skip
    np.savez(tmp_path / "old.npz", **old)
    q4 = load_policy(tmp_path / "old.npz")
    assert q4.last_stage == 4 and q4.sha256 == p4.sha256


@pytest.mark.parametrize(
    ("arrays", "rule"),
    [
        ({"last_stage": np.int64(3)}, "last_stage: must be one number, 4 or 5 (got 3)"),
        ({"last_stage": np.array([5, 5])}, "last_stage: must be one number, 4 or 5"),
        ({"hover_centred": np.int64(2)}, "hover_centred: must be one number, 0 or 1 (got 2)"),
        ({"hover_fade_s": np.array([1.5, 1.0])}, "hover_fade_s: must be two numbers (from, to)"),
        ({"hover_fade_s": np.array([0.5, 2.5])}, "0 <= from < to <= 2, or (0, 0) (got [0.5, 2.5])"),
        ({"hover_fade_s": np.float64(1.0)}, "hover_fade_s: must be two numbers"),
        ({"hover_hand_over": np.int64(3)}, "hover_hand_over: must be one number, 0 or 1"),
        ({"w1": np.zeros((4, 23))}, "w1: must be (4, 24)"),
        ({"b2": np.zeros(2)}, "b2: must be (3,)"),
        ({"w1": np.zeros((40, 24)), "b1": np.zeros(40), "w2": np.zeros((3, 40))}, "<= 32"),
        ({"b1": np.full(4, np.nan)}, "b1: must be finite"),
        ({"rate_scale_rad_s": np.float64(-1.0)}, "rate_scale_rad_s: must be >= 0"),
        ({"w2": None}, "missing array(s) w2"),
    ],
)
def test_a_bad_policy_file_is_a_one_line_error(tmp_path, arrays, rule):
    good = {"w1": np.zeros((4, 24)), "b1": np.zeros(4), "w2": np.zeros((3, 4)),
            "b2": np.zeros(3), "thrust_scale": np.float64(0.3),
            "rate_scale_rad_s": np.float64(4.0)}  # fmt: skip
    data = {**good, **arrays}
    path = tmp_path / "bad.npz"
    np.savez(path, **{k: v for k, v in data.items() if v is not None})
    with pytest.raises(InputError, match=re.escape(rule)) as err:
        load_policy(path)
    assert "\n" not in str(err.value) and "bad.npz" in str(err.value)


def test_a_missing_or_unreadable_policy_is_a_one_line_error(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        load_policy(tmp_path / "none.npz")
    (tmp_path / "text.npz").write_text("not an archive")
    with pytest.raises(InputError, match="not a .npz policy file"):
        load_policy(tmp_path / "text.npz")
    from quadimpact.inputs.scenarios import scenario_from_dict

    data = {"kind": "impact-trial", "controller_params": {"policy": str(tmp_path / "none.npz")}}
    with pytest.raises(InputError, match="controller_params.policy: no such file") as err:
        scenario_from_dict(data, where="trial.toml")
    assert "\n" not in str(err.value)


SHIPPED = policy_path("learned")


@pytest.mark.skipif(not SHIPPED.is_file(), reason="no shipped policy (inputs/policies/learned.npz)")
def test_the_shipped_policy_flies_seeded_trials_with_numpy_and_the_loop_only():
    """In a fresh interpreter: the shipped weights load, fly five seeded wall trials, and
    no training library (cma, a deep-learning framework) is imported; the NumPy network
    gives bounded outputs. The policy shipped before it, ``learned-imu``, loads too."""
    code = """
import json, sys
import numpy as np
from quadimpact import ImpactTrial, simulate
from quadimpact.inputs.policy_file import load_policy
p = load_policy("learned")
out = p.outputs(np.zeros((2, 24)))
rows = []
for seed in range(5):
    s = ImpactTrial(vehicle="navi", speed_m_s=2.0, pitch_deg=-30.0 + 10 * seed,
                    pre_impact="spin-down", sensors="onboard",
                    estimator="nav-ekf", seed=seed, controller_params={"policy": "learned"})
    r = simulate(s).summary
    rows.append([r["status"], r["detected"], r["recovered"], r["height_loss_m"]])
old = load_policy("learned-imu")
print(json.dumps({"rows": rows, "hidden": p.hidden, "out": out.tolist(), "sha": p.sha256,
                  "old": [old.sha256, old.last_stage], "last_stage": p.last_stage,
                  "libraries": [m for m in ("cma", "torch", "jax", "stable_baselines3")
                                if m in sys.modules]}))
"""
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    got = json.loads(res.stdout.strip().splitlines()[-1])
    assert got["libraries"] == []
    assert got["last_stage"] == 5 and got["old"][1] == 4 and got["old"][0] != got["sha"]
    assert len(got["rows"]) == 5 and all(r[0] != "failed" and r[1] for r in got["rows"])
    assert sum(bool(r[2]) for r in got["rows"]) >= 3
    assert np.all(np.abs(got["out"]) < 1.0) and len(got["sha"]) == 64
    assert SHIPPED.stat().st_size < 2_000_000
