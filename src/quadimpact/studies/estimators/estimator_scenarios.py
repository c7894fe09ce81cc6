"""The estimator study's scenarios, estimators and switches (docs/ESTIMATION.md 8).

Two scenarios, each a function from a trial's index to a scenario mapping
(seeded: the same index gives the same trial with every estimator):

* ``impact`` (the default): quadimpact's impact trial (docs/RECOVERY.md 5)
  from the authors' distribution (roll, pitch, yaw, speed), with the
  ``impact`` sensors, the estimate in the loop;
* ``authors-2016``: the authors' estimator study, a hover then a
  position-controlled flight toward a waypoint behind the wall, the wall,
  the staged recovery, the end 5 s after stage 4; their sensors
  (``sensors = "authors-2016"``), the estimators out of the loop.

:data:`SWITCHES` names the replica's parts, each of which can be set back to
quadimpact's own trial on its own (``why they differ``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = [
    "AUTHORS_2016",
    "ESTIMATORS",
    "INITIAL_ERRORS",
    "SCENARIOS",
    "SWITCHES",
    "Approach",
    "estimator_rows",
    "trial_scenario",
]

#: The authors' figures (their saved results): crash-phase RMS attitude error, mean over
#: 250 trials, deg; with initial errors also the not-crash figure.
AUTHORS_2016 = {
    "none": {"cf": {"crash": 10.85}, "ekf": {"crash": 1.60}},
    "authors": {
        "cf": {"crash": 12.29, "not_crash": 5.68},
        "ekf": {"crash": 4.28, "not_crash": 3.74},
    },
}
SCENARIOS = ("impact", "authors-2016")
#: Trials whose error over time the report's figure averages.
CURVE_TRIALS = 20
INITIAL_ERRORS = ("none", "authors")

#: The estimators of the study: (row label, registered estimator, its parameters).
ESTIMATORS: tuple[tuple[str, str, dict[str, Any]], ...] = (
    ("ideal", "ideal", {}),
    ("cf", "complementary", {"form": "raw"}),
    ("ekf-as-written", "ekf-additive", {"transition": "as-written"}),
    ("ekf-additive", "ekf-additive", {"transition": "correct"}),
    ("complementary", "complementary", {}),
    ("ekf", "ekf", {}),
)
#: Which rows the authors' figures stand beside.
AUTHORS_ROWS = {"cf": "cf", "ekf-as-written": "ekf"}


@dataclass(frozen=True)
class Approach:
    """The authors' flight before the wall (the parts the spec leaves open are options).

    Attributes
    ----------
    hover_s : float
        Hover before the waypoint is set, s (their script of that month: about 4).
    start_distance_m : float
        CM distance from the wall at the start, m (1.125).
    waypoint_behind_m : tuple of 2 floats
        The waypoint's distance behind the wall, uniform between these, m (1.5-3.5).
    kp_1_s, kv_1_s, v_max_m_s, tilt_max_deg : float
        The position loop (:class:`~quadimpact.inputs.waypoint.Waypoint`).
    altitude_m : float
        Start altitude, m (5).
    after_recovery_s : float
        The run ends this long after stage 4, s (5).
    """

    hover_s: float = 4.0
    start_distance_m: float = 1.125
    waypoint_behind_m: tuple[float, float] = (1.5, 3.5)
    kp_1_s: float = 1.0
    kv_1_s: float = 2.0
    v_max_m_s: float = 2.5
    tilt_max_deg: float = 30.0
    altitude_m: float = 5.0
    after_recovery_s: float = 5.0


def _uniform(seed: int, key: int, index: int, lo: float, hi: float) -> float:
    """The ``index``-th of a stream of uniform draws (independent of how many are drawn)."""
    rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed, spawn_key=(key, index))))
    return float(lo + (hi - lo) * rng.random())


SWITCHES: tuple[str, ...] = (
    "flight", "gain", "rate", "impact_noise", "in_loop", "initial_error", "sensors",
)  # fmt: skip
"""The replica's parts, in the order the study sets them back to quadimpact's trial:
the flight before the wall (waypoint flight -> the impact trial's 0.32-m spin-down
start), the CF's gain (the authors' raw form -> quadimpact's unit form), the rate (the
authors' 100 Hz of the sensors, filters and controller -> quadimpact's 200 Hz), the
impact noise (replacing -> added), the estimators (observers -> in the loop), the
initial errors (as asked -> none), the rest of the sensor model (their IMU and
magnetometer -> the ``impact`` sensors: no magnetometer, biases of 0.05 m/s^2,
saturation, a gyro bias walk, the IMU at the
vehicle's IMU position)."""


#: The model of every trial: the staged law the study was built with, the default before
#: the benchmark (issue #45), so that its figures (docs/ESTIMATION.md 8) hold.
LAW_MODEL = "classic"


def trial_scenario(
    scenario: str,
    index: int,
    *,
    seed: int = 0,
    approach: Approach | None = None,
    back: frozenset[str] = frozenset(),
) -> dict[str, Any]:
    """The scenario mapping of trial ``index`` (no estimator yet).

    ``back``: switches of :data:`SWITCHES` set back to quadimpact's trial
    (``authors-2016`` only; ``gain`` and ``initial_error`` are the estimators').
    """
    if scenario == "impact":
        return _impact_trial(index, seed)
    a = approach or Approach()
    yaw = _uniform(seed, 0, index, -180.0, 180.0)
    if "flight" in back:
        base = _impact_trial(index, seed)
        base["final_time_s"] = 12.0
    else:
        lo, hi = a.waypoint_behind_m
        behind = _uniform(seed, 1, index, lo, hi)
        base = {
            "kind": "flight",
            "model": LAW_MODEL,
            "vehicle": "navi",
            "controller": "recovery",
            "pre_impact": "nominal",
            "nominal_controller": "cascade-pid",
            "position_m": [-a.start_distance_m, 0.0, -a.altitude_m],
            "euler_deg": [0.0, 0.0, yaw],
            "surfaces": [{"name": "wall", "point_m": [0.0, 0.0, 0.0], "normal": [-1.0, 0.0, 0.0]}],
            "ground": "none",
            "friction_coefficient": 0.3,
            "rotor_slew_limit_rad_s2": "vehicle",
            "output_rate_hz": 100.0,
            "final_time_s": a.hover_s + 12.0,
            "waypoint": {
                "x_m": behind,
                "y_m": 0.0,
                "time_s": a.hover_s,
                "kp_1_s": a.kp_1_s,
                "kv_1_s": a.kv_1_s,
                "v_max_m_s": a.v_max_m_s,
                "tilt_max_deg": a.tilt_max_deg,
            },
        }
    base["end_after_recovery_s"] = a.after_recovery_s
    base["estimate_in_loop"] = "in_loop" in back
    if "sensors" in back:
        base["sensors"] = "impact"
        imu: dict[str, Any] = {"preset": "impact", "rate_hz": 100.0}
        if "impact_noise" not in back:
            imu["impact_disturbance"] = {"mode": "replace"}
    else:
        base["sensors"] = "authors-2016"
        imu = {"preset": "authors-2016", "rate_hz": 100.0, "position": "cm"}
        if "impact_noise" in back:
            imu["impact_disturbance"] = {"mode": "add"}
    if "rate" in back:
        imu.pop("rate_hz")
    else:  # their code ran everything at 100 Hz: the sensors, the filters, the controller
        base["control_rate_hz"] = 100.0
    base["imu"] = imu
    base["seed"] = int(seed) * 1_000_003 + int(index)
    return base


def _impact_trial(index: int, seed: int) -> dict[str, Any]:
    """quadimpact's impact trial with the authors' distribution and the ``impact`` sensors."""
    return {
        "kind": "impact-trial",
        "model": LAW_MODEL,
        "roll_deg": _uniform(seed, 10, index, -15.0, 15.0),
        "pitch_deg": _uniform(seed, 11, index, -45.0, 45.0),
        "yaw_deg": _uniform(seed, 12, index, -45.0, 45.0),
        "speed_m_s": _uniform(seed, 13, index, 0.5, 2.5),
        "sensors": "impact",
        "output_rate_hz": 100.0,
        "seed": int(seed) * 1_000_003 + int(index),
    }


def estimator_rows(
    scenario: str,
    initial_error: str,
    back: frozenset[str] = frozenset(),
    initial_bias: str | None = None,
) -> list[tuple[str, str, dict[str, Any]]]:
    """The study's estimators with their parameters for a scenario and initial error.

    ``initial_error = "authors"``: ZYX Euler errors N(0, (2, 2, 5) deg) and the gyro
    bias estimate 0 (``ideal`` has none). ``initial_bias``: ``"true"`` or ``"zero"``
    whatever the initial error (None: ``zero`` with the authors' errors, else
    ``true``). ``gain`` in ``back``: the CF row in quadimpact's unit form.
    """
    rows = []
    authors = initial_error == "authors" and "initial_error" not in back
    for label, name, params in ESTIMATORS:
        p = dict(params)
        if label == "cf" and "gain" in back:
            p.pop("form")
        if name != "ideal":
            if authors:
                p["initial_euler_error_deg"] = [2.0, 2.0, 5.0]
            bias = initial_bias or ("zero" if authors else "true")
            if bias != "true":
                p["initial_bias"] = bias
        rows.append((label, name, p))
    return rows
