"""The seven real crashes of the paper's Table III, as scenarios.

The conditions (heading, impact speed, inclination and their uncertainties)
and the response types are the paper's Table III (docs/STUDIES.md section 4); the
motor power-off schedules and altitudes come from the crash set's data file
and are written into the scenario files in ``crashes/crash_N.toml``, shipped
with the package.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from quadimpact.inputs.scenarios import WallApproach, load_scenario_file

HEADING_UNCERTAINTY_DEG = 6.4  # Table III: psi +- 6.4 deg
SPEED_UNCERTAINTY_M_S = 0.01  # Table III: V_c +- 0.01 m/s


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

    def scenario(self, model: str = "default") -> WallApproach:
        """The crash's scenario file, in the given model variant."""
        return scenario_file(self.number).model_copy(update={"model": model})


TABLE3: tuple[Crash, ...] = (
    Crash(1, 20.0, 0.7, 4.5, 7.0, "B", "B", "I-03", "spiri-crash-set-1/crash_3.mat"),
    Crash(2, 10.0, 1.1, 4.4, 7.0, "B", "B", "I-05", "spiri-crash-set-1/crash_5.mat"),
    Crash(3, 14.0, 1.1, 6.8, 7.0, "B", "B", "I-06", "spiri-crash-set-1/crash_6.mat"),
    Crash(4, 14.0, 1.3, 11.0, 8.0, "B", "B", "I-07", "spiri-crash-set-1/crash_7.mat"),
    Crash(5, 11.0, 2.0, 15.0, 7.0, "Other", "Other", "I-09", "spiri-crash-set-1/crash_9.mat"),
    Crash(6, 4.0, 2.7, 16.0, 7.0, "D", "D", "I-10", "spiri-crash-set-1/crash_10.mat"),
    Crash(7, 11.0, 2.0, 19.0, 8.0, "D", "D", "I-11", "spiri-crash-set-1/crash_11.mat"),
)


def scenario_path(number: int) -> Path:
    """Path of the shipped scenario file of crash ``number`` (1-7)."""
    return Path(str(resources.files("quadimpact.experiments") / "crashes" / f"crash_{number}.toml"))


def scenario_file(number: int) -> WallApproach:
    """The validated scenario of crash ``number``."""
    scenario = load_scenario_file(scenario_path(number))
    if not isinstance(scenario, WallApproach):  # pragma: no cover - shipped files
        raise TypeError(f"crash_{number}.toml is not a wall approach")
    return scenario
