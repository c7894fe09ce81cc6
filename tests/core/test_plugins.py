"""The core's extension points, each used once by plug-ins that exist only in this test.

A ball (a new feature kind) falls onto a spherical obstacle (a new shape
kind): the pair's geometry is registered in the contact-geometry table
(``core.geometry.register_geometry``), a proximity sensor is sampled with the
IMU (``make_kernel(sensor=...)``), and a controller reads that sensor and
reports a stage when the ball is close (``make_kernel(step=...)``). One loop
is compiled around the three (docs/ARCHITECTURE.md, "Where to add").

Physics checked: a central impact of a sphere on a fixed sphere is the 1-DOF
Hunt-Crossley contact, so the rebound speed is the restitution of the 1-DOF
law (integrated independently here) times the impact speed, with no lateral
force and no rotation; the stage is reported at the first control tick at
which the sensor reads less than its threshold (the fall is at constant
speed without gravity, so that tick is known in closed form).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit
from scipy.integrate import solve_ivp

from quadimpact.core import controller_slots as CTL
from quadimpact.core import feature_slots as FS
from quadimpact.core import geometry
from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.geometry import PR_GEOMETRY
from quadimpact.core.geometry.contact_record import material_record
from quadimpact.core.kernel import make_kernel
from quadimpact.core.recording_slots import E_FEATURE, E_SHAPE, E_T_START, E_V_I, OUT_X
from quadimpact.core.records import model, new_output
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.core.sensors import measurement_slots as MSS

FEAT_BALL = 50  # the new feature kind: a sphere of radius F_RADIUS at F_CENTRE
SHAPE_SPHERE = 60  # the new shape kind: a sphere of radius SH_RADIUS at SH_POINT
NEAR_M = 0.0525  # the controller's threshold on the sensor's reading


@njit
def ball_sphere(x, C, feat, f, shapes, s):  # pragma: no cover - compiled
    """Contact record of a ball feature against a sphere obstacle (closed form).

    Copies the centre (an allocation, as every plug-in here makes one: the loop
    is compiled without reference counting, its plug-ins with it).
    """
    cb = feat[f, FS.F_CENTRE : FS.F_CENTRE + 3].copy()
    ox = C[0, 0] * cb[0] + C[0, 1] * cb[1] + C[0, 2] * cb[2]
    oy = C[1, 0] * cb[0] + C[1, 1] * cb[1] + C[1, 2] * cb[2]
    oz = C[2, 0] * cb[0] + C[2, 1] * cb[1] + C[2, 2] * cb[2]
    rx = x[L.X_POS] + ox - shapes[s, SHP.SH_POINT]
    ry = x[L.X_POS + 1] + oy - shapes[s, SHP.SH_POINT + 1]
    rz = x[L.X_POS + 2] + oz - shapes[s, SHP.SH_POINT + 2]
    dist = math.sqrt(rx * rx + ry * ry + rz * rz)
    nx, ny, nz = rx / dist, ry / dist, rz / dist  # out of the obstacle, toward the ball
    rf = feat[f, FS.F_RADIUS]
    delta = rf + shapes[s, SHP.SH_RADIUS] - dist
    return material_record(x, C, delta, ox - rf * nx, oy - rf * ny, oz - rf * nz, nx, ny, nz)


@njit
def sphere_distance(px, py, pz, shapes, s):  # pragma: no cover - compiled
    dx = px - shapes[s, SHP.SH_POINT]
    dy = py - shapes[s, SHP.SH_POINT + 1]
    dz = pz - shapes[s, SHP.SH_POINT + 2]
    return math.sqrt(dx * dx + dy * dy + dz * dz) - shapes[s, SHP.SH_RADIUS]


@njit
def proximity(t, x, xdot, C, m, d):  # pragma: no cover - compiled
    """The gap between the ball (feature 0) and the nearest sphere, into the user block."""
    gap = np.inf
    p = x[L.X_POS : L.X_POS + 3].copy()
    for s in range(m.shapes.shape[0]):
        g = sphere_distance(p[0], p[1], p[2], m.shapes, s)
        gap = min(gap, g - m.feat[0, FS.F_RADIUS])
    d.meas[MSS.MS_USER] = gap
    d.meas[MSS.MS_USER + 1] = t


@njit
def brace(t, meas, ctrl, mem, veh, dt, cmd):  # pragma: no cover - compiled
    """No thrust; stage 1 once the proximity sensor reads less than NEAR_M."""
    off = np.zeros(4)
    for j in range(4):
        cmd[j] = off[j]
    if mem[L.MEM_STAGE] < 1.0 and meas[MSS.MS_USER] < NEAR_M:
        mem[L.MEM_STAGE] = 1.0


@pytest.fixture
def registered():
    before = dict(geometry.GEOMETRIES), dict(geometry.SHAPE_DISTANCES)
    gid = geometry.register_geometry(FEAT_BALL, SHAPE_SPHERE, ball_sphere)
    geometry.register_shape_distance(SHAPE_SPHERE, sphere_distance)
    yield gid
    geometry.GEOMETRIES.clear()
    geometry.GEOMETRIES.update(before[0])
    geometry.SHAPE_DISTANCES.clear()
    geometry.SHAPE_DISTANCES.update(before[1])


def _ball_drop(v_in: float, k: float, n: float, e: float, rate_hz: float):
    """A 1-kg ball of radius 0.1 m falling at ``v_in`` (no gravity) onto a sphere of 0.5 m."""
    veh = np.zeros(VS.NVEH)
    veh[VS.V_MASS] = 1.0
    inertia = np.diag([0.004, 0.004, 0.004])
    veh[VS.V_INERTIA : VS.V_INERTIA + 9] = inertia.ravel()
    veh[VS.V_INERTIA_INV : VS.V_INERTIA_INV + 9] = np.linalg.inv(inertia).ravel()
    veh[VS.V_SPIN : VS.V_SPIN + 4] = (-1.0, 1.0, -1.0, 1.0)
    feat = np.zeros((1, FS.NFEAT))
    feat[0, FS.F_KIND] = FEAT_BALL
    feat[0, [FS.F_RADIUS, FS.F_K, FS.F_N, FS.F_E]] = (0.1, k, n, e)
    shapes = np.zeros((1, SHP.NSHAPE))
    shapes[0, SHP.SH_KIND] = SHAPE_SPHERE
    shapes[0, SHP.SH_POINT : SHP.SH_POINT + 3] = (0.0, 0.0, 0.5)  # top at Z = 0 (NED, down)
    shapes[0, SHP.SH_RADIUS] = 0.5
    x0 = np.zeros(L.NX)
    x0[L.X_POS + 2] = -0.3  # the ball's bottom 0.2 m above the sphere
    x0[L.X_QUAT] = 1.0
    x0[L.X_VEL + 2] = v_in  # falling (down is +Z)
    opts = np.zeros(L.NOPT)
    opts[L.O_CRASH_RULE] = L.CRASH_NONE
    opts[[L.O_DT_CONTROL, L.O_RTOL, L.O_ATOL, L.O_MAX_STEPS, L.O_EVENT_TOL]] = (
        0.005, 1e-10, 1e-12, 1e6, 1e-12
    )  # fmt: skip
    opts[[L.O_V_MIN, L.O_V_REG, L.O_POWER_OFF_T]] = (1e-3, 1e-2, np.inf)
    ctrl = np.zeros(CTL.NCTRL)
    ctrl[CTL.C_KIND] = L.CTRL_USER
    scfg = np.zeros(IMS.NSCFG)
    scfg[IMS.SC_RATE] = rate_hz
    return model(
        x0=x0, t0=0.0, tf=0.6, veh=veh, feat=feat, shapes=shapes,
        pairs=geometry.pair_table(feat, shapes), opts=opts, ctrl=ctrl, scfg=scfg,
        t_out=np.array([0.0, 0.6]),
    )  # fmt: skip


def _restitution_1dof(k: float, n: float, e: float, m: float, v_in: float) -> float:
    """Rebound over impact speed of the 1-DOF Hunt-Crossley law (Herbert-McWhannell damping)."""
    lam = 6.0 * (1.0 - e) * k / (((2.0 * e - 1.0) ** 2 + 3.0) * v_in)

    def rhs(_t, y):
        delta, rate = y
        f = max(0.0, k * max(delta, 0.0) ** n * (1.0 + lam / k * rate))
        return [rate, -f / m]

    def leave(_t, y):
        return y[0]

    leave.terminal, leave.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 10.0), [0.0, v_in], events=leave, rtol=1e-12, atol=1e-14)
    return -sol.y_events[0][0][1] / v_in


@pytest.mark.slow  # compiles a whole loop around the plug-ins (about a minute)
def test_a_registered_feature_shape_sensor_and_controller_run_in_one_loop(registered):
    assert registered >= geometry.GEOM_PLUGIN
    kernel = make_kernel(brace, geometry=True, sensor=proximity)
    v_in, k, n, e, rate = 1.0, 400.0, 0.66, 0.8, 200.0
    m = _ball_drop(v_in, k, n, e, rate)
    assert m.pairs[0, PR_GEOMETRY] == registered
    o = new_output(m, int(0.6 * rate) + 2, 16)
    kernel.run(m, o)
    st = o.stats
    assert st[L.ST_STATUS] == L.STATUS_COMPLETED
    # one contact episode of the ball with the sphere, onset located at the analytic time
    assert int(st[L.ST_N_EPISODES]) == 1
    ep = o.episodes[0]
    assert ep[E_FEATURE] == 0 and ep[E_SHAPE] == 0
    assert ep[E_T_START] == pytest.approx(0.2 / v_in, abs=1e-9)
    assert ep[E_V_I] == pytest.approx(v_in, rel=1e-9)
    # the rebound: the 1-DOF restitution, straight up, no spin
    x_end = o.out[-1, OUT_X : OUT_X + L.NX]
    assert -x_end[L.X_VEL + 2] / v_in == pytest.approx(
        _restitution_1dof(k, n, e, 1.0, v_in), rel=1e-6
    )
    assert np.abs(x_end[L.X_VEL : L.X_VEL + 2]).max() < 1e-12
    assert np.abs(x_end[L.X_OMEGA : L.X_OMEGA + 3]).max() < 1e-12
    # the controller saw the sensor: stage 1 at the first tick whose sample reads < NEAR_M
    ticks = np.arange(0.0, 0.6, 0.005)
    first = ticks[(0.2 - v_in * ticks) < NEAR_M][0]
    assert st[L.ST_STAGE_T + 1] == pytest.approx(first, abs=1e-12)


def test_the_table_names_what_it_lacks_and_refuses_what_it_cannot_compile():
    with pytest.raises(KeyError, match="feature kind ring against shape kind 60"):
        geometry.geometry_id(L.FEAT_RING, SHAPE_SPHERE)
    with pytest.raises(TypeError, match="njit"):
        geometry.register_geometry(FEAT_BALL, SHAPE_SPHERE, ball_sphere.py_func)
    with pytest.raises(ValueError, match="built-in"):
        geometry.register_geometry(L.FEAT_RING, L.SHAPE_PLANE, ball_sphere)
    with pytest.raises(TypeError, match="njit"):
        make_kernel(sensor=proximity.py_func)
