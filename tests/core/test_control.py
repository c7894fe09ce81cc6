"""Controllers: hover hold, recovery from a perturbed start, plug-in interface."""

import numpy as np
import pytest
from numba import njit

from quadimpact import FlightScenario, WallApproach, simulate
from quadimpact.core import layout as L
from quadimpact.core.kernel import make_kernel
from quadimpact.core.sensors import measurement_slots as MSS
from quadimpact.simulation.stepping import Simulation

CONTROLLERS = ["paper", "cascade-pid"]


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_trimmed_hover_is_held(controller):
    """From the trimmed state both controllers hold altitude and attitude for 10 s."""
    r = simulate(FlightScenario(final_time_s=10.0, controller=controller))
    ts = r.timeseries
    assert r.summary["status"] == "completed" and ts["t_s"].iloc[-1] == 10.0
    assert np.max(np.abs(ts["altitude_m"] - 2.0)) < 1e-6
    for col in ("roll_deg", "pitch_deg", "yaw_deg"):
        assert np.max(np.abs(ts[col])) < 1e-5
    assert np.max(np.abs(ts[["x_m", "y_m"]].to_numpy())) < 1e-6


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_perturbed_hover_recovers(controller):
    """Start 0.2 m low, rolled, pitched and yawed: back on the references within 10 s."""
    r = simulate(
        FlightScenario(
            position_m=(0.0, 0.0, -1.8),
            euler_deg=(5.0, -3.0, 10.0),
            altitude_ref_m=2.0,
            attitude_ref_deg=(0.0, 0.0, 0.0),
            final_time_s=10.0,
            controller=controller,
        )
    )
    ts = r.timeseries
    late = ts[ts["t_s"] >= 8.0]
    assert np.max(np.abs(late["altitude_m"] - 2.0)) < 5e-3
    for col in ("roll_deg", "pitch_deg", "yaw_deg"):
        assert np.max(np.abs(late[col])) < 0.05
    # bounded transient: no overshoot beyond the initial errors
    assert ts["altitude_m"].max() < 2.1
    assert np.max(np.abs(ts["roll_deg"])) < 5.05


def test_paper_controller_sinks_when_tilted():
    """The paper's law multiplies the thrust by cos(phi) cos(theta): a held tilt loses height."""
    r = simulate(FlightScenario(euler_deg=(0.0, -15.0, 0.0), final_time_s=0.5))
    h = r.timeseries["altitude_m"].to_numpy()
    assert h[-1] < 2.0 - 1e-3


@njit(cache=False)
def _hold_initial_speeds(t, meas, ctrl, mem, veh, dt, cmd):
    if mem[0] == 0.0:
        for j in range(4):
            mem[1 + j] = meas[MSS.MS_X + L.X_ROTOR + j]
        mem[0] = 1.0
    for j in range(4):
        cmd[j] = mem[1 + j]


@pytest.fixture(scope="module")
def held_kernel():
    """The loop compiled around ``_hold_initial_speeds`` (once for the module, ~20 s)."""
    return make_kernel(_hold_initial_speeds)


@pytest.mark.slow  # the fixture compiles a whole loop around the plug-in (~20 s)
def test_plugin_controller_runs_in_the_compiled_loop(held_kernel):
    """A user's njit controller plugs into the same loop (here: open-loop hover speeds)."""
    r = simulate(FlightScenario(final_time_s=1.0), kernel=held_kernel)
    ts = r.timeseries
    assert r.summary["integrator"]["control_ticks"] == 200
    np.testing.assert_allclose(ts["omega_cmd1_rad_s"], ts["omega1_rad_s"].iloc[0])
    # trimmed speeds balance the weight exactly: the vehicle stays put
    assert np.max(np.abs(ts["altitude_m"] - 2.0)) < 1e-9


@pytest.mark.slow  # the fixture compiles a whole loop around the plug-in (~20 s)
def test_a_plugin_loop_flies_the_wall_approach_with_its_own_controller(held_kernel):
    """The approach's shooting runs are the plug-in loop's (``core/approach.py``, compiled
    into the kernel): with the rotors held instead of the paper controller the run still
    touches the wall first at T_c with V_c (a late start here: Brent's search too), from
    another start than the paper controller needs."""
    scenario = WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.5)
    held = simulate(scenario, kernel=held_kernel)
    s = held.summary
    assert s["first_contact_s"] == pytest.approx(0.5, abs=1e-6)
    assert s["impact_speed_m_s"] == pytest.approx(0.5, abs=1e-6)
    assert s["approach"]["late_start"] and abs(s["approach"]["speed_residual_m_s"]) <= 1e-12
    ts = held.timeseries  # the rotors really were held from the start
    before = ts[ts["t_s"] < 0.5 - 1e-6]
    np.testing.assert_array_equal(before["omega_cmd1_rad_s"], before["omega1_rad_s"].iloc[0])
    paper = simulate(scenario).summary["approach"]
    assert s["approach"]["start_time_s"] != paper["start_time_s"]
    # the stepping front end prepares the same start with the kernel it is given
    assert Simulation(scenario, kernel=held_kernel).setup.approach == s["approach"]
