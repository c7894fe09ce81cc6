"""Rigid body: a torque-free tumbling body conserves energy and angular momentum."""

import numpy as np

from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.recording_slots import OUT_T
from quadimpact.inputs.scenarios import FlightScenario
from quadimpact.rotations import quat_to_matrix
from quadimpact.simulation.setup import prepare

from helpers import run_packed, states


def tumble(final_time_s: float = 10.0, **kw):
    """Spiri without gravity, rotors stopped, no surfaces, spun about all axes."""
    setup = prepare(
        FlightScenario(
            euler_deg=(10.0, 20.0, 30.0),
            angular_velocity_rad_s=(3.0, -2.0, 5.0),
            velocity_m_s=(0.3, -0.2, 0.1),
            rotor_speeds_rad_s=(0.0, 0.0, 0.0, 0.0),
            final_time_s=final_time_s,
            **kw,
        )
    )
    veh = setup.veh.copy()
    veh[VS.V_GRAVITY] = 0.0
    ctrl = setup.ctrl.copy()
    ctrl[CTL.C_KIND] = L.CTRL_NONE
    out, _, stats = run_packed(setup, veh=veh, ctrl=ctrl)
    return setup, out, stats


def test_torque_free_tumble_conserves_energy_and_momentum():
    setup, out, stats = tumble()
    assert stats[L.ST_STATUS] == L.STATUS_COMPLETED
    assert out[-1, OUT_T] == 10.0
    x = states(out)
    inertia = setup.vehicle.inertia
    w = x[:, L.X_OMEGA : L.X_OMEGA + 3]
    q = x[:, L.X_QUAT : L.X_QUAT + 4]
    energy = 0.5 * np.einsum("ni,ij,nj->n", w, inertia, w)
    h_inertial = np.einsum("nij,nj->ni", quat_to_matrix(q), w @ inertia.T)
    assert np.max(np.abs(energy / energy[0] - 1.0)) < 1e-8
    dh = np.linalg.norm(h_inertial - h_inertial[0], axis=1) / np.linalg.norm(h_inertial[0])
    assert dh.max() < 1e-8
    assert np.max(np.abs(np.linalg.norm(q, axis=1) - 1.0)) < 1e-9
    # the body really tumbles: the attitude goes far from its start
    assert np.min(q @ q[0]) < 0.5


def test_free_body_translates_uniformly():
    setup, out, _ = tumble(final_time_s=2.0)
    x = states(out)
    v_inertial = np.einsum("nij,nj->ni", quat_to_matrix(x[:, 6:10]), x[:, 3:6])
    np.testing.assert_allclose(v_inertial, np.tile([0.3, -0.2, 0.1], (len(x), 1)), atol=1e-9)
    t = out[:, OUT_T]
    np.testing.assert_allclose(x[:, 0], 0.3 * t, atol=1e-9)
