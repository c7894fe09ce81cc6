"""The controller registry as an extension point, end to end.

A controller registered in this module through ``register_controller(name,
step=..., params=..., pack=...)`` alone is selected by name from a scenario
file, a sweep (``workers=1``: in this process) and the command line (in this
process, through click's test runner: a subprocess would not see the
registration). It really runs: its rotor commands are in the time series,
and the motion they cause is the analytic one.

The plug-in commands a constant collective thrust ``thrust_n`` (a parameter
from ``[controller_params]``, packed at ``ctrl[C_PARAMS]``) with zero torques,
through the inverse allocation of the packed head (``ctrl[C_ALLOC_INV]``).
Started level and at rest, the vehicle then moves straight up or down with
the constant acceleration ``T / m - g`` (ideal rotors: the command holds from
the first tick; no torque, so no tilt), so after ``t`` seconds its upward
speed is ``(T / m - g) t`` and its altitude changed by half that times ``t``.

Compiling a plug-in's kernel takes ~15 s; the registration (and so the
kernel, cached on its registry entry) is shared by the whole module.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from numba import njit
from pydantic import BaseModel, ConfigDict, Field

from quadimpact import load_scenario_file, load_vehicle, read_result, simulate
from quadimpact.cli import cli
from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.errors import InputError
from quadimpact.inputs.controllers import (
    controller_names,
    register_controller,
    unregister_controller,
)
from quadimpact.inputs.scenarios import scenario_from_dict
from quadimpact.simulation.setup import prepare
from quadimpact.simulation.trim import trim_rotor_speeds
from quadimpact.sweep import run_sweep

NAME = "test-constant-thrust"
THRUST = 10.5  # N, from [controller_params] (the Spiri weighs 9.15 N)
DEFAULT_THRUST = 8.0  # N, the parameter's default
FINAL_T = 0.2  # s
SPIRI = load_vehicle()


class ConstantThrustParams(BaseModel):
    """The plug-in's one parameter."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    thrust_n: float = Field(DEFAULT_THRUST, gt=0, description="Collective thrust held, N.")


def pack_constant_thrust(params: ConstantThrustParams, context: object) -> np.ndarray:
    block = np.zeros(CTL.NPARAM)
    block[0] = params.thrust_n
    return block


@njit
def constant_thrust_step(t, meas, ctrl, mem, veh, dt, cmd):  # pragma: no cover - compiled
    for j in range(4):  # Omega_j^2 = (A^-1)[j, 0] T: thrust T, zero torques
        cmd[j] = np.sqrt(max(ctrl[CTL.C_ALLOC_INV + 4 * j] * ctrl[CTL.C_PARAMS], 0.0))


@pytest.fixture(scope="module")
def plugin():
    entry = register_controller(
        NAME,
        step=constant_thrust_step,
        params=ConstantThrustParams,
        pack=pack_constant_thrust,
        description="a constant collective thrust (a test plug-in)",
    )
    yield entry
    unregister_controller(NAME)


def scenario_toml(path: Path, *, controller: bool = True) -> Path:
    text = f"""\
kind = "flight"
position_m = [0.0, 0.0, -5.0]
final_time_s = {FINAL_T}
output_rate_hz = 100
ground = "none"
"""
    if controller:
        text += f'controller = "{NAME}"\n\n[controller_params]\nthrust_n = {THRUST}\n'
    path.write_text(text, encoding="utf-8")
    return path


def vertical_speed(thrust_n: float, mass_kg: float, t: float) -> float:
    """Upward speed after ``t`` s at constant thrust and level attitude, from rest (m/s)."""
    return (thrust_n / mass_kg - SPIRI.gravity_m_s2) * t


def check_plugin_ran(ts, thrust_n: float) -> None:
    """Its commands in the time series, and the analytic motion they cause."""
    speeds = trim_rotor_speeds(SPIRI, thrust_n, yaw_paper=False)  # the allocation, solved here
    after = ts[ts["t_s"] > 1e-9]
    for j in (1, 2, 3, 4):
        np.testing.assert_allclose(after[f"omega_cmd{j}_rad_s"], speeds[j - 1], rtol=1e-12)
        np.testing.assert_allclose(after[f"omega{j}_rad_s"], speeds[j - 1], rtol=1e-12)
    t = ts["t_s"].to_numpy()
    v_up = vertical_speed(thrust_n, SPIRI.mass_kg, t)
    np.testing.assert_allclose(-ts["vz_m_s"].to_numpy(), v_up, atol=1e-9)
    np.testing.assert_allclose(ts["altitude_m"].to_numpy() - 5.0, 0.5 * v_up * t, atol=1e-9)
    # level throughout (the spin-up reaction of the first tick's speed change, a yaw
    # impulse, tilts it by ~1e-7 deg through the inertia products)
    np.testing.assert_allclose(ts[["roll_deg", "pitch_deg"]].to_numpy(), 0.0, atol=1e-6)


def test_a_scenario_file_selects_the_plugin_and_its_parameter(plugin, tmp_path: Path) -> None:
    scenario = load_scenario_file(scenario_toml(tmp_path / "flight.toml"))
    assert scenario.controller == NAME
    setup = prepare(scenario)
    assert setup.ctrl[CTL.C_KIND] == L.CTRL_USER
    assert setup.ctrl[CTL.C_PARAMS] == THRUST  # the parameter reached its packed block
    assert setup.kernel is plugin.kernel_cache["kernel"]
    result = simulate(scenario)
    assert result.summary["status"] == "completed" and result.summary["controller"] == NAME
    check_plugin_ran(result.timeseries, THRUST)
    assert result.world["resolved"]["controller_params"] == {"thrust_n": THRUST}
    # its parameters are validated like a built-in's
    bad = {"kind": "flight", "controller": NAME}
    with pytest.raises(InputError, match=r"controller_params.thrust_n: must be > 0"):
        scenario_from_dict({**bad, "controller_params": {"thrust_n": -1.0}})
    with pytest.raises(InputError, match=r"controller_params.thrust\b.*thrust_n"):
        scenario_from_dict({**bad, "controller_params": {"thrust": 9.0}})


def test_a_sweep_runs_the_plugin_in_process(plugin, tmp_path: Path) -> None:
    base = {
        "kind": "flight",
        "position_m": [0.0, 0.0, -5.0],
        "final_time_s": FINAL_T,
        "output_rate_hz": 100,
        "ground": "none",
        "controller": NAME,
        "controller_params": {"thrust_n": THRUST},
    }
    masses = [0.8, 0.933, 1.5]
    table = run_sweep({"base": base, "grid": {"mass_kg": masses}}, tmp_path / "sweep", workers=1)
    assert table.attrs["sweep"]["backend"] == "serial"
    assert table["status"].tolist() == ["completed"] * 3
    assert table["controller"].tolist() == [NAME] * 3
    expected = [abs(vertical_speed(THRUST, m, FINAL_T)) for m in masses]
    np.testing.assert_allclose(table["final_speed_m_s"], expected, rtol=1e-9)
    assert min(expected[0], expected[-1]) > 0.5  # the light one climbs, the heavy one sinks:
    sink = vertical_speed(THRUST, masses[-1], FINAL_T) * FINAL_T / 2  # the lowest altitude
    np.testing.assert_allclose(table["min_altitude_m"], [5.0, 5.0, 5.0 + sink], rtol=1e-9)


@pytest.mark.slow  # a whole command with its figures (~10 s)
def test_the_command_line_selects_the_plugin(plugin, tmp_path: Path) -> None:
    runner = CliRunner()
    help_text = runner.invoke(cli, ["run", "--help"]).output
    assert NAME in help_text  # the registry's choices, read when asked
    # --controller NAME on a file that names none: the parameter's default
    plain = scenario_toml(tmp_path / "plain.toml", controller=False)
    out = tmp_path / "by-flag"
    done = runner.invoke(cli, ["run", str(plain), "--controller", NAME, "--out", str(out)])
    assert done.exit_code == 0, done.output
    result = read_result(out)
    assert result.summary["controller"] == NAME
    check_plugin_ran(result.timeseries, DEFAULT_THRUST)
    # a file naming it, with [controller_params]
    out = tmp_path / "by-file"
    named = scenario_toml(tmp_path / "named.toml")
    done = runner.invoke(cli, ["run", str(named), "--out", str(out)])
    assert done.exit_code == 0, done.output
    check_plugin_ran(read_result(out).timeseries, THRUST)
    # a name nobody registered: a usage error listing the registered ones
    done = runner.invoke(cli, ["run", "--controller", "test-constant-thrst", "--out", str(out)])
    assert done.exit_code == 2
    assert f"did you mean {NAME!r}" in done.output


def test_unregistered_it_is_gone(plugin) -> None:
    assert NAME in controller_names()
    unregister_controller(NAME)
    try:
        assert NAME not in controller_names()
        with pytest.raises(InputError, match="controller: must be one of 'paper'"):
            scenario_from_dict({"kind": "flight", "controller": NAME})
    finally:
        register_controller(
            NAME, step=constant_thrust_step, params=ConstantThrustParams, pack=pack_constant_thrust
        )
