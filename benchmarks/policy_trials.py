"""Trials for training and judging a learned recovery policy (train_policy.py, eval_policy.py).

A trial is a seeded impact scenario of a benchmark task (wall or pole; the
edge with ``eval_policy.py --edge``) with the ``impact`` sensors and the EKF
unless told otherwise. It is prepared once (:func:`prepare_trial`) and then
flown with any policy by writing the policy's block into a copy of the run's
controller vector (``ctrl[C_POLICY:]``, exactly what ``--policy`` packs) and
running the compiled loop: the same computation as ``quadimpact recovery
--policy`` and ``quadimpact pole --policy`` on that trial.

Trial sets (never the benchmark's for training):

* ``train_wall``: the authors' Monte Carlo distribution, seed 4747;
* ``train_pole``: the pole grid's held-out points (half-degree pitches, odd
  half-centimetre offsets: none on the benchmark's grid), sensors seeded 4748;
* ``bench_wall``: the benchmark's wall task (seed 0), ``bench_pole`` and
  ``bench_edge``: its grids (sensors seeded 0), the held-out judgement.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

# the trainer's own flyer (same trial, policy block and summary as quadimpact train),
# re-exported for train_policy.py and eval_policy.py (PT.Flyer)
from quadimpact.studies.training.flying import Flyer as Flyer

TRAIN_WALL_SEED = 4747
TRAIN_POLE_SEED = 4748


@dataclass
class Trial:
    """One prepared trial: its task, index and the prepared run."""

    task: str  # wall | pole | edge
    index: int
    scenario: Any
    setup: Any
    altitude_m: float


def _sensing(sensors: str, estimator: str = "ekf"):
    from quadimpact.studies.benchmark.suite import sensor_set

    return sensor_set(sensors, estimator)


def wall_dicts(n: int, seed: int, sensors: str = "impact", vehicle: str | None = None,
               mass_kg: float | None = None) -> list[dict[str, Any]]:  # fmt: skip
    """Scenario mappings of ``n`` wall trials of the authors' distribution with ``seed``
    (``vehicle``: another vehicle file; ``mass_kg``: the vehicle's mass overridden)."""
    from quadimpact.studies.benchmark.suite import TASKS
    from quadimpact.studies.recovery.recovery_spec import DISTRIBUTION
    from quadimpact.sweep import SweepSpec

    base = TASKS["wall"].wall_study(False, _sensing(sensors)).base()
    if vehicle is not None:
        base["vehicle"] = vehicle
    if mass_kg is not None:
        base["vehicle_overrides"] = {**base.get("vehicle_overrides", {}), "mass_kg": mass_kg}
    ranges = {k: list(v) for k, v in DISTRIBUTION.items()}
    trials = {"n": n, "seed": seed, "ranges": ranges, "seed_field": "seed"}
    spec = SweepSpec(base=base, trials=trials, where="wall")
    return [spec.scenario_dict(i) for i in range(n)]


def grid_points(task: str, held_out: bool) -> list[tuple[float, float]]:
    """The grid's (pitch deg, lateral offset m) points: the benchmark's, or held-out ones."""
    from quadimpact.studies.benchmark.suite import TASKS

    if not held_out:
        study = TASKS[task].grid_study(False, _sensing("ideal"))
        return [(float(p), float(o)) for p in study.pitches() for o in study.offsets()]
    pitches = [-(0.5 + k) for k in range(45)]
    offsets = [round(-0.345 + 0.01 * k, 6) for k in range(70)]
    return [(p, o) for p in pitches for o in offsets]


def grid_dicts(task: str, held_out: bool, seed: int, sensors: str = "impact") -> list[dict]:
    """Scenario mappings of the recovery arm at every point of a grid task."""
    from quadimpact.inputs.toml_files import apply_overrides
    from quadimpact.studies.benchmark.suite import TASKS
    from quadimpact.sweep.trials import trial_draws

    study = TASKS[task].grid_study(False, _sensing(sensors))
    arm = study.arms()[1]
    out = []
    for i, (p, o) in enumerate(grid_points(task, held_out)):
        run = {"pitch_deg": p, "lateral_offset_m": o, **arm}
        if sensors != "ideal":
            run["seed"] = trial_draws(seed, i, {}, "seed")["seed"]
        out.append(apply_overrides(study.base(), run, ()))
    return out


def prepare_trial(task: str, index: int, data: dict[str, Any]) -> Trial | None:
    """Validate and prepare one scenario mapping (None: it cannot run, e.g. in contact)."""
    from quadimpact.inputs.scenarios import scenario_from_dict
    from quadimpact.simulation.setup import prepare

    try:
        scenario = scenario_from_dict(data, where=f"{task} {index}")
        setup = prepare(scenario)
    except Exception:  # noqa: BLE001 - such a trial is counted invalid by the caller
        return None
    return Trial(task, index, scenario, setup, float(data.get("altitude_m", 2.0)))


def outcome(trial: Trial, s: dict[str, Any]) -> tuple[bool, bool, float]:
    """(valid, success, height lost m) of a flown trial, as the studies count them.

    Wall: the recovery study's classes (valid: not failed, not started in
    contact, the bumper model not exceeded; success: recovered, detected, no
    false detection, never below altitude 0). Grids: the pole study's (less
    than 2 m lost, not failed; every point valid).
    """
    failed = s.get("status") == "failed"
    lost = float(trial.altitude_m) - _num(s.get("final_altitude_m"))
    if trial.task != "wall":
        return True, bool(not failed and math.isfinite(lost) and lost < 2.0), lost
    valid = not failed and s.get("bumper_model_valid") is not False
    ok = (
        valid
        and bool(s.get("recovered"))
        and bool(s.get("detected"))
        and not bool(s.get("false_detection"))
        and not bool(s.get("not_detected"))
        and not _num(s.get("min_altitude_m")) < 0.0
    )
    return valid, bool(ok), _num(s.get("height_loss_m"), lost)


def _num(v: Any, default: float = math.nan) -> float:
    try:
        out = float(v)
    except (TypeError, ValueError):
        return default
    return out if math.isfinite(out) else default
