"""The benchmark's suite: its tasks, its sensor sets and its version (docs/BENCHMARK.md 1).

Three tasks, each an existing study's trials (reused, not copied):

* ``wall``: the authors' Monte Carlo of wall impacts
  (:class:`~quadimpact.studies.recovery.recovery_spec.RecoveryStudy`, seed 0):
  10,000 trials, 1,000 with ``quick``;
* ``pole``: the authors' pole grid
  (:class:`~quadimpact.studies.pole.pole_study.PoleStudy`): 46 pitches x 71
  offsets, 3,266 points; ``quick`` every 3rd pitch and every 5th offset
  (16 x 15 = 240 points);
* ``edge``: the same grid against the vertical edge of a square pillar
  (:data:`EDGE_PILLAR`: a box 1 m x 1 m in plan, 100 m tall, one vertical
  edge on the pole's axis, its faces at +-45 deg to the approach).

Each task is flown with two sensor sets (:data:`SENSOR_SETS`): ``ideal``
(the ideal IMU, the controller reading the true state) and ``impact`` (the
``impact`` preset of sensors and a state estimator, ``ekf`` unless the thing
benchmarked names another). Every trial is seeded: the wall's by the
Monte Carlo's seed and its index, the grid points' sensors by
:data:`GRID_SEED` and the point's index (:meth:`PoleStudy.point_seeds`).

:data:`SUITE_VERSION` names this definition: any change to a task, a sensor
set, a success criterion or a metric gets a new version, and every output
says which it is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from quadimpact.errors import InputError
from quadimpact.studies.pole.pole_study import SUCCESS_LOSS_M, PoleStudy
from quadimpact.studies.recovery.recovery_spec import RecoveryStudy

__all__ = [
    "DEFAULT_ESTIMATOR",
    "EDGE_PILLAR",
    "GRID_SEED",
    "SENSOR_SETS",
    "SUITE_VERSION",
    "TASKS",
    "WALL_SEED",
    "SensorSet",
    "Task",
    "parse_tasks",
    "sensor_set",
    "task",
]

#: The suite's version: in every output; a new one for any change of what it measures.
SUITE_VERSION = "1"
#: The seed of the wall task's trials (``quadimpact recovery``'s default).
WALL_SEED = 0
#: The seed of the grid tasks' points' own seeds (their sensors' noise).
GRID_SEED = 0
#: The state estimator of the ``impact`` sensor set unless the thing benchmarked names one.
DEFAULT_ESTIMATOR = "ekf"

_HALF_DIAGONAL = math.sqrt(0.5)  # m, centre to vertical edge of a 1 m x 1 m square
#: The edge task's obstacle: a square pillar 1 m x 1 m in plan and 100 m tall (from 50 m
#: below the start's level to 50 m above: taller than any 3-s flight), turned 45 deg about
#: the vertical so that one vertical edge lies on the pole's axis (X = Y = 0) and its two
#: faces there meet the approach (+X) at +-45 deg.
EDGE_PILLAR: dict[str, Any] = {
    "kind": "box",
    "name": "pillar",
    "centre_m": [_HALF_DIAGONAL, 0.0, 0.0],
    "half_extents_m": [0.5, 0.5, 50.0],
    "euler_deg": [0.0, 0.0, 45.0],
}


@dataclass(frozen=True)
class SensorSet:
    """What the vehicle senses with: a preset of sensors and the estimator read.

    Attributes
    ----------
    name : {"ideal", "impact"}
    sensors : str or None
        The preset of sensors (``None``: the ideal IMU).
    estimator : str
        The state estimator (``"ideal"``: the true state).
    """

    name: str
    sensors: str | None
    estimator: str


#: The sensor sets, in the order of every table.
SENSOR_SETS = ("ideal", "impact")


def sensor_set(name: str, estimator: str = DEFAULT_ESTIMATOR) -> SensorSet:
    """The sensor set ``name``; ``estimator``: the ``impact`` set's estimator."""
    if name == "ideal":
        return SensorSet("ideal", None, "ideal")
    if name == "impact":
        return SensorSet("impact", "impact", estimator)
    known = ", ".join(repr(s) for s in SENSOR_SETS)
    raise InputError(f"sensor set: must be one of {known} (got {name!r})")


@dataclass(frozen=True)
class Task:
    """One task of the suite.

    Attributes
    ----------
    name : {"wall", "pole", "edge"}
    kind : {"wall", "grid"}
        The authors' Monte Carlo of wall impacts, or a pitch x offset grid
        against an obstacle (the pole study's).
    title : str
        One line for reports.
    success : str
        Its success criterion, in words.
    """

    name: str
    kind: str
    title: str
    success: str

    def wall_study(self, quick: bool, sensing: SensorSet, model: str = "default") -> RecoveryStudy:
        """The wall task as the recovery study (``quick``: its first 1,000 trials)."""
        return RecoveryStudy(
            n=1_000 if quick else 10_000,
            seed=WALL_SEED,
            model=model,
            estimator=sensing.estimator,
            sensors=sensing.sensors,
        )

    def grid_study(self, quick: bool, sensing: SensorSet, model: str = "default") -> PoleStudy:
        """A grid task as the pole study (``quick``: every 3rd pitch, every 5th offset)."""
        steps = {"pitch_step_deg": 3.0, "offset_step_m": 0.05} if quick else {}
        obstacles = (dict(EDGE_PILLAR),) if self.name == "edge" else None
        return PoleStudy(
            **steps,
            model=model,
            obstacles=obstacles,
            estimator=sensing.estimator,
            sensors=sensing.sensors,
            seed=GRID_SEED,
        )

    def size(self, quick: bool) -> int:
        """Trials (wall) or grid points of the task."""
        if self.kind == "wall":
            return 1_000 if quick else 10_000
        study = self.grid_study(quick, sensor_set("ideal"))
        return len(study.pitches()) * len(study.offsets())


_GRID_SUCCESS = (
    f"less than {SUCCESS_LOSS_M:g} m of height lost over the 3-s run (altitude at the start "
    "minus at the end), the authors' pole criterion"
)
TASKS: dict[str, Task] = {
    "wall": Task(
        "wall",
        "wall",
        "the authors' Monte Carlo of wall impacts (roll +-15 deg, pitch +-45 deg, yaw "
        "+-45 deg, 0.5-2.5 m/s; rotors spun down until the detection)",
        "recovery declared (stage 4) and the altitude never below 0, over the valid trials "
        "(docs/RECOVERY.md 8)",
    ),
    "pole": Task(
        "pole",
        "grid",
        "the authors' pole grid (pitch 0 to -45 deg x offsets +-0.35 m, 2 m/s, a 0.1-m pole)",
        _GRID_SUCCESS,
    ),
    "edge": Task(
        "edge",
        "grid",
        "the pole grid against the vertical edge of a 1 m x 1 m pillar (faces at +-45 deg)",
        _GRID_SUCCESS,
    ),
}
"""The tasks by name, in the order of every table."""


def task(name: str) -> Task:
    """The task ``name`` (one-line error for an unknown one)."""
    if name not in TASKS:
        known = ", ".join(TASKS)
        raise InputError(f"--tasks: unknown task {name!r} (the suite's: {known})")
    return TASKS[name]


def parse_tasks(text: str | None) -> tuple[str, ...]:
    """``"wall,pole"`` as task names in the suite's order (``None``: every task).

    Raises
    ------
    InputError
        An unknown, empty or repeated task name.
    """
    if text is None:
        return tuple(TASKS)
    names = [part.strip() for part in text.split(",")]
    if not all(names):
        raise InputError(f"--tasks: empty task name (got {text!r})")
    twice = sorted({name for name in names if names.count(name) > 1})
    if twice:
        raise InputError(
            f"--tasks: each task at most once; {', '.join(map(repr, twice))} named more than "
            f"once (got {text!r})"
        )
    for name in names:
        task(name)
    return tuple(t for t in TASKS if t in names)
