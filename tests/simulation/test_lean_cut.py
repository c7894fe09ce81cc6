"""The staged law's lean cut: stage 1 idles the rotors while the vehicle leans into the
obstacle and the contact still pushes (docs/RECOVERY.md 3.4)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadimpact import FlightScenario, Simulation
from quadimpact.core import layout as L
from quadimpact.core.controllers.recovery import lean_cut
from quadimpact.core.sensors import measurement_slots as MSS
from quadimpact.simulation.setup import prepare

G = 9.81


def _pitched(pitch_deg: float) -> np.ndarray:
    """A state at rest with the Z-Y-X pitch ``pitch_deg`` (negative: nose down, NED/FRD)."""
    x = np.zeros(L.NX)
    h = math.radians(pitch_deg) / 2
    x[L.X_QUAT : L.X_QUAT + 4] = (math.cos(h), 0.0, math.sin(h), 0.0)
    return x


def _ctrl(model: str, **params) -> np.ndarray:
    s = FlightScenario(controller="recovery", controller_params=params, ground="none",
                       model=model)  # fmt: skip
    return prepare(s).ctrl


@pytest.mark.parametrize(
    ("pitch_deg", "force", "model", "params", "cut"),
    [
        (-40.0, 10.0, "classic", {"lean_cut_deg": 30.0, "lean_cut_force_m_s2": G / 2}, True),
        # leaning 40 deg into the wall (up axis toward +X, the normal -X): beyond 30, not 45
        (-40.0, 10.0, "classic", {"lean_cut_deg": 45.0, "lean_cut_force_m_s2": G / 2}, False),
        (40.0, 10.0, "classic", {"lean_cut_deg": 30.0, "lean_cut_force_m_s2": G / 2}, False),
        (-40.0, 4.0, "classic", {"lean_cut_deg": 30.0, "lean_cut_force_m_s2": G / 2}, False),
        (-40.0, 0.0, "classic", {"lean_cut_deg": 30.0, "lean_cut_force_m_s2": 0.0}, True),
        (-89.0, 10.0, "classic", {}, False),  # the classic law has none
        # the default law: beyond 40 deg with g/4 of push
        (-45.0, 10.0, "default", {}, True),
        (-35.0, 10.0, "default", {}, False),
        (-45.0, 2.0, "default", {}, False),
    ],
)
def test_the_cut_reads_the_lean_and_the_push(pitch_deg, force, model, params, cut):
    meas = np.zeros(MSS.NMEAS)
    meas[MSS.MS_IMU_F : MSS.MS_IMU_F + 3] = (force * 0.6, force * 0.8, -G)  # |f_xy| = force
    normal = np.array([-1.0, 0.0, 0.0])  # out of a wall at +X
    assert lean_cut(_pitched(pitch_deg), normal, meas, _ctrl(model, **params)) is cut


def test_a_cut_stage_1_commands_idle_rotors_and_the_default_does_not():
    """Detection injected, nose 40 deg into a wall at +X, no contact, no slew limit: without
    the force condition stage 1 idles every rotor at the floor of the Navi's range; with it
    (the air pushes nothing) or without the cut, it commands the law's speeds."""

    def first_commands(params):
        s = FlightScenario(vehicle="navi", position_m=(0, 0, -20), euler_deg=(0, -40, 0),
                           controller="recovery", pre_impact="hold", ground="none",
                           model="classic",
                           controller_params={"hover": False, **params},
                           final_time_s=0.05)  # fmt: skip
        sim = Simulation(s)
        sim._d.meas[MSS.MS_DETECTED] = 1.0
        sim._d.meas[MSS.MS_NORMAL : MSS.MS_NORMAL + 3] = (-1.0, 0.0, 0.0)
        ts = sim.run().timeseries
        return ts[[f"omega_cmd{j}_rad_s" for j in (1, 2, 3, 4)]].to_numpy()[1]

    floor = 1000 * 2 * math.pi / 60
    cut = first_commands({"lean_cut_deg": 30.0, "lean_cut_force_m_s2": 0.0})
    assert cut == pytest.approx([floor] * 4, rel=1e-12)
    pushed = first_commands({"lean_cut_deg": 30.0, "lean_cut_force_m_s2": G / 2})
    plain = first_commands({})
    assert np.array_equal(pushed, plain)  # free air: no push, no cut
    assert plain.max() > 2 * floor
