"""Flying training trials with candidate policies, and the reward: the benchmark's success.

A trial is prepared once (:func:`prepare_trial`: validated and packed as any
run is) and then flown with each candidate by writing the candidate's block
into a copy of the run's controller vector (``ctrl[C_POLICY:]``: exactly what
``--policy FILE`` packs) and running the compiled loop (:class:`Flyer`). That
is the computation of ``quadimpact benchmark --policy FILE`` on that trial.

The reward of a trial (:func:`rewards`) is the benchmark's success in its
latest suite (``held_hover_success`` of ``studies/benchmark/cells.py``, the
same function on the same columns): a held hover reached (true speed below
0.2 m/s, tilt below 5 deg, rates below 20 deg/s, no contact, for 0.5 s), less
than 2 m of height lost (the start altitude minus the lowest), the ground
never touched and no contact once the hover began. To it is added a small
term of height kept, ``shaping * exp(-lost / 1 m)`` (lost >= 0), which ranks
the failures. With a drift weight ``w > 0`` a success scores
``1 - w min(drift / 0.1 m, 1)`` instead of 1: ``drift`` is the true
horizontal distance of the CM from the hover point (where the held hover
began) at its farthest, from then to the run's end (:func:`hover_drift_m`).
A trial that is not valid for the benchmark (started in contact, a bumper
beyond its model) or cannot be prepared scores 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["DRIFT_SCALE_M", "Flyer", "PreparedTrial", "hover_drift_m", "prepare_trial", "rewards"]

#: The drift at which a success's drift penalty is whole, m (``rewards``).
DRIFT_SCALE_M = 0.1


@dataclass
class PreparedTrial:
    """One prepared trial: its task, the validated scenario and the packed run."""

    task: str
    scenario: Any
    setup: Any
    altitude_m: float


def prepare_trial(task: str, data: dict[str, Any]) -> PreparedTrial | None:
    """Validate and prepare one scenario mapping (None: it cannot run, e.g. in contact)."""
    from quadimpact.errors import InputError
    from quadimpact.inputs.scenarios import scenario_from_dict
    from quadimpact.simulation.setup import prepare

    scenario = scenario_from_dict(data, where=f"train: {task}")  # a bad problem: an error
    try:
        setup = prepare(scenario)
    except (InputError, ValueError):
        return None  # a trial the benchmark counts invalid (started in contact)
    return PreparedTrial(task, scenario, setup, float(scenario.altitude_m))


class Flyer:
    """Flies prepared trials with a policy block (or none), keeping the output buffers.

    ``drift=True``: the loop also writes its output rows (time and state, no
    contact columns), and each summary gains ``hover_drift_m``
    (:func:`hover_drift_m`; None without a held hover).
    """

    def __init__(self, drift: bool = False) -> None:
        from quadimpact.simulation.batch import _Buffers

        self.buffers = _Buffers(1024)
        self.drift = bool(drift)
        self._rows: Any = None

    def fly(self, trial: PreparedTrial, block: np.ndarray | None) -> dict[str, Any]:
        """The trial's summary flown with ``block`` at ``ctrl[C_POLICY:]`` (None: the law)."""
        import time

        from quadimpact.core import controller_slots as CTL
        from quadimpact.core.kernel import BUILTIN
        from quadimpact.core.records import raw_record
        from quadimpact.simulation.simulate import analyse

        setup = trial.setup
        ctrl = setup.ctrl.copy()
        ctrl[CTL.C_POLICY : CTL.C_POLICY + CTL.NPOLICY] = 0.0
        if block is not None:
            ctrl[CTL.C_POLICY : CTL.C_POLICY + block.size] = block
        m = setup.model(ctrl=ctrl)
        n_imu = int(setup.n_imu)
        o = self._output_rows(m, n_imu) if self.drift else self.buffers.output(m, n_imu)
        start = time.perf_counter()
        (setup.kernel or BUILTIN).run(m, o)
        wall = time.perf_counter() - start
        raw = raw_record(o)
        summary = analyse(setup, trial.scenario, raw, wall).summary
        if self.drift:
            summary = {**summary, "hover_drift_m": hover_drift_m(raw.out, raw.stats)}
        return summary

    def _output_rows(self, m: Any, n_imu: int) -> Any:
        """Outputs with a row per output time (no contact columns), reused while they fit."""
        from quadimpact.core.records import new_output

        o = self._rows
        n_out = int(m.t_out.shape[0])
        if o is None or o.out.shape[0] != n_out or o.imu.shape[0] < n_imu:
            o = self._rows = new_output(m, n_imu, self.buffers.max_episodes,
                                        contact_columns=False)  # fmt: skip
        return o._replace(imu=o.imu[:n_imu])


def hover_drift_m(out: np.ndarray, stats: np.ndarray) -> float | None:
    """The held hover's drift: the CM's largest horizontal distance from the hover point.

    Parameters
    ----------
    out : ndarray, shape (rows, >= NOUT)
        The run's output rows (``OUT_T`` time, s; ``OUT_X`` state, inertial position first).
    stats : ndarray
        The run's stats: at ``ST_HELD``, ``HH_T_HELD`` (s, when the held hover
        began) and ``HH_HELD_X`` (m, the CM there, inertial).

    Returns
    -------
    float or None
        m, over the rows from the hover's start to the run's end; None without
        a held hover.
    """
    from quadimpact.core import layout as L
    from quadimpact.core.hover_slots import HH_HELD_X, HH_T_HELD
    from quadimpact.core.recording_slots import OUT_T, OUT_X

    t_held = float(stats[L.ST_HELD + HH_T_HELD])
    if not math.isfinite(t_held):
        return None
    after = out[out[:, OUT_T] >= t_held]
    if after.shape[0] == 0:
        return 0.0
    held = L.ST_HELD + HH_HELD_X
    dx = after[:, OUT_X + L.X_POS] - stats[held]
    dy = after[:, OUT_X + L.X_POS + 1] - stats[held + 1]
    return float(np.sqrt(dx * dx + dy * dy).max())


_COLUMNS = ("status", "reason", "bumper_model_valid", "held_hover", "touched_after_hover",
            "min_altitude_m", "crash_time_s")  # fmt: skip


def rewards(
    summaries: list[dict[str, Any] | None],
    altitudes_m: list[float],
    shaping: float,
    drift_weight: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Each trial's reward and success (module docstring); ``None``: a trial not prepared.

    ``drift_weight > 0`` needs ``hover_drift_m`` in the successes' summaries
    (``Flyer(drift=True)``).

    Returns
    -------
    reward, success : numpy.ndarray
        Floats in [0, 1 + shaping] and booleans, one per trial.
    """
    import pandas as pd

    from quadimpact import libm
    from quadimpact.studies.benchmark.cells import held_hover_success
    from quadimpact.studies.trial_analysis import model_valid

    n = len(summaries)
    rows = [{c: (s or {}).get(c) for c in _COLUMNS} for s in summaries]
    t = pd.DataFrame(rows, columns=list(_COLUMNS))
    t["status"] = [
        "failed" if s is None else r["status"] for s, r in zip(summaries, rows, strict=True)
    ]
    lowest = pd.to_numeric(t["min_altitude_m"], errors="coerce").to_numpy(dtype=float)
    t["height_lost_m"] = np.asarray(altitudes_m, dtype=float) - lowest
    prepared = np.array([s is not None for s in summaries], dtype=bool)
    t["valid"] = model_valid(t) & prepared
    success = held_hover_success(t) if n else np.zeros(0, dtype=bool)
    lost = t["height_lost_m"].to_numpy(dtype=float)
    kept = np.where(np.isfinite(lost), libm.exp(-np.maximum(lost, 0.0)), 0.0)  # same on any CPU
    score = success.astype(float)
    if drift_weight > 0.0:
        drift = np.array([finite((s or {}).get("hover_drift_m")) for s in summaries])
        if np.isnan(drift[success]).any():
            raise ValueError("rewards: a success without its hover_drift_m (Flyer(drift=True))")
        penalty = drift_weight * np.minimum(np.nan_to_num(drift, nan=0.0) / DRIFT_SCALE_M, 1.0)
        score = np.where(success, 1.0 - penalty, 0.0)
    reward = np.where(t["valid"].to_numpy(dtype=bool), score + shaping * kept, 0.0)
    return reward.astype(float), success.astype(bool)


def finite(value: Any) -> float:
    """``value`` as a finite float, else NaN."""
    try:
        out = float(value)
    except (TypeError, ValueError):
        return math.nan
    return out if math.isfinite(out) else math.nan
