"""The recovery study's spec: the authors' distribution, the trials' sampling and
:class:`RecoveryStudy` (docs/RECOVERY.md 8).

Light on purpose: the command line validates a study's options with this module
alone, before the simulator, pandas or the pool load (``quadimpact.studies.recovery.recovery_study``
runs it).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from quadimpact.errors import InputError, format_value
from quadimpact.inputs.estimators import estimator_entry
from quadimpact.inputs.model import resolve_model_options
from quadimpact.inputs.policy_file import checked_policy, record_policy
from quadimpact.inputs.sensors import sensor_preset_names
from quadimpact.inputs.vehicle import Vehicle, bundled_vehicles, load_vehicle
from quadimpact.packing.constants import RPM
from quadimpact.studies.recovery import DEFAULT_N, IMUS, MODELS, PRE_IMPACTS

if TYPE_CHECKING:
    from quadimpact.sweep.spec import SweepSpec

__all__ = [
    "DISTRIBUTION",
    "SLEW_DONOR",
    "TRIAL_FIELDS",
    "RecoveryStudy",
    "sample_trials",
]

#: The authors' distribution: field -> (low, high), each uniform.
DISTRIBUTION: dict[str, tuple[float, float]] = {
    "roll_deg": (-15.0, 15.0),
    "pitch_deg": (-45.0, 45.0),
    "yaw_deg": (-45.0, 45.0),
    "speed_m_s": (0.5, 2.5),
}
#: The vehicle whose rotor slew limit a vehicle without one borrows.
SLEW_DONOR = "navi"
#: The trial inputs every row of ``trials.parquet`` carries.
TRIAL_FIELDS = ("roll_deg", "pitch_deg", "yaw_deg", "speed_m_s", "seed")


# ------------------------------------------------------------------ sampling
def sample_trials(
    n: int, seed: int, ranges: dict[str, tuple[float, float]] | None = None
) -> list[dict[str, float | int]]:
    """The inputs of ``n`` trials: each field uniform in its range, and an IMU seed.

    Parameters
    ----------
    n : int
        Number of trials, >= 1.
    seed : int
        The study's seed, >= 0.
    ranges : dict, optional
        Field -> (low, high) (default :data:`DISTRIBUTION`: degrees and m/s).

    Returns
    -------
    list of dict
        Per trial, in order: the fields of ``ranges`` and ``seed`` (the run's
        IMU seed, an integer in [0, 2**53)). Trial ``i`` depends on ``seed``
        and ``i`` only (:func:`quadimpact.sweep.trials.trial_draws`), as the
        study's sweep draws it (its ``trials``, when it runs).
    """
    from quadimpact.sweep.trials import trial_draws

    ranges = DISTRIBUTION if ranges is None else ranges
    return [trial_draws(seed, i, ranges, "seed") for i in range(n)]


# --------------------------------------------------------------------- spec
def _check_choice(name: str, value: Any, choices: tuple[str, ...]) -> None:
    if value not in choices:
        known = ", ".join(repr(c) for c in choices)
        raise InputError(f"{name}: must be one of {known} (got {format_value(value)})")


def _check_int(name: str, value: Any, low: int) -> None:
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise InputError(f"{name}: must be an integer >= {low} (got {format_value(value)})")


def _vehicle(ref: str, where: str = "vehicle") -> Vehicle:
    try:
        return load_vehicle(ref)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


@dataclass(frozen=True)
class RecoveryStudy:
    """The authors' Monte Carlo of impact trials, with quadimpact's variants.

    Attributes
    ----------
    vehicle : str
        Bundled vehicle name (``"navi"``, ``"spiri"``) or a vehicle TOML file.
    n : int
        Number of trials, >= 1.
    seed : int
        The study's seed, >= 0 (trial inputs and IMU seeds, :func:`sample_trials`).
    model : {"default", "recovery-replica", "pole-replica"}
        Model variant (docs/VARIANTS.md).
    imu : {"ideal", "noisy", "impact"}
        IMU preset (docs/RECOVERY.md 1.4).
    pre_impact : {"spin-down", "hold"} or None
        The recovery controller's behaviour before the detection; ``None`` (the
        default): the one the model variant forces (``"hold"`` in the pole
        replica), else ``"spin-down"``, the authors' Monte Carlo; it is
        resolved on construction. The recovery replica forces spin-down and
        the pole replica hold through their ``pre_impact`` switch; with the
        other behaviour given here that switch is set to ``"scenario"``.
    estimator : str
        The state estimator the controller and the detector read
        (docs/ESTIMATION.md): ``"ideal"`` (the default), ``"complementary"``,
        ``"ekf"`` or a registered one.
    sensors : str or None
        A preset of sensors ("ideal", "noisy", "impact", "indoor", "onboard",
        "authors-2016" or a registered one); it replaces ``imu`` (``None``:
        ``imu`` alone).
        The same seed gives the same trials (conditions and IMU seeds) with
        any estimator and sensors, so studies compare row by row.
    policy : str or None
        A learned residual on the recovery law (docs/LEARNING.md 12): ``"learned"``
        (the policy shipped with quadimpact) or a ``.npz`` policy file; ``None``
        (the default): the law alone. Recorded as the name or the file's absolute
        path, with the weights' SHA-256 in :meth:`options`.

    Notes
    -----
    A vehicle whose file has no rotor slew limit (the Spiri) is given the
    Navi's (70,000 RPM/s, as the scenario field ``rotor_slew_limit_rad_s2``):
    without a slew limit the spin-down would stop the rotors within one
    control tick.
    """

    vehicle: str = "navi"
    n: int = DEFAULT_N
    seed: int = 0
    model: str = "default"
    imu: str = "ideal"
    pre_impact: str | None = None
    estimator: str = "ideal"
    sensors: str | None = None
    policy: str | None = None
    _vehicle_ref: str = field(init=False, repr=False, compare=False)
    _policy_sha256: str = field(init=False, repr=False, compare=False, default="")

    def __post_init__(self) -> None:
        _check_int("n", self.n, 1)
        if self.policy is not None:
            ref, sha = checked_policy(str(self.policy))
            object.__setattr__(self, "policy", ref)
            object.__setattr__(self, "_policy_sha256", sha)
        _check_int("seed", self.seed, 0)
        _check_choice("model", self.model, MODELS)
        _check_choice("imu", self.imu, IMUS)
        if self.pre_impact is None:
            forced = resolve_model_options(self.model).pre_impact
            object.__setattr__(
                self, "pre_impact", forced if forced in PRE_IMPACTS else PRE_IMPACTS[0]
            )
        _check_choice("pre_impact", self.pre_impact, PRE_IMPACTS)
        if self.sensors is not None:  # a built-in preset or a plug-in's (registered)
            _check_choice("sensors", self.sensors, sensor_preset_names())
        estimator_entry(self.estimator)
        if not isinstance(self.vehicle, str) or not self.vehicle:
            raise InputError(f"vehicle: must be a vehicle name or file (got {self.vehicle!r})")
        _vehicle(self.vehicle)
        # a file by its absolute path, so that a rerun from elsewhere resumes
        ref = self.vehicle
        if ref not in bundled_vehicles():
            ref = str(Path(ref).resolve())
        object.__setattr__(self, "_vehicle_ref", ref)

    def lent_slew_limit_rad_s2(self) -> float | None:
        """The slew limit lent to a vehicle without one (rad/s^2), None if it has its own."""
        if _vehicle(self.vehicle).rotor_slew_limit_rpm_per_s is not None:
            return None
        donor = load_vehicle(SLEW_DONOR).rotor_slew_limit_rpm_per_s
        assert donor is not None  # the shipped Navi file has one
        return float(donor) * RPM

    def base(self) -> dict[str, Any]:
        """The impact-trial base scenario of every trial (a scenario-file mapping)."""
        base: dict[str, Any] = {
            "kind": "impact-trial",
            "vehicle": self._vehicle_ref,
            "model": self.model,
            "controller": "recovery",
            "imu": self.imu,
            "pre_impact": self.pre_impact,
        }
        if self.estimator != "ideal":
            base["estimator"] = self.estimator
        if self.sensors is not None:
            base["sensors"] = self.sensors
            del base["imu"]
        forced = resolve_model_options(self.model).pre_impact
        if forced != "scenario" and forced != self.pre_impact:
            base["model_options"] = {"pre_impact": "scenario"}
        slew = self.lent_slew_limit_rad_s2()
        if slew is not None:
            base["rotor_slew_limit_rad_s2"] = slew
        if self.policy is not None:
            base["controller_params"] = {"policy": self.policy}
        return base

    def sweep_spec(self) -> SweepSpec:
        """The study as a sweep: the base and its ``trials`` (each drawn when it runs)."""
        from quadimpact.sweep.spec import SweepSpec

        ranges = {name: list(bounds) for name, bounds in DISTRIBUTION.items()}
        trials = {"n": self.n, "seed": self.seed, "ranges": ranges, "seed_field": "seed"}
        return SweepSpec(base=self.base(), trials=trials, where="recovery")

    def options(self) -> dict[str, Any]:
        """The study's options as plain data (``study.json``)."""
        d = asdict(self)
        d.pop("_vehicle_ref", None)
        record_policy(d, self._policy_sha256)
        return d
