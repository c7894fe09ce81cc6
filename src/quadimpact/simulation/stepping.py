"""A run advanced from Python one control interval at a time: :class:`Simulation`.

Built on the compiled core's ``step.start`` / ``step.advance``: all the loop
state lives in NumPy arrays owned by the :class:`Simulation`, and each
:meth:`Simulation.advance` call runs whole control ticks in compiled code.
Between calls a user (a learning agent, a controller prototyped in Python, a
sensor model) can read the state and the measurement record and set the next
rotor command::

    sim = Simulation(ImpactTrial(roll_deg=5, pitch_deg=-30, speed_m_s=1.5))
    while not sim.done:
        sim.advance(1)                      # one 5-ms control interval
    result = sim.result()                   # as simulate() returns it

A run advanced tick by tick to the end gives the same result as
:func:`quadimpact.simulate` (bit for bit in the tables; the summary is built
by the same code).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from quadimpact.core import layout as L
from quadimpact.core import step as core_step
from quadimpact.results.result import SimulationResult
from quadimpact.simulation.checks import whole_ticks
from quadimpact.simulation.setup import RunSetup, prepare
from quadimpact.simulation.simulate import analyse

__all__ = ["Simulation"]


class _Record:
    """The filled parts of the output arrays (what ``core.run.execute_record`` returns)."""

    def __init__(self, out, episodes, stats, imu) -> None:
        self.out = out
        self.episodes = episodes
        self.stats = stats
        self.imu = imu


class Simulation:
    """One run, advanced one control interval (5 ms) at a time.

    Parameters
    ----------
    scenario : WallApproach or FlightScenario or ImpactTrial
        The validated scenario (prepared once, approach solve included).
    max_episodes : int, optional
        Size of the episode buffer.
    kernel : callable, optional
        A run loop from ``core.run.make_kernel`` (a plug-in controller); default
        the registered controller's.

    Attributes
    ----------
    setup : RunSetup
        The packed inputs of the run.
    """

    def __init__(
        self, scenario: Any, *, max_episodes: int = 1024, kernel: Callable | None = None
    ) -> None:
        self.scenario = scenario
        self.setup: RunSetup = prepare(scenario)
        kernel = kernel or self.setup.kernel
        self._advance = kernel.advance if kernel is not None else core_step.advance
        s = self.setup
        nc = 4 * s.surf.shape[0]
        self._t_out = np.ascontiguousarray(s.output_times(), dtype=np.float64)
        self._x = np.ascontiguousarray(s.x0, dtype=np.float64).copy()
        self._ls = np.zeros(L.NLS)
        self._cs = np.zeros((nc, L.NCS))
        self._rin = np.zeros(L.NRIN)
        self._mem = np.zeros(L.NMEM)
        self._meas = np.zeros(L.NMEAS)
        self._sst = np.zeros(L.NSST)
        self._out = np.zeros((self._t_out.shape[0], L.NOUT))
        self._imu = np.zeros((max(int(s.n_imu), 0), L.NIMU))
        self._episodes = np.zeros((max_episodes, L.NEP))
        self._stats = np.zeros(L.NSTAT)
        self._sched = (
            np.ascontiguousarray(s.sched_t, dtype=np.float64),
            np.ascontiguousarray(s.sched_rate, dtype=np.float64),
            np.ascontiguousarray(s.sched_stop, dtype=np.float64),
        )
        self._noise = np.ascontiguousarray(s.noise, dtype=np.float64)
        core_step.start(
            self._x, float(s.t0), float(s.tf), self._ls, self._cs, self._rin, self._mem,
            self._meas, self._sst, s.veh, s.surf, s.opts, s.scfg, self._noise, self._t_out,
            self._out, self._imu, self._stats,
        )  # fmt: skip

    # ------------------------------------------------------------ stepping
    def advance(self, n_ticks: int = 1, command: Sequence[float] | None = None) -> int:
        """Run ``n_ticks`` control ticks (fewer if the run ends); return the ticks run.

        Parameters
        ----------
        n_ticks : int
            Control ticks to run; ``-1``: to the end.
        command : sequence of 4 floats, optional
            Rotor speed commands (rad/s) to apply at each of these ticks instead
            of the controller's (the loop's generic limits still apply).
        """
        n_ticks = whole_ticks(n_ticks)
        s = self.setup
        args = (
            self._x, self._ls, self._cs, self._rin, self._mem, self._meas, self._sst,
            s.veh, s.surf, s.opts, s.ctrl, s.scfg, *self._sched, self._noise, self._t_out,
            self._out, self._imu, self._episodes, self._stats,
        )  # fmt: skip
        if command is None:
            return int(self._advance(int(n_ticks), *args))
        cmd = np.asarray(command, dtype=np.float64).reshape(4)
        if not np.all(np.isfinite(cmd)):
            raise ValueError("command: four finite rotor speeds (rad/s)")
        ticks = 0
        while not self.done and (n_ticks < 0 or ticks < n_ticks):
            self._ls[L.LS_EXT] = 1.0
            self._ls[L.LS_EXT_CMD : L.LS_EXT_CMD + 4] = cmd
            ticks += int(self._advance(1, *args))
        self._ls[L.LS_EXT] = 0.0
        return ticks

    def run(self) -> SimulationResult:
        """Advance to the end and return the result."""
        self.advance(-1)
        return self.result()

    # ------------------------------------------------------------- reading
    @property
    def done(self) -> bool:
        """Whether the run has ended (final time, crash, or numerical failure)."""
        return bool(self._ls[L.LS_DONE] > 0.5)

    @property
    def time(self) -> float:
        """Simulated time reached, s."""
        return float(self._ls[L.LS_T])

    @property
    def tick(self) -> int:
        """Index of the next control tick (ticks run so far)."""
        return int(self._ls[L.LS_K])

    @property
    def dt(self) -> float:
        """The control period, s."""
        return float(self.setup.opts[L.O_DT_CONTROL])

    @property
    def state(self) -> np.ndarray:
        """A copy of the state (layout ``X_*``: position inertial NED m, velocity body m/s,
        quaternion body -> inertial, body rates rad/s, rotor speeds rad/s)."""
        return self._x.copy()

    @property
    def measurement(self) -> np.ndarray:
        """A copy of the measurement record (layout ``MS_*``) of the last tick."""
        return self._meas.copy()

    @property
    def stage(self) -> int:
        """The controller's stage in force (0 for controllers without stages)."""
        return int(self._ls[L.LS_STAGE])

    @property
    def stats(self) -> np.ndarray:
        """A copy of the run's counters and records (layout ``ST_*``)."""
        return self._stats.copy()

    def result(self) -> SimulationResult:
        """The result so far (the whole run's once :attr:`done`), as ``simulate`` returns it.

        Reads copies: the run can be advanced further afterwards.
        """
        ls = self._ls.copy()
        cs = self._cs.copy()
        episodes = self._episodes.copy()
        stats = self._stats.copy()
        core_step.finish(ls, cs, episodes, stats)
        n_imu = min(int(stats[L.ST_N_IMU]), self._imu.shape[0])
        rec = _Record(
            self._out[: int(stats[L.ST_N_OUT])].copy(),
            episodes[: int(stats[L.ST_N_EPISODES])],
            stats,
            self._imu[:n_imu].copy(),
        )
        return analyse(self.setup, self.scenario, rec)

    def __repr__(self) -> str:
        state = "done" if self.done else "running"
        return f"Simulation(t={self.time:.3f} s, tick={self.tick}, stage={self.stage}, {state})"
