"""One scenario in, one :class:`~quadimpact.results.result.SimulationResult` out.

``simulate`` prepares the packed inputs (:func:`~quadimpact.simulation.setup.prepare`),
runs the compiled loop once, and reads its raw record into tables
(:mod:`~quadimpact.simulation.record`) and the summary
(:mod:`~quadimpact.simulation.summary`).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from quadimpact.core import layout as L
from quadimpact.core.run import execute
from quadimpact.inputs.scenarios import FlightScenario, WallApproach
from quadimpact.results.result import SimulationResult
from quadimpact.simulation.record import episodes_frame, timeseries_frame
from quadimpact.simulation.setup import RunSetup, prepare
from quadimpact.simulation.summary import build_summary

__all__ = ["run_setup", "simulate"]


def simulate(
    scenario: WallApproach | FlightScenario,
    *,
    max_episodes: int = 1024,
    kernel: Callable | None = None,
) -> SimulationResult:
    """Run one scenario.

    Parameters
    ----------
    scenario : WallApproach or FlightScenario
        Validated input (``quadimpact.inputs.scenarios``).
    max_episodes : int
        Size of the episode buffer; episodes beyond it are counted and reported.
    kernel : callable, optional
        A run loop from ``quadimpact.core.run.make_kernel`` (plug-in controller);
        default: the cached kernel with the built-in controllers.

    Returns
    -------
    SimulationResult
        ``.summary`` (dict of summary.json), ``.episodes`` and ``.timeseries``
        (pandas DataFrames, SI units, inertial NED / body FRD).
    """
    setup = prepare(scenario)
    return run_setup(setup, scenario, max_episodes=max_episodes, kernel=kernel)


def run_setup(
    setup: RunSetup,
    scenario: Any = None,
    *,
    max_episodes: int = 1024,
    kernel: Callable | None = None,
) -> SimulationResult:
    """Run a prepared setup through the compiled loop and analyse the record."""
    t_out = setup.output_times()
    wall_start = time.perf_counter()
    out, ep, st = execute(
        setup.x0,
        setup.t0,
        setup.tf,
        setup.veh,
        setup.surf,
        setup.opts,
        setup.ctrl,
        t_out,
        max_episodes=max_episodes,
        kernel=kernel,
        **setup.schedule(),
    )
    wall_s = time.perf_counter() - wall_start
    ts = timeseries_frame(out, out.shape[0])
    episodes = episodes_frame(ep, ep.shape[0], setup.surface_names)
    summary = build_summary(setup, scenario, ts, episodes, st)
    stats = {
        "steps": int(st[L.ST_N_STEPS]),
        "rejected_steps": int(st[L.ST_N_REJECTED]),
        "rhs_evaluations": int(st[L.ST_N_RHS]),
        "control_ticks": int(st[L.ST_N_TICKS]),
        "output_rows": int(st[L.ST_N_OUT]),
        "wall_time_s": wall_s,
    }
    summary["integrator"] = stats
    return SimulationResult(
        summary=summary,
        episodes=episodes,
        timeseries=ts,
        references=dict(setup.references),
        scenario=scenario,
        stats=stats,
    )
