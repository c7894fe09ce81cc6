"""How a policy is trained (``quadimpact train``'s options) and what a training run made."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from pathlib import Path

from quadimpact.errors import InputError

__all__ = ["Settings", "TrainingResult", "settings_fields"]


@dataclass(frozen=True)
class Settings:
    """How a policy is trained (module docstring; ``quadimpact train --help``).

    Attributes
    ----------
    hidden : int
        Hidden units of the network (1-32); ``hidden * 28 + 3`` parameters.
    popsize : int
        Candidates per generation (>= 2).
    batch : int
        Training trials per generation, each flown by every candidate (>= 1).
    sigma : float
        CMA-ES's initial step size, in weight units (> 0).
    thrust_scale : float
        The largest thrust correction, a fraction of ``m g`` (>= 0).
    rate_scale_rad_s : float
        The largest roll and pitch rate-reference correction, rad/s (>= 0).
    last_stage : int
        The last stage the policy acts in: 5 (every stage, the hover too) or 4.
    shaping : float
        The weight of the height-kept term in the reward (>= 0).
    drift_weight : float
        The weight of the held hover's drift in the reward (>= 0; 0: none): a
        success scores ``1 - drift_weight * min(drift / 0.1 m, 1)``
        (``flying.rewards``), and the check set then keeps the best mean reward.
    loss_weight : float
        A candidate's penalty for each training trial the law succeeds in and it
        fails (>= 0; 0: none). The law flies every batch beside the candidates, so
        this is free; it pushes the search toward policies that win trials without
        losing others.
    contested : int
        Screen this many training trials before generation 1 and train on those
        that separate the start from its neighbours (>= 0; 0: fresh trials every
        generation). The start, the law and ``popsize`` draws around the start
        (at ``sigma``) fly the screen; a trial is kept when their successes
        differ. Batches then cycle through the kept trials: every trial of a
        batch can rank the candidates, where a fresh batch is mostly trials that
        every candidate wins or every candidate loses.
    check : int
        Trials of the check set (>= 1).
    check_every : int
        Generations between two checks (>= 1).
    hover_centred : bool
        The policy's correction in the hover stage is zero at the hover itself
        (``core/controllers/residual.py``): it may change how the law reaches its
        hover, not where it holds it.
    hover_hand_over : bool
        In the hover stage the policy acts only while the law brakes, not once
        the law has captured the point it holds (the law alone holds it).
    hover_fade_s : tuple of float
        ``(from, to)``, s after the detection: the policy's correction in the
        hover stage fades linearly to zero between them, so the law alone holds
        the hover it reached (``0 <= from < to <= 2``; ``(0, 0)``: no fade).
    init : str or None
        A policy (``learned`` or a file) whose weights start the search instead
        of the law (a zero output layer). Its hidden width, scales and last
        stage must be these settings'; recorded with its weights' digest.
    init_sha256 : str
        The digest of ``init``'s weights (set from the file; part of the run's identity).
    """

    hidden: int = 8
    popsize: int = 12
    batch: int = 24
    sigma: float = 0.05
    thrust_scale: float = 0.3
    rate_scale_rad_s: float = 4.0
    last_stage: int = 5
    shaping: float = 0.1
    drift_weight: float = 0.0
    loss_weight: float = 0.0
    contested: int = 0
    check: int = 60
    check_every: int = 5
    hover_centred: bool = False
    hover_hand_over: bool = False
    hover_fade_s: tuple[float, float] = (0.0, 0.0)
    init: str | None = None
    init_sha256: str = ""

    def __post_init__(self) -> None:
        from quadimpact.core.controller_slots import MAX_HIDDEN

        rules = {
            "hidden": (self.hidden, 1 <= self.hidden <= MAX_HIDDEN, f"in 1..{MAX_HIDDEN}"),
            "popsize": (self.popsize, self.popsize >= 2, ">= 2"),
            "batch": (self.batch, self.batch >= 1, ">= 1"),
            "sigma": (self.sigma, math.isfinite(self.sigma) and self.sigma > 0, "finite, > 0"),
            "thrust-scale": (self.thrust_scale, _nonneg(self.thrust_scale), "finite, >= 0"),
            "rate-scale": (self.rate_scale_rad_s, _nonneg(self.rate_scale_rad_s), "finite, >= 0"),
            "stages": (self.last_stage, self.last_stage in (4, 5), "4 or 5"),
            "shaping": (self.shaping, _nonneg(self.shaping), "finite, >= 0"),
            "drift-weight": (self.drift_weight, _nonneg(self.drift_weight), "finite, >= 0"),
            "loss-weight": (self.loss_weight, _nonneg(self.loss_weight), "finite, >= 0"),
            "contested": (self.contested, self.contested >= 0, ">= 0"),
            "check": (self.check, self.check >= 1, ">= 1"),
            "check-every": (self.check_every, self.check_every >= 1, ">= 1"),
            "hover-centred": (
                self.hover_centred,
                not self.hover_centred or self.last_stage == 5,
                "given with --stages 1-5 (it acts in the hover stage)",
            ),
        }
        rules["hover-hand-over"] = (
            self.hover_hand_over,
            not self.hover_hand_over or self.last_stage == 5,
            "given with --stages 1-5 (it acts in the hover stage)",
        )
        fade = tuple(float(v) for v in self.hover_fade_s)
        rules["hover-fade"] = (
            fade,
            fade == (0.0, 0.0) or (self.last_stage == 5 and 0.0 <= fade[0] < fade[1] <= 2.0),
            "FROM,TO s with 0 <= FROM < TO <= 2, given with --stages 1-5",
        )
        for name, (value, ok, rule) in rules.items():
            if not ok:
                raise InputError(f"--{name}: must be {rule} (got {value})")
        object.__setattr__(self, "hover_fade_s", fade)


def _nonneg(x: float) -> bool:
    return math.isfinite(x) and x >= 0.0


@dataclass
class TrainingResult:
    """What a training run (or its part up to an interrupt) made."""

    out: Path
    generations: int
    runs: int
    minutes: float
    law_check: float
    best_check: float
    best_generation: int
    finished: bool
    resumed_from: int


def settings_fields() -> tuple[str, ...]:
    """The names of :class:`Settings`' fields."""
    return tuple(f.name for f in fields(Settings))
