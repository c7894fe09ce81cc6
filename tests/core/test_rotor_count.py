"""Vehicles with n rotors (docs/MODEL.md 3.2, 3.4): hover, allocation, impact, Jr = 0.

The hexacopter is ``examples/vehicles/hexa.toml``: the Navi's mass, inertia and
arm length, six rotors 60 deg apart with alternating spins. Each test checks a
physical property that a wrong rotor count, stride or sum would break:

* a trimmed hexacopter hovers: its state stays constant to round-off;
* the allocation's pseudo-inverse gives back every feasible wrench, and a
  wrench outside the feasible set has its negative squares clipped to 0;
* a hexacopter thrown at a wall recovers with the staged law (stage 5, hover);
* ``Jr = 0`` is accepted and leaves no gyroscopic moment.

A quadrotor's numbers are pinned elsewhere (``-m pinned``); here its packed
inverse is checked to be the exact inverse of the square ``A``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from quadimpact import FlightScenario, ImpactTrial, simulate
from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.controllers.common import allocate
from quadimpact.core.rotors import rotor_wrench
from quadimpact.errors import InputError
from quadimpact.inputs.vehicle import load_vehicle
from quadimpact.linalg import inverse
from quadimpact.packing.vehicle_block import allocation_inverse, allocation_matrix, pack_vehicle
from quadimpact.simulation.setup import prepare

HEXA = Path(__file__).resolve().parents[2] / "examples" / "vehicles" / "hexa.toml"


@pytest.fixture(scope="module")
def hexa():
    return load_vehicle(HEXA)


def _hexa_ctrl(hexa) -> np.ndarray:
    """A packed ``ctrl`` head for the hexacopter (the physical yaw row)."""
    ctrl = np.zeros(CTL.NCTRL)
    n = hexa.rotor_count
    ctrl[CTL.C_N_ROTORS] = n
    ctrl[CTL.C_ALLOC_INV : CTL.C_ALLOC_INV + CTL.N_WRENCH * n] = allocation_inverse(
        hexa, False
    ).ravel()
    return ctrl


def test_hexacopter_file_is_a_six_rotor_vehicle(hexa):
    assert hexa.rotor_count == 6
    veh = pack_vehicle(hexa)
    assert veh[VS.V_N_ROTORS] == 6
    # per-rotor slots: one coefficient per rotor, zeros beyond the sixth
    assert np.all(veh[VS.V_KT : VS.V_KT + 6] == hexa.thrust_coefficient)
    assert np.all(veh[VS.V_KT + 6 : VS.V_KT + L.MAX_ROTORS] == 0.0)
    assert np.all(veh[VS.V_SPIN + 6 : VS.V_SPIN + L.MAX_ROTORS] == 0.0)
    # 60 deg apart on one arm length
    r = hexa.rotor_positions[:, :2]
    arms = np.hypot(r[:, 0], r[:, 1])
    assert np.allclose(arms, arms[0], rtol=1e-9, atol=0)
    gaps = [np.hypot(*(r[j] - r[(j + 1) % 6])) for j in range(6)]
    assert np.allclose(gaps, arms[0], rtol=1e-9)  # a regular hexagon: side = radius
    assert list(hexa.spin_directions) == [-1, 1, -1, 1, -1, 1]


# ------------------------------------------------------------------ hover
def test_hexacopter_hovers_at_its_trim(hexa):
    """Level, at rest, at the trimmed speeds under the cascade PID: nothing moves over 5 s."""
    s = FlightScenario(
        vehicle=str(HEXA),
        controller="cascade-pid",
        position_m=(0.0, 0.0, -2.0),
        final_time_s=5.0,
        ground="none",
        output_rate_hz=50.0,
    )
    r = simulate(s)
    assert r.summary["status"] == "completed"
    ts = r.timeseries
    drift = np.hypot(np.hypot(ts["x_m"], ts["y_m"]), ts["z_m"] + 2.0).max()
    tilt = np.abs(ts[["roll_deg", "pitch_deg", "yaw_deg"]].to_numpy()).max()
    speeds = ts[[f"omega{j}_rad_s" for j in range(1, 7)]].to_numpy()
    trim = math.sqrt(hexa.mass_kg * hexa.gravity_m_s2 / (6 * hexa.thrust_coefficient))
    assert "omega7_rad_s" not in ts.columns  # the table has the vehicle's six rotors
    assert drift < 1e-9, drift
    assert tilt < 1e-9, tilt
    assert np.abs(speeds - trim).max() < 1e-9 * trim
    # the trim is the allocation of m g: A Omega^2 = [m g, 0, 0, 0]
    wrench = allocation_matrix(hexa, False) @ speeds[0] ** 2
    weight = hexa.mass_kg * hexa.gravity_m_s2
    assert abs(wrench[0] - weight) < 1e-12 * weight
    assert np.abs(wrench[1:]).max() < 1e-12 * weight


# -------------------------------------------------------------- allocation
def test_allocation_reproduces_feasible_wrenches(hexa):
    """``A Omega^2`` equals the commanded wrench wherever no square is clipped."""
    ctrl = _hexa_ctrl(hexa)
    a = allocation_matrix(hexa, False)
    weight = hexa.mass_kg * hexa.gravity_m_s2
    rng = np.random.default_rng(56)
    cmd = np.zeros(L.MAX_ROTORS)
    inside = 0
    for _ in range(2000):
        wrench = np.array(
            [
                rng.uniform(0.3, 2.0) * weight,
                rng.uniform(-0.3, 0.3),
                rng.uniform(-0.3, 0.3),
                rng.uniform(-0.03, 0.03),
            ]
        )
        clipped = allocate(ctrl, *wrench, cmd)
        w2 = cmd[:6] ** 2
        exact = ctrl[CTL.C_ALLOC_INV : CTL.C_ALLOC_INV + 24].reshape(6, 4) @ wrench
        assert clipped == bool(np.any(exact < 0.0))
        assert np.all(cmd[6:] == 0.0)  # rotors beyond the sixth: never written
        if clipped:
            continue
        inside += 1
        got = a @ w2
        scale = np.abs(wrench).max()
        assert np.abs(got - wrench).max() <= 1e-9 * scale, (wrench, got)
    assert inside > 1500  # most of the sampled wrenches are feasible


def test_allocation_clips_negative_squares_outside_the_feasible_set(hexa):
    """A roll torque beyond what the thrust allows: the rotors that would push get 0."""
    ctrl = _hexa_ctrl(hexa)
    weight = hexa.mass_kg * hexa.gravity_m_s2
    cmd = np.full(L.MAX_ROTORS, -1.0)
    wrench = (0.2 * weight, 2.0, 0.0, 0.0)  # tau_x = 2 N m on 0.2 m g of thrust
    assert allocate(ctrl, *wrench, cmd)
    exact = ctrl[CTL.C_ALLOC_INV : CTL.C_ALLOC_INV + 24].reshape(6, 4) @ np.array(wrench)
    neg = exact < 0.0
    assert neg.any() and (~neg).any()
    assert np.all(cmd[:6][neg] == 0.0)  # clipped squares are 0
    assert np.array_equal(cmd[:6][~neg], np.sqrt(exact[~neg]))  # the others kept as computed
    # a positive roll torque needs the port rotors (y < 0) to push harder: the starboard
    # ones (y > 0) are the clipped ones
    y = hexa.rotor_positions[:, 1]
    assert np.all(y[neg] > 0.0)
    assert cmd[6] == -1.0  # beyond the rotor count: left alone


def test_quadrotor_allocation_is_the_exact_inverse():
    """A quadrotor keeps ``A^-1`` (not the pseudo-inverse), packed with stride 4."""
    for name in ("spiri", "navi"):
        v = load_vehicle(name)
        for model, yaw_paper in (("default", False), ("paper-replica", True)):
            a = allocation_matrix(v, yaw_paper)
            assert a.shape == (4, 4)
            inv = inverse(a)
            assert np.array_equal(allocation_inverse(v, yaw_paper), inv)
            s = FlightScenario(
                vehicle=name,
                model=model,
                controller="cascade-pid",
                position_m=(0.0, 0.0, -2.0),
                final_time_s=0.1,
            )
            ctrl = prepare(s).ctrl
            assert ctrl[CTL.C_N_ROTORS] == 4
            packed = ctrl[CTL.C_ALLOC_INV : CTL.C_ALLOC_INV + CTL.N_WRENCH * L.MAX_ROTORS]
            assert np.array_equal(packed[:16].reshape(4, 4), inv)
            assert np.all(packed[16:] == 0.0)


def test_pseudo_inverse_is_a_right_inverse(hexa):
    for yaw_paper in (False, True):
        a = allocation_matrix(hexa, yaw_paper)
        p = allocation_inverse(hexa, yaw_paper)
        assert p.shape == (6, 4)
        assert np.abs(a @ p - np.eye(4)).max() < 1e-12
        assert np.abs(p - np.linalg.pinv(a)).max() < 1e-10 * np.abs(p).max()


# -------------------------------------------------------------- wall impact
def test_hexacopter_recovers_from_a_wall_impact():
    """The staged recovery law brings a hexacopter thrown at a wall back to hover."""
    trial = ImpactTrial(
        vehicle=str(HEXA),
        controller="recovery",
        roll_deg=5.0,
        pitch_deg=-20.0,
        yaw_deg=30.0,
        speed_m_s=1.5,
        start_distance_m=0.32,
        altitude_m=5.0,
        final_time_s=4.0,
        ground="none",
    )
    r = simulate(trial)
    s = r.summary
    assert s["status"] == "completed"
    assert s["n_episodes"] >= 1 and s["delta_init_m"] > 0.0  # it did hit the wall
    assert s["detected"]
    assert s["recovered"]
    assert math.isfinite(s["t_stage5_s"])  # the hover stage
    ts = r.timeseries
    assert {f"omega{j}_rad_s" for j in range(1, 7)} <= set(ts.columns)
    late = ts[ts["t_s"] >= s["t_stage5_s"]]
    assert late["altitude_m"].min() > 3.0  # it did not fall out of the sky


# ------------------------------------------------------------------ Jr = 0
def test_zero_rotor_inertia_is_accepted_and_gives_no_gyroscopic_moment(hexa):
    navi = load_vehicle("navi")
    for v in (navi, hexa):
        v0 = v.with_overrides(rotor_inertia_kg_m2=0.0)
        veh0 = pack_vehicle(v0)
        veh = pack_vehicle(v)
        n = v.rotor_count
        x = np.zeros(L.NX)
        x[L.X_QUAT] = 1.0
        x[L.X_OMEGA : L.X_OMEGA + 3] = (3.0, -2.0, 1.5)  # tumbling
        rng = np.random.default_rng(n)
        x[L.X_ROTOR : L.X_ROTOR + n] = rng.uniform(300.0, 700.0, n)  # spins unbalanced
        wdot = np.zeros(L.MAX_ROTORS)
        wdot[:n] = rng.uniform(-500.0, 500.0, n)  # spinning up and down
        f0, mx0, my0, mz0 = rotor_wrench(x, wdot, veh0, False, False)
        # with Jr = 0: thrust moments and drag torques only
        w2 = x[L.X_ROTOR : L.X_ROTOR + n] ** 2
        kt = v.thrust_coefficients
        r = v.rotor_positions
        assert f0 == pytest.approx(-(kt * w2).sum(), rel=1e-14)
        assert mx0 == pytest.approx(-(r[:, 1] * kt * w2).sum(), rel=1e-12)
        assert my0 == pytest.approx((r[:, 0] * kt * w2).sum(), rel=1e-12)
        dt = v.drag_torque_coefficients
        assert mz0 == pytest.approx(-(v.spins * dt * w2).sum(), rel=1e-12)
        # the same state with Jr > 0 differs by the gyroscopic and spin-up moments exactly
        f1, mx1, my1, mz1 = rotor_wrench(x, wdot, veh, False, False)
        jr = v.rotor_inertia_kg_m2
        spin = (v.spins * x[L.X_ROTOR : L.X_ROTOR + n]).sum()
        p, q = x[L.X_OMEGA], x[L.X_OMEGA + 1]
        assert f1 == f0
        assert mx1 - mx0 == pytest.approx(-jr * spin * q, rel=1e-9)
        assert my1 - my0 == pytest.approx(jr * spin * p, rel=1e-9)
        assert mz1 - mz0 == pytest.approx(-jr * (v.spins * wdot[:n]).sum(), rel=1e-9)


def test_rotor_inertia_must_not_be_negative():
    with pytest.raises(InputError, match="rotor_inertia_kg_m2"):
        load_vehicle("navi").with_overrides(rotor_inertia_kg_m2=-1e-6)


# ---------------------------------------------------------------- validation
def test_rotor_count_rules(hexa):
    with pytest.raises(InputError, match="spin_directions"):
        hexa.with_overrides(spin_directions=[-1, 1, -1, 1])
    with pytest.raises(InputError, match="thrust_coefficient"):
        hexa.with_overrides(thrust_coefficient=[7.9e-6] * 5)
    with pytest.raises(InputError, match="rotor_positions_m"):
        hexa.with_overrides(rotor_positions_m=[[0.1, 0.0, 0.0]] * 9)
    with pytest.raises(InputError, match="features"):  # six rotors, four bumper rings
        load_vehicle("navi").with_overrides(
            rotor_positions_m=[list(r) for r in hexa.rotor_positions],
            spin_directions=list(hexa.spin_directions),
        )
    # one coefficient per rotor: the same vehicle as one shared value
    per_rotor = hexa.with_overrides(thrust_coefficient=[hexa.thrust_coefficient] * 6)
    assert np.array_equal(pack_vehicle(per_rotor), pack_vehicle(hexa))
