"""The summary of a run (``summary.json``, docs/STUDIES.md section 2) and its one-line outcome.

Built from the run's setup, its episodes and the kernel's raw stats (never the
time series: the loop keeps the samples' attitude excursion and the last
state in its stats): the status, warnings, the impact conditions reached at
the first onset, the approach solution and the metrics of
:mod:`quadimpact.simulation.metrics`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from quadimpact import __version__
from quadimpact.core import layout as L
from quadimpact.core.excursion import DEG
from quadimpact.inputs.scenarios import WallApproach
from quadimpact.linalg import dot, matvec
from quadimpact.rotations import inclination_deg, matrix_to_euler_zyx, quat_to_matrix
from quadimpact.simulation.estimation_metrics import estimation_metrics
from quadimpact.simulation.impacts import RunEpisodes
from quadimpact.simulation.metrics import impact_metrics_of, short_impacts_of
from quadimpact.simulation.recovery_metrics import onset_normal, recovery_metrics
from quadimpact.simulation.response_types import classify_response
from quadimpact.simulation.setup import RunSetup

__all__ = ["STATUS_NAMES", "build_summary", "describe_outcome"]

STATUS_NAMES = {
    L.STATUS_COMPLETED: "completed",
    L.STATUS_CRASHED: "crashed",
    L.STATUS_FAILED: "failed",
}
SPEED_CHECK_TOL_M_S = 1e-6  # reached impact speed vs request, warn beyond
ONSET_TIME_TOL_S = 1e-6  # first contact time vs T_c, warn beyond


def _nan_to_none(v: float) -> float | None:
    return None if v is None or (isinstance(v, float) and math.isnan(v)) else float(v)


def build_summary(setup: RunSetup, scenario: Any, episodes: Any, st: np.ndarray) -> dict[str, Any]:
    """The summary (docs/STUDIES.md section 2, docs/RECOVERY.md section 6) of a run.

    From the kernel's stats (among them the output samples' attitude
    excursion and the last sample's state: the state at the end of the run)
    and the episodes (a :class:`~quadimpact.simulation.impacts.RunEpisodes`,
    or a table of them); no time series.
    """
    obstacles = _obstacle_names(setup)
    if not isinstance(episodes, RunEpisodes):
        episodes = RunEpisodes.of_table(episodes, obstacles)
    status_code = int(st[L.ST_STATUS])
    status = STATUS_NAMES[status_code]
    warnings = list(setup.warnings)
    reason = L.REASON_TEXT[int(st[L.ST_REASON])]
    n_features = len(setup.feature_names)
    metrics = impact_metrics_of(episodes.impacts, n_features)
    rb = setup.vehicle.valid_depth_m()

    onset_t = float(st[L.ST_ONSET_T])
    speed = heading = incl = math.nan
    first_normal = None  # (bumper, contact normal) of the first obstacle contact
    if not math.isnan(onset_t):
        xo = st[L.ST_ONSET_X : L.ST_ONSET_X + L.NX]
        C = quat_to_matrix(xo[L.X_QUAT : L.X_QUAT + 4])  # the attitude at the onset
        vel = matvec(C, xo[L.X_VEL : L.X_VEL + 3])
        first_normal = onset_normal(  # the normal there, from the contact geometry
            st, episodes.first_obstacle, setup.feat, setup.shapes, setup.shape_names, C
        )
        if first_normal is not None:
            speed = -dot(vel, first_normal[1])
        heading = float(np.degrees(matrix_to_euler_zyx(C)[2]))
        incl = float(inclination_deg(C))

    crash_t = float(st[L.ST_CRASH_T])
    crash_pos = st[L.ST_CRASH_X : L.ST_CRASH_X + 3]
    max_pen = float(st[L.ST_MAX_DELTA])
    if max_pen > rb:
        warnings.append(_too_deep(setup, episodes.table(), max_pen, rb))
    if st[L.ST_MISSED_ONSETS] > 0:
        warnings.append(
            f"{int(st[L.ST_MISSED_ONSETS])} contact(s) found already penetrating "
            "(onset not located; v_i taken at first sight)"
        )
    short = _short_contact_warning(setup, episodes)
    if short:
        warnings.append(short)
    if st[L.ST_EPISODES_DROPPED] > 0:
        warnings.append(
            f"{int(st[L.ST_EPISODES_DROPPED])} episodes beyond the buffer were not recorded"
        )

    summary: dict[str, Any] = {
        "status": status,
        "reason": reason,
        "warnings": warnings,
        "model": getattr(scenario, "model", None),
        "model_options": setup.options.model_dump(),
        "controller": getattr(scenario, "controller", None),
        "vehicle": setup.vehicle.name,
        "delta_init_m": _nan_to_none(metrics["delta_init_m"]),
        "peak_force_n": _nan_to_none(metrics["peak_force_n"]),
        "initial_impact_duration_s": _nan_to_none(metrics["initial_impact_duration_s"]),
        "first_contact_s": _nan_to_none(onset_t),
        "impact_speed_m_s": _nan_to_none(speed),
        "heading_deg": getattr(scenario, "heading_deg", None),
        "inclination_deg": getattr(scenario, "inclination_deg", None),
        "impact_heading_deg": _nan_to_none(heading),
        "impact_inclination_deg": _nan_to_none(incl),
        "leading_bumpers": metrics["leading_bumpers"],
        "aft_bumpers": metrics["aft_bumpers"],
        "response_type": None
        if status == "failed"
        else classify_response(
            metrics["leading_bumpers"], metrics["subsequent_impacts"], not math.isnan(crash_t)
        ),
        "n_episodes": int(metrics["n_episodes"]),
        "n_grazes": int(metrics["n_grazes"]),
        "n_subsequent_impacts": int(metrics["n_subsequent_impacts"]),
        "n_subsequent_episodes": int(metrics["n_subsequent_episodes"]),
        "subsequent_impacts": metrics["subsequent_impacts"],
        "crash_time_s": _nan_to_none(crash_t),
        "power_off_time_s": _nan_to_none(float(st[L.ST_POWER_OFF_T])),
        "crash_position_m": None if math.isnan(crash_t) else [float(c) for c in crash_pos],
        "max_penetration_m": max_pen,
        "bumper_model_valid": bool(max_pen <= rb),
        "t_start_s": float(setup.t0),
        "t_final_s": float(st[L.ST_T_END]),
        "references": {k: float(v) for k, v in setup.references.items()},
        "quadimpact_version": __version__,
    }
    if setup.wall is not None:
        d = setup.wall.point_m[0]
        summary["wall_distance_m"] = d
        summary["crash_distance_from_wall_m"] = (
            None if math.isnan(crash_t) else float(d - crash_pos[0])
        )
        summary["approach"] = setup.approach
    if isinstance(scenario, WallApproach):
        summary["requested"] = {
            "heading_deg": scenario.heading_deg,
            "inclination_deg": scenario.inclination_deg,
            "speed_m_s": scenario.speed_m_s,
            "impact_time_s": scenario.impact_time_s,
        }
        if math.isnan(onset_t):
            warnings.append("the vehicle never touched the wall")
        else:
            if abs(onset_t - scenario.impact_time_s) > ONSET_TIME_TOL_S:
                warnings.append(
                    f"first contact at {onset_t:.6f} s, "
                    f"not at the requested {scenario.impact_time_s} s"
                )
            if abs(speed - scenario.speed_m_s) > SPEED_CHECK_TOL_M_S:
                warnings.append(
                    f"impact speed {speed:.6f} m/s differs from the requested {scenario.speed_m_s}"
                )
    final_state = setup.x0
    if st[L.ST_N_OUT] > 0:
        summary["attitude_excursion"] = excursion_deg(st)
        final_state = st[L.ST_X_LAST : L.ST_X_LAST + L.NX]
    summary["pre_impact"] = (
        scenario.resolved_pre_impact() if getattr(scenario, "controller", None) == "recovery"
        else None
    )  # fmt: skip
    summary["detection_threshold_m_s2"] = float(setup.scfg[L.SC_DET_THRESHOLD]) or None
    summary.update(
        recovery_metrics(
            st,
            None,  # the episodes' impacts and first obstacle contact are given
            feat=setup.feat,
            shapes=setup.shapes,
            surface_names=setup.shape_names,
            obstacle_names=obstacles,
            final_state=np.asarray(final_state, dtype=float),
            first_obstacle_contact=first_normal,
            impacts=episodes.obstacle_impacts,
        )
    )
    summary["final_altitude_m"] = _nan_to_none(-float(final_state[L.X_POS + 2]))
    summary["first_contact_bumper"] = None
    summary["first_contact_normal"] = None
    if first_normal is not None:
        summary["first_contact_bumper"] = int(first_normal[0])
        summary["first_contact_normal"] = [float(c) for c in first_normal[1]]
    summary.update(_estimation(setup, scenario, st))
    rings = setup.vehicle.features is None
    summary["outcome"] = describe_outcome(summary, None if rings else setup.feature_names)
    return summary


def excursion_deg(st: np.ndarray) -> dict[str, float]:
    """The output samples' attitude excursion (degrees), as
    :func:`~quadimpact.simulation.metrics.attitude_excursion_deg` of the time series
    gives it: the loop's ``ST_EXCURSION`` (``core/excursion.py``) in degrees."""
    e = st[L.ST_EXCURSION : L.ST_EXCURSION + L.NEX].tolist()
    return {
        "roll_excursion_deg": e[L.EX_DEV] * DEG,
        "pitch_excursion_deg": e[L.EX_DEV + 1] * DEG,
        "yaw_excursion_deg": e[L.EX_DEV + 2] * DEG,
        "tilt_max_deg": math.acos(e[L.EX_COS_TILT]) * DEG,
    }


def _estimation(setup: RunSetup, scenario: Any, st: np.ndarray) -> dict[str, Any]:
    """The estimator, the added sensors and the estimate's errors (docs/ESTIMATION.md 4)."""
    scfg = setup.scfg
    out: dict[str, Any] = {
        "estimator": setup.estimator,
        "estimator_settings": setup.estimator_settings,
        "sensors": getattr(scenario, "sensors", None),
        "impact_disturbance": bool(scfg[L.SC_IMPACT_TAU] > 0.0),
        "magnetometer": bool(scfg[L.SC_MAG] > 0.5),
        "pose_sensor": bool(scfg[L.SC_POSE] > 0.5),
    }
    out.update(estimation_metrics(st))
    return out


def _too_deep(setup: RunSetup, episodes: Any, max_pen: float, rb: float) -> str:
    """The warning of a penetration beyond the bumper radius (plainer for the ground)."""
    peaks = np.asarray(episodes["peak_delta_m"], dtype=float)
    surface = str(episodes["surface"][int(np.nanargmax(peaks))]) if np.any(peaks > rb) else ""
    if surface and surface not in _obstacle_names(setup):
        return (
            f"penetration {max_pen * 1e3:.1f} mm into the {surface}, beyond the bumper radius "
            f"{rb * 1e3:.0f} mm: only the bumper rims can touch a surface, so the body (and the "
            "CM) passed through the ground; ground contact shows the bumpers' touch-down, and "
            'ground = "crash" (the default) ends a run when the CM reaches the ground'
        )
    return (
        f"penetration {max_pen * 1e3:.1f} mm exceeds the bumper radius {rb * 1e3:.0f} mm: "
        "the body itself would be in the surface, beyond what the bumper model covers"
    )


def _short_contact_warning(setup: RunSetup, episodes: RunEpisodes) -> str:
    """A warning when an impact is shorter than the IMU's sample period ('' otherwise).

    Such an impact can fall between two IMU samples: the IMU (and the
    detection) may not see it at all (docs/STUDIES.md 2.2).
    """
    rate = float(setup.scfg[L.SC_RATE])
    if not rate > 0.0:
        return ""
    count, shortest = short_impacts_of(episodes.impacts, 1.0 / rate)
    if not count:
        return ""
    return (
        f"{count} impact(s) shorter than the IMU's sample period {1e3 / rate:.3g} ms "
        f"({rate:g} Hz; shortest {shortest:.3g} s): the IMU may take no sample during "
        "it and the detection may miss it (stiff bumpers make contacts short)"
    )


def _obstacle_names(setup: RunSetup) -> list[str]:
    """Names of the packed shapes that are obstacles (not the ground)."""
    return [n for k, n in enumerate(setup.shape_names) if setup.shapes[k, L.SH_IS_GROUND] < 0.5]


def describe_outcome(s: dict[str, Any], feature_names: Any = None) -> str:
    """One sentence saying what the run did after the first impact.

    ``feature_names``: the vehicle's named features (the leading ones are
    named, not numbered); ``None`` for the four bumper rings.
    """
    if s["status"] == "failed":
        return f"failed at t = {s['t_final_s']:.3f} s: {s['reason']}"
    if s["delta_init_m"] is None:
        first = "no contact"
    else:
        if feature_names is None:
            what = "bumper(s) " + ", ".join(str(b) for b in s["leading_bumpers"])
        else:
            what = "feature(s) " + ", ".join(feature_names[b - 1] for b in s["leading_bumpers"])
        first = (
            f"initial impact on {what} (delta_init {s['delta_init_m'] * 1e3:.2f} mm), "
            f"then {s['n_subsequent_impacts']} subsequent impact(s) "
            f"({s['n_subsequent_episodes']} episode(s))"
        )
    if s.get("t_detect_s") is not None:
        first += f"; impact detected at t = {s['t_detect_s']:.3f} s"
    if s.get("recovered"):
        first += f"; recovered (stage 4) at t = {s['t_stage4_s']:.3f} s"
    elif s.get("t_stage1_s") is not None:
        first += "; not recovered"
    if s["crash_time_s"] is not None:
        where = ""
        if s.get("crash_distance_from_wall_m") is not None:
            where = f", {s['crash_distance_from_wall_m']:.2f} m from the wall"
        return f"{first}; crashed at t = {s['crash_time_s']:.3f} s{where}"
    return f"{first}; still flying at t = {s['t_final_s']:.3f} s"
