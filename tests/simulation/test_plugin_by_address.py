"""Plug-in steps called by address from the one cached loop (``core/plugin_call.py``).

A plug-in controller is compiled alone and the cached loop calls it through
its address in ``ctrl[C_STEP]``: the loop is not compiled again for it. The
checks: a plug-in that is the built-in paper law (its step calls
``paper_step``, its parameters packed by the built-in packer) flies the
built-in's run bit for bit, the wall approach's shooting included; a second
plug-in adds no compiled version of the loop; a step of the wrong kind is
refused in one line; an exception in a step reaches the caller as a
``PluginError``.
"""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from quadimpact import ImpactTrial, WallApproach, simulate
from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.core.controllers.paper import paper_step
from quadimpact.core.kernel import BUILTIN, execute
from quadimpact.core.sensors import measurement_slots as MSS
from quadimpact.inputs.controllers import (
    controller_entry,
    register_controller,
    unregister_controller,
)
from quadimpact.packing.controller_block import BUILTIN_PACKERS
from quadimpact.simulation.plugin_kernel import PluginError
from quadimpact.simulation.setup import prepare


@njit
def same_paper(t, meas, ctrl, mem, veh, dt, cmd):  # pragma: no cover - compiled
    paper_step(t, meas, ctrl, mem, veh, dt, cmd)


@njit
def held(t, meas, ctrl, mem, veh, dt, cmd):  # pragma: no cover - compiled
    for j in range(4):
        cmd[j] = meas[MSS.MS_X + L.X_ROTOR + j]


@njit
def returns_thrust(t, meas, ctrl, mem, veh, dt, cmd):  # pragma: no cover - compiled
    return 1.0


@njit
def raises_late(t, meas, ctrl, mem, veh, dt, cmd):  # pragma: no cover - compiled
    if t > 0.1:
        raise ValueError("late")
    for j in range(4):
        cmd[j] = meas[MSS.MS_X + L.X_ROTOR + j]


@pytest.fixture
def plugins():
    names = []

    def register(name, step, **kw):
        register_controller(name, step=step, replace=True, **kw)
        names.append(name)
        return name

    yield register
    for name in names:
        unregister_controller(name)


def _records_equal(a, b) -> bool:
    return all(
        np.array_equal(getattr(a, f), getattr(b, f), equal_nan=True)
        for f in ("out", "episodes", "stats", "imu")
    )


def test_the_paper_law_as_a_plugin_flies_the_builtin_run_bit_for_bit(plugins):
    name = plugins(
        "t-same-paper", same_paper, params=controller_entry("paper").params,
        pack=BUILTIN_PACKERS[L.CTRL_PAPER],
    )  # fmt: skip
    example = {"heading_deg": 45.0, "inclination_deg": 15.0, "speed_m_s": 0.75}
    built_in = prepare(WallApproach(**example, controller="paper"))
    plugged = prepare(WallApproach(**example, controller=name))
    assert plugged.ctrl[CTL.C_STEP] != 0.0 and built_in.ctrl[CTL.C_STEP] == 0.0
    assert plugged.run.x0.tobytes() == built_in.run.x0.tobytes()  # the shooting flew it too
    assert plugged.run.span.tobytes() == built_in.run.span.tobytes()
    mine = execute(plugged.model(), n_imu=plugged.n_imu, kernel=plugged.kernel)
    theirs = execute(built_in.model(), n_imu=built_in.n_imu)
    assert _records_equal(mine, theirs)
    a = simulate(WallApproach(**example, controller=name)).summary
    b = simulate(WallApproach(**example, controller="paper")).summary
    assert a["delta_init_m"] == b["delta_init_m"] and a["crash_time_s"] == b["crash_time_s"]


def test_a_second_plugin_compiles_its_step_and_not_the_loop(plugins):
    simulate(ImpactTrial(final_time_s=0.05))  # the cached loop, loaded
    loops = {e: len(getattr(BUILTIN, e).signatures) for e in ("start", "advance")}  # run: Python
    for i, step in enumerate((held, same_paper)):
        name = plugins(f"t-plugin-{i}", step)
        setup = prepare(ImpactTrial(controller=name, final_time_s=0.05))
        assert setup.kernel.run.__wrapped__ is BUILTIN.run
        assert simulate(ImpactTrial(controller=name, final_time_s=0.05)).summary["outcome"]
    assert {e: len(getattr(BUILTIN, e).signatures) for e in loops} == loops


def test_a_step_that_returns_a_value_is_refused_in_one_line(plugins):
    name = plugins("t-returns", returns_thrust)
    with pytest.raises(PluginError) as info:
        prepare(ImpactTrial(controller=name, final_time_s=0.05))
    text = str(info.value)
    assert (
        "\n" not in text
        and "t-returns" in text
        and "returns float64; a controller step returns nothing" in text
    ), text


def test_an_exception_in_a_step_reaches_the_caller_as_a_plugin_error(plugins):
    name = plugins("t-raises-late", raises_late)
    with pytest.raises(PluginError, match="raised ValueError: late"):
        simulate(ImpactTrial(controller=name, final_time_s=0.3))
    # the loop is left usable: the next built-in run gives its numbers
    a = simulate(ImpactTrial(final_time_s=0.3)).summary
    b = simulate(ImpactTrial(final_time_s=0.3)).summary
    assert a["outcome"] == b["outcome"]
