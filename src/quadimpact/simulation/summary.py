"""The summary of a run (``summary.json``, docs/STUDIES.md section 2) and its one-line outcome.

Built from the run's setup, its episodes and the kernel's raw stats (never the
time series: the loop keeps the samples' attitude excursion and the last
state in its stats): the status, warnings, the impact conditions reached at
the first onset, the approach solution and the metrics of
:mod:`quadimpact.simulation.metrics`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from quadimpact import __version__
from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP
from quadimpact.core.excursion import DEG
from quadimpact.core.excursion_slots import EX_COS_TILT, EX_DEV, NEX
from quadimpact.core.sensors import detection as DET
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.core.sensors.registry import config_address
from quadimpact.inputs.scenarios import WallApproach
from quadimpact.linalg import dot, matvec
from quadimpact.results.summary_record import (
    ApproachTable,
    EstimationPart,
    ExcursionPart,
    ExcursionTable,
    ImpactPart,
    ModelOptionsTable,
    OutcomePart,
    RecoveryPart,
    ReferencesTable,
    RequestedTable,
    RequestPart,
    RunPart,
    SpanPart,
    Summary,
    WallPart,
)
from quadimpact.rotations import inclination_deg, matrix_to_euler_zyx, quat_to_matrix
from quadimpact.simulation.estimation_metrics import estimation_metrics
from quadimpact.simulation.impacts import RunEpisodes
from quadimpact.simulation.metrics import impact_metrics_of, short_impacts_of
from quadimpact.simulation.recovery_metrics import onset_normal, recovery_metrics
from quadimpact.simulation.response_types import classify_response
from quadimpact.simulation.setup import RunSetup

__all__ = [
    "KIND_PARTS",
    "STATUS_NAMES",
    "build_summary",
    "describe_outcome",
    "episode_count",
    "summary_record",
]

STATUS_NAMES = {
    L.STATUS_COMPLETED: "completed",
    L.STATUS_CRASHED: "crashed",
    L.STATUS_FAILED: "failed",
}
_MAG_ON = config_address("magnetometer", "on")  # sensor components' switches
_POSE_ON = config_address("pose_sensor", "on")
SPEED_CHECK_TOL_M_S = 1e-6  # reached impact speed vs request, warn beyond
ONSET_TIME_TOL_S = 1e-6  # first contact time vs T_c, warn beyond


def _nan_to_none(v: float) -> float | None:
    return None if v is None or (isinstance(v, float) and math.isnan(v)) else float(v)


def build_summary(setup: RunSetup, scenario: Any, episodes: Any, st: np.ndarray) -> dict[str, Any]:
    """The summary (docs/STUDIES.md section 2, docs/RECOVERY.md section 6) of a run, as
    ``summary.json`` holds it: :func:`summary_record`'s parts, in order."""
    return _summary_dict(setup, scenario, episodes, st)[1]


@dataclass(frozen=True)
class _Onset:
    """The first contact with an obstacle: time, speed along its normal, heading and
    inclination (deg) there, and the (bumper, normal) of that contact (None: no contact)."""

    t: float
    speed: float
    heading: float
    inclination: float
    first_normal: tuple[int, np.ndarray] | None


def summary_record(setup: RunSetup, scenario: Any, episodes: Any, st: np.ndarray) -> Summary:
    """The typed summary of a run (:class:`quadimpact.results.summary_record.Summary`).

    From the kernel's stats (among them the output samples' attitude
    excursion and the last sample's state: the state at the end of the run)
    and the episodes (a :class:`~quadimpact.simulation.impacts.RunEpisodes`,
    or a table of them); no time series. The parts a scenario kind adds are
    :data:`KIND_PARTS`'s.
    """
    return _summary_dict(setup, scenario, episodes, st)[0]


def _summary_dict(
    setup: RunSetup, scenario: Any, episodes: Any, st: np.ndarray
) -> tuple[Summary, dict[str, Any]]:
    """:func:`summary_record` and its ``to_dict()``, the dict made once: the outcome
    sentence reads it, then takes its place in it (the last key but the counters')."""
    obstacles = _obstacle_names(setup)
    if not isinstance(episodes, RunEpisodes):
        episodes = RunEpisodes.of_table(episodes, obstacles)
    status = STATUS_NAMES[int(st[L.ST_STATUS])]
    warnings = list(setup.warnings)
    onset = _onset(setup, episodes, st)
    impact = _impact_part(setup, episodes, st, onset, status)
    warnings += _run_warnings(setup, episodes, st)
    request = (
        KIND_PARTS[scenario.kind](scenario, onset, warnings)
        if scenario.kind in KIND_PARTS
        else None
    )
    if request is not None:
        impact.heading_deg = request.requested.heading_deg
        impact.inclination_deg = request.requested.inclination_deg
    final_state = setup.x0
    excursion = None
    if st[L.ST_N_OUT] > 0:
        excursion = ExcursionPart(ExcursionTable(**excursion_deg(st)))
        final_state = st[L.ST_X_LAST : L.ST_X_LAST + L.NX]
    summary = Summary(
        run=RunPart(
            status=status,
            reason=L.REASON_TEXT[int(st[L.ST_REASON])],
            warnings=warnings,
            model=scenario.model,
            model_options=ModelOptionsTable(**_options_fields(setup.options)),
            controller=scenario.controller,
            vehicle=setup.vehicle.name,
        ),
        impact=impact,
        span=SpanPart(
            t_start_s=float(setup.t0),
            t_final_s=float(st[L.ST_T_END]),
            references=ReferencesTable(**{k: float(v) for k, v in setup.references.items()}),
            quadimpact_version=__version__,
        ),
        wall=_wall_part(setup, st),
        request=request,
        excursion=excursion,
        recovery=_recovery_part(setup, scenario, st, episodes, onset, final_state, obstacles),
        estimation=EstimationPart(**_estimation(setup, scenario, st)),
        outcome=OutcomePart(),
    )
    rings = setup.vehicle.features is None
    out = summary.to_dict()
    outcome = describe_outcome(out, None if rings else setup.feature_names)
    summary.outcome.outcome = out["outcome"] = outcome
    return summary, out


_OPTIONS_FIELDS: dict[int, tuple[Any, dict[str, Any]]] = {}


def _options_fields(options: Any) -> dict[str, Any]:
    """``options.model_dump()``, once per resolved options object (``inputs.model`` keeps
    them, frozen, per variant and overrides): a copy of the kept dict."""
    hit = _OPTIONS_FIELDS.get(id(options))
    if hit is None or hit[0] is not options:
        if len(_OPTIONS_FIELDS) >= 256:
            _OPTIONS_FIELDS.pop(next(iter(_OPTIONS_FIELDS)))
        hit = (options, options.model_dump())  # holds options, so its id stays its own
        _OPTIONS_FIELDS[id(options)] = hit
    return dict(hit[1])


def _onset(setup: RunSetup, episodes: RunEpisodes, st: np.ndarray) -> _Onset:
    """The state at the first contact with an obstacle (NaN and None without one)."""
    t = float(st[L.ST_ONSET_T])
    if math.isnan(t):
        return _Onset(t, math.nan, math.nan, math.nan, None)
    xo = st[L.ST_ONSET_X : L.ST_ONSET_X + L.NX]
    C = quat_to_matrix(xo[L.X_QUAT : L.X_QUAT + 4])  # the attitude at the onset
    vel = matvec(C, xo[L.X_VEL : L.X_VEL + 3])
    first_normal = onset_normal(  # the normal there, from the contact geometry
        st, episodes.first_obstacle, setup.feat, setup.shapes, setup.shape_names, C
    )
    speed = -dot(vel, first_normal[1]) if first_normal is not None else math.nan
    heading = float(np.degrees(matrix_to_euler_zyx(C)[2]))
    return _Onset(t, speed, heading, float(inclination_deg(C)), first_normal)


def _impact_part(
    setup: RunSetup, episodes: RunEpisodes, st: np.ndarray, onset: _Onset, status: str
) -> ImpactPart:
    """The initial impact, the later ones and the crash."""
    metrics = impact_metrics_of(episodes.impacts, len(setup.feature_names))
    crash_t = float(st[L.ST_CRASH_T])
    crash_pos = st[L.ST_CRASH_X : L.ST_CRASH_X + 3]
    max_pen = float(st[L.ST_MAX_DELTA])
    return ImpactPart(
        delta_init_m=_nan_to_none(metrics["delta_init_m"]),
        peak_force_n=_nan_to_none(metrics["peak_force_n"]),
        initial_impact_duration_s=_nan_to_none(metrics["initial_impact_duration_s"]),
        first_contact_s=_nan_to_none(onset.t),
        impact_speed_m_s=_nan_to_none(onset.speed),
        impact_heading_deg=_nan_to_none(onset.heading),
        impact_inclination_deg=_nan_to_none(onset.inclination),
        leading_bumpers=metrics["leading_bumpers"],
        aft_bumpers=metrics["aft_bumpers"],
        response_type=None
        if status == "failed"
        else classify_response(
            metrics["leading_bumpers"], metrics["subsequent_impacts"], not math.isnan(crash_t)
        ),
        n_episodes=int(metrics["n_episodes"]),
        n_grazes=int(metrics["n_grazes"]),
        n_subsequent_impacts=int(metrics["n_subsequent_impacts"]),
        n_subsequent_episodes=int(metrics["n_subsequent_episodes"]),
        subsequent_impacts=metrics["subsequent_impacts"],
        crash_time_s=_nan_to_none(crash_t),
        power_off_time_s=_nan_to_none(float(st[L.ST_POWER_OFF_T])),
        crash_position_m=None if math.isnan(crash_t) else [float(c) for c in crash_pos],
        max_penetration_m=max_pen,
        bumper_model_valid=bool(max_pen <= setup.vehicle.valid_depth_m()),
    )


def _run_warnings(setup: RunSetup, episodes: RunEpisodes, st: np.ndarray) -> list[str]:
    """What a run's record says is beyond its model: too deep, onsets missed, short
    impacts, episodes dropped."""
    warnings = []
    rb = setup.vehicle.valid_depth_m()
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
    return warnings


def _wall_part(setup: RunSetup, st: np.ndarray) -> WallPart | None:
    """The wall plane and the approach solve, for a run with a wall (None otherwise)."""
    if setup.wall is None:
        return None
    d = setup.wall.point_m[0]
    crash_t = float(st[L.ST_CRASH_T])
    crash_x = float(st[L.ST_CRASH_X])
    return WallPart(
        wall_distance_m=d,
        crash_distance_from_wall_m=None if math.isnan(crash_t) else float(d - crash_x),
        # an empty table: no approach was solved (an impact trial against the wall)
        approach=ApproachTable(**setup.approach) if setup.approach else {},
    )


def _wall_approach_request(
    scenario: WallApproach, onset: _Onset, warnings: list[str]
) -> RequestPart:
    """What a wall approach asked for; a warning where the run did not reach it."""
    if math.isnan(onset.t):
        warnings.append("the vehicle never touched the wall")
    else:
        if abs(onset.t - scenario.impact_time_s) > ONSET_TIME_TOL_S:
            warnings.append(
                f"first contact at {onset.t:.6f} s, not at the requested {scenario.impact_time_s} s"
            )
        if abs(onset.speed - scenario.speed_m_s) > SPEED_CHECK_TOL_M_S:
            warnings.append(
                f"impact speed {onset.speed:.6f} m/s differs from the requested "
                f"{scenario.speed_m_s}"
            )
    return RequestPart(
        RequestedTable(
            heading_deg=scenario.heading_deg,
            inclination_deg=scenario.inclination_deg,
            speed_m_s=scenario.speed_m_s,
            impact_time_s=scenario.impact_time_s,
        )
    )


#: The summary part a scenario kind adds, by its ``kind`` (with the warnings it gives).
KIND_PARTS: dict[str, Callable[[Any, _Onset, list[str]], RequestPart]] = {
    "wall-approach": _wall_approach_request,
}


def _recovery_part(
    setup: RunSetup,
    scenario: Any,
    st: np.ndarray,
    episodes: RunEpisodes,
    onset: _Onset,
    final_state: np.ndarray,
    obstacles: list[str],
) -> RecoveryPart:
    """Detection, the recovery stages and the run's end (docs/RECOVERY.md 6)."""
    metrics = recovery_metrics(
        st,
        None,  # the episodes' impacts and first obstacle contact are given
        feat=setup.feat,
        shapes=setup.shapes,
        surface_names=setup.shape_names,
        obstacle_names=obstacles,
        final_state=np.asarray(final_state, dtype=float),
        first_obstacle_contact=onset.first_normal,
        impacts=episodes.obstacle_impacts,
    )
    first = onset.first_normal
    return RecoveryPart(
        pre_impact=scenario.resolved_pre_impact() if scenario.controller == "recovery" else None,
        detection_threshold_m_s2=float(setup.scfg[DET.SC_DET_THRESHOLD]) or None,
        final_altitude_m=_nan_to_none(-float(final_state[L.X_POS + 2])),
        first_contact_bumper=None if first is None else int(first[0]),
        first_contact_normal=None if first is None else [float(c) for c in first[1]],
        **metrics,
    )


def excursion_deg(st: np.ndarray) -> dict[str, float]:
    """The output samples' attitude excursion (degrees), as
    :func:`~quadimpact.simulation.metrics.attitude_excursion_deg` of the time series
    gives it: the loop's ``ST_EXCURSION`` (``core/excursion.py``) in degrees."""
    e = st[L.ST_EXCURSION : L.ST_EXCURSION + NEX].tolist()
    return {
        "roll_excursion_deg": e[EX_DEV] * DEG,
        "pitch_excursion_deg": e[EX_DEV + 1] * DEG,
        "yaw_excursion_deg": e[EX_DEV + 2] * DEG,
        "tilt_max_deg": math.acos(e[EX_COS_TILT]) * DEG,
    }


def _estimation(setup: RunSetup, scenario: Any, st: np.ndarray) -> dict[str, Any]:
    """The estimator, the added sensors and the estimate's errors (docs/ESTIMATION.md 4)."""
    scfg = setup.scfg
    out: dict[str, Any] = {
        "estimator": setup.estimator,
        "estimator_settings": setup.estimator_settings,
        "sensors": getattr(scenario, "sensors", None),
        "impact_disturbance": bool(scfg[IMS.SC_IMPACT_TAU] > 0.0),
        "magnetometer": bool(scfg[_MAG_ON] > 0.5),
        "pose_sensor": bool(scfg[_POSE_ON] > 0.5),
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
    rate = float(setup.scfg[IMS.SC_RATE])
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
    return [n for k, n in enumerate(setup.shape_names) if setup.shapes[k, SHP.SH_IS_GROUND] < 0.5]


def episode_count(s: Mapping[str, Any]) -> int | None:
    """The run's contact episodes with obstacles, the initial impact's included (None: unknown).

    One definition (the summary's ``n_episodes``), for the run's outcome
    sentence (the viewer's headline) and ``quadimpact run``'s summary.
    """
    n = s.get("n_episodes")
    return None if n is None else int(n)


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
            f"then {s['n_subsequent_impacts']} subsequent impact(s)"
        )
        n = episode_count(s)
        if n is not None:
            first += f"; {n} contact episode{'' if n == 1 else 's'} in all"
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
