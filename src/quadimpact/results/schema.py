"""The one schema of results: summary keys and table columns, with kinds, units and meaning.

Everything that describes what a run writes is defined here once:

* :data:`SUMMARY_KEYS`: the keys of ``summary.json`` (nested tables flattened
  with ``__``, as the sweep table's columns are), each with its kind, unit
  and a one-line description. The sweep table's columns
  (``quadimpact.sweep.store.SUMMARY_COLUMNS``) are derived from it, and a test
  checks that every summary a run produces has exactly these keys.
* :data:`EPISODE_COLUMNS`, :data:`TIMESERIES_COLUMNS`, :data:`IMU_COLUMNS`:
  the columns of ``episodes.csv``, ``timeseries.parquet`` and ``imu.parquet``.

Kinds: ``f`` float64, ``i`` integer, ``b`` boolean, ``s`` text, ``j`` a list
or table (JSON text in the sweep table). Units: SI; ``1`` for dimensionless;
``""`` for text and flags. Frames: inertial NED, body FRD (docs/MODEL.md 1).
docs/RESULTS.md explains each in full.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = [
    "BUMPERS",
    "feature_columns",
    "EPISODE_COLUMNS",
    "IMU_COLUMNS",
    "Key",
    "SUMMARY_KEYS",
    "TIMESERIES_COLUMNS",
    "summary_key",
]

#: Bumper numbers as printed everywhere outside the kernel (rotor j = bumper j).
BUMPERS: tuple[int, ...] = (1, 2, 3, 4)


def feature_columns(columns) -> list[tuple[str, str, str]]:
    """(feature name, deflection column, force column) of a time series, in column order.

    A ring vehicle's are ``("1", "delta1_m", "force1_n")`` to ``"4"`` (all
    four as soon as one numbered column is there, so that a missing bumper's
    column is named); a vehicle with named features has ``delta_<name>_m`` and
    ``force_<name>_n`` (``quadimpact.inputs.features.feature_column``).
    """
    import re

    found = []
    for c in columns:
        m = re.fullmatch(r"delta(\d+)_m|delta_(\w+)_m", str(c))
        if m and str(c) != "delta_init_m":
            found.append(m.group(1) or m.group(2))
    if any(name.isdigit() for name in found):  # the four bumpers are all there, or missed
        numbered = sorted({int(n) for n in found if n.isdigit()} | set(BUMPERS))
        found = [str(j) for j in numbered] + [n for n in found if not n.isdigit()]
    return [
        (n, f"delta{n}_m", f"force{n}_n") if n.isdigit() else (n, f"delta_{n}_m", f"force_{n}_n")
        for n in found
    ]


@dataclass(frozen=True)
class Key:
    """One summary key: flattened name, kind (f, i, b, s, j), unit and meaning."""

    name: str
    kind: str
    unit: str
    description: str


def _k(name: str, kind: str, unit: str, description: str) -> Key:
    return Key(name, kind, unit, description)


_MODEL_OPTIONS = (
    _k("model_options__yaw_reaction", "s", "", "rotor drag-torque sense and allocation yaw row"),
    _k("model_options__bumper1_yaw_twice", "b", "", "bumper 1's contact yaw moment counted twice"),
    _k("model_options__initial_rotor_speeds", "s", "", "initial rotor speed rule"),
    _k("model_options__attitude_mapping", "s", "", "heading/inclination to roll/pitch mapping"),
    _k("model_options__crash_rule", "s", "", "crash rule"),
    _k("model_options__approach_start", "s", "", "wall-approach start rule"),
    _k("model_options__spinup_reaction", "s", "", "rotor spin-up reaction (spin sign or not)"),
    _k("model_options__detection_tick_reference", "s", "", "recovery target at detection tick"),
    _k("model_options__contact_gate_m", "f", "m", "contact force gate on the CM distance (0: off)"),
    _k("model_options__pre_impact", "s", "", "recovery pre-impact rule of the model"),
    _k("model_options__cut_step_motors", "j", "", "motors a power-off cuts at the next tick"),
    _k("model_options__bumper_force_scale", "j", "", "factor on each bumper's contact force"),
)

_ERR_UNITS = {"deg": "deg", "m_s": "m/s", "rad_s": "rad/s", "m": "m"}
_PHASE_TEXT = {
    "pre": "before the first contact",
    "crash": "from the first contact to stage 4 (or the end)",
    "post": "after stage 4",
}
_ESTIMATION = tuple(
    _k(f"est_{q}_{stat}_{phase}_{unit}", "f", _ERR_UNITS[unit],
       f"estimation: {q} error, {'RMS' if stat == 'rms' else 'maximum'}, {_PHASE_TEXT[phase]}")
    for q, unit in (("attitude", "deg"), ("velocity", "m_s"), ("bias", "rad_s"), ("position", "m"))
    for phase in ("pre", "crash", "post")
    for stat in ("rms", "max")
)  # fmt: skip

SUMMARY_KEYS: tuple[Key, ...] = (
    _k("status", "s", "", "completed, crashed or failed"),
    _k("reason", "s", "", "why a run failed (empty otherwise)"),
    _k("warnings", "j", "", "warnings of the run, one sentence each"),
    _k("model", "s", "", "model variant"),
    *_MODEL_OPTIONS,
    _k("controller", "s", "", "controller name"),
    _k("vehicle", "s", "", "vehicle name"),
    _k("delta_init_m", "f", "m", "largest peak deflection of the initial impact"),
    _k("peak_force_n", "f", "N", "largest peak normal force of the initial impact"),
    _k("initial_impact_duration_s", "f", "s", "duration of the initial impact"),
    _k("first_contact_s", "f", "s", "time of the first contact with an obstacle"),
    _k("impact_speed_m_s", "f", "m/s", "CM speed along the contact normal at first contact"),
    _k("heading_deg", "f", "deg", "requested heading (wall approach)"),
    _k("inclination_deg", "f", "deg", "requested inclination (wall approach)"),
    _k("impact_heading_deg", "f", "deg", "yaw at the first contact"),
    _k("impact_inclination_deg", "f", "deg", "inclination at the first contact"),
    _k("leading_bumpers", "j", "", "bumpers of the initial impact"),
    _k("aft_bumpers", "j", "", "the other bumpers"),
    _k("response_type", "s", "", "A, B, C, D or Other (docs/STUDIES.md 3)"),
    _k("n_episodes", "i", "1", "contact episodes with obstacles"),
    _k("n_grazes", "i", "1", "grazes: obstacle episodes of under 1 % of the largest impulse"),
    _k("n_subsequent_impacts", "i", "1", "impacts after the initial one"),
    _k("n_subsequent_episodes", "i", "1", "episodes in those impacts"),
    _k("subsequent_impacts", "j", "", "bumpers of each subsequent impact"),
    _k("crash_time_s", "f", "s", "time of the crash (null: none)"),
    _k("power_off_time_s", "f", "s", "time the motor power-off started (null: none)"),
    _k("crash_position_m", "j", "m", "CM position at the crash, inertial NED"),
    _k("max_penetration_m", "f", "m", "deepest penetration of any bumper"),
    _k("bumper_model_valid", "b", "", "max_penetration_m within the bumper radius"),
    _k("t_start_s", "f", "s", "start time of the run"),
    _k("t_final_s", "f", "s", "time reached"),
    _k("references__altitude_m", "f", "m", "controller altitude reference"),
    _k("references__roll_rad", "f", "rad", "controller roll reference"),
    _k("references__pitch_rad", "f", "rad", "controller pitch reference"),
    _k("references__yaw_rad", "f", "rad", "controller yaw reference"),
    _k("quadimpact_version", "s", "", "version that produced the run"),
    _k("wall_distance_m", "f", "m", "X of the wall plane"),
    _k("crash_distance_from_wall_m", "f", "m", "wall X minus CM X at the crash"),
    _k("approach__start_time_s", "f", "s", "wall approach: start time"),
    _k("approach__start_x_m", "f", "m", "wall approach: start X"),
    _k("approach__start_speed_m_s", "f", "m/s", "wall approach: start speed"),
    _k("approach__late_start", "b", "", "wall approach: started late, at rest"),
    _k("approach__speed_residual_m_s", "f", "m/s", "wall approach: speed residual"),
    _k("requested__heading_deg", "f", "deg", "wall approach: requested heading"),
    _k("requested__inclination_deg", "f", "deg", "wall approach: requested inclination"),
    _k("requested__speed_m_s", "f", "m/s", "wall approach: requested impact speed"),
    _k("requested__impact_time_s", "f", "s", "wall approach: requested impact time"),
    _k("attitude_excursion__roll_excursion_deg", "f", "deg", "largest roll departure"),
    _k("attitude_excursion__pitch_excursion_deg", "f", "deg", "largest pitch departure"),
    _k("attitude_excursion__yaw_excursion_deg", "f", "deg", "largest yaw departure"),
    _k("attitude_excursion__tilt_max_deg", "f", "deg", "largest tilt from the reference"),
    _k("pre_impact", "s", "", "recovery controller's pre-impact behaviour in force"),
    _k("detection_threshold_m_s2", "f", "m/s^2", "impact detector threshold (null: off)"),
    _k("detected", "b", "", "the detector fired"),
    _k("not_detected", "b", "", "a contact happened and was never detected"),
    _k("false_detection", "b", "", "the detector fired before any contact"),
    _k("n_detections", "i", "1", "rising edges of the detection condition"),
    _k("t_detect_s", "f", "s", "time of the detecting IMU sample"),
    _k("detection_latency_s", "f", "s", "detection time minus first contact"),
    _k("normal_error_deg", "f", "deg", "wall-normal estimate vs the true contact normal"),
    _k("t_stage1_s", "f", "s", "recovery: tick of entry into stage 1 (detected)"),
    _k("t_stage2_s", "f", "s", "recovery: tick of entry into stage 2 (tilted away)"),
    _k("t_stage3_s", "f", "s", "recovery: tick of entry into stage 3 (level)"),
    _k("t_stage4_s", "f", "s", "recovery: tick of entry into stage 4 (recovered)"),
    _k("recovered", "b", "", "stage 4 reached before the final time"),
    _k("time_to_recover_s", "f", "s", "detection to stage 4"),
    _k("t_stage5_s", "f", "s", "recovery: tick of entry into stage 5 (hover, position hold)"),
    _k("time_to_hover_s", "f", "s", "detection to speed < 0.2 m/s and tilt < 5 deg for 0.5 s"),
    _k("height_loss_stage2_m", "f", "m", "altitude at detection minus at stage 2 entry"),
    _k("height_loss_stage3_m", "f", "m", "altitude at detection minus at stage 3 entry"),
    _k("height_loss_m", "f", "m", "altitude at detection minus at stage 4 entry"),
    _k("horizontal_drift_stage2_m", "f", "m", "horizontal distance detection -> stage 2"),
    _k("horizontal_drift_stage3_m", "f", "m", "horizontal distance detection -> stage 3"),
    _k("horizontal_drift_m", "f", "m", "horizontal distance detection -> stage 4"),
    _k("min_altitude_m", "f", "m", "lowest CM altitude of the run"),
    _k("impacts_after_detection", "i", "1", "impacts starting after the detection"),
    _k("max_tilt_deg", "f", "deg", "after detection: largest tilt from vertical"),
    _k("max_rate_rad_s", "f", "rad/s", "after detection: largest body rate"),
    _k("final_speed_m_s", "f", "m/s", "CM speed at the end of the run"),
    _k("final_altitude_m", "f", "m", "CM altitude at the end of the run"),
    _k("first_contact_bumper", "i", "1", "feature (bumper) of the first obstacle contact"),
    _k("first_contact_normal", "j", "1", "its contact normal there, inertial NED, unit"),
    _k("estimator", "s", "", "state estimator"),
    _k("estimator_settings", "s", "", "the estimator's parameters, name=value, ..."),
    _k("sensors", "s", "", "preset of sensors (null: none given)"),
    _k("impact_disturbance", "b", "", "the IMU's impact disturbance is on"),
    _k("magnetometer", "b", "", "the run has a magnetometer"),
    _k("pose_sensor", "b", "", "the run has a pose sensor"),
    *_ESTIMATION,
    _k("est_attitude_rms_run_deg", "f", "deg", "estimation: attitude error, RMS over the run"),
    _k(
        "est_attitude_rms_not_crash_deg",
        "f",
        "deg",
        "estimation: attitude error, RMS over the run but the crash (pre and post)",
    ),  # fmt: skip
    _k("outcome", "s", "", "one sentence on what the run did"),
    _k("integrator__steps", "i", "1", "accepted steps"),
    _k("integrator__rejected_steps", "i", "1", "rejected steps"),
    _k("integrator__rhs_evaluations", "i", "1", "right-hand-side evaluations"),
    _k("integrator__control_ticks", "i", "1", "controller updates"),
    _k("integrator__output_rows", "i", "1", "time-series rows"),
    _k("integrator__wall_time_s", "f", "s", "wall-clock time of the kernel (not in sweeps)"),
    _k("cost__kernel_cpu_s", "f", "s", "CPU time in the compiled loop (shooting runs included)"),
    _k("cost__total_cpu_s", "f", "s", "CPU time of the whole run, scenario to summary or row"),
)
"""Every summary key, flattened, in order."""

_BY_NAME = {k.name: k for k in SUMMARY_KEYS}


def summary_key(name: str) -> Key:
    """The :class:`Key` of a flattened summary key (``KeyError`` if unknown)."""
    return _BY_NAME[name]


#: Columns of the episodes table, in order (docs/RESULTS.md).
EPISODE_COLUMNS: tuple[str, ...] = (
    "bumper",
    "surface",
    "t_start_s",
    "t_end_s",
    "v_i_m_s",
    "peak_delta_m",
    "t_peak_s",
    "peak_force_n",
    "t_peak_force_s",
    "open",
)

#: Columns of the time-series table of a ring vehicle, in order (docs/RESULTS.md); a
#: vehicle with named features has ``delta_<name>_m`` and ``force_<name>_n`` instead.
TIMESERIES_COLUMNS: tuple[str, ...] = (
    "t_s",
    "x_m",
    "y_m",
    "z_m",
    "u_m_s",
    "v_m_s",
    "w_m_s",
    "vx_m_s",
    "vy_m_s",
    "vz_m_s",
    "q0",
    "q1",
    "q2",
    "q3",
    "p_rad_s",
    "q_rad_s",
    "r_rad_s",
    *(f"omega{j}_rad_s" for j in BUMPERS),
    *(f"omega_cmd{j}_rad_s" for j in BUMPERS),
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
    "altitude_m",
    *(f"delta{j}_m" for j in BUMPERS),
    *(f"force{j}_n" for j in BUMPERS),
    "stage",
)

#: Columns of the IMU table (imu.parquet), in order (docs/RESULTS.md): the
#: measured specific force (body FRD) and angular rate, the true ones, the
#: detector's horizontal measure, the magnetometer and the pose sensor (NaN
#: where absent), the estimate after the sample, the gyro's true bias and the
#: estimate's errors.
IMU_COLUMNS: tuple[str, ...] = (
    "t_s",
    "fx_m_s2",
    "fy_m_s2",
    "fz_m_s2",
    "p_rad_s",
    "q_rad_s",
    "r_rad_s",
    "fx_true_m_s2",
    "fy_true_m_s2",
    "fz_true_m_s2",
    "p_true_rad_s",
    "q_true_rad_s",
    "r_true_rad_s",
    "f_horizontal_m_s2",
    "mx",
    "my",
    "mz",
    "pose_x_m",
    "pose_y_m",
    "pose_z_m",
    "pose_q0",
    "pose_q1",
    "pose_q2",
    "pose_q3",
    "q0_hat",
    "q1_hat",
    "q2_hat",
    "q3_hat",
    "bias_p_hat_rad_s",
    "bias_q_hat_rad_s",
    "bias_r_hat_rad_s",
    "vx_hat_m_s",
    "vy_hat_m_s",
    "vz_hat_m_s",
    "x_hat_m",
    "y_hat_m",
    "z_hat_m",
    "bias_p_true_rad_s",
    "bias_q_true_rad_s",
    "bias_r_true_rad_s",
    "attitude_error_deg",
    "velocity_error_m_s",
    "bias_error_rad_s",
    "position_error_m",
)
