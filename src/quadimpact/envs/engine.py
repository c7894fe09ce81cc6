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

from quadimpact.core import announce_compilation
from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.envs import stacked as B
from quadimpact.core.envs.episode_layout import ENV_ROTORS
from quadimpact.core.recording_slots import OUT_X
from quadimpact.core.records import Data, Output, new_data, new_output, raw_record, set_row, stacked
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.core.step import finish
from quadimpact.envs.settings import TrialDistribution
from quadimpact.errors import InputError
from quadimpact.inputs.scenarios import ImpactTrial
from quadimpact.results.result import SimulationResult
from quadimpact.simulation.recovery_metrics import RECOVERY_KEYS, recovery_metrics
from quadimpact.simulation.setup import RunSetup, prepare
from quadimpact.simulation.simulate import analyse
from quadimpact.simulation.tables import episode_columns

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


def _quadrotor(setup: RunSetup) -> RunSetup:
    """The prepared run, refused unless its vehicle is a quadrotor (the environments'
    actions and observations have four rotors: ``core.envs.episode_layout.ENV_ROTORS``)."""
    n = int(setup.veh[VS.V_N_ROTORS])
    if n != ENV_ROTORS:
        raise InputError(
            f"vehicle: the learning environments fly quadrotors ({ENV_ROTORS} rotors); "
            f"{setup.vehicle.name} has {n}"
        )
    return setup


class Slots:
    """N impact trials stacked in the compiled core's arrays.

    Parameters
    ----------
    n : int
        Number of rows (runs stepped together).
    trials : TrialDistribution
        What a row's trial is drawn from (also sizes the arrays).
    par : numpy.ndarray
        The packed environment parameters (``packing.episode_block.pack_episode``).
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
        announce_compilation("environments")  # a first use compiles their loop
        self.n = int(n)
        self.trials = trials
        self.until_detection = until_detection
        self.ground = ground
        self.record = record
        template = self._prepare(self._template_fields())
        fields = self._template_fields()
        setups = [self._prepare({**fields, "imu": p}) for p in trials.imu_choices()]
        self.n_noise = max(x.noise.shape[0] for x in setups)
        self.n_snoise = max(x.snoise.shape[0] for x in [template, *setups])
        self.n_cnoise = max(x.cnoise.shape[0] for x in [template, *setups])
        m = template.model(
            noise=np.zeros((self.n_noise, 6)),
            snoise=np.zeros((self.n_snoise, IMS.NSN)),
            cnoise=np.zeros((self.n_cnoise, template.cnoise.shape[1])),
        )
        self.M = stacked(m, n)
        self.D = stacked(new_data(m), n)
        self.O = stacked(new_output(m, int(template.n_imu) if record else 0, max_episodes), n)
        n_obs = B.n_observations(int(par[B.EP_OBSERVE]))
        obs_dtype = np.float64 if par[B.EP_OBSERVE] == B.OBS_ESTIMATE else np.float32
        self.E = B.Env(
            state=np.zeros((n, B.NB)),
            par=par,
            tmeas=np.zeros((n, self.D.meas.shape[1])),  # NMEAS and the components' tail
            reported=np.full(n, -1.0),
            obs=np.zeros((n, n_obs), dtype=obs_dtype),
            reward=np.zeros(n),
            terminated=np.zeros(n, dtype=np.bool_),
            truncated=np.zeros(n, dtype=np.bool_),
        )
        self.episode_id = np.zeros(n, dtype=np.int64)  # increases at every reset of a row
        self.setups: list[RunSetup | None] = [None] * n
        self.scenarios: list[ImpactTrial | None] = [None] * n
        self.trial_fields: list[dict[str, Any]] = [{} for _ in range(n)]
        self.redraws = np.zeros(n, dtype=np.int64)

    # ------------------------------------------------------------ views
    @property
    def obs(self) -> np.ndarray:
        """The observations (N, n_obs), float32 (float64 in the ``estimate`` mode)."""
        return self.E.obs

    @property
    def reported(self) -> np.ndarray:
        """The stages the policy reports for the next step (N,; < 0: none)."""
        return self.E.reported

    @property
    def TMEAS(self) -> np.ndarray:  # noqa: N802 - the core's name for the stacked records
        """The measurement record of each row's next tick (N, NMEAS)."""
        return self.E.tmeas

    @property
    def ENV(self) -> np.ndarray:  # noqa: N802
        """Each row's episode state (N, NB), layout ``core.envs.episode_layout.B_*``."""
        return self.E.state

    @property
    def reward(self) -> np.ndarray:
        """The rewards of the last step (N,)."""
        return self.E.reward

    @property
    def terminated(self) -> np.ndarray:
        """Which rows' episodes ended in the last step by a termination (N,)."""
        return self.E.terminated

    @property
    def truncated(self) -> np.ndarray:
        """Which rows' episodes were cut in the last step (time limit, failure) (N,)."""
        return self.E.truncated

    @property
    def par(self) -> np.ndarray:
        """The packed environment parameters (``core.envs.episode_layout.EP_*``)."""
        return self.E.par

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
        return _quadrotor(
            prepare(self.trials.trial(fields, ground=self.ground, record=self.record))
        )

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
        s = _quadrotor(prepare(scenario))
        m = s.model()
        same_grid = m.t_out.shape[0] == self.M.t_out.shape[1]
        if (m.shapes.shape != self.M.shapes.shape[1:] or m.feat.shape != self.M.feat.shape[1:]
                or not same_grid or s.tf != self.trials.final_time_s):  # fmt: skip
            raise ValueError(
                "trial: its vehicle's features, its surfaces and its final time must be those "
                f"of the environment's trials ({self.M.shapes.shape[1]} surfaces, "
                f"{self.trials.final_time_s:g} s)"
            )
        if (
            s.noise.shape[0] > self.n_noise
            or s.snoise.shape[0] > self.n_snoise
            or s.cnoise.shape[0] > self.n_cnoise
        ):
            raise ValueError("trial: a noisy sensor in an environment made for ideal ones")
        if s.kernel is not None or s.controller != "recovery":
            raise ValueError("trial: the environment's trials run the 'recovery' controller")
        noise = np.zeros((self.n_noise, 6))
        noise[: s.noise.shape[0]] = s.noise
        snoise = np.zeros((self.n_snoise, IMS.NSN))
        snoise[: s.snoise.shape[0]] = s.snoise
        cnoise = np.zeros((self.n_cnoise, m.cnoise.shape[1]))
        cnoise[: s.cnoise.shape[0]] = s.cnoise
        set_row(self.M, k, m._replace(noise=noise, snoise=snoise, cnoise=cnoise))
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
            ok = B.reset_slot(k, self.until_detection, self.M, self.D, self.O, self.E)
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
        B.step_batch(actions, self.M, self.D, self.O, self.E)
        self.reported[:] = -1.0

    def active(self) -> np.ndarray:
        """Rows whose episode runs (bool, N)."""
        return self.E.state[:, B.B_ACTIVE] > 0.5

    # ------------------------------------------------------------ reading
    def stage(self, k: int) -> int:
        """The stage in force in row ``k`` (policy's or observer's)."""
        return int(self.E.state[k, B.B_STAGE])

    def time(self, k: int) -> float:
        """Simulated time reached in row ``k``, s."""
        return float(self.D.ls[k, L.LS_T])

    def metrics(self, k: int) -> dict[str, Any]:
        """Row ``k``'s episode metrics: docs/RECOVERY.md 6's keys, outcome, return, steps.

        The recovery keys are computed by ``recovery_metrics`` from the row's
        stats and episodes, as in every summary (``analyse``).
        """
        s = self.setups[k]
        st = self.O.stats[k].copy()
        n_ep = int(st[L.ST_N_EPISODES])
        episodes = episode_columns(self.O.episodes[k], n_ep, s.shape_names, len(s.feature_names))
        obstacles = [n for i, n in enumerate(s.shape_names) if s.shapes[i, SHP.SH_IS_GROUND] < 0.5]
        # the state at the end: the output row at the final time when the run got there
        # (as analyse reads it), else the state reached
        n_out = int(st[L.ST_N_OUT])
        if n_out == self.M.t_out.shape[1]:
            final = self.O.out[k, n_out - 1, OUT_X : OUT_X + L.NX].copy()
        else:
            final = self.D.x[k].copy()
        out = recovery_metrics(
            st, episodes, feat=s.feat, shapes=s.shapes, surface_names=s.shape_names,
            obstacle_names=obstacles, final_state=final,
        )  # fmt: skip
        out = {key: out[key] for key in RECOVERY_KEYS}
        out["outcome"] = OUTCOMES[int(self.E.state[k, B.B_OUTCOME])]
        out["episode_return"] = float(self.E.state[k, B.B_RETURN])
        out["episode_steps"] = int(self.E.state[k, B.B_STEPS])
        out["t_end_s"] = float(self.D.ls[k, L.LS_T])
        out["stage_source"] = "policy" if self.E.state[k, B.B_POLICY] > 0.5 else "observer"
        out["inexact_commands"] = int(self.E.state[k, B.B_INEXACT])
        return out

    def result(self, k: int) -> SimulationResult:
        """Row ``k``'s run so far as ``simulate`` returns it (``analyse`` of its record)."""
        s = self.setups[k]
        d = Data(*(a[k].copy() for a in self.D))
        o = Output(*(a[k].copy() for a in self.O))
        finish(d, o)
        rec = raw_record(o)
        return analyse(s, self.scenarios[k], rec)
