"""Episodes: takeover, termination, truncation, the reward, the metrics and the loop's limits."""

from __future__ import annotations

import math

import numpy as np
import pytest

import quadimpact.envs as E
from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.envs import stacked as B
from quadimpact.core.rotors import RIN_CMD
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.simulation.recovery_metrics import RECOVERY_KEYS


def _until_end(env, policy, obs):
    total, n = 0.0, 0
    while True:
        obs, r, term, trunc, info = env.step(policy(obs))
        total += r
        n += 1
        if term or trunc:
            return obs, total, n, term, trunc, info


def test_recovered_termination_holds_the_condition_and_pays_the_bonus():
    env = E.ImpactRecoveryEnv(hold_s=0.2)
    pol = E.RecoveryPolicy(env)
    s = env._slots
    for seed in (1, 2, 3):
        obs, info = env.reset(seed=seed)
        t0 = info["t"]
        held, stages, total = [], [], 0.0
        while True:
            obs, r, term, trunc, info = env.step(pol(obs))
            total += r
            held.append(B.recovered_condition(s.TMEAS[0], s.M.ctrl[0], s.M.veh[0]))
            stages.append(info["stage"])
            if term or trunc:
                break
        m = info["metrics"]
        if not m["recovered"]:
            continue
        n = len(held)
        assert term and not trunc and info["outcome"] == "recovered"
        assert m["episode_steps"] == n and m["episode_return"] == pytest.approx(total)
        assert m["t_end_s"] == pytest.approx(t0 + n * 0.005)
        # the condition held on the last 40 ticks (0.2 s), in stage 4; never so before
        assert all(held[-40:]) and stages[-1] == 4 and m["t_end_s"] > m["t_stage4_s"]
        run = 0
        for i in range(n - 1):
            run = run + 1 if held[i] else 0
            assert not (run >= 40 and stages[i] >= 4), i
        assert set(RECOVERY_KEYS) <= set(m)
        assert r > 1.0 - 0.005 * 2.6  # the last step pays the bonus (1) less at most a tick's cost
        return
    pytest.fail("no recovery in three trials")


def test_truncation_at_the_final_time_and_recovered_without_termination():
    env = E.ImpactRecoveryEnv(end_on_recovery=False, envelope=E.Envelope(180.0, 1e9, 1e9, 1e9))
    obs, _ = env.reset(seed=4)
    _, _, n, term, trunc, info = _until_end(env, E.RecoveryPolicy(env), obs)
    assert trunc and not term and info["outcome"] == "time limit"
    assert info["t"] == 3.0 and info["metrics"]["t_end_s"] == 3.0
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros(4))


def test_envelope_failure_pays_for_the_time_left():
    env = E.ImpactRecoveryEnv(envelope=E.Envelope(max_tilt_deg=30.0))
    obs, _ = env.reset(seed=5)
    pol = E.RandomPolicy(env, seed=1)
    while True:
        obs, r, term, trunc, info = env.step(pol(obs))
        if term or trunc:
            break
    assert term and info["outcome"].startswith("envelope")
    w = E.RewardWeights()
    max_rate = w.tilt + w.rate + w.vertical_speed + w.height_loss + w.effort
    left = 3.0 - info["t"]
    assert r <= -w.failure_penalty - max_rate * left + 1e-12
    assert r >= -w.failure_penalty - max_rate * (left + 0.005) - 1e-12


def test_the_ground_ends_the_episode_when_enabled():
    env = E.ImpactRecoveryEnv(ground=True, trials=E.TrialDistribution(altitude_m=1.0),
                              envelope=E.Envelope(180.0, 1e9, 1e9, 1e9))  # fmt: skip
    obs, _ = env.reset(seed=6)
    assert env.run_setup.shape_names == ("wall", "ground")
    _, _, _, term, _, info = _until_end(env, lambda o: np.full(4, -1.0), obs)  # rotors at minimum
    assert term and info["outcome"] == "ground"
    assert info["metrics"]["min_altitude_m"] < 0.4  # a bumper reaches the ground, not the CM


def test_reward_is_the_documented_cost():
    w = E.RewardWeights(tilt=0.7, rate=0.3, vertical_speed=0.2, height_loss=0.4, effort=0.9)
    env = E.ImpactRecoveryEnv(reward=w, end_on_recovery=False)
    obs, _ = env.reset(seed=8)
    h_ref = -env.unwrapped._slots.D.x[0, L.X_POS + 2]
    s = env._slots
    veh = s.M.veh[0]
    hover = math.sqrt(veh[VS.V_MASS] * veh[VS.V_GRAVITY] / (4 * veh[VS.V_KT]))
    span = s.M.ctrl[0, CTL.C_OMEGA_MAX] - s.M.ctrl[0, CTL.C_OMEGA_MIN]
    rng = np.random.default_rng(0)
    for _ in range(30):
        obs, r, term, trunc, _ = env.step(rng.uniform(-0.2, 0.4, 4))
        x = s.D.x[0]
        q = x[L.X_QUAT : L.X_QUAT + 4] / np.linalg.norm(x[L.X_QUAT : L.X_QUAT + 4])
        c22 = 1 - 2 * (q[1] ** 2 + q[2] ** 2)
        from quadimpact.rotations import quat_to_matrix

        vz = (quat_to_matrix(q) @ x[L.X_VEL : L.X_VEL + 3])[2]
        cmd = s.D.rin[0, RIN_CMD : RIN_CMD + 4]
        cost = (
            w.tilt * (1 - c22) / 2
            + w.rate * min(np.linalg.norm(x[L.X_OMEGA : L.X_OMEGA + 3]) / 10.0, 1.0)
            + w.vertical_speed * min(abs(vz), 1.0)
            + w.height_loss * min(max(h_ref + x[L.X_POS + 2], 0.0), 1.0)
            + w.effort * min(np.mean(((cmd - hover) / span) ** 2), 1.0)
        )
        assert r == pytest.approx(-0.005 * cost, rel=1e-9, abs=1e-15)
        if term or trunc:
            break


def test_the_loop_limits_apply_to_the_agent():
    # rotor_floor "zero": a = -1 commands 0 rad/s; the slew limit lowers the speeds a step a tick
    env = E.ImpactRecoveryEnv(start="trial", rotor_floor="zero")
    env.reset(seed=3)
    before = env._slots.D.x[0, L.X_ROTOR : L.X_ROTOR + 4].copy()
    env.step(np.full(4, -1.0))
    slew = env.run_setup.opts[L.O_SLEW_MAX] * 0.005
    np.testing.assert_allclose(env._slots.D.x[0, L.X_ROTOR : L.X_ROTOR + 4], before - slew)
    env.step(np.full(4, 2.0))  # clipped to 1 (the top), slewed back up
    np.testing.assert_allclose(env._slots.D.x[0, L.X_ROTOR : L.X_ROTOR + 4], before, rtol=1e-12)


def test_info_metrics_are_those_of_the_summary():
    env = E.ImpactRecoveryEnv(record=True)
    obs, _ = env.reset(seed=10)
    *_, info = _until_end(env, E.RecoveryPolicy(env), obs)
    summary = env.result().summary  # analyse() of the run, as simulate() builds it
    for key in RECOVERY_KEYS:
        if key == "final_speed_m_s":
            continue  # the summary reads the last 1-kHz row, the metrics the state reached
        assert info["metrics"][key] == summary[key], key
    assert env.result().timeseries["t_s"].iloc[-1] == pytest.approx(info["t"], abs=1e-3)


def test_undetected_trials_are_redrawn_then_reported():
    never = E.TrialDistribution(overrides={"detection": {"enabled": False}})
    env = E.ImpactRecoveryEnv(trials=never, max_redraws=2)
    with pytest.raises(RuntimeError, match="no detection in 2"):
        env.reset(seed=0)
    with pytest.raises(RuntimeError, match="never fired"):
        env.reset(seed=0, options={"trial": {"speed_m_s": 1.0}})
    # some undetected: a far wall reached only by the fast trials within 1 s
    far = E.TrialDistribution(start_distance_m=1.0, speed_m_s=(0.2, 2.5), final_time_s=1.0)
    env = E.ImpactRecoveryEnv(trials=far)
    redraws = [env.reset(seed=s)[1]["redraws"] for s in range(20)]
    assert max(redraws) > 0
    assert all(env.reset(seed=s)[1]["redraws"] == r for s, r in enumerate(redraws))
    # trial mode needs no detection: the agent acts from t = 0
    env = E.ImpactRecoveryEnv(trials=never, start="trial")
    _, info = env.reset(seed=0)
    assert info["t"] == 0.0 and info["redraws"] == 0


def test_given_trials_and_their_checks():
    env = E.ImpactRecoveryEnv()
    _, info = env.reset(seed=0, options={"trial": {"pitch_deg": -20.0, "speed_m_s": 1.5}})
    assert env.scenario.pitch_deg == -20.0 and env.scenario.vehicle == "navi"
    assert env.scenario.friction_coefficient == 0.3  # the default trial's
    with pytest.raises(ValueError, match="final time"):
        env.reset(options={"trial": {"final_time_s": 2.0}})
    with pytest.raises(ValueError, match="noisy"):
        env.reset(options={"trial": {"imu": "noisy"}})
    noisy = E.ImpactRecoveryEnv(trials=E.TrialDistribution(imu=("ideal", "noisy")))
    kinds = {noisy.reset(seed=s)[1]["trial"]["imu"] for s in range(8)}
    assert kinds == {"ideal", "noisy"}
    replica = E.TrialDistribution(vehicle="spiri", model="recovery-replica")
    spiri = E.ImpactRecoveryEnv(trials=replica)
    spiri.reset(seed=1)
    assert spiri.run_setup.vehicle.name.lower().startswith("spiri")
    # an IMU table in the overrides replaces the preset choice
    table = {"imu": {"preset": "noisy", "position": "cm"}}
    cm = E.ImpactRecoveryEnv(trials=E.TrialDistribution(overrides=table))
    cm.reset(seed=2)
    scfg = cm.run_setup.scfg
    assert scfg[IMS.SC_NOISE_F] == 1.0 and np.all(scfg[IMS.SC_POS : IMS.SC_POS + 3] == 0)
