"""Checks of a prepared run before it runs: the initial state must not start inside a surface.

``simulation.setup`` calls them for every prepared run (so for ``simulate``,
``Simulation``, sweeps and the learning environment): the IMU must sit on the
vehicle and read its hover (:func:`check_imu`, once per shared packing: what
runs share), and the run must not start in contact
(:func:`check_initial_contact`, through :func:`check_prepared`, once per run):

* an **impact trial** starts its vehicle away from the wall (docs/RECOVERY.md
  5.1): a bumper already touching or in the wall at the start (depth > 0) is
  an input error;
* **any scenario** whose initial state has a bumper deeper than
  :data:`INITIAL_PENETRATION_TOL_M` (1 mm) in a contact surface is an input
  error: the contact law would start from an onset it never saw (``v_i``
  taken at first sight) and push the vehicle out with a force of a
  deflection nobody asked for.

The messages say which bumper, which surface and how deep, and name the
field to change. :func:`check_record_size` refuses, before any work, a run
whose raw record would exceed :data:`MAX_RECORD_MB` (``quadimpact run`` and
sweeps; ``--max-record-mb`` raises it). A sweep records such a run as failed with this message
(its ``reason``); the recovery study classes it ``invalid: started in
contact`` (:data:`STARTED_IN_CONTACT` is the phrase it looks for).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from quadimpact.core import shape_slots as SHP
from quadimpact.core.recording_slots import out_width
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.errors import InputError
from quadimpact.linalg import norm

__all__ = [
    "INITIAL_PENETRATION_TOL_M",
    "MAX_RECORD_MB",
    "STARTED_IN_CONTACT",
    "check_imu",
    "check_initial_contact",
    "check_prepared",
    "check_scenario_type",
    "whole_ticks",
    "check_record_size",
    "record_size_bytes",
]

#: Deepest bumper penetration into a surface that an initial state may have, m.
INITIAL_PENETRATION_TOL_M = 1e-3
#: The phrase of the impact trial's error (what the recovery study's classes look for).
STARTED_IN_CONTACT = "starts in contact with the wall"


def check_prepared(scenario: Any, setup: Any) -> None:
    """The checks of a prepared run's own state (``simulation.setup.prepare`` calls this once).

    :func:`check_initial_contact`. :func:`check_imu` checks what runs share,
    once per shared packing (``simulation.setup``), before this.
    """
    check_initial_contact(scenario, setup)


def check_imu(setup: Any) -> None:
    """Refuse an IMU that cannot serve the run: off the vehicle, or saturated at hover.

    Rules (the vehicle's gravity ``g``, its rotor arms and bumper radius):

    * the IMU sits on the vehicle: no farther from the CM than the rotors'
      reach (the longest arm plus the bumper radius);
    * the accelerometer range is at least ``g``: it reads ``g`` in hover, so
      a smaller range saturates in level flight;
    * the detector's threshold can be reached within the range: at most
      ``sqrt(2)`` times the range (two saturated horizontal axes; ``sqrt(3)``
      in world axes), else detection is impossible.

    Raises
    ------
    InputError
        The rule, the value and the limit, naming the ``[imu]`` field.
    """
    # the detector's slots, loaded where runs are prepared (not by a sweep's checks)
    from quadimpact.core.sensors import detection as DET

    scfg = setup.scfg
    if scfg is None or not scfg[IMS.SC_RATE] > 0.0:
        return
    vehicle = setup.vehicle
    position = np.asarray(scfg[IMS.SC_POS : IMS.SC_POS + 3], dtype=float)
    reach = vehicle.reach_m()
    distance = float(norm(np.asarray(position, dtype=np.float64)))
    if distance > reach:
        shown = ", ".join(f"{c:g}" for c in position)
        raise InputError(
            f"imu: position: ({shown}) m is {distance:.3g} m from the CM, off the vehicle (its "
            f"rotors and bumpers reach {reach:.3g} m): the IMU must sit on the vehicle"
        )
    g = float(vehicle.gravity_m_s2)
    accel_range = float(scfg[IMS.SC_RANGE_F])
    if accel_range <= 0.0:
        return
    if accel_range < g:
        raise InputError(
            f"imu: accel_range_m_s2: must be at least g = {g:g} m/s^2, what the accelerometer "
            f"reads in hover (got {accel_range:g}): it would saturate in level flight"
        )
    threshold = float(scfg[DET.SC_DET_THRESHOLD])
    reachable = accel_range * (math.sqrt(3.0) if scfg[DET.SC_DET_WORLD] > 0.5 else math.sqrt(2.0))
    if threshold > reachable:
        raise InputError(
            f"detection: threshold_g: {threshold / g:g} g = {threshold:.4g} m/s^2 can never be "
            f"read by an accelerometer of range {accel_range:g} m/s^2 per axis (at most "
            f"{reachable:.4g} m/s^2 horizontally): detection would be impossible; raise "
            "imu.accel_range_m_s2 or lower the threshold"
        )


def check_initial_contact(scenario: Any, setup: Any) -> None:
    """Refuse an initial state that starts in contact (impact trial) or inside a surface.

    Parameters
    ----------
    scenario : WallApproach or FlightScenario or ImpactTrial
        The validated scenario (its kind and fields name the problem).
    setup : RunSetup
        Its prepared run (``x0``, ``feat``, ``shapes``, ``shape_names``).

    Raises
    ------
    InputError
        One line: the bumper, the surface, the depth and what to change.
    """
    # the compiled contact geometry, loaded where runs are prepared (not by a sweep's checks)
    from quadimpact.simulation.approach import pair_depths_at

    kind = getattr(scenario, "kind", "scenario")
    n_features = setup.feat.shape[0]
    if n_features == 0:
        return
    every = pair_depths_at(setup.x0, setup.feat, setup.shapes, setup.pair_table())
    if not every.max(initial=-np.inf) > 0.0:  # no feature in any surface (NaN looks below)
        return
    for s, name in enumerate(setup.shape_names):
        depths = every[s * n_features : (s + 1) * n_features]  # pair c = s * n_features + f
        deepest = int(np.argmax(depths))
        depth = float(depths[deepest])
        feature = _feature_label(setup.feature_names[deepest])
        ground = setup.shapes[s, SHP.SH_IS_GROUND] > 0.5
        if kind == "impact-trial" and not ground and depth > 0.0:
            raise InputError(
                f"impact trial: {STARTED_IN_CONTACT}: {feature} is "
                f"{depth * 1e3:.1f} mm into it at the start (start_distance_m = "
                f"{float(scenario.start_distance_m):g} m is too short for this attitude; "
                "the trial must start before the first contact)"
            )
        if depth > INITIAL_PENETRATION_TOL_M:
            raise InputError(
                f"{kind}: the initial state has {feature} {depth * 1e3:.1f} mm "
                f"inside the {name}, more than the {INITIAL_PENETRATION_TOL_M * 1e3:g} mm "
                "tolerance for a start in contact (move the start away from it)"
            )


def _feature_label(name: str) -> str:
    """``bumper 2`` for the rings named by their number, ``feature cage`` otherwise."""
    return f"bumper {name}" if name.isdigit() else f"feature {name}"


# ------------------------------------------------------------ output size
#: The largest raw record (time series and IMU samples) a run may allocate by default, MB.
MAX_RECORD_MB = 1024.0


def vehicle_feature_count(scenario: Any) -> int:
    """The contact features of a scenario's vehicle (4, the rings, if it cannot be built:
    an invalid vehicle is refused, by name, when the run is prepared)."""
    try:
        return len(scenario.build_vehicle().contact_features())
    except Exception:
        return 4


def record_size_bytes(scenario: Any, n_features: int | None = None) -> int:
    """The memory of a run's raw record, bytes, from its scenario alone (before any work).

    ``final time x output rate`` rows of the time series (``core/layout.py``'s
    ``out_width`` columns of 8 bytes: the fixed ones and two per contact
    feature of the vehicle) and ``final time x IMU rate`` IMU samples
    (``NIMU`` columns); the tables built from them take about as much again.
    ``n_features``: :func:`vehicle_feature_count` of the scenario, when the
    caller knows it (a sweep, once per vehicle).
    """
    from quadimpact.inputs.resolve import control_rate_hz

    duration = float(scenario.final_time_s) - float(getattr(scenario, "start_time_s", 0.0) or 0.0)
    rows = math.ceil(max(duration, 0.0) * float(scenario.output_rate_hz)) + 2
    imu_rate = getattr(getattr(scenario, "imu", None), "rate_hz", None) or control_rate_hz(scenario)
    samples = math.ceil(max(duration, 0.0) * float(imu_rate)) + 1
    if n_features is None:
        n_features = vehicle_feature_count(scenario)
    return 8 * (rows * out_width(n_features) + samples * IMS.NIMU)


def check_record_size(
    scenario: Any, limit_mb: float = MAX_RECORD_MB, flag: str = "", n_features: int | None = None
) -> None:
    """Refuse a run whose raw record would exceed ``limit_mb`` (:func:`record_size_bytes`).

    Raises
    ------
    InputError
        With the estimate, what makes it (duration, rates) and how to raise the limit.
    """
    size = record_size_bytes(scenario, n_features)
    if size <= limit_mb * 1e6:
        return
    duration = float(scenario.final_time_s) - float(getattr(scenario, "start_time_s", 0.0) or 0.0)
    raise_it = f"; {flag} MB raises the limit" if flag else ""
    raise InputError(
        f"output: the run's record would take {size / 2**30:.1f} GiB ({duration:g} s at "
        f"output_rate_hz = {float(scenario.output_rate_hz):g}), more than the "
        f"{limit_mb:g} MB limit: lower output_rate_hz or final_time_s{raise_it}"
    )


# ------------------------------------------------------------ Python calls
def check_scenario_type(scenario: Any) -> None:
    """Refuse anything but a validated scenario, saying what is accepted and how to get one.

    Raises
    ------
    TypeError
        For ``None``, a mapping, a file path or any other object.
    """
    from quadimpact.inputs.scenarios import FlightScenario, ImpactTrial, WallApproach

    if isinstance(scenario, (WallApproach, FlightScenario, ImpactTrial)):
        return
    got = f"{type(scenario).__name__} {scenario!r}"
    if len(got) > 80:
        got = got[:77] + "..."
    hint = ""
    if isinstance(scenario, (str, bytes)) or hasattr(scenario, "__fspath__"):
        hint = "; for a file: quadimpact.inputs.scenarios.load_scenario_file(path)"
    elif isinstance(scenario, dict):
        hint = (
            "; for a mapping of scenario-file keys: "
            "quadimpact.inputs.scenarios.scenario_from_dict(d)"
        )
    raise TypeError(
        f"scenario: must be a WallApproach, FlightScenario or ImpactTrial (got {got}){hint}"
    )


def whole_ticks(n_ticks: Any) -> int:
    """A number of control ticks: an integer (``-1``: to the end); 1.5 or ``True`` refused."""
    import numbers

    if isinstance(n_ticks, bool) or not isinstance(n_ticks, numbers.Integral):
        raise TypeError(f"n_ticks: must be a whole number of control ticks (got {n_ticks!r})")
    if n_ticks < -1:
        raise ValueError(f"n_ticks: must be >= 0, or -1 for to the end (got {n_ticks!r})")
    return int(n_ticks)
