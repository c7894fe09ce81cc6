"""The trials a policy is trained on: the benchmark's tasks, drawn from streams of their own.

A :class:`Problem` names what is trained for: a vehicle, the tasks (``wall``,
``pole``, ``edge``: the benchmark's, docs/BENCHMARK.md 1), one or more sensor
sets (``onboard`` by default; ``"onboard,ideal"`` flies every trial with each)
and a seed. Its trials are the benchmark's trials in
every setting (the scenario of the task and sensor set in the benchmark's
latest suite: 4-s runs, the ground a contact surface that ends the run, the
sensor set's sensors and estimator), flown by the recovery law, with other
draws:

* ``wall``: the authors' distribution (roll, pitch, yaw, speed) and the run's
  own sensor seed;
* ``pole``, ``edge``: a point drawn uniformly over the grid's box (pitch 0 to
  -45 deg, offset -0.35 to 0.35 m) and the run's sensor seed.

**Never the benchmark's trials.** Trial ``i`` of task ``k`` for purpose ``j``
(0 training, 1 the check set, 2 the screened pool) draws from its own stream, NumPy's PCG64 seeded
with ``SeedSequence(seed, spawn_key=(k, j, i))``. The benchmark's trials draw
from ``SeedSequence(0, spawn_key=(i,))`` (the wall, :data:`WALL_SEED`) and
its grid points' sensors from the same (:data:`GRID_SEED`); its grid points
lie on a 1-deg x 1-cm lattice. So:

1. the seed must differ from the benchmark's seeds (:func:`check_seed`: 0 is
   refused), and whatever it is, a three-part spawn key is another stream
   than a one-part one: no training draw repeats a benchmark draw;
2. a grid point within 1e-6 of the benchmark's lattice (which a continuous
   draw reaches with probability about 1e-12) is moved by half a degree of
   pitch (:func:`held_out_point`), so no training point is a benchmark point;
3. the training, check and screened trials (``--contested``) differ in their
   purpose key.

``tests/studies/test_training.py`` checks these against the benchmark's own
trials (the 10,000 wall trials and the full grids).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from quadimpact.errors import InputError

__all__ = [
    "PURPOSE_CHECK",
    "PURPOSE_SCREEN",
    "PURPOSE_TRAIN",
    "Problem",
    "check_seed",
    "held_out_point",
    "trial_stream",
]

#: The purpose key of the training trials and of the check set's.
PURPOSE_TRAIN = 0
PURPOSE_CHECK = 1
#: The purpose key of the screened pool (``--contested``), whose separating trials are trained on.
PURPOSE_SCREEN = 2
#: The grid's box (the benchmark's full grid: pitch 0 to -45 deg, offsets +-0.35 m).
_PITCH_RANGE_DEG = (-45.0, 0.0)
_OFFSET_RANGE_M = (-0.35, 0.35)
#: The benchmark grid's lattice: whole degrees of pitch, whole centimetres of offset.
_LATTICE_TOL = 1e-6


def check_seed(seed: int) -> int:
    """``seed`` checked: an integer >= 1, not one of the benchmark's seeds (0)."""
    from quadimpact.studies.benchmark.suite import GRID_SEED, WALL_SEED

    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError(f"--seed: must be an integer >= 1 (got {seed!r})")
    if seed in (WALL_SEED, GRID_SEED):
        raise InputError(
            f"--seed: {seed} is the benchmark's own seed; training trials must come from "
            "another (any integer >= 1)"
        )
    return seed


def trial_stream(seed: int, task_key: int, purpose: int, index: int) -> np.random.Generator:
    """The random stream of one training or check trial (module docstring)."""
    seq = np.random.SeedSequence(seed, spawn_key=(task_key, purpose, index))
    return np.random.Generator(np.random.PCG64(seq))


def held_out_point(pitch_deg: float, offset_m: float) -> tuple[float, float]:
    """A drawn grid point, moved off the benchmark's lattice (whole degrees, whole cm) if on it.

    A point within 1e-6 of a lattice point in both coordinates gets 0.5 deg more
    pitch toward level (or less, at the level end), which no lattice point has.
    """
    on_pitch = abs(pitch_deg - round(pitch_deg)) < _LATTICE_TOL
    on_offset = abs(offset_m * 100.0 - round(offset_m * 100.0)) < _LATTICE_TOL
    if on_pitch and on_offset:
        pitch_deg = pitch_deg + 0.5 if pitch_deg + 0.5 <= 0.0 else pitch_deg - 0.5
    return pitch_deg, offset_m


@dataclass(frozen=True)
class Problem:
    """What a policy is trained for (module docstring).

    Attributes
    ----------
    vehicle : str
        A bundled vehicle's name or a vehicle TOML file.
    tasks : tuple of str
        The benchmark's tasks trained on, in the suite's order.
    sensors : str
        The benchmark's sensor set (``onboard``, ``lab``, ``impact``, ``ideal``), or
        several, comma-separated (``"onboard,ideal"``): each trial is then flown with
        each set, the same draw (a policy that must not lose with one set while it
        learns from another).
    seed : int
        The trials' seed (>= 1; :func:`check_seed`).
    """

    vehicle: str = "navi"
    tasks: tuple[str, ...] = ("wall", "pole", "edge")
    sensors: str = "onboard"
    seed: int = 61

    def __post_init__(self) -> None:
        from quadimpact.studies.benchmark.suite import TASKS, sensor_set, task

        if not self.tasks:
            raise InputError("--tasks: name at least one task")
        for name in self.tasks:
            task(name)
        object.__setattr__(self, "tasks", tuple(t for t in TASKS if t in self.tasks))
        names = [n.strip() for n in str(self.sensors).split(",")]
        if not all(names) or len(set(names)) != len(names):
            raise InputError(f"--sensors: name each sensor set once (got {self.sensors!r})")
        for name in names:
            sensor_set(name)
        object.__setattr__(self, "sensors", ",".join(names))
        check_seed(self.seed)

    @property
    def sensor_sets(self) -> tuple[str, ...]:
        """The sensor sets each trial is flown with, in the order given."""
        return tuple(self.sensors.split(","))

    def describe(self) -> dict[str, Any]:
        """The problem as plain data (train.json, the policy's meta)."""
        return {
            "vehicle": self.vehicle,
            "tasks": list(self.tasks),
            "sensors": self.sensors,
            "seed": self.seed,
        }

    @cached_property
    def _bases(self) -> dict[tuple[str, str], tuple[dict[str, Any], dict[str, Any]]]:
        """Each task's scenario base and ranges with each sensor set: the benchmark's sweep
        of the default law."""
        from quadimpact.studies.benchmark.subject import Subject
        from quadimpact.studies.benchmark.suite import SUITE_VERSION, TASKS, sensor_set

        out = {}
        for name in self.tasks:
            t = TASKS[name]
            for sensors in self.sensor_sets:
                spec = Subject("train").spec(t, False, sensor_set(sensors), version=SUITE_VERSION)
                base = {**spec.base, "vehicle": self.vehicle}
                if t.kind == "wall":
                    ranges = {k: tuple(v) for k, v in spec.trials["ranges"].items()}
                else:
                    arm = {k: v for k, v in spec.runs[0].items()
                           if k not in ("pitch_deg", "lateral_offset_m", "seed")}  # fmt: skip
                    base.update(arm)
                    ranges = {"pitch_deg": _PITCH_RANGE_DEG, "lateral_offset_m": _OFFSET_RANGE_M}
                out[(name, sensors)] = (base, ranges)
        return out

    def trial(
        self, task: str, purpose: int, index: int, sensors: str | None = None
    ) -> dict[str, Any]:
        """Trial ``index`` of ``task`` for ``purpose`` as a scenario mapping, flown with
        ``sensors`` (default: the first sensor set). The draw does not depend on the set."""
        from quadimpact.sweep.trials import SEED_LIMIT

        base, ranges = self._bases[(task, sensors or self.sensor_sets[0])]
        rng = trial_stream(self.seed, self.tasks.index(task), purpose, index)
        u = rng.random(len(ranges))
        values = {k: float(lo + (hi - lo) * x)
                  for (k, (lo, hi)), x in zip(ranges.items(), u, strict=True)}  # fmt: skip
        values["seed"] = int(rng.integers(0, SEED_LIMIT))
        if "lateral_offset_m" in values:
            values["pitch_deg"], values["lateral_offset_m"] = held_out_point(
                values["pitch_deg"], values["lateral_offset_m"]
            )
        return {**base, **values}

    def batch(self, purpose: int, start: int, n: int) -> list[tuple[str, dict[str, Any]]]:
        """``n`` trials, the tasks in turn and, within a task, the sensor sets in turn:
        trial ``j = start + k`` is draw ``j // (tasks x sets)`` of task
        ``(j // sets) mod tasks``, flown with set ``j mod sets``. With one set, trial
        ``j`` goes to task ``j mod tasks`` with that task's index ``j // tasks``."""
        m, n_sets = len(self.tasks), len(self.sensor_sets)
        out = []
        for j in range(start, start + n):
            name = self.tasks[(j // n_sets) % m]
            sensors = self.sensor_sets[j % n_sets]
            out.append((name, self.trial(name, purpose, j // (m * n_sets), sensors)))
        return out
