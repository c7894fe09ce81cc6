"""What a benchmark row flies: the thing benchmarked and the reference rows (docs/BENCHMARK.md 2).

A :class:`Subject` is a controller (a built-in law or variant with its
parameters, or a registered plug-in controller), the state estimator of the
``impact`` sensor set (a built-in or a registered one), or a policy: a
learned residual on the staged law (``learned``, the policy shipped with
quadimpact, or a ``.npz`` policy file: docs/LEARNING.md 12), flown by the
recovery controller in the compiled loop, or a policy registered with
:func:`register_policy` (its own scenario fields). It turns each task and sensor set
into the runs of a sweep: the wall task's trials
(:meth:`Subject.wall_spec`) and a grid task's points (:meth:`Subject.grid_spec`),
each with the subject's controller, model, parameters and estimator.

:data:`REFERENCES` are the rows every benchmark shows beside it: the default
law, the previous default (``classic``), the authors' two replicas and the
baseline without recovery; :data:`PUBLISHED` the authors' own figures, with
their sources (never computed, never edited).
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from quadimpact.errors import InputError
from quadimpact.inputs.controllers import controller_entry
from quadimpact.inputs.estimators import estimator_entry
from quadimpact.inputs.model import MODEL_VARIANTS
from quadimpact.studies.benchmark.suite import (
    DEFAULT_ESTIMATOR,
    SUITE_VERSION,
    SensorSet,
    Task,
    suite,
)
from quadimpact.studies.trial_analysis import recovery_arm

if TYPE_CHECKING:
    from quadimpact.sweep import SweepSpec

__all__ = [
    "KINDS",
    "PUBLISHED",
    "REFERENCES",
    "Published",
    "Subject",
    "register_policy",
]

#: What a benchmark's subject can be.
KINDS = ("controller", "estimator", "policy")
#: The controllers the cached kernel runs (any other is a plug-in, compiled per process).
BUILTIN_CONTROLLERS = ("paper", "cascade-pid", "recovery")
BUILTIN_ESTIMATORS = ("ideal", "complementary", "ekf", "ekf-additive", "nav-ekf")

_POLICIES: dict[str, Callable[[], dict[str, Any]]] = {}


def register_policy(name: str, overrides: Callable[[], dict[str, Any]]) -> None:
    """Make a policy of the learning environment a benchmark subject (``--policy NAME``).

    ``overrides()`` returns the scenario fields that fly it in the loop (its
    controller and parameters: a policy runs as a compiled controller, so
    that the tasks' sweeps fly it like any other). A name not registered is
    read as a residual policy (``learned`` or a ``.npz`` file).
    """
    _POLICIES[name] = overrides


@dataclass(frozen=True)
class Subject:
    """One row of the leaderboard: what flies the tasks.

    Attributes
    ----------
    name : str
        The row's name in every output.
    kind : {"controller", "estimator", "policy"}
        What the row benchmarks (for the reference rows: ``"controller"``).
    controller : str
        A registered controller: ``"recovery"`` (the staged law), ``"paper"`` (no
        recovery: the baseline) or a plug-in.
    model : str
        The model variant (docs/VARIANTS.md): for ``recovery`` the law's tuning and
        its pre-impact behaviour when the variant forces one.
    params : mapping
        The controller's ``[controller_params]`` (JSON-able).
    estimator : str
        The state estimator of every sensor set of real sensors (``impact``, ``lab``).
    policy : str or None
        A policy: a learned residual on the recovery law (``learned`` or a
        ``.npz`` file, recorded as the name or the file's absolute path), or one
        registered with :func:`register_policy` instead of a controller.
    reference : bool
        A reference row (beside the subject, read from the cache when there).
    note : str
        What it is, in one line.
    """

    name: str
    kind: str = "controller"
    controller: str = "recovery"
    model: str = "default"
    params: Mapping[str, Any] = field(default_factory=dict)
    estimator: str = DEFAULT_ESTIMATOR
    policy: str | None = None
    reference: bool = False
    note: str = ""
    _policy_sha256: str = field(default="", init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise InputError(f"kind: must be one of {', '.join(KINDS)} (got {self.kind!r})")
        if self.model not in MODEL_VARIANTS:
            known = ", ".join(repr(m) for m in MODEL_VARIANTS)
            raise InputError(f"--model: must be one of {known} (got {self.model!r})")
        if self.residual:
            from quadimpact.inputs.policy_file import checked_policy

            try:
                ref, sha = checked_policy(str(self.policy))
            except InputError as exc:
                raise InputError(f"--{exc}") from None
            object.__setattr__(self, "policy", ref)
            object.__setattr__(self, "_policy_sha256", sha)
        controller_entry(self.controller)
        estimator_entry(self.estimator)
        object.__setattr__(self, "params", json.loads(json.dumps(dict(self.params))))

    # ------------------------------------------------------------ describe
    @property
    def residual(self) -> bool:
        """Whether it flies a learned residual on the recovery law (not a registered policy)."""
        return self.policy is not None and self.policy not in _POLICIES

    @property
    def law(self) -> bool:
        """Whether the recovery controller flies it in the row's model (the staged law, with
        or without a learned residual)."""
        return self.controller == "recovery" and (self.policy is None or self.residual)

    @property
    def plugin(self) -> bool:
        """Whether it flies a plug-in (compiled per process; never cached)."""
        return (
            (self.policy is not None and not self.residual)
            or self.controller not in BUILTIN_CONTROLLERS
            or self.estimator not in BUILTIN_ESTIMATORS
        )

    @property
    def cacheable(self) -> bool:
        """Whether its cells may be kept in and read from the cache: built-in code only, and a
        residual policy only when shipped (a user's file may change under the same path)."""
        from quadimpact.inputs.policy_file import SHIPPED_POLICIES

        return not self.plugin and (not self.residual or self.policy in SHIPPED_POLICIES)

    @property
    def recovers(self) -> bool:
        """Whether it flies a recovery law (the baseline does not)."""
        return self.controller != "paper" or self.policy is not None

    def describe(self) -> dict[str, Any]:
        """The row as plain data (every output carries it)."""
        return {
            "row": self.name,
            "role": "reference" if self.reference else "subject",
            "kind": self.kind,
            "controller": self.controller,
            "model": self.model,
            "params": json.dumps(self.params, sort_keys=True),
            "estimator": self.estimator,
            "policy": (
                f"{self.policy} (sha256 {self._policy_sha256[:12]})"
                if self.residual
                else self.policy or ""
            ),
            "note": self.note,
        }

    # --------------------------------------------------------------- runs
    def _fields(self) -> dict[str, Any]:
        """The scenario fields of its controller (its parameters, its policy's fields)."""
        fields: dict[str, Any] = {}
        if self.policy is not None and not self.residual:
            fields.update(_POLICIES[self.policy]())
        else:
            fields["controller"] = self.controller
        if self.residual:
            fields["controller_params"] = {"policy": self.policy}
        if self.params:
            fields["controller_params"] = {**fields.get("controller_params", {}), **self.params}
        return fields

    def _sensing(self, sensing: SensorSet) -> SensorSet:
        """The set as this row flies it: its own estimator for a set of real sensors (a set
        with an estimator of its own keeps it unless the row names another than the default)."""
        return sensing.flown_with(self.estimator)

    def wall_spec(self, task: Task, quick: bool, sensing: SensorSet) -> SweepSpec:
        """The wall task's trials flown by this row (the recovery study's sweep)."""
        from quadimpact.sweep import SweepSpec

        sensing = self._sensing(sensing)
        model = self.model if self.law else "default"
        spec = task.wall_study(quick, sensing, model).sweep_spec()
        base = dict(spec.base)
        if not self.law:
            base.pop("pre_impact", None)  # a behaviour of the recovery controller only
        base.update(self._fields())
        return SweepSpec(base=base, trials=spec.trials, where=f"benchmark: {task.name}")

    def grid_spec(self, task: Task, quick: bool, sensing: SensorSet) -> SweepSpec:
        """A grid task's points flown by this row (the pole study's sweep, one arm)."""
        study = task.grid_study(quick, self._sensing(sensing))
        if self.law:
            arm = recovery_arm(self.model, study.baseline)
        else:
            arm = {"model": self.model}
        arm.update(self._fields())
        spec = study.sweep_spec([arm])
        spec.where = f"benchmark: {task.name}"
        return spec

    def spec(
        self,
        task: Task,
        quick: bool,
        sensing: SensorSet,
        limit: int | None = None,
        version: str = SUITE_VERSION,
    ) -> SweepSpec:
        """The sweep of one task and sensor set in the suite ``version``; ``limit``: only
        its first runs (a smoke test's: the same runs as the task's first, listed).

        Suite 2 flies every trial for the suite's run length with the ground as a
        contact surface whose first touch ends the run (``ground = "crash"``).
        """
        from quadimpact.sweep import SweepSpec

        if task.kind == "wall":
            spec = self.wall_spec(task, quick, sensing)
        else:
            spec = self.grid_spec(task, quick, sensing)
        s = suite(version)
        if s.held_hover:
            base = {**spec.base, "final_time_s": s.final_time_s, "ground": "crash"}
            spec = SweepSpec(
                base=base, grid=spec.grid or None, runs=spec.runs, trials=spec.trials,
                where=spec.where,
            )  # fmt: skip
        if limit is None or limit >= spec.n_runs:
            return spec
        runs = [spec.inputs(i) for i in range(limit)]
        return SweepSpec(base=spec.base, runs=runs, where=spec.where)


REFERENCES: tuple[Subject, ...] = (
    Subject(
        "default",
        reference=True,
        note="the default staged law (docs/RECOVERY.md 3)",
    ),
    Subject(
        "classic",
        model="classic",
        reference=True,
        note="the default law before the benchmark (issue #45): `--model classic`",
    ),
    Subject(
        "recovery-replica",
        model="recovery-replica",
        reference=True,
        note="the authors' recovery simulator and law (docs/VARIANTS.md 5)",
    ),
    Subject(
        "pole-replica",
        model="pole-replica",
        reference=True,
        note="the authors' retuned pole law, rotors held until the detection (docs/VARIANTS.md 8)",
    ),
    Subject(
        "baseline",
        controller="paper",
        reference=True,
        note="no recovery: the paper controller holding the initial attitude and altitude",
    ),
)
"""The reference rows, in the leaderboard's order."""


@dataclass(frozen=True)
class Published:
    """One of the authors' published figures (read from their papers, never computed).

    Attributes
    ----------
    row : str
        The leaderboard row it belongs to (``"authors"`` or ``"authors, no recovery"``).
    task : str
        The task it measures (the full task; the ``ideal`` sensor set).
    share : float
        The published success share.
    n : int
        The trials or grid points it is a share of.
    source : str
        Where it is published.
    """

    row: str
    task: str
    share: float
    n: int
    source: str


PUBLISHED: tuple[Published, ...] = (
    Published(
        "authors",
        "wall",
        0.919,
        10_000,
        "the authors' 10,000-trial Monte Carlo of their recovery law (as quoted in issue #45)",
    ),
    Published(
        "authors",
        "pole",
        0.948,
        3_266,
        "the authors' pole study with their retuned law (docs/OBSTACLES.md 6.1)",
    ),
    Published(
        "authors, no recovery",
        "pole",
        0.585,
        3_266,
        "the authors' pole study without recovery (docs/OBSTACLES.md 6.1)",
    ),
)
"""The authors' published figures shown beside the computed rows."""
