"""A run advanced from Python one control interval at a time: :class:`Simulation`.

Built on the compiled core's ``step.start`` / ``step.advance``: all the loop
state lives in the run's records (``core/records.py``) owned by the
:class:`Simulation`, and each
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

from collections.abc import Sequence
from typing import Any

import numpy as np

from quadimpact.core import layout as L
from quadimpact.core import step as core_step
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.kernel import BUILTIN, Kernel
from quadimpact.core.named import MEASUREMENT_FIELDS, STATE_FIELDS, NamedVector, block_fields
from quadimpact.core.records import new_data, new_output, raw_record
from quadimpact.results.result import SimulationResult
from quadimpact.simulation.checks import whole_ticks
from quadimpact.simulation.setup import RunSetup, prepare
from quadimpact.simulation.simulate import analyse

__all__ = ["Simulation"]

_STATS_FIELDS = (
    block_fields("stats", "ST_")
    + block_fields("stats.hover", "HV_", at=L.ST_HOVER)
    + block_fields("stats.held", "HH_", at=L.ST_HELD)
    + block_fields("stats.steps", "IS_", at=L.ST_STEPS)
)  # the parts' slots keep their names in stats (t_hover, held_x, n_steps...)


class Simulation:
    """One run, advanced one control interval (5 ms) at a time.

    Parameters
    ----------
    scenario : WallApproach or FlightScenario or ImpactTrial
        The validated scenario (prepared once, approach solve included).
    max_episodes : int, optional
        Size of the episode buffer.
    kernel : Kernel, optional
        A run loop from ``core.kernel.make_kernel`` (plug-ins); default the
        registered controller's. A wall approach's shooting runs fly with it too.

    Attributes
    ----------
    setup : RunSetup
        The packed inputs of the run.
    """

    def __init__(
        self, scenario: Any, *, max_episodes: int = 1024, kernel: Kernel | None = None
    ) -> None:
        self.scenario = scenario
        self.setup: RunSetup = prepare(scenario, kernel)
        self._kernel = self.setup.kernel or BUILTIN
        self._m = self.setup.model()
        self._d = new_data(self._m)
        self._o = new_output(self._m, int(self.setup.n_imu), int(max_episodes))
        self._kernel.start(self._m, self._d, self._o)

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
        advance = self._kernel.advance
        if command is None:
            return int(advance(int(n_ticks), self._m, self._d, self._o))
        n = int(self._m.veh[VS.V_N_ROTORS])
        cmd = np.asarray(command, dtype=np.float64).ravel()
        if cmd.shape != (n,) or not np.all(np.isfinite(cmd)):
            raise ValueError(f"command: {n} finite rotor speeds (rad/s), one per rotor")
        ticks = 0
        ls = self._d.ls
        while not self.done and (n_ticks < 0 or ticks < n_ticks):
            ls[L.LS_EXT] = 1.0
            ls[L.LS_EXT_CMD : L.LS_EXT_CMD + n] = cmd
            ticks += int(advance(1, self._m, self._d, self._o))
        ls[L.LS_EXT] = 0.0
        return ticks

    def run(self) -> SimulationResult:
        """Advance to the end and return the result."""
        self.advance(-1)
        return self.result()

    # ------------------------------------------------------------- reading
    @property
    def done(self) -> bool:
        """Whether the run has ended (final time, crash, or numerical failure)."""
        return bool(self._d.ls[L.LS_DONE] > 0.5)

    @property
    def time(self) -> float:
        """Simulated time reached, s."""
        return float(self._d.ls[L.LS_T])

    @property
    def tick(self) -> int:
        """Index of the next control tick (ticks run so far)."""
        return int(self._d.ls[L.LS_K])

    @property
    def dt(self) -> float:
        """The control period, s."""
        return float(self.setup.opts[L.O_DT_CONTROL])

    @property
    def state(self) -> NamedVector:
        """A read-only copy of the state, by name: ``position`` (inertial NED, m),
        ``velocity_body`` (body FRD, m/s), ``attitude`` (quaternion, scalar first, body ->
        inertial), ``body_rates`` (rad/s), ``rotor_speeds`` (rad/s); as an array, layout
        ``X_*`` (``quadimpact.core.named.STATE_FIELDS``)."""
        return NamedVector(self._d.x, STATE_FIELDS)

    @property
    def measurement(self) -> NamedVector:
        """A read-only copy of the last tick's measurement record, by name (what the
        controller read: the estimate's ``position``, ``attitude``..., ``imu_specific_force``,
        ``detected``, ``wall_normal``...: ``quadimpact.core.named.MEASUREMENT_FIELDS``); as an
        array, layout ``MS_*``."""
        return NamedVector(self._d.meas, MEASUREMENT_FIELDS)

    @property
    def stage(self) -> int:
        """The controller's stage in force (0 for controllers without stages)."""
        return int(self._d.ls[L.LS_STAGE])

    @property
    def stats(self) -> NamedVector:
        """A read-only copy of the run's counters and records, by the names of their slots
        (``t_end``, ``n_steps``, ``crash_t``, ``onset_t``...); as an array, layout ``ST_*``."""
        return NamedVector(self._o.stats, _STATS_FIELDS)

    def result(self) -> SimulationResult:
        """The result so far (the whole run's once :attr:`done`), as ``simulate`` returns it.

        Reads copies: the run can be advanced further afterwards.
        """
        d = self._d._replace(ls=self._d.ls.copy(), cs=self._d.cs.copy())
        o = self._o._replace(episodes=self._o.episodes.copy(), stats=self._o.stats.copy())
        core_step.finish(d, o)
        rec = raw_record(o, copy=True)
        return analyse(self.setup, self.scenario, rec)

    def __repr__(self) -> str:
        state = "done" if self.done else "running"
        return f"Simulation(t={self.time:.3f} s, tick={self.tick}, stage={self.stage}, {state})"
