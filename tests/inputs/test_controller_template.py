"""The controller template (examples/controller_template.py) and the named access a plug-in
and a Simulation have to the loop's records (quadimpact.core.named).

The template's step, compiled alone, is checked on constructed measurements: at
its references it asks for the weight and no torque, and an attitude error
gives the torque that removes it; flown in the loop (the cached one, which
calls the step by its address) it brings a vehicle started low and rolled back
to its references.
"""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit
from pydantic import BaseModel

from quadimpact import FlightScenario, Simulation
from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.core import named
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.interval_slots import IS_N_STEPS
from quadimpact.core.sensors import measurement_slots as MSS
from quadimpact.inputs.controllers import param_index, param_slots, register_controller
from quadimpact.simulation.setup import prepare

from helpers import load_example


@pytest.fixture(scope="module")
def template():
    return load_example("controller_template.py")


def _records(scenario: FlightScenario):
    setup = prepare(scenario)
    m = setup.model()
    meas = np.zeros(MSS.NMEAS)
    meas[MSS.MS_X : MSS.MS_X + L.NX] = setup.x0
    return setup, m, meas


def _wrench(m, cmd: np.ndarray) -> np.ndarray:
    """[thrust N, torques N m] that the commands ask for (the allocation's inverse, inverted)."""
    a_inv = m.ctrl[CTL.C_ALLOC_INV : CTL.C_ALLOC_INV + 16].reshape(4, 4)
    return np.linalg.solve(a_inv, cmd**2)


def test_the_default_packing_names_the_parameters_in_order(template) -> None:
    slots = param_slots(template.HoldParams)
    assert list(slots) == list(template.HoldParams.model_fields)
    assert [o for o, _ in slots.values()] == list(range(len(slots)))
    assert template.K_ATT == param_index(template.HoldParams, "k_attitude_1_s2") == 3

    class Mixed(BaseModel):
        gain: float = 2.0
        limits: tuple[float, float] = (-1.0, 1.0)
        on: bool = True

    assert param_slots(Mixed) == {"gain": (0, 1), "limits": (1, 2), "on": (3, 1)}

    class Texts(BaseModel):
        mode: str = "fast"

    with pytest.raises(TypeError, match=r"Texts\.mode: the default packing takes numbers"):
        register_controller("texts", step=template.hold_step, params=Texts, replace=True)


def test_at_its_references_the_step_asks_for_the_weight_and_no_torque(template) -> None:
    s = FlightScenario(controller="template-hold", position_m=(0.0, 0.0, -2.0))
    setup, m, meas = _records(s)
    mem, cmd = np.zeros(L.NMEM), np.zeros(4)
    template.hold_step(0.0, meas, m.ctrl, mem, m.veh, 0.005, cmd)
    thrust, *torque = _wrench(m, cmd)
    weight = setup.vehicle.mass_kg * setup.vehicle.gravity_m_s2
    assert thrust == pytest.approx(weight, rel=1e-12)
    assert np.allclose(torque, 0.0, atol=1e-12 * weight)
    assert np.allclose(cmd, setup.x0[L.X_ROTOR : L.X_ROTOR + 4], rtol=1e-9)  # trimmed hover


@pytest.mark.parametrize(("axis", "euler"), [(0, (5.0, 0.0, 0.0)), (1, (0.0, -4.0, 0.0))])
def test_an_attitude_error_asks_for_the_torque_that_removes_it(template, axis, euler) -> None:
    s = FlightScenario(controller="template-hold", position_m=(0.0, 0.0, -2.0), euler_deg=euler,
                       attitude_ref_deg=(0.0, 0.0, 0.0))  # fmt: skip
    setup, m, meas = _records(s)
    cmd = np.zeros(4)
    template.hold_step(0.0, meas, m.ctrl, np.zeros(L.NMEM), m.veh, 0.005, cmd)
    torque = _wrench(m, cmd)[1:]
    angle = np.radians(euler[axis])
    expected = setup.vehicle.inertia[axis, axis] * 50.0 * -angle  # k_attitude 50
    assert torque[axis] == pytest.approx(expected, rel=0.02)  # the inertia's products aside
    assert abs(torque[2]) < 0.05 * abs(expected)


def test_each_named_quantity_is_its_slots() -> None:
    meas = np.arange(MSS.NMEAS, dtype=float)
    ctrl = np.arange(CTL.NCTRL, dtype=float)
    veh = np.arange(VS.NVEH, dtype=float)

    @njit
    def read(meas, ctrl, veh):
        return (
            named.position(meas).copy(), named.attitude(meas).copy(), named.body_rates(meas).copy(),
            named.rotor_speeds(meas).copy(), named.imu_specific_force(meas).copy(),
            named.wall_normal(meas).copy(), named.tick_time(meas), named.detection_time(meas),
            named.params(ctrl)[:3].copy(), named.allocation_inverse(ctrl)[1, 2],
            named.references(ctrl), named.rotor_speed_range(ctrl), named.mass(veh),
            named.inertia(veh)[2, 1], named.gravity(veh), named.thrust_coefficient(veh),
        )  # fmt: skip

    got = read(meas, ctrl, veh)
    x = MSS.MS_X
    assert got[0].tolist() == list(range(x + L.X_POS, x + L.X_POS + 3))
    assert got[1].tolist() == list(range(x + L.X_QUAT, x + L.X_QUAT + 4))
    assert got[2].tolist() == list(range(MSS.MS_W_HAT, MSS.MS_W_HAT + 3))
    assert got[3].tolist() == list(range(x + L.X_ROTOR, x + L.X_ROTOR + L.MAX_ROTORS))
    assert got[4].tolist() == list(range(MSS.MS_IMU_F, MSS.MS_IMU_F + 3))
    assert got[5].tolist() == list(range(MSS.MS_NORMAL, MSS.MS_NORMAL + 3))
    assert (got[6], got[7]) == (MSS.MS_T, MSS.MS_T_DETECT)
    assert got[8].tolist() == [CTL.C_PARAMS, CTL.C_PARAMS + 1, CTL.C_PARAMS + 2]
    assert got[9] == CTL.C_ALLOC_INV + 6
    assert got[10] == (CTL.C_H_REF, CTL.C_PHI_REF, CTL.C_THETA_REF, CTL.C_PSI_REF)
    assert got[11] == (CTL.C_OMEGA_MIN, CTL.C_OMEGA_MAX)
    assert got[12:] == (VS.V_MASS, VS.V_INERTIA + 7, VS.V_GRAVITY, VS.V_KT)


def test_a_simulation_hands_out_its_records_by_name_read_only() -> None:
    sim = Simulation(FlightScenario(final_time_s=0.1, euler_deg=(3.0, 0.0, 0.0)))
    sim.advance(2)
    x, meas, stats = sim.state, sim.measurement, sim.stats
    assert np.array_equal(x.position, np.asarray(x)[L.X_POS : L.X_POS + 3])
    assert np.array_equal(x.attitude, np.asarray(x)[L.X_QUAT : L.X_QUAT + 4])
    q = MSS.MS_X + L.X_QUAT
    assert np.array_equal(meas.attitude, np.asarray(meas)[q : q + 4])
    assert meas.tick_time == pytest.approx(0.005) and meas.detected == 0.0
    assert stats.n_steps == stats[L.ST_STEPS + IS_N_STEPS] > 0
    assert stats.t_end == pytest.approx(0.01)
    assert {f.name for f in x.fields()} == {
        "position", "velocity_body", "attitude", "body_rates", "rotor_speeds"
    }  # fmt: skip
    with pytest.raises(ValueError, match="read-only"):
        x.position[0] = 1.0
    with pytest.raises(AttributeError, match="no field 'speed'"):
        _ = x.speed
    assert type(x[0:3]).__name__ == "NamedVector" and not hasattr(x[0:3], "position")


def test_the_template_flies_a_vehicle_back_to_its_references(template) -> None:
    from quadimpact import simulate

    s = FlightScenario(controller="template-hold", position_m=(0.0, 0.0, -1.7),
                       euler_deg=(5.0, 0.0, 0.0), altitude_ref_m=2.0,
                       attitude_ref_deg=(0.0, 0.0, 0.0), final_time_s=6.0)  # fmt: skip
    ts = simulate(s).timeseries
    end = ts.iloc[-1]
    assert -end["z_m"] == pytest.approx(2.0, abs=0.02)
    assert abs(end["roll_deg"]) < 0.05 and abs(end["pitch_deg"]) < 0.05
    assert -ts["z_m"].max() > 1.69  # it climbed, never sank below the start much
