"""The stacked runs behind both environments: N impact trials in the compiled core's arrays.

:class:`Slots` owns the arrays of ``core.batch`` for N runs (row ``k`` is run
``k``), loads a trial into a row (``prepare`` of the trial, then its packed
arrays copied in), resets, steps all rows in one compiled call, and reads an
ended row's metrics with the code the recovery study uses
(``simulation.recovery_metrics.recovery_metrics``, as ``Simulation.result()``
and ``analyse`` do). The single environment is ``Slots(1)``; the batched one
``Slots(N)``: the same computation per row.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from quadimpact.core import batch as B
from quadimpact.core import layout as L
from quadimpact.core.run import RawRecord
from quadimpact.core.step import finish
from quadimpact.envs.settings import TrialDistribution
from quadimpact.inputs.scenarios import ImpactTrial
from quadimpact.results.result import SimulationResult
from quadimpact.simulation.record import episode_columns
from quadimpact.simulation.recovery_metrics import RECOVERY_KEYS, recovery_metrics
from quadimpact.simulation.setup import RunSetup, prepare
from quadimpact.simulation.simulate import analyse

__all__ = ["OUTCOMES", "Slots"]

OUTCOMES = {
    B.OC_RUNNING: "running",
    B.OC_RECOVERED: "recovered",
    B.OC_GROUND: "ground",
    B.OC_TILT: "envelope: tilt",
    B.OC_ALTITUDE: "envelope: altitude",
    B.OC_DISTANCE: "envelope: distance",
    B.OC_RATE: "envelope: rate",
    B.OC_TIME_LIMIT: "time limit",
    B.OC_FAILED: "simulation failed",
}
"""Episode outcomes (``info["outcome"]``)."""


class Slots:
    """N impact trials stacked in the compiled core's arrays.

    Parameters
    ----------
    n : int
        Number of rows (runs stepped together).
    trials : TrialDistribution
        What a row's trial is drawn from (also sizes the arrays).
    par : numpy.ndarray
        The packed environment parameters (``settings.pack_parameters``).
    until_detection : bool
        Detection mode: a reset runs the pre-impact behaviour until the
        detector fires.
    ground, record : bool
        As :meth:`TrialDistribution.trial`.
    max_episodes : int
        Contact-episode buffer per row.
    """

    def __init__(
        self,
        n: int,
        trials: TrialDistribution,
        par: np.ndarray,
        *,
        until_detection: bool,
        ground: bool,
        record: bool,
        max_episodes: int = 256,
    ) -> None:
        self.n = int(n)
        self.trials = trials
        self.par = par
        self.until_detection = until_detection
        self.ground = ground
        self.record = record
        template = self._prepare(self._template_fields())
        n_surf = template.surf.shape[0]
        n_out = template.output_times().shape[0]
        n_imu = int(template.n_imu)
        self.n_noise = max(
            self._prepare({**self._template_fields(), "imu": p}).noise.shape[0]
            for p in trials.imu_choices()
        )
        nc = 4 * n_surf
        self.X = np.zeros((n, L.NX))
        self.LS = np.zeros((n, L.NLS))
        self.CS = np.zeros((n, nc, L.NCS))
        self.RIN = np.zeros((n, L.NRIN))
        self.MEM = np.zeros((n, L.NMEM))
        self.MEAS = np.zeros((n, L.NMEAS))
        self.TMEAS = np.zeros((n, L.NMEAS))
        self.SST = np.zeros((n, L.NSST))
        self.VEH = np.zeros((n, L.NVEH))
        self.SURF = np.zeros((n, n_surf, L.NSURF))
        self.OPTS = np.zeros((n, L.NOPT))
        self.CTRL = np.zeros((n, L.NCTRL))
        self.SCFG = np.zeros((n, L.NSCFG))
        self.NOISE = np.zeros((n, self.n_noise, 6))
        self.T_OUT = np.zeros((n, n_out))
        self.OUT = np.zeros((n, n_out, L.NOUT))
        self.IMU = np.zeros((n, n_imu if record else 0, L.NIMU))
        self.EPISODES = np.zeros((n, max_episodes, L.NEP))
        self.STATS = np.zeros((n, L.NSTAT))
        self.ENV = np.zeros((n, B.NB))
        self.sched = (np.zeros(0), np.zeros((0, 4)), np.zeros(4))
        n_obs = B.N_OBS_STATE if par[B.P_OBSERVE] == B.OBS_STATE else B.N_OBS_IMU
        self.obs = np.zeros((n, n_obs), dtype=np.float32)
        self.reward = np.zeros(n)
        self.terminated = np.zeros(n, dtype=np.bool_)
        self.truncated = np.zeros(n, dtype=np.bool_)
        self.reported = np.full(n, -1.0)
        self.episode_id = np.zeros(n, dtype=np.int64)  # increases at every reset of a row
        self.setups: list[RunSetup | None] = [None] * n
        self.scenarios: list[ImpactTrial | None] = [None] * n
        self.trial_fields: list[dict[str, Any]] = [{} for _ in range(n)]
        self.redraws = np.zeros(n, dtype=np.int64)

    # ------------------------------------------------------------ trials
    def _template_fields(self) -> dict[str, Any]:
        t = self.trials
        first = {
            "vehicle": t.vehicle if isinstance(t.vehicle, str) else t.vehicle[0],
            "model": t.model if isinstance(t.model, str) else t.model[0],
            "imu": t.imu_choices()[0],
        }
        return first

    def _prepare(self, fields: Mapping[str, Any]) -> RunSetup:
        return prepare(self.trials.trial(fields, ground=self.ground, record=self.record))

    def load(self, k: int, trial: ImpactTrial | Mapping[str, Any]) -> None:
        """Put a trial's packed arrays into row ``k`` (not started)."""
        if isinstance(trial, ImpactTrial):
            # the environment's output grid (it changes no computed value, only what is kept)
            scenario = trial
            if not self.record:
                scenario = trial.model_copy(update={"output_rate_hz": 1.0 / trial.final_time_s})
            fields = trial.model_dump(exclude_defaults=True)
        else:
            fields = dict(trial)
            scenario = self.trials.trial(fields, ground=self.ground, record=self.record)
        s = prepare(scenario)
        same_grid = s.output_times().shape[0] == self.T_OUT.shape[1]
        if s.surf.shape != self.SURF.shape[1:] or not same_grid or s.tf != self.trials.final_time_s:
            raise ValueError(
                "trial: its surfaces and final time must be those of the environment's trials "
                f"({self.SURF.shape[1]} surfaces, {self.trials.final_time_s:g} s)"
            )
        if s.noise.shape[0] > self.n_noise:
            raise ValueError("trial: a noisy IMU in an environment made for ideal IMUs")
        if s.kernel is not None or s.controller != "recovery":
            raise ValueError("trial: the environment's trials run the 'recovery' controller")
        self.X[k] = s.x0
        self.VEH[k] = s.veh
        self.SURF[k] = s.surf
        self.OPTS[k] = s.opts
        self.CTRL[k] = s.ctrl
        self.SCFG[k] = s.scfg
        self.NOISE[k] = 0.0
        self.NOISE[k, : s.noise.shape[0]] = s.noise
        self.T_OUT[k] = s.output_times()
        self.setups[k] = s
        self.scenarios[k] = scenario
        self.trial_fields[k] = fields

    def reset(
        self, k: int, rng: np.random.Generator, trial: ImpactTrial | Mapping[str, Any] | None,
        max_redraws: int,
    ) -> None:  # fmt: skip
        """Begin a new episode in row ``k``: the given trial, or one drawn from ``rng``.

        In detection mode a drawn trial whose detector never fires before its
        final time is replaced by a new draw (counted in :attr:`redraws`); a
        given trial that does so raises ``RuntimeError``.
        """
        self.redraws[k] = 0
        while True:
            self.load(k, trial if trial is not None else self.trials.draw(rng))
            s = self.setups[k]
            ok = B.reset_slot(
                k, float(s.t0), float(s.tf), self.until_detection, self.X, self.LS, self.CS,
                self.RIN, self.MEM, self.MEAS, self.TMEAS, self.SST, self.VEH, self.SURF,
                self.OPTS, self.CTRL, self.SCFG, *self.sched, self.NOISE, self.T_OUT, self.OUT,
                self.IMU, self.EPISODES, self.STATS, self.ENV, self.par, self.obs,
            )  # fmt: skip
            if ok:
                break
            if trial is not None:
                raise RuntimeError("trial: the detector never fired before the final time")
            self.redraws[k] += 1
            if self.redraws[k] > max_redraws:
                raise RuntimeError(f"no detection in {max_redraws} drawn trials in a row")
        self.reported[k] = -1.0
        self.episode_id[k] += 1

    # ------------------------------------------------------------ stepping
    def step(self, actions: np.ndarray) -> None:
        """One tick of every active row (compiled); clears the reported stages."""
        B.step_batch(
            actions, self.reported, self.X, self.LS, self.CS, self.RIN, self.MEM, self.MEAS,
            self.TMEAS, self.SST, self.VEH, self.SURF, self.OPTS, self.CTRL, self.SCFG,
            *self.sched, self.NOISE, self.T_OUT, self.OUT, self.IMU, self.EPISODES, self.STATS,
            self.ENV, self.par, self.obs, self.reward, self.terminated, self.truncated,
        )  # fmt: skip
        self.reported[:] = -1.0

    def active(self) -> np.ndarray:
        """Rows whose episode runs (bool, N)."""
        return self.ENV[:, B.B_ACTIVE] > 0.5

    # ------------------------------------------------------------ reading
    def stage(self, k: int) -> int:
        """The stage in force in row ``k`` (policy's or observer's)."""
        return int(self.ENV[k, B.B_STAGE])

    def time(self, k: int) -> float:
        """Simulated time reached in row ``k``, s."""
        return float(self.LS[k, L.LS_T])

    def metrics(self, k: int) -> dict[str, Any]:
        """Row ``k``'s episode metrics: docs/RECOVERY.md 6's keys, outcome, return, steps.

        The recovery keys are computed by ``recovery_metrics`` from the row's
        stats and episodes, as in every summary (``analyse``).
        """
        s = self.setups[k]
        st = self.STATS[k].copy()
        n_ep = int(st[L.ST_N_EPISODES])
        episodes = episode_columns(self.EPISODES[k], n_ep, s.surface_names)
        obstacles = [n for i, n in enumerate(s.surface_names) if s.surf[i, L.S_IS_GROUND] < 0.5]
        # the state at the end: the output row at the final time when the run got there
        # (as analyse reads it), else the state reached
        n_out = int(st[L.ST_N_OUT])
        if n_out == self.T_OUT.shape[1]:
            final = self.OUT[k, n_out - 1, L.OUT_X : L.OUT_X + L.NX].copy()
        else:
            final = self.X[k].copy()
        out = recovery_metrics(
            st, episodes, veh=s.veh, surf=s.surf, surface_names=s.surface_names,
            obstacle_names=obstacles, final_state=final,
        )  # fmt: skip
        out = {key: out[key] for key in RECOVERY_KEYS}
        out["outcome"] = OUTCOMES[int(self.ENV[k, B.B_OUTCOME])]
        out["episode_return"] = float(self.ENV[k, B.B_RETURN])
        out["episode_steps"] = int(self.ENV[k, B.B_STEPS])
        out["t_end_s"] = float(self.LS[k, L.LS_T])
        out["stage_source"] = "policy" if self.ENV[k, B.B_POLICY] > 0.5 else "observer"
        out["inexact_commands"] = int(self.ENV[k, B.B_INEXACT])
        return out

    def result(self, k: int) -> SimulationResult:
        """Row ``k``'s run so far as ``simulate`` returns it (``analyse`` of its record)."""
        s = self.setups[k]
        ls = self.LS[k].copy()
        cs = self.CS[k].copy()
        episodes = self.EPISODES[k].copy()
        stats = self.STATS[k].copy()
        finish(ls, cs, episodes, stats)
        n_imu = min(int(stats[L.ST_N_IMU]), self.IMU.shape[1])
        rec = RawRecord(
            self.OUT[k, : int(stats[L.ST_N_OUT])].copy(),
            episodes[: int(stats[L.ST_N_EPISODES])],
            stats,
            self.IMU[k, :n_imu].copy(),
        )
        return analyse(s, self.scenarios[k], rec)
