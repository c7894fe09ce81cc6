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

Each task is flown with the sensor sets of the suite's version
(:data:`SUITES`), each a preset of sensors and a state estimator declared
once in :data:`SENSOR_SET_DEFS` (``ideal``, ``impact``, ``lab``, ``onboard``): a new
sensor set is one entry there and a new version that names it; the tasks do
not change. Every trial is seeded: the wall's by the Monte Carlo's seed and
its index, the grid points' sensors by :data:`GRID_SEED` and the point's
index (:meth:`PoleStudy.point_seeds`). Version 3 adds the ``onboard`` set
(flow, range, barometer and a navigation filter) to version 2.

A :class:`Suite` is one version of the benchmark: its sensor sets, the
sets it can fly by name beyond them, the run length of its trials and its
success criterion. Version 1 counts the authors' published criteria;
version 2 counts a held hover (docs/BENCHMARK.md 1); version 3
(:data:`SUITE_VERSION`, the default) is version 2 with the ``onboard`` set.
Any change to a task, a sensor set, a success criterion or a metric gets a
new version, and every output says which it is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from quadimpact.errors import InputError
from quadimpact.studies.pole import PoleStudy
from quadimpact.studies.recovery.recovery_spec import RecoveryStudy
from quadimpact.studies.trial_analysis import SUCCESS_LOSS_M

__all__ = [
    "DEFAULT_ESTIMATOR",
    "EDGE_PILLAR",
    "GRID_SEED",
    "SENSOR_SETS",
    "SENSOR_SET_DEFS",
    "SUITES",
    "SUITE_VERSION",
    "TASKS",
    "WALL_SEED",
    "SensorSet",
    "Suite",
    "Task",
    "parse_sensor_sets",
    "parse_tasks",
    "sensor_set",
    "suite",
    "task",
]

#: The suite's latest version (the default): in every output; a new one for any change of
#: what it measures.
SUITE_VERSION = "3"
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
    name : str
        The set's name in every output (``"ideal"``, ``"impact"``, ``"lab"``).
    sensors : str or None
        The preset of sensors (docs/ESTIMATION.md; ``None``: the ideal IMU).
    estimator : str
        The state estimator (``"ideal"``: the true state).
    title : str
        What it is, in one line (for reports).
    own_estimator : bool
        The set needs its own estimator (``onboard``: a navigation filter that
        fuses its flow and range): a row keeps it unless the row names another
        than the default ``ekf``.
    plugin : bool
        A plug-in's preset of sensors (registered with
        :func:`~quadimpact.inputs.sensors.register_sensor_preset`): its cells are
        never cached, since the name alone does not say what the sensors are.
    """

    name: str
    sensors: str | None
    estimator: str
    title: str = ""
    own_estimator: bool = False
    plugin: bool = False

    def flown_with(self, estimator: str) -> SensorSet:
        """The set as a row whose estimator is ``estimator`` flies it."""
        if self.sensors is None or (self.own_estimator and estimator == DEFAULT_ESTIMATOR):
            return self
        return SensorSet(
            self.name, self.sensors, estimator, self.title, self.own_estimator, self.plugin
        )


#: Every sensor set a suite can fly, by name: a new one is an entry here (and a suite
#: version that names it).
SENSOR_SET_DEFS: dict[str, SensorSet] = {
    "ideal": SensorSet("ideal", None, "ideal", "the true state (the ideal IMU)"),
    "impact": SensorSet(
        "impact",
        "impact",
        DEFAULT_ESTIMATOR,
        "an IMU alone (noise, its impact disturbance, gyro bias walk) and a state estimator",
    ),
    "lab": SensorSet(
        "lab",
        "indoor",
        DEFAULT_ESTIMATOR,
        "what the authors flew: the IMU with its impact disturbance, a magnetometer and "
        "motion-capture pose at 100 Hz (the `indoor` preset), and a state estimator",
    ),
    "onboard": SensorSet(
        "onboard",
        "onboard",
        "nav-ekf",
        "what a small drone carries to hover without motion capture: the IMU with its "
        "impact disturbance, a magnetometer, a barometer, a lidar rangefinder and a downward "
        "optical-flow camera (the `onboard` preset), fused by the `nav-ekf` navigation filter",
        own_estimator=True,
    ),
}

#: The sensor sets of suite 1, in the order of its tables.
SENSOR_SETS = ("ideal", "impact")


def plugin_sensor_sets() -> tuple[str, ...]:
    """The presets of sensors plug-ins registered: each is a sensor set of its own name."""
    from quadimpact.inputs.sensors import BUILTIN_SENSOR_PRESETS, sensor_preset_names

    return tuple(
        n
        for n in sensor_preset_names()
        if n not in BUILTIN_SENSOR_PRESETS and n not in SENSOR_SET_DEFS
    )


def sensor_set(name: str, estimator: str = DEFAULT_ESTIMATOR) -> SensorSet:
    """The sensor set ``name`` flown with ``estimator`` (:meth:`SensorSet.flown_with`).

    ``name`` is a built-in set (:data:`SENSOR_SET_DEFS`) or a preset of sensors a
    plug-in registered (flown with ``estimator``, the row's: ``ekf`` by default).
    """
    if name in SENSOR_SET_DEFS:
        return SENSOR_SET_DEFS[name].flown_with(estimator)
    if name in plugin_sensor_sets():
        title = f"the plug-in preset of sensors `{name}`, and a state estimator"
        return SensorSet(name, name, DEFAULT_ESTIMATOR, title, plugin=True).flown_with(estimator)
    known = ", ".join(repr(s) for s in (*SENSOR_SET_DEFS, *plugin_sensor_sets()))
    raise InputError(f"--sensors: unknown sensor set {name!r} (one of {known})")


@dataclass(frozen=True)
class Suite:
    """One version of the benchmark (docs/BENCHMARK.md 1).

    Attributes
    ----------
    version : str
        Its name in every output (``"1"``, ``"2"``, ``"3"``).
    sensor_sets : tuple of str
        The sensor sets of its leaderboard, in table order.
    extra_sensor_sets : tuple of str
        Sets it flies only when named (``--sensors``), with the reason in ``extra_note``.
    final_time_s : float or None
        The run length of every trial, s (None: the studies' own, 3 s).
    criterion : {"published", "held-hover"}
        Success: each task's published criterion (version 1), or a held hover
        reached with less than 2 m of height lost, the ground and the obstacle
        untouched once it began (version 2).
    extra_note : str
        Why the extra sets are off the leaderboard.
    """

    version: str
    sensor_sets: tuple[str, ...]
    extra_sensor_sets: tuple[str, ...]
    final_time_s: float | None
    criterion: str
    extra_note: str = ""

    @property
    def held_hover(self) -> bool:
        """Whether success is the held hover (version 2 on)."""
        return self.criterion == "held-hover"


#: The run length of suite 2's trials, s: the shortest whole second in which the ideal-sensor
#: default law's held hover (0.5 s held) is complete in at least 95 % of the wall trials (96.1 %
#: of the quick wall; 89.6 % at 3 s, 97.5 % at 5 s) and in every pole and edge point where it
#: is reached at all (the latest end at 3.6 s); docs/BENCHMARK.md 1.3.
RUN_LENGTH_S = 4.0

SUITES: dict[str, Suite] = {
    "1": Suite("1", ("ideal", "impact"), (), None, "published"),
    "2": Suite(
        "2",
        ("ideal", "lab"),
        ("impact",),
        RUN_LENGTH_S,
        "held-hover",
        "the `impact` set (an IMU alone) measures no velocity or position, so no law reaches "
        "a held hover with it (1-2 % of trials in suite 1): it is off the leaderboard, and "
        "flies only when named (`--sensors ideal,lab,impact`)",
    ),
    "3": Suite(
        "3",
        ("ideal", "lab", "onboard"),
        ("impact",),
        RUN_LENGTH_S,
        "held-hover",
        "the `impact` set (an IMU alone) measures no velocity or position, so no law reaches "
        "a held hover with it (1-2 % of trials in suite 1): it is off the leaderboard, and "
        "flies only when named (`--sensors ideal,lab,onboard,impact`)",
    ),
}
"""The benchmark's versions by name."""


def suite(version: str) -> Suite:
    """The suite ``version`` (one-line error for an unknown one)."""
    if str(version) not in SUITES:
        known = ", ".join(SUITES)
        raise InputError(f"--suite: unknown suite version {version!r} (one of {known})")
    return SUITES[str(version)]


def parse_sensor_sets(text: str | None, version: str = SUITE_VERSION) -> tuple[str, ...]:
    """``"ideal,lab"`` as sensor-set names of the suite ``version`` (``None``: its own).

    Raises
    ------
    InputError
        An unknown, repeated or empty name, or one the suite cannot fly.
    """
    s = suite(version)
    if text is None:
        return s.sensor_sets
    names = [part.strip() for part in text.split(",")]
    if not all(names):
        raise InputError(f"--sensors: empty sensor set name (got {text!r})")
    # a plug-in's preset flies in any suite that judges by the held hover (2 and later)
    plugins = plugin_sensor_sets() if s.held_hover else ()
    allowed = (*s.sensor_sets, *s.extra_sensor_sets, *plugins)
    for name in names:
        sensor_set(name)
        if name not in allowed:
            raise InputError(f"--sensors: suite {s.version} flies {', '.join(allowed)} "
                             f"(got {name!r})")  # fmt: skip
    if len(set(names)) != len(names):
        raise InputError(f"--sensors: a sensor set named twice (got {text!r})")
    return tuple(n for n in allowed if n in names)


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


HELD_HOVER_SUCCESS = (
    "a held hover reached before the run ends (the true CM speed below 0.2 m/s, the tilt below "
    "5 deg, the body rate below 20 deg/s and no contact, for 0.5 s, tested from the first "
    "contact with the obstacle on), with less than 2 m of height lost (the altitude at the "
    "start minus the lowest of the run), the ground never touched and no contact once the "
    "hover began, over the valid trials"
)
"""Suite 2's success criterion, the same for every task (docs/BENCHMARK.md 1.2)."""


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
