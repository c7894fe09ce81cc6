"""What an impact-recovery environment is made of: its trials, reward, envelope and spaces.

* :class:`TrialDistribution`: the impact trials ``reset`` draws (default: the
  authors' distribution of docs/RECOVERY.md section 5.1, the Navi);
* :class:`RewardWeights`: the reward's terms and weights;
* :class:`Envelope`: the limits whose crossing ends an episode as a failure;
* :func:`check_episode_options`: the action and observation modes and the
  episode's options, checked (``packing.episode_block.pack_episode`` packs it
  all as the compiled core's parameter vector).

Units: SI, angles in degrees where a name says ``_deg``; frames inertial NED
and body FRD (docs/MODEL.md section 1).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from quadimpact.inputs.scenarios import ImpactTrial
from quadimpact.packing.episode_block import ACTION_MODES, OBSERVATION_MODES

__all__ = [
    "ACTION_MODES",
    "OBSERVATION_MODES",
    "Envelope",
    "RewardWeights",
    "TrialDistribution",
    "check_episode_options",
    "coerce",
]


Range = float | tuple[float, float]


def _uniform(rng: np.random.Generator, r: Range) -> float:
    """One draw of a field: a fixed value, or uniform in ``[lo, hi]`` (always one draw)."""
    u = float(rng.uniform(0.0, 1.0))
    if isinstance(r, (int, float)):
        return float(r)
    lo, hi = (float(v) for v in r)
    return lo + u * (hi - lo)


def _choice(rng: np.random.Generator, options: str | Sequence[str]) -> str:
    """One of ``options`` (uniform; always one draw), or the single value given."""
    k = int(rng.integers(0, 1 << 30))
    if isinstance(options, str):
        return options
    return str(options[k % len(options)])


def _number(name: str, value: Any, *, low: float | None = None, low_open: bool = False) -> float:
    """A finite real number (not a bool), optionally above ``low``; else ``ValueError``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.number)):
        raise ValueError(f"{name}: must be a number (got {value!r})")
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"{name}: must be a finite number (got {value!r})")
    if low is not None and (x < low or (low_open and x == low)):
        raise ValueError(f"{name}: must be {'>' if low_open else '>='} {low:g} (got {value!r})")
    return x


def _flag(name: str, value: Any) -> bool:
    """A boolean option: True or False (NumPy's too), nothing else."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name}: must be True or False (got {value!r})")
    return bool(value)


def _check_range(name: str, value: Any) -> None:
    """A fixed value or ``(lo, hi)`` with ``lo <= hi``, finite; valid for ImpactTrial's field."""
    if isinstance(value, (str, bytes)) or not (
        isinstance(value, (int, float, np.number)) or isinstance(value, Sequence)
    ):
        raise ValueError(f"{name}: must be a number or (low, high) (got {value!r})")
    ends = [value] if not isinstance(value, Sequence) else list(value)
    if isinstance(value, Sequence) and len(ends) != 2:
        raise ValueError(f"{name}: must be a number or (low, high) (got {value!r})")
    numbers = [_number(name, v) for v in ends]
    if numbers[0] > numbers[-1]:
        raise ValueError(f"{name}: (low, high) needs low <= high (got {value!r})")
    field_name = "friction_coefficient" if name == "friction" else name
    for x in numbers:  # each end a valid trial value: checked now, not when drawn
        try:
            ImpactTrial.model_validate({field_name: x})
        except Exception as exc:  # pydantic's ValidationError: the field's own rule
            from quadimpact.errors import input_error_from_validation

            rule = str(input_error_from_validation(exc)).partition(": ")[2] or str(exc)
            raise ValueError(f"{name}: {rule}") from None


def _check_choices(name: str, value: Any) -> None:
    """A non-empty string or a non-empty sequence of them."""
    items = [value] if isinstance(value, str) else value
    if (
        not isinstance(items, Sequence)
        or not items
        or not all(isinstance(v, str) and v for v in items)
    ):
        raise ValueError(f"{name}: must be a name or a non-empty list of names (got {value!r})")


def coerce(cls: type, value: Any, name: str) -> Any:
    """``value`` as a ``cls`` (a settings dataclass): itself, or a mapping of its fields.

    Raises
    ------
    TypeError
        Anything else, or a mapping with a key that is not a field.
    """
    if value is None:
        return cls()
    if isinstance(value, cls):
        return value
    if isinstance(value, Mapping):
        known = [f for f in cls.__dataclass_fields__ if not f.startswith("_")]
        unknown = [k for k in value if k not in known]
        if unknown:
            raise TypeError(
                f"{name}: unknown field(s) {', '.join(map(repr, unknown))} of {cls.__name__} "
                f"(fields: {', '.join(known)})"
            )
        return cls(**value)
    raise TypeError(
        f"{name}: must be a {cls.__name__} or a mapping of its fields (got "
        f"{type(value).__name__} {value!r})"
    )


@dataclass(frozen=True)
class TrialDistribution:
    """The impact trials an environment draws at ``reset`` (docs/RECOVERY.md section 5.1).

    Each range is a fixed value or ``(lo, hi)`` (uniform); each choice a value
    or a sequence of values (uniform). Every trial makes the same draws in the
    same order from the environment's generator (``np_random``): roll, pitch,
    yaw, speed, friction, vehicle, model, IMU preset, then the trial's own
    seed (its IMU noise and bias), so a seed gives the same trials whatever is
    fixed.

    Attributes
    ----------
    roll_deg, pitch_deg, yaw_deg : float or (float, float)
        Initial attitude (ZYX), deg. Default the authors': roll +-15, pitch
        +-45, yaw +-45.
    speed_m_s : float or (float, float)
        Initial speed toward the wall, m/s. Default 0.5-2.5.
    friction : float or (float, float)
        Coulomb friction coefficient at the bumpers. Default 0.3.
    vehicle : str or sequence of str
        Bundled vehicle names (``"navi"``, ``"spiri"``) or vehicle file paths.
    model : str or sequence of str
        Model variants: ``"default"`` or ``"recovery-replica"``.
    imu : str or sequence of str
        IMU presets: ``"ideal"`` or ``"noisy"``.
    start_distance_m, altitude_m, final_time_s : float
        Start of the CM from the wall (m), its altitude (m), the trial's end (s).
    controller_params : mapping
        The ``recovery`` controller's parameters (docs/RECOVERY.md 3.5): its
        stage tolerances are the observer's, its ``k_rate_1_s`` the ctbr rate
        loop's. Stage 5 (``hover``) is off unless set here: an episode ends
        at the confirmed recovery (stage 4), which stage 5's braking would delay.
    estimator : str
        The trials' state estimator (``"ideal"``, ``"complementary"``, ``"ekf"``
        or a registered one; docs/ESTIMATION.md); what the ``estimate``
        observation shows.
    estimator_params : mapping
        Its parameters.
    sensors : str or None
        A preset of sensors (``"ideal"``, ``"noisy"``, ``"impact"``, ``"indoor"``,
        ``"onboard"``, ``"authors-2016"``);
        it replaces the IMU preset choice.
    overrides : mapping
        Any other :class:`~quadimpact.inputs.scenarios.ImpactTrial` field
        (e.g. ``{"detection": {"threshold_g": 1.0}}``, ``{"imu": {"position": "cm"}}``
        replaces the preset choice).
    """

    roll_deg: Range = (-15.0, 15.0)
    pitch_deg: Range = (-45.0, 45.0)
    yaw_deg: Range = (-45.0, 45.0)
    speed_m_s: Range = (0.5, 2.5)
    friction: Range = 0.3
    vehicle: str | Sequence[str] = "navi"
    model: str | Sequence[str] = "default"
    imu: str | Sequence[str] = "ideal"
    start_distance_m: float = 0.32
    altitude_m: float = 5.0
    final_time_s: float = 3.0
    controller_params: Mapping[str, Any] = field(default_factory=dict)
    estimator: str = "ideal"
    estimator_params: Mapping[str, Any] = field(default_factory=dict)
    sensors: str | None = None
    overrides: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in ("roll_deg", "pitch_deg", "yaw_deg", "speed_m_s", "friction"):
            _check_range(name, getattr(self, name))
        for name in ("vehicle", "model", "imu"):
            _check_choices(name, getattr(self, name))
        _number("start_distance_m", self.start_distance_m, low=0.0, low_open=True)
        _number("altitude_m", self.altitude_m, low=0.0, low_open=True)
        _number("final_time_s", self.final_time_s, low=0.0, low_open=True)
        for name in ("controller_params", "overrides"):
            if not isinstance(getattr(self, name), Mapping):
                raise TypeError(f"{name}: must be a mapping (got {getattr(self, name)!r})")

    def imu_choices(self) -> list[Any]:
        """The IMU settings a trial can have (presets, or the override's table)."""
        if "imu" in self.overrides:
            return [self.overrides["imu"]]
        return [self.imu] if isinstance(self.imu, str) else list(self.imu)

    def draw(self, rng: np.random.Generator) -> dict[str, Any]:
        """The drawn fields of one trial (the :class:`ImpactTrial` keywords that vary)."""
        fields: dict[str, Any] = {
            "roll_deg": _uniform(rng, self.roll_deg),
            "pitch_deg": _uniform(rng, self.pitch_deg),
            "yaw_deg": _uniform(rng, self.yaw_deg),
            "speed_m_s": _uniform(rng, self.speed_m_s),
            "friction_coefficient": _uniform(rng, self.friction),
            "vehicle": _choice(rng, self.vehicle),
            "model": _choice(rng, self.model),
            "imu": _choice(rng, self.imu),
        }
        if "imu" in self.overrides:  # a full IMU table replaces the preset choice
            fields["imu"] = self.overrides["imu"]
        fields["seed"] = int(rng.integers(0, 2**63 - 1))
        return fields

    def trial(self, fields: Mapping[str, Any], *, ground: bool, record: bool) -> ImpactTrial:
        """The validated trial of drawn (or given) fields.

        ``ground``: the ground is a contact surface (its first contact ends the
        episode); ``record``: keep the 1-kHz time series (otherwise only the
        start and end rows, which the metrics do not need).
        """
        values: dict[str, Any] = {
            "start_distance_m": self.start_distance_m,
            "altitude_m": self.altitude_m,
            "final_time_s": self.final_time_s,
            "controller_params": {"hover": False, **dict(self.controller_params)},
            **dict(self.overrides),
            **dict(fields),
        }
        if self.estimator != "ideal" or self.estimator_params:
            values.setdefault("estimator", self.estimator)
            values.setdefault("estimator_params", dict(self.estimator_params))
        if self.sensors is not None:
            values.setdefault("sensors", self.sensors)
            if "imu" not in self.overrides:  # the preset's IMU, not the drawn preset name
                values.pop("imu", None)
        values.setdefault("ground", "contact" if ground else "none")
        if not record:
            values["output_rate_hz"] = 1.0 / float(values["final_time_s"])
        return ImpactTrial(**values)


@dataclass(frozen=True)
class RewardWeights:
    """The reward (docs/LEARNING.md section 4): costs per second, a bonus, a penalty.

    Per control period of length ``dt`` (5 ms) the reward is
    ``-dt * (tilt * c_tilt + rate * c_rate + vertical_speed * c_vz
    + height_loss * c_height + effort * c_effort)``, each cost in [0, 1] at the
    state reached:

    * ``c_tilt = (1 - cos tilt)/2`` (tilt of the body z axis from vertical);
    * ``c_rate = min(|omega| / rate_scale_rad_s, 1)``;
    * ``c_vz = min(|h_dot| / vertical_speed_scale_m_s, 1)``;
    * ``c_height = min(max(h_takeover - h, 0) / height_scale_m, 1)``;
    * ``c_effort`` = mean over the rotors of ``((Omega_cmd - Omega_hover) / span)^2``
      (``span`` the rotor range, ``Omega_hover`` the level-hover speed).

    On the recovered termination ``+ recovery_bonus``; on a failure (ground,
    envelope) ``- failure_penalty`` and, if ``failure_remaining``, the largest
    cost rate times the time left in the trial (so failing never costs less
    than going on). Costs only (no positive per-step term), so an episode that
    ends recovered is never worth less than one that drags on.
    """

    tilt: float = 1.0
    rate: float = 0.5
    vertical_speed: float = 0.5
    height_loss: float = 0.5
    effort: float = 0.1
    recovery_bonus: float = 1.0
    failure_penalty: float = 1.0
    failure_remaining: bool = True
    rate_scale_rad_s: float = 10.0
    vertical_speed_scale_m_s: float = 1.0
    height_scale_m: float = 1.0

    def __post_init__(self) -> None:
        for name in ("tilt", "rate", "vertical_speed", "height_loss", "effort",
                     "recovery_bonus", "failure_penalty"):  # fmt: skip
            _number(name, getattr(self, name), low=0.0)
        for name in ("rate_scale_rad_s", "vertical_speed_scale_m_s", "height_scale_m"):
            _number(name, getattr(self, name), low=0.0, low_open=True)
        _flag("failure_remaining", self.failure_remaining)


@dataclass(frozen=True)
class Envelope:
    """Limits whose crossing ends an episode as a failure (checked at every tick).

    Attributes
    ----------
    max_tilt_deg : float
        Tilt of the body z axis from vertical, deg.
    max_drop_m : float
        Altitude below the altitude at the takeover, m.
    max_distance_m : float
        Horizontal distance of the CM from its position at the takeover, m.
    max_rate_rad_s : float
        Angular-rate magnitude ``|omega|``, rad/s.
    """

    max_tilt_deg: float = 150.0
    max_drop_m: float = 10.0
    max_distance_m: float = 10.0
    max_rate_rad_s: float = 40.0

    def __post_init__(self) -> None:
        for name in ("max_tilt_deg", "max_drop_m", "max_distance_m", "max_rate_rad_s"):
            _number(name, getattr(self, name), low=0.0, low_open=True)
        if self.max_tilt_deg > 180.0:
            raise ValueError(f"max_tilt_deg: must be <= 180 (got {self.max_tilt_deg!r})")


def check_episode_options(
    *,
    action: str,
    observe: str,
    rotor_floor: str,
    hold_s: float,
    end_on_recovery: bool,
    ground: bool,
) -> None:
    """Refuse an environment's modes and episode options that are not allowed.

    Raises
    ------
    ValueError
        Naming the option and its rule: ``action`` not in :data:`ACTION_MODES`,
        ``observe`` not in :data:`OBSERVATION_MODES`, ``rotor_floor`` not
        ``"vehicle"`` or ``"zero"``, ``hold_s`` (s) not > 0, a flag not a bool.
    """
    if action not in ACTION_MODES:
        raise ValueError(f"action: one of {ACTION_MODES} (got {action!r})")
    if observe not in OBSERVATION_MODES:
        raise ValueError(f"observe: one of {OBSERVATION_MODES} (got {observe!r})")
    if rotor_floor not in ("vehicle", "zero"):
        raise ValueError(f"rotor_floor: 'vehicle' or 'zero' (got {rotor_floor!r})")
    _number("hold_s", hold_s, low=0.0, low_open=True)
    _flag("end_on_recovery", end_on_recovery)
    _flag("ground", ground)
