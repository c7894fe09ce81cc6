"""Contact law: bumper-plane geometry and the Hunt-Crossley restitution."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from quadimpact import FlightScenario, load_vehicle
from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.geometry import contact_record
from quadimpact.core.recording_slots import E_FEATURE, E_V_I, OUT_X
from quadimpact.inputs.world import GROUND, Plane
from quadimpact.packing.vehicle_block import pack_features
from quadimpact.packing.world_block import pack_surfaces
from quadimpact.rotations import euler_zyx_to_quat, quat_to_matrix
from quadimpact.simulation.setup import prepare

from helpers import run_packed

SPIRI = load_vehicle()
RB = SPIRI.bumper_radius_m
ALPHA = math.radians(SPIRI.bumper_tilt_deg)
WALL_D = 1.0
WALL = pack_surfaces([Plane.wall(WALL_D)])


def state(pos, euler_deg, v_body=(0.0, 0.0, 0.0), omega=(0.0, 0.0, 0.0)):
    x = np.zeros(L.NX)
    x[0:3] = pos
    x[3:6] = v_body
    x[6:10] = euler_zyx_to_quat(*np.radians(euler_deg))
    x[10:13] = omega
    return x


def contact(x, j, surf=WALL, vehicle=SPIRI):
    C = np.ascontiguousarray(quat_to_matrix(x[6:10]))
    return contact_record(x, C, pack_features(vehicle, 0.0), surf, j, 0)


def brute_force_depth(x, j, p0, m, vehicle=SPIRI, n=200001):
    """Deepest rim point by sampling the circle (independent of the closed form)."""
    centres, u, nrm = vehicle.bumper_frames()
    C = quat_to_matrix(x[6:10])
    beta = np.linspace(0.0, 2 * np.pi, n)
    w = np.cross(nrm[j], u[j])
    rim_b = centres[j] + vehicle.bumper_radius_m * (
        np.cos(beta)[:, None] * u[j] + np.sin(beta)[:, None] * w
    )
    rim_i = x[0:3] + rim_b @ C.T
    depth = -(rim_i - p0) @ m
    k = np.argmax(depth)
    return depth[k], rim_i[k] - x[0:3]


def test_level_heading_0_two_front_bumpers_equally_deep():
    # hand value: deepest X of a front bumper = x_c + Rb sqrt(1 - n_x^2), n_x = -sin(a)/sqrt(2)
    x = state((0.8, 0.0, -2.0), (0, 0, 0))
    reach = 0.13192 + RB * math.sqrt(1.0 - math.sin(ALPHA) ** 2 / 2.0)
    for j in (0, 3):  # bumpers 1 and 4
        d = contact(x, j)[0]
        assert d == pytest.approx(0.8 + reach - WALL_D, abs=1e-12)
    # rear bumpers are far from the wall
    assert contact(x, 1)[0] < -0.2 and contact(x, 2)[0] < -0.2


def test_level_heading_45_bumper_4_leads_with_hand_computed_point():
    x = state((0.8, 0.0, -2.0), (0, 0, 45))
    c = math.cos(math.pi / 4)
    cx = c * 0.13192 - c * (-0.12662)  # rotor 4 centre, inertial X
    cy = c * 0.13192 + c * (-0.12662)
    d, dd, rx, ry, rz, *_ = contact(x, 3)
    assert d == pytest.approx(0.8 + cx + RB * math.cos(ALPHA) - WALL_D, abs=1e-12)
    # contact point: c + Rb u, u = (cos a, 0, -sin a) in inertial axes (rim raised by alpha)
    r_inertial = quat_to_matrix(x[6:10]) @ np.array([rx, ry, rz])
    np.testing.assert_allclose(
        r_inertial, [cx + RB * math.cos(ALPHA), cy, -0.02416 - RB * math.sin(ALPHA)], atol=1e-12
    )
    assert d > max(contact(x, j)[0] for j in (0, 1, 2))


@pytest.mark.parametrize(
    "euler_deg", [(0, -15, 0), (-10.54, -10.73, 45), (20, 35, -60), (-170, 80, 123), (5, 0, 180)]
)
@pytest.mark.parametrize(
    "plane",
    [
        ((1.0, 0.0, 0.0), (-1.0, 0.0, 0.0)),
        ((0.0, 0.0, 0.0), (0.0, 0.0, -1.0)),
        ((0.3, -0.2, -1.0), (0.3, -0.5, 0.8)),
    ],
)
def test_closed_form_matches_brute_force(euler_deg, plane):
    p0 = np.array(plane[0])
    m = np.array(plane[1]) / np.linalg.norm(plane[1])
    surf = pack_surfaces([Plane(name="s", point_m=tuple(p0), normal=tuple(m))])
    x = state((0.7, 0.1, -1.9), euler_deg)
    for j in range(4):
        d, _, rx, ry, rz, *_ = contact(x, j, surf)
        d_bf, r_bf = brute_force_depth(x, j, p0, m)
        assert d == pytest.approx(d_bf, abs=1e-10)  # sampling error <= Rb (pi/n)^2 / 2
        r_i = quat_to_matrix(x[6:10]) @ np.array([rx, ry, rz])
        np.testing.assert_allclose(r_i, r_bf, atol=5e-5)


def test_circle_parallel_to_plane_touches_at_its_centre():
    flat = SPIRI.with_overrides(bumper_tilt_deg=0.0)
    ground = pack_surfaces([GROUND])
    x = state((0.0, 0.0, 0.05), (0, 0, 0), v_body=(0.0, 0.0, 0.7))
    for j in range(4):
        d, dd, rx, ry, rz, *_ = contact(x, j, ground, flat)
        centre = flat.rotor_positions[j]
        assert d == pytest.approx(0.05 + centre[2], abs=1e-15)
        assert dd == pytest.approx(0.7, abs=1e-15)
        np.testing.assert_allclose([rx, ry, rz], centre, atol=1e-15)


def test_penetration_rate_is_the_time_derivative_of_penetration():
    """delta_dot (material velocity of the deepest point) equals d(delta)/dt."""
    x = state((0.9, 0.0, -2.0), (12, -20, 33), v_body=(0.4, -0.3, 0.2), omega=(1.5, -2.0, 3.0))
    h = 1e-6
    for j in range(4):
        d0, dd, *_ = contact(x, j)
        # advance the pose kinematically by h (first order is enough for a derivative check)
        xp = x.copy()
        C = quat_to_matrix(x[6:10])
        xp[0:3] += h * C @ x[3:6]
        w = x[10:13]
        dq = (
            0.5
            * h
            * np.array(
                [
                    -x[7] * w[0] - x[8] * w[1] - x[9] * w[2],
                    x[6] * w[0] + x[8] * w[2] - x[9] * w[1],
                    x[6] * w[1] + x[9] * w[0] - x[7] * w[2],
                    x[6] * w[2] + x[7] * w[1] - x[8] * w[0],
                ]
            )
        )
        xm = x.copy()
        xm[0:3] -= h * C @ x[3:6]
        xp[6:10] += dq
        xm[6:10] -= dq
        fd = (contact(xp, j)[0] - contact(xm, j)[0]) / (2 * h)
        assert fd == pytest.approx(dd, abs=1e-7)


# ---------------------------------------------------------------- restitution
def one_dof_restitution(k, n, e, mass, v_i):
    """Restitution of m x'' = -(k x^n + lambda x^n x') from x = 0, x' = v_i (scipy, independent)."""
    lam = 6.0 * (1.0 - e) * k / (((2.0 * e - 1.0) ** 2 + 3.0) * v_i)

    def f(t, y):
        x, v = y
        xn = max(x, 0.0) ** n
        return [v, -max(0.0, k * xn + lam * xn * v) / mass]

    def back(t, y):
        return y[0]

    back.terminal = True
    back.direction = -1
    sol = solve_ivp(
        f,
        (0.0, 10.0),
        [1e-15, v_i],
        events=back,
        rtol=1e-12,
        atol=1e-15,
        method="DOP853",
        max_step=1e-3,
    )
    return -sol.y_events[0][0][1] / v_i


def test_one_dof_restitution_is_close_to_e_and_independent_of_k_and_mass():
    e_ref = one_dof_restitution(40.0, 0.54, 0.9, 0.933, 0.75)
    assert e_ref == pytest.approx(0.9, abs=0.01)
    for k, mass, v in [(400.0, 0.933, 0.75), (40.0, 5.0, 0.75), (40.0, 0.933, 2.0)]:
        assert one_dof_restitution(k, 0.54, 0.9, mass, v) == pytest.approx(e_ref, rel=1e-6)


@pytest.mark.parametrize("speed", [0.5, 1.5])
def test_point_mass_impact_restitution_matches_one_dof(speed):
    """A vehicle with huge inertia (a point mass) bouncing off the wall on one bumper."""
    heavy = {"inertia_kg_m2": [[1e6, 0, 0], [0, 1e6, 0], [0, 0, 1e6]]}
    setup = prepare(
        FlightScenario(
            position_m=(0.6, 0.0, -2.0),
            velocity_m_s=(speed, 0.0, 0.0),
            euler_deg=(0.0, 0.0, 45.0),
            rotor_speeds_rad_s=(0.0, 0.0, 0.0, 0.0),
            vehicle_overrides=heavy,
            surfaces=[{"name": "wall", "point_m": (1.0, 0.0, 0.0), "normal": (-1.0, 0.0, 0.0)}],
            final_time_s=1.0,
        )
    )
    veh = setup.veh.copy()
    veh[VS.V_GRAVITY] = 0.0
    ctrl = setup.ctrl.copy()
    ctrl[CTL.C_KIND] = L.CTRL_NONE
    out, ep, stats = run_packed(setup, veh=veh, ctrl=ctrl)
    assert ep.shape[0] == 1 and int(ep[0, E_FEATURE]) == 3  # bumper 4, once
    assert ep[0, E_V_I] == pytest.approx(speed, rel=1e-9)
    q = out[-1, OUT_X + 6 : OUT_X + 10]
    v_after = quat_to_matrix(q) @ out[-1, OUT_X + 3 : OUT_X + 6]
    e_sim = -v_after[0] / speed
    v = SPIRI
    e_1dof = one_dof_restitution(
        v.contact_stiffness, v.contact_exponent, v.restitution, v.mass_kg, speed
    )
    assert e_sim == pytest.approx(e_1dof, abs=1e-6)
    assert e_sim == pytest.approx(v.restitution, abs=0.01)
