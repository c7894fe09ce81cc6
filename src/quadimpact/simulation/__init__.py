"""One run, Python side: inputs to packed arrays, the compiled loop, tables and summary.

* :mod:`~quadimpact.simulation.packing`: validated inputs -> the kernel's flat arrays;
* :mod:`~quadimpact.simulation.approach`: the wall approach's attitude and shooting;
* :mod:`~quadimpact.simulation.setup`: :class:`RunSetup`, ``prepare(scenario)``;
* :mod:`~quadimpact.simulation.record`: raw kernel arrays -> episodes and time series;
* :mod:`~quadimpact.simulation.metrics`: impacts, metrics, response types;
* :mod:`~quadimpact.simulation.summary`: the summary of a run;
* :mod:`~quadimpact.simulation.recovery_metrics`: detection and recovery metrics;
* :mod:`~quadimpact.simulation.simulate`: :func:`simulate` and :func:`run_setup`;
* :mod:`~quadimpact.simulation.stepping`: :class:`Simulation`, a run advanced
  one control interval at a time from Python.
"""

from quadimpact.simulation.batch import simulate_batch
from quadimpact.simulation.simulate import run_setup, simulate
from quadimpact.simulation.stepping import Simulation
from quadimpact.simulation.summary import build_summary

__all__ = ["Simulation", "build_summary", "run_setup", "simulate", "simulate_batch"]
