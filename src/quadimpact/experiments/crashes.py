"""The seven real crashes of the paper's Table III, as scenarios.

Each crash can be run at two sets of pre-impact conditions:

* ``"nominal"``: the paper's Table III (heading, impact speed, inclination and
  their uncertainties; docs/STUDIES.md section 4), the altitude set-point
  held from the start: the shipped scenario files ``crashes/crash_N.toml``;
* ``"matched"``: the conditions the authors matched in their own simulations
  of these crashes (the crash set's description file): the measured roll,
  pitch and heading held by the controller, a start at t = 0 at a lower
  altitude with the rotors at level hover and the controller climbing toward
  the set-point, first contact 0.5 s later at the matched speed. The vehicle
  reaches the wall climbing (and drifting sideways, its thrust tilted partly
  across the wall) as theirs did. The approach is the same in both variants
  (:data:`MATCHED_APPROACH_OPTIONS`): conditions, not model.

Both carry the measured motor schedule from the first contact (a zero rate:
the motor switched off). In the ``paper-replica`` variant a crash also runs
with the switches of the authors' crash runs (:data:`REPLICA_CRASH_SWITCHES`,
docs/EXPERIMENTS.md): the crash at the first control tick with the CM at or
below the ground, their thrust coefficient, and motor 2 cut at the first tick
after the contact as a one-tick command step. Crash I-03's hand modification
(:data:`HAND_MODIFICATION`) is off unless asked for.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from quadimpact.inputs.scenarios import WallApproach, load_scenario_file

HEADING_UNCERTAINTY_DEG = 6.4  # Table III: psi +- 6.4 deg
SPEED_UNCERTAINTY_M_S = 0.01  # Table III: V_c +- 0.01 m/s
#: The two sets of pre-impact conditions of a crash.
CONDITIONS = ("nominal", "matched")
#: The model variants of the crash runs (the replica with its crash-run switches).
VARIANTS = ("default", "paper-replica")
#: First contact of the matched approach, s ("about 0.5 s" after the start).
MATCHED_CONTACT_TIME_S = 0.5
#: The matched approach's start, in every variant (the authors' approach): at t = 0,
#: moving away from the wall at first if the tilt needs it (crash 1: the default
#: variant's late start would begin 0.1 s later, at rest), with the rotors at level
#: hover (the first control tick commands them at once).
MATCHED_APPROACH_OPTIONS: dict[str, str] = {
    "approach_start": "paper",
    "initial_rotor_speeds": "level-hover",
}
#: The rotor thrust coefficient of the authors' crash runs, N/rpm^2 (Table I: 7.015e-8).
AUTHORS_THRUST_COEFFICIENT_N_PER_RPM2 = 8.7e-8
#: The switches of the authors' crash runs, on in the replica's crash runs:
#: name -> what it is (docs/EXPERIMENTS.md says what each changes).
REPLICA_CRASH_SWITCHES: dict[str, str] = {
    "ground_tick_crash": "the crash at the first control tick with the CM at or below the "
    "ground (crash_rule = 'ground-ticks'), not at -0.3 m",
    "thrust_coefficient": f"the rotor thrust coefficient {AUTHORS_THRUST_COEFFICIENT_N_PER_RPM2:g} "
    "N/rpm^2 of their runs (vehicle_overrides.thrust_coefficient)",
    "motor2_cut_step": "motor 2, off from the contact, cut at the first control tick after it "
    "as a one-tick command step with its spin-up reaction (cut_step_motors = [2])",
}
#: Crash I-03 (Table III row 1) as the authors ran it, off by default: bumper 2's
#: contact force doubled and motor 2 cut as above although its log shows it
#: running, an undocumented hand modification.
HAND_MODIFICATION = "i03_hand_modification"

#: The changes of the switch runs (matched conditions), each against the run as
#: made: what it tests, and the variant it is run in (docs/EXPERIMENTS.md,
#: "What each change does"; the runs: ``experiments.table3``).
SWITCH_CHANGES: dict[str, str] = {
    "zero rate held": "a zero scheduled rate read the earlier way, the motor keeping its speed "
    "(only a motor whose rates never exceed 100 rpm/s stopped, at the contact); both variants",
    "offs at the segment's end": "each motor the schedule switches off after the contact "
    "kept at its speed to the end of that segment (the log's next sample, which reads it off) "
    "instead of off from its start: the latest switch-off the log allows; both variants",
    "late start": "the default variant's own start rule for the approach (a late start at "
    "rest where the tilt needs v0 < 0, trimmed rotors) instead of the authors' start at "
    "t = 0; default",
    "heading 180 - yaw": "the heading from the other sense of the data's yaw (180° - yaw "
    "instead of yaw - 180°); both variants",
    "with motor2_cut_step": "the replica's one-tick cut of motor 2 (held to the first tick "
    "after the contact, then braked in one step with its spin-up kick); default",
    "with thrust_coefficient": "the authors' thrust coefficient 8.7e-8 N/rpm²; default",
    "without ground_tick_crash": "the replica's own crash rule (h <= -0.3 m at the ticks); replica",
    "without thrust_coefficient": "Table I's thrust coefficient everywhere; replica",
    "without motor2_cut_step": "motor 2 off from the contact by the schedule alone (no hold "
    "to the tick, no kick); replica",
    "with i03_hand_modification": "crash 1: bumper 2's contact force doubled and motor 2 cut "
    "though its log shows it running (the authors' undocumented modification); replica",
}


@dataclass(frozen=True)
class Matched:
    """The pre-impact conditions the authors matched in their simulation of a crash.

    From the crash set's description file (``spiri_crash_set_1.toml``):
    ``roll_deg``, ``pitch_deg`` Z-Y-X Euler angles as in docs/MODEL.md; the
    heading of the wall approach is ``yaw_from_wall_normal_deg - 180`` (rear
    first, bumper 2 leading); the vehicle starts at ``altitude_at_start_m``
    and climbs toward ``altitude_setpoint_m``.
    """

    speed_m_s: float
    roll_deg: float
    pitch_deg: float
    yaw_from_wall_normal_deg: float
    altitude_at_start_m: float
    altitude_setpoint_m: float

    @property
    def heading_deg(self) -> float:
        """The wall approach's heading (rear first), deg."""
        return self.yaw_from_wall_normal_deg - 180.0

    @property
    def inclination_deg(self) -> float:
        """The inclination toward the wall of this attitude (docs/STUDIES.md 1), deg."""
        from quadimpact.rotations import euler_zyx_to_quat, inclination_deg, quat_to_matrix

        q = euler_zyx_to_quat(*(math.radians(a) for a in (self.roll_deg, self.pitch_deg,
                                                          self.heading_deg)))  # fmt: skip
        return float(inclination_deg(quat_to_matrix(q)))

    def fields(self) -> dict[str, Any]:
        """The wall approach's fields for these conditions."""
        return {
            "heading_deg": self.heading_deg,
            "speed_m_s": self.speed_m_s,
            "inclination_deg": round(self.inclination_deg, 6),
            "roll_deg": self.roll_deg,
            "pitch_deg": self.pitch_deg,
            "start_altitude_m": self.altitude_at_start_m,
            "altitude_m": self.altitude_setpoint_m,
            "impact_time_s": MATCHED_CONTACT_TIME_S,
        }


@dataclass(frozen=True)
class Crash:
    """One row of the paper's Table III."""

    number: int
    heading_deg: float
    speed_m_s: float
    inclination_deg: float
    inclination_uncertainty_deg: float
    type_experiment: str
    type_paper_simulation: str
    flight: str  # the crash set's flight name
    log_file: str  # relative to the data folder
    matched: Matched

    def scenario(
        self,
        model: str = "default",
        conditions: str = "nominal",
        switches: Iterable[str] | None = None,
    ) -> WallApproach:
        """The crash's scenario in a model variant, at its nominal or matched conditions.

        Parameters
        ----------
        model : str
            The model variant.
        conditions : {"nominal", "matched"}
            Table III's conditions (the scenario file), or the authors' matched ones.
        switches : iterable of str, optional
            Switches of the authors' crash runs to apply (keys of
            :data:`REPLICA_CRASH_SWITCHES`, and :data:`HAND_MODIFICATION`);
            default: all of :data:`REPLICA_CRASH_SWITCHES` in the
            ``paper-replica`` variant, none otherwise.
        """
        if conditions not in CONDITIONS:
            raise ValueError(f"conditions: must be one of {CONDITIONS} (got {conditions!r})")
        base = scenario_file(self.number)
        update: dict[str, Any] = {"model": model}
        if conditions == "matched":
            update.update(self.matched.fields())
        if switches is None:
            switches = REPLICA_CRASH_SWITCHES if model == "paper-replica" else ()
        update.update(crash_run_changes(self.number, base, switches))
        if conditions == "matched":
            update["model_options"] = {**MATCHED_APPROACH_OPTIONS, **update["model_options"]}
        return WallApproach.model_validate({**base.model_dump(exclude_unset=True), **update})


def crash_run_changes(number: int, base: WallApproach, switches: Iterable[str]) -> dict[str, Any]:
    """The scenario fields that the switches of the authors' crash runs set.

    ``motor2_cut_step`` applies where the schedule has motor 2 off from the
    contact (a zero rate in its first segment: crashes 2-7); crash 1's motor 2
    runs, except with :data:`HAND_MODIFICATION`.
    """
    from quadimpact.packing.constants import RPM

    switches = set(switches)
    unknown = switches - set(REPLICA_CRASH_SWITCHES) - {HAND_MODIFICATION}
    if unknown:
        raise ValueError(f"unknown crash-run switches: {sorted(unknown)}")
    options = base.model_options.model_dump(exclude_none=True)
    overrides = dict(base.vehicle_overrides)
    if "ground_tick_crash" in switches:
        options["crash_rule"] = "ground-ticks"
    if "thrust_coefficient" in switches:
        overrides["thrust_coefficient"] = AUTHORS_THRUST_COEFFICIENT_N_PER_RPM2 / RPM**2
    motor2_off = base.power_off is not None and base.power_off.rates_rpm_per_s[0][1] == 0.0
    hand = HAND_MODIFICATION in switches and number == 1
    if ("motor2_cut_step" in switches and motor2_off) or hand:
        options["cut_step_motors"] = (2,)
    if hand:
        options["bumper_force_scale"] = (1.0, 2.0, 1.0, 1.0)
    return {"model_options": options, "vehicle_overrides": overrides}


# The matched conditions: the crash set's description file, spiri_crash_set_1.toml.
TABLE3: tuple[Crash, ...] = (
    Crash(1, 20.0, 0.7, 4.5, 7.0, "B", "B", "I-03", "spiri-crash-set-1/crash_3.mat",
          Matched(0.6856, -1.3, 10.0, 26.0, 0.2, 1.1)),
    Crash(2, 10.0, 1.1, 4.4, 7.0, "B", "B", "I-05", "spiri-crash-set-1/crash_5.mat",
          Matched(1.1056, 0.6, 4.4, 4.6, 0.2, 0.51)),
    Crash(3, 14.0, 1.1, 6.8, 7.0, "B", "B", "I-06", "spiri-crash-set-1/crash_6.mat",
          Matched(1.15, 4.0, 6.0, 11.0, 0.7, 1.37)),
    Crash(4, 14.0, 1.3, 11.0, 8.0, "B", "B", "I-07", "spiri-crash-set-1/crash_7.mat",
          Matched(1.351, -5.1, 6.7, 8.86, 0.6, 0.88)),
    Crash(5, 11.0, 2.0, 15.0, 7.0, "Other", "Other", "I-09", "spiri-crash-set-1/crash_9.mat",
          Matched(2.0283, -2.7, 9.4, 17.0, 0.6, 1.02)),
    Crash(6, 4.0, 2.7, 16.0, 7.0, "D", "D", "I-10", "spiri-crash-set-1/crash_10.mat",
          Matched(2.6799, -1.2, 16.0, 4.0, 0.6, 0.66)),
    Crash(7, 11.0, 2.0, 19.0, 8.0, "D", "D", "I-11", "spiri-crash-set-1/crash_11.mat",
          Matched(1.98, -2.2, 20.2, 8.5, 0.0, 0.92)),
)  # fmt: skip


def scenario_path(number: int) -> Path:
    """Path of the shipped scenario file of crash ``number`` (1-7)."""
    return Path(str(resources.files("quadimpact.experiments") / "crashes" / f"crash_{number}.toml"))


def scenario_file(number: int) -> WallApproach:
    """The validated scenario of crash ``number``."""
    scenario = load_scenario_file(scenario_path(number))
    if not isinstance(scenario, WallApproach):  # pragma: no cover - shipped files
        raise TypeError(f"crash_{number}.toml is not a wall approach")
    return scenario
