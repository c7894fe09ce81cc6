"""One scenario in, one :class:`~quadimpact.results.result.SimulationResult` out.

``simulate`` prepares the packed inputs (:func:`~quadimpact.simulation.setup.prepare`),
runs the compiled loop once, and reads its raw record into tables
(:mod:`~quadimpact.simulation.tables`) and the summary
(:mod:`~quadimpact.simulation.summary`).
"""

from __future__ import annotations

import time
from typing import Any

from quadimpact import __version__
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.interval_slots import IS_N_REJECTED, IS_N_RHS, IS_N_STEPS
from quadimpact.core.kernel import Kernel, execute
from quadimpact.inputs.scenarios import FlightScenario, ImpactTrial, WallApproach
from quadimpact.packing.vehicle_block import feature_records
from quadimpact.packing.world_block import surface_records
from quadimpact.results.costs import cpu_time
from quadimpact.results.result import SimulationResult
from quadimpact.simulation.impacts import run_episodes
from quadimpact.simulation.plugin_kernel import compile_cpu_total
from quadimpact.simulation.setup import RunSetup, prepare
from quadimpact.simulation.summary import build_summary
from quadimpact.simulation.tables import (
    episode_columns,
    episodes_frame,
    imu_columns,
    imu_frame,
    timeseries_columns,
    timeseries_frame,
)

__all__ = ["analyse", "run_cost", "run_setup", "simulate", "world_record"]


def simulate(
    scenario: WallApproach | FlightScenario | ImpactTrial,
    *,
    max_episodes: int = 1024,
    kernel: Kernel | None = None,
) -> SimulationResult:
    """Run one scenario.

    Parameters
    ----------
    scenario : WallApproach or FlightScenario or ImpactTrial
        Validated input (``quadimpact.inputs.scenarios``).
    max_episodes : int
        Size of the episode buffer; episodes beyond it are counted and reported.
    kernel : Kernel, optional
        A run loop from ``quadimpact.core.kernel.make_kernel`` (plug-ins);
        default: the registered controller's (the cached kernel for built-ins).
        A wall approach's shooting runs fly with it too.

    Returns
    -------
    SimulationResult
        ``.summary`` (dict of summary.json), ``.episodes``, ``.timeseries`` and
        ``.imu`` (pandas DataFrames, SI units, inertial NED / body FRD).
    """
    setup = prepare(scenario, kernel)
    return run_setup(setup, scenario, max_episodes=max_episodes)


def run_setup(
    setup: RunSetup,
    scenario: Any = None,
    *,
    max_episodes: int = 1024,
    kernel: Kernel | None = None,
) -> SimulationResult:
    """Run a prepared setup through the compiled loop and analyse the record."""
    started = cpu_time()
    m = setup.model()
    wall_start = time.perf_counter()
    cpu_start = cpu_time()
    compiled = compile_cpu_total()
    rec = execute(m, n_imu=setup.n_imu, max_episodes=max_episodes, kernel=kernel or setup.kernel)
    compiled = compile_cpu_total() - compiled  # a plug-in's loop compiled first: apart
    setup.compile_cpu_s += compiled
    started += compiled
    kernel_cpu_s = cpu_time() - cpu_start - compiled
    wall_s = time.perf_counter() - wall_start
    return analyse(setup, scenario, rec, wall_s, kernel_cpu_s=kernel_cpu_s, since=started)


def run_cost(
    setup: RunSetup, kernel_cpu_s: float | None, since: float | None
) -> dict[str, float | None]:
    """The summary's ``cost``: CPU time in the compiled loops and in the whole run, s, and
    apart from both, compiling a plug-in's loop (``RunSetup.compile_cpu_s``).

    ``kernel_cpu_s`` (the main run's) adds the approach's shooting runs;
    ``since`` (:func:`~quadimpact.results.costs.cpu_time` when the run
    started after :func:`prepare`) makes the total, :func:`prepare` included.
    Null where not measured.
    """
    kernel = None if kernel_cpu_s is None else setup.kernel_cpu_s + kernel_cpu_s
    total = None if since is None else setup.prepare_cpu_s + (cpu_time() - since)
    return {"kernel_cpu_s": kernel, "total_cpu_s": total, "compile_cpu_s": setup.compile_cpu_s}


def world_record(setup: RunSetup, scenario: Any = None) -> dict[str, Any]:
    """The world that ran, as plain data: the content of ``scenario.json`` (docs/RESULTS.md).

    Parameters
    ----------
    setup : RunSetup
        The prepared run.
    scenario : WallApproach or FlightScenario or ImpactTrial, optional
        The validated scenario it was prepared from.

    Returns
    -------
    dict
        ``scenario``: every field of the validated scenario (``None`` without
        one); ``resolved``: what its settings resolved to
        (:attr:`RunSetup.resolved`); ``vehicle``: every field of the vehicle
        with its overrides applied (body FRD, SI); ``surfaces``: every contact
        surface as packed for the kernel (the ground of ``ground = "contact"``
        included; :func:`~quadimpact.packing.world_block.surface_records`);
        ``features``: the vehicle's contact features as packed
        (:func:`~quadimpact.packing.vehicle_block.feature_records`).
    """
    return {
        "scenario": scenario.model_dump(mode="json") if hasattr(scenario, "model_dump") else None,
        "resolved": dict(setup.resolved),
        "vehicle": setup.vehicle.model_dump(mode="json"),
        "surfaces": surface_records(setup.shapes, setup.shape_names),
        "features": feature_records(setup.feat, setup.feature_names),
        "quadimpact_version": __version__,
    }


def analyse(
    setup: RunSetup,
    scenario: Any,
    rec: Any,
    wall_s: float = float("nan"),
    *,
    kernel_cpu_s: float | None = None,
    since: float | None = None,
):
    """Summary, tables and world record of a raw record (``core.records.RawRecord``) of ``setup``.

    The summary is computed from the raw arrays (no DataFrame; the impacts by
    one compiled pass over the episodes, ``simulation.impacts``); the result's
    ``timeseries``, ``episodes`` and ``imu`` tables and its ``world`` record
    are built when first read. ``kernel_cpu_s``: the CPU time of the run's
    compiled loop; ``since``: :func:`~quadimpact.results.costs.cpu_time`
    when the run started after :func:`prepare` (both for the summary's
    ``cost``; null when not given).
    """
    out, ep, st = rec.out, rec.episodes, rec.stats
    nf = len(setup.feature_names)
    episodes = run_episodes(ep, ep.shape[0], setup.shape_names, nf, setup.shapes)
    summary = build_summary(setup, scenario, episodes, st)
    stats = {
        "steps": int(st[L.ST_STEPS + IS_N_STEPS]),
        "rejected_steps": int(st[L.ST_STEPS + IS_N_REJECTED]),
        "rhs_evaluations": int(st[L.ST_STEPS + IS_N_RHS]),
        "control_ticks": int(st[L.ST_N_TICKS]),
        "output_rows": int(st[L.ST_N_OUT]),
        "wall_time_s": wall_s,
    }
    summary["integrator"] = stats
    summary["cost"] = run_cost(setup, kernel_cpu_s, since)
    names = setup.shape_names
    features = setup.feature_names
    rotors = int(setup.veh[VS.V_N_ROTORS])
    imu = rec.imu

    def tables(name: str) -> Any:
        if name == "timeseries":
            return timeseries_frame(out, out.shape[0], features, rotors)
        if name == "timeseries_columns":
            return timeseries_columns(out, out.shape[0], features, rotors)
        if name == "episodes":
            return episodes_frame(ep, ep.shape[0], names, nf)
        if name == "episodes_columns":
            return episode_columns(ep, ep.shape[0], names, nf)
        if name == "imu_columns":
            return imu_columns(imu, setup.scfg)
        if name == "world":
            return world_record(setup, scenario)
        return imu_frame(imu, setup.scfg)

    return SimulationResult(
        summary=summary,
        references=dict(setup.references),
        scenario=scenario,
        stats=stats,
        tables=tables,
    )
