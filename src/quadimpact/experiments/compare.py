"""Compare a simulated run with a flight log, aligned at the impact.

:func:`compare` puts both on the time since impact, ``tau = t - t_impact``
(the simulation's first contact, the log's :attr:`FlightLog.impact_time_s`),
interpolates the simulation (1 kHz) onto the log's own sample times (the log
is the reference) and reports, over ``[0, w]`` for each window ``w``, the RMS
and largest absolute error per quantity and per group:

========  ===============================================  =====
group     quantities                                       unit
========  ===============================================  =====
position  X, Y, altitude: displacement since the impact    m
attitude  roll, pitch, yaw (unwrapped, see below)        deg
rates     body rates p, q, r                               rad/s
motors    rotor speeds 1-4 (log samples with the motor on) rad/s
========  ===============================================  =====

Positions are compared as displacements from each one's own position at the
impact (``relative_position=True``): the log's motion-capture origin and the
simulated wall distance and altitude differ by construction.

Roll and yaw are unwrapped on both sides (continuous through +-180 deg), and
the log's are moved by whole turns onto the simulation's branch at the
impact: a yaw of -175 deg against a logged +175 deg is 10 deg apart, not 350,
in the errors and in the plot. The errors are the differences of the
unwrapped angles (not wrapped again), so two motions that turn apart by more
than half a turn show it. Near 90 deg of pitch roll and yaw themselves jump
by 180 deg (the Euler angles' singularity); the ``rotation`` error (the angle
between the two attitudes) has no such jumps.

:func:`log_response` classifies the log's response type (docs/STUDIES.md section
3) from the log's own motion, where the motion capture allows it, and says
why not otherwise. (The tests turn a simulated run into a :class:`FlightLog`,
``tests/synthetic_log.py``: a run compared with itself has zero error.)
"""

from __future__ import annotations

import math
import os
import textwrap
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from quadimpact import libm
from quadimpact.experiments.log_estimates import MOCAP_GAP_S, bumper_rim_extent
from quadimpact.experiments.logs import FlightLog, PreImpact
from quadimpact.linalg import norm
from quadimpact.rotations import quat_to_matrix, unwrap_deg, wrap_angle_deg
from quadimpact.simulation.response_types import classify_response

if TYPE_CHECKING:  # Matplotlib only where a figure is drawn
    from matplotlib.figure import Figure

__all__ = [
    "CONTACT_TOL_M",
    "GROUPS",
    "LANDING_DROP_M",
    "LANDING_HOLD_S",
    "LANDING_TOL_M",
    "SEPARATION_M",
    "Comparison",
    "LogResponse",
    "compare",
    "log_response",
]

#: Quantity groups: group -> (unit, [(quantity, column, wrapped)]).
GROUPS: dict[str, tuple[str, list[tuple[str, str, bool]]]] = {
    "position": ("m", [("X", "x_m", False), ("Y", "y_m", False),
                       ("altitude", "altitude_m", False)]),
    "attitude": ("deg", [("roll", "roll_deg", True), ("pitch", "pitch_deg", False),
                         ("yaw", "yaw_deg", True)]),
    "rates": ("rad/s", [("p", "p_rad_s", False), ("q", "q_rad_s", False),
                        ("r", "r_rad_s", False)]),
    "motors": ("rad/s", [(f"omega{j}", f"omega{j}_rad_s", False) for j in range(1, 5)]),
}  # fmt: skip

#: Log response: a bumper touches the wall when its rim is within CONTACT_TOL_M
#: of the wall plane; an impact ends when every rim is SEPARATION_M away.
CONTACT_TOL_M = 0.01
SEPARATION_M = 0.02
#: A crash (landing) is seen when the altitude falls this much below the impact's.
LANDING_DROP_M = 0.3
#: The landing: the first time the altitude is within this of its post-impact minimum,
#: that minimum followed by at least LANDING_HOLD_S of tracking (or the log ending
#: at rest with the motors off).
LANDING_TOL_M = 0.05
LANDING_HOLD_S = 0.2


# ------------------------------------------------------------------ log response
@dataclass(frozen=True)
class LogResponse:
    """The response type of a logged crash, from its own motion.

    Attributes
    ----------
    type : str
        ``"A"``, ``"B"``, ``"C"``, ``"D"``, ``"Other"`` (docs/STUDIES.md section 3)
        or ``"unknown"`` when the motion capture does not cover the impact to
        the landing.
    crashed : bool or None
        Whether the vehicle came down (None: not decidable).
    landing_time_s : float or None
        Reference clock.
    leading_bumpers : tuple of int
        Bumpers of the initial impact (log numbering).
    subsequent_impacts : tuple of tuple of int
        Later impacts seen before the tracking ended, bumpers in start order.
    tracked_until_s : float or None
        End of the continuous motion capture after the impact.
    notes : tuple of str
        What was and was not observable.
    """

    type: str
    crashed: bool | None = None
    landing_time_s: float | None = None
    leading_bumpers: tuple[int, ...] = ()
    subsequent_impacts: tuple[tuple[int, ...], ...] = ()
    tracked_until_s: float | None = None
    notes: tuple[str, ...] = ()


def _crashed_from_motors(log: FlightLog) -> bool | None:
    """All motors off after the impact and the vehicle at rest: it came down."""
    try:
        mot = log.motors()
    except (KeyError, NotImplementedError):
        return None
    after = mot[mot["t_s"] > log.impact_time_s]
    if after.empty:
        return None
    offs = after[[f"off{j}" for j in range(1, 5)]].to_numpy().all(axis=1)
    rest = log.rest_time_s
    if offs.any() and rest is not None:
        return True
    return None


def log_response(log: FlightLog, *, contact_tol_m: float = CONTACT_TOL_M) -> LogResponse:
    """Classify a log's response type from its own motion (see the module docstring).

    Observable: the wall contacts of the bumper rims (motion-capture pose,
    the bumper geometry of the Spiri, the wall plane found at the contact) and
    the landing (altitude dropping :data:`LANDING_DROP_M` below the impact's
    and settling). Not observable: contacts after the motion capture loses the
    vehicle (common: it tumbles), contacts of parts other than the bumper rims,
    contacts shallower than the wall-plane uncertainty (~1-2 cm). The type is
    ``"unknown"`` unless the tracking is continuous (gaps <= ``MOCAP_GAP_S``)
    from the impact to the landing or, without a landing, to the log's end.
    The on-board signals (15 Hz, saturating during the tumble) cannot separate
    later impacts from the tumble itself, so they only decide the crash.
    """
    notes: list[str] = []
    crashed_motors = _crashed_from_motors(log)
    pose = log.pose()
    t0 = log.impact_time_s
    wall = log.wall_x_m
    if pose.empty or not math.isfinite(wall):
        notes.append("no motion capture of the impact (or no wall plane): contacts not observable")
        return LogResponse("unknown", crashed=crashed_motors, notes=tuple(notes))
    t = pose["t_s"].to_numpy()
    tracked = _tracked_after_impact(t, t0)
    if isinstance(tracked, str):
        notes.append(tracked)
        return LogResponse("unknown", crashed=crashed_motors, notes=tuple(notes))
    idx, observed_to_end = tracked
    tp = t[idx]
    tracked_until = float(tp[-1])
    touching, separated = _rims_at_wall(pose, idx, wall, contact_tol_m)
    impacts = _rim_impacts(touching, separated)
    if not impacts:
        pi = log.pre_impact()
        lead = [pi.leading_bumper] if isinstance(pi, PreImpact) and pi.leading_bumper else []
        impacts = [lead]
        notes.append("no rim within the contact tolerance after the impact; leading bumper "
                     "taken from the pre-impact estimate")  # fmt: skip
    leading = tuple(impacts[0])
    subsequent = tuple(tuple(i) for i in impacts[1:])
    landing = _landing(pose["altitude_m"].to_numpy()[idx], tp, crashed_motors)
    crashed: bool | None = True if landing is not None else None
    if landing is None:
        if crashed_motors:
            notes.append(f"motion capture lost at {tracked_until - t0:+.3f} s after the "
                         "impact, before the landing; the motors are off and the vehicle "
                         "ends at rest, so it crashed")  # fmt: skip
            return LogResponse("unknown", crashed=True, leading_bumpers=leading,
                               subsequent_impacts=subsequent, tracked_until_s=tracked_until,
                               notes=tuple(notes))  # fmt: skip
        if not observed_to_end:
            notes.append(f"motion capture lost at {tracked_until - t0:+.3f} s after the impact")
            return LogResponse("unknown", crashed=None, leading_bumpers=leading,
                               subsequent_impacts=subsequent, tracked_until_s=tracked_until,
                               notes=tuple(notes))  # fmt: skip
        crashed = False
    # contacts after the landing are not subsequent impacts
    if landing is not None:
        kept = []
        starts = _impact_starts(touching, separated, tp)
        for imp, ts in zip(impacts[1:], starts[1:], strict=False):
            if ts <= landing:
                kept.append(tuple(imp))
        subsequent = tuple(kept)
    kind = classify_response(leading, subsequent, bool(crashed))
    notes.append("contacts from the bumper rims in the motion capture; the landing from "
                 "the altitude")  # fmt: skip
    return LogResponse(kind, crashed=crashed, landing_time_s=landing, leading_bumpers=leading,
                       subsequent_impacts=subsequent, tracked_until_s=tracked_until,
                       notes=tuple(notes))  # fmt: skip


def _tracked_after_impact(t: np.ndarray, t0: float) -> tuple[np.ndarray, bool] | str:
    """The motion-capture samples (indices into the times ``t``, s) tracked without a gap
    over :data:`MOCAP_GAP_S` from the impact ``t0`` (s; from 20 ms before it), and whether
    they reach the log's end; or, where the tracking does not cover the impact, why not."""
    post = t >= t0 - 0.02
    if not post.any():
        return "motion capture ends before the impact"
    idx = np.flatnonzero(post)
    tp = t[idx]
    gaps = np.flatnonzero(np.diff(tp) > MOCAP_GAP_S)
    end = int(gaps[0]) + 1 if gaps.size else len(idx)
    if tp[0] > t0 + MOCAP_GAP_S:
        return f"motion capture resumes only {tp[0] - t0:.3f} s after the impact"
    return idx[:end], end == len(idx) and float(tp[end - 1]) >= t[-1] - 1e-9


def _rims_at_wall(
    pose: pd.DataFrame, idx: np.ndarray, wall: float, contact_tol_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """At the pose samples ``idx``: which bumper rims touch the wall plane ``X = wall``
    (m; within ``contact_tol_m``), (n, 4), and whether every rim is separated from it
    (farther than :data:`SEPARATION_M`), (n,)."""
    q = pose[["q0", "q1", "q2", "q3"]].to_numpy()[idx]
    C = quat_to_matrix(q)
    reach = bumper_rim_extent(C, np.array([1.0, 0.0, 0.0]))
    rim = pose["x_m"].to_numpy()[idx][:, None] + reach  # (n, 4)
    return rim >= wall - contact_tol_m, (rim < wall - SEPARATION_M).all(axis=1)


def _rim_impacts(touching: np.ndarray, separated: np.ndarray) -> list[list[int]]:
    """The impacts seen in the motion capture: runs of samples with a rim touching the wall,
    each ended by a sample with every rim fully separated; each impact's bumpers (1-4) in
    the order they touched."""
    impacts: list[list[int]] = []
    current: list[int] | None = None
    for k in range(len(touching)):
        if touching[k].any():
            if current is None:
                current = []
                impacts.append(current)
            for b in np.flatnonzero(touching[k]) + 1:
                if int(b) not in current:
                    current.append(int(b))
        elif separated[k]:
            current = None
    return impacts


def _landing(alt: np.ndarray, t: np.ndarray, crashed_motors: bool) -> float | None:
    """The landing's time: the altitude dropped :data:`LANDING_DROP_M` below the impact's
    and settled (or the motors are off); None without one."""
    if not alt.min() < float(alt[0]) - LANDING_DROP_M:
        return None
    k = int(np.argmax(alt <= alt.min() + LANDING_TOL_M))
    settled = t[-1] - t[int(np.argmin(alt))] >= LANDING_HOLD_S
    return float(t[k]) if settled or crashed_motors else None


def _impact_starts(touching: np.ndarray, separated: np.ndarray, t: np.ndarray) -> list[float]:
    starts: list[float] = []
    inside = False
    for k in range(len(t)):
        if touching[k].any():
            if not inside:
                starts.append(float(t[k]))
                inside = True
        elif separated[k]:
            inside = False
    return starts


# ------------------------------------------------------------------ comparison
def _interp_segments(t_new: np.ndarray, t: np.ndarray, y: np.ndarray, gap: float) -> np.ndarray:
    """Linear interpolation that gives nan inside gaps longer than ``gap`` and outside."""
    out = np.interp(t_new, t, y, left=np.nan, right=np.nan)
    if len(t) > 1:
        k = np.clip(np.searchsorted(t, t_new), 1, len(t) - 1)
        bad = (t[k] - t[k - 1] > gap) & (t_new > t[k - 1]) & (t_new < t[k])
        out[bad] = np.nan
    return out


@dataclass
class Comparison:
    """A simulated run against a log, aligned at the impact (see :func:`compare`).

    Attributes
    ----------
    errors : pandas.DataFrame
        ``group, quantity, unit, window_s, rms, max_abs, n``; per quantity and
        per group (``quantity == "all"``: all the group's samples together).
    sim : pandas.DataFrame
        The simulation on ``tau_s`` (its own samples), relative positions.
    log_pose, log_motors : pandas.DataFrame
        The log on ``tau_s`` (its own samples), relative positions.
    sim_response : str or None
        The run's response type (``summary["response_type"]``).
    log_response : LogResponse or None
    """

    name: str
    windows: tuple[float, ...]
    errors: pd.DataFrame
    sim: pd.DataFrame
    log_pose: pd.DataFrame
    log_motors: pd.DataFrame
    t_impact_sim: float
    t_impact_log: float
    sim_response: str | None = None
    log_response: LogResponse | None = None
    notes: list[str] = field(default_factory=list)

    def table(self) -> pd.DataFrame:
        """The error table (a copy), one row per (group, quantity, window)."""
        return self.errors.copy()

    def error(self, group: str, window_s: float, quantity: str = "all",
              stat: str = "rms") -> float:  # fmt: skip
        """One number of the table, e.g. ``error("attitude", 0.3)``."""
        e = self.errors
        row = e[(e.group == group) & (e.quantity == quantity) & np.isclose(e.window_s, window_s)]
        if row.empty:
            raise KeyError((group, quantity, window_s))
        return float(row[stat].iloc[0])

    def departures(self, window_s: float = 0.3) -> dict[str, tuple[float, float]]:
        """How far each Euler angle moved after the impact, in the run and in the log.

        Parameters
        ----------
        window_s : float
            The window ``[0, window_s]`` after the impact.

        Returns
        -------
        dict
            ``{"roll": (sim, log), "pitch": ..., "yaw": ...}``, deg: the signed
            largest departure from the value at the impact (roll and yaw
            unwrapped), each on its own samples; nan where a side has none.
        """
        out = {}
        for name, col, _ in GROUPS["attitude"][1]:
            pair = []
            for table in (self.sim, self.log_pose):
                if col not in table:
                    pair.append(math.nan)
                    continue
                tau, y = table["tau_s"].to_numpy(), table[col].to_numpy(dtype=float)
                ok = np.isfinite(y)
                inside = ok & (tau >= 0.0) & (tau <= window_s)
                if not inside.any():
                    pair.append(math.nan)
                    continue
                y0 = float(np.interp(0.0, tau[ok], y[ok]))
                d = y[inside] - y0
                pair.append(float(d[int(np.argmax(np.abs(d)))]))
            out[name] = (pair[0], pair[1])
        return out

    def plot(self, path: str | os.PathLike[str], title: str | None = None) -> Path:
        """:meth:`figure` written as a PNG; returns the path."""
        from quadimpact.results.figures import save_figure

        return save_figure(self.figure(title), path)

    def figure(self, title: str | None = None) -> Figure:
        """Side-by-side panels: the simulation's lines, the log's markers, the errors."""
        from quadimpact.results.figures import fit_title, new_figure

        # fixed margins (no constrained layout: half the time of this 12-panel figure)
        margins = {"left": 0.06, "right": 0.98, "bottom": 0.05, "top": 0.94,
                   "hspace": 0.3, "wspace": 0.25}  # fmt: skip
        fig = new_figure(15, 13, margins=margins)
        axes = fig.subplots(4, 3)
        tmax = max(self.windows) + 0.2
        tmin = -0.2
        panels = [
            ("x_m", "X - X(impact) (m)"), ("y_m", "Y - Y(impact) (m)"),
            ("altitude_m", "altitude - at impact (m)"),
            ("roll_deg", "roll, unwrapped (deg)"), ("pitch_deg", "pitch (deg)"),
            ("yaw_deg", "yaw, unwrapped (deg)"),
            ("p_rad_s", "p (rad/s)"), ("q_rad_s", "q (rad/s)"), ("r_rad_s", "r (rad/s)"),
        ]  # fmt: skip
        sim = self.sim[(self.sim.tau_s >= tmin) & (self.sim.tau_s <= tmax)]
        lp = self.log_pose[(self.log_pose.tau_s >= tmin) & (self.log_pose.tau_s <= tmax)]
        lm = self.log_motors[(self.log_motors.tau_s >= tmin) & (self.log_motors.tau_s <= tmax)]
        for ax, (col, label) in zip(axes.flat[:9], panels, strict=True):
            # roll and yaw: both unwrapped, the log on the simulation's branch (compare())
            if col in sim:
                ax.plot(sim.tau_s, sim[col], "-", color="tab:blue", lw=1.2, label="simulation")
            if col in lp:
                ax.plot(lp.tau_s, lp[col], "o", color="tab:red", ms=3, label="log")
            ax.set_ylabel(label)
        colors = ["tab:blue", "tab:orange", "tab:green", "tab:red"]
        for ax, motors in zip(axes.flat[9:11], ((1, 2), (3, 4)), strict=True):
            for j in motors:
                c = colors[j - 1]
                col = f"omega{j}_rad_s"
                if col in sim:
                    ax.plot(sim.tau_s, sim[col], "-", color=c, lw=1.2, label=f"sim {j}")
                if col in lm:
                    ax.plot(lm.tau_s, lm[col], "o", color=c, ms=3, label=f"log {j}")
            ax.set_ylabel("rotor speed (rad/s)")
            ax.legend(fontsize=7, ncol=2)
        for ax in axes.flat[:11]:
            ax.set_xlim(tmin, tmax)
            ax.axvline(0.0, color="k", lw=0.8)
            for w in self.windows:
                ax.axvline(w, color="0.6", lw=0.8, ls=":")
            ax.grid(alpha=0.3)
            ax.set_xlabel("time since impact (s)")
        axes.flat[0].legend(fontsize=8)
        text = axes.flat[11]
        text.axis("off")
        e = self.errors[self.errors.quantity.isin(["all", "rotation"])]
        lines = ["RMS / max error after impact"]
        for _, r in e.iterrows():
            name = "rotation" if r.quantity == "rotation" else r.group
            lines.append(f"{name:9s} [0,{r.window_s:g}] s: {r.rms:.3g} / {r.max_abs:.3g} "
                         f"{r.unit} (n={r.n})")  # fmt: skip
        lr = self.log_response.type if self.log_response else "n/a"
        lines.append("")
        lines.append(f"response type: simulation {self.sim_response}, log {lr}")
        for note in self.notes:
            lines.append(textwrap.fill(note, 60))
        text.text(0.0, 1.0, "\n".join(lines), va="top", family="monospace", fontsize=8)
        fit_title(fig, title or f"{self.name}: simulation vs log, aligned at impact")
        return fig


def _sim_table(result_or_timeseries: Any) -> tuple[pd.DataFrame, float | None, str | None]:
    if isinstance(result_or_timeseries, pd.DataFrame):
        return result_or_timeseries, None, None
    ts = result_or_timeseries.timeseries
    summary = getattr(result_or_timeseries, "summary", {}) or {}
    return ts, summary.get("first_contact_s"), summary.get("response_type")


def compare(
    result_or_timeseries: Any,
    log: FlightLog,
    t_impact_sim: float | None = None,
    windows: tuple[float, ...] = (0.3, 0.5),
    *,
    relative_position: bool = True,
    classify_log: bool = True,
) -> Comparison:
    """Compare a simulated run with a flight log, aligned at the impact.

    Parameters
    ----------
    result_or_timeseries : SimulationResult or pandas.DataFrame
        The run, or its time series (then ``t_impact_sim`` is required).
    log : FlightLog
        The reference.
    t_impact_sim : float, optional
        The run's impact time (default: ``summary["first_contact_s"]``).
    windows : tuple of float
        Error windows after the impact, s: errors over ``[0, w]``.
    relative_position : bool
        Compare X, Y and altitude as displacements since the impact.
    classify_log : bool
        Also classify the log's response type (:func:`log_response`).

    Returns
    -------
    Comparison
        Errors: the simulation interpolated linearly onto the log's samples
        with ``0 <= tau <= w`` (roll and yaw unwrapped on both sides, the
        log's on the simulation's branch at the impact, differences not
        wrapped: the module docstring); samples where either side is nan
        (log tracking gaps, powered-off motors, outside the run) are left out
        and counted in ``n`` only when used.
    """
    ts, t_sim_default, sim_type = _sim_table(result_or_timeseries)
    if t_impact_sim is None:
        t_impact_sim = t_sim_default
    if t_impact_sim is None:
        raise ValueError("t_impact_sim is required (the run has no first contact)")
    t_impact_sim = float(t_impact_sim)
    t_log0 = float(log.impact_time_s)
    notes: list[str] = []

    sim = _sim_on_tau(ts, t_impact_sim)
    quats = ["q0", "q1", "q2", "q3"]
    pose = _log_pose_on_tau(log, t_log0, sim, notes)
    have_quats = all(c in sim for c in quats) and all(c in pose for c in quats)
    motors = log.motors().copy()
    motors.insert(0, "tau_s", motors["t_s"].to_numpy(dtype=float) - t_log0)

    if relative_position:
        _displacements_since_impact(sim, pose, notes)
    errors = _errors(sim, pose, motors, windows, have_quats)
    resp = log_response(log) if classify_log else None
    return Comparison(
        name=getattr(log, "name", "") or "log",
        windows=tuple(float(w) for w in windows),
        errors=errors,
        sim=sim,
        log_pose=pose,
        log_motors=motors,
        t_impact_sim=t_impact_sim,
        t_impact_log=t_log0,
        sim_response=sim_type,
        log_response=resp,
        notes=notes,
    )


def _sim_on_tau(ts: pd.DataFrame, t_impact_sim: float) -> pd.DataFrame:
    """The run's compared columns on the time since its impact (roll and yaw unwrapped)."""
    sim = pd.DataFrame({"tau_s": ts["t_s"].to_numpy(dtype=float) - t_impact_sim})
    for _, (_, quantities) in GROUPS.items():
        for _, col, wrapped in quantities:
            if col in ts:
                v = ts[col].to_numpy(dtype=float)
                sim[col] = unwrap_deg(v) if wrapped else v
    for c in ("q0", "q1", "q2", "q3"):
        if c in ts:
            sim[c] = ts[c].to_numpy(dtype=float)
    return sim


def _log_pose_on_tau(
    log: FlightLog, t_log0: float, sim: pd.DataFrame, notes: list[str]
) -> pd.DataFrame:
    """The log's pose on the time since its impact ``t_log0`` (s, column ``tau_s``), roll
    and yaw unwrapped onto the run's branch at the impact (``sim``: the run on its own
    ``tau_s``); a note added to ``notes`` when the headings at the impact are more than
    90 deg apart (one approaches rear first, the other front first)."""
    pose = log.pose().copy()
    pose.insert(0, "tau_s", pose["t_s"].to_numpy(dtype=float) - t_log0)
    if "yaw_deg" in sim and "yaw_deg" in pose and len(pose):
        y_sim0 = float(np.interp(0.0, sim["tau_s"], sim["yaw_deg"]))
        k0 = int(np.argmin(np.abs(pose["tau_s"].to_numpy())))
        dyaw = float(wrap_angle_deg(np.array(y_sim0 - pose["yaw_deg"].iloc[k0])))
        if abs(dyaw) > 90.0:
            notes.append(
                f"headings at the impact differ by {dyaw:.0f} deg: the log approaches "
                "rear-first and the run front-first (or the reverse); read the log with "
                "front_first=True to compare like with like"
            )
    for _, col, wrapped in GROUPS["attitude"][1]:
        if wrapped and col in sim and col in pose and len(pose):
            pose[col] = _unwrap_onto(pose["tau_s"].to_numpy(), pose[col].to_numpy(dtype=float),
                                     float(np.interp(0.0, sim["tau_s"], sim[col])))  # fmt: skip
    return pose


def _displacements_since_impact(sim: pd.DataFrame, pose: pd.DataFrame, notes: list[str]) -> None:
    """X, Y and altitude of both sides made displacements since the impact (in place)."""
    for col in ("x_m", "y_m", "altitude_m"):
        if col in sim:
            sim[col] = sim[col] - np.interp(0.0, sim["tau_s"], sim[col])
        if col in pose and len(pose):
            tp = pose["tau_s"].to_numpy()
            ref = _interp_segments(np.array([0.0]), tp, pose[col].to_numpy(), MOCAP_GAP_S)[0]
            if not math.isfinite(ref):
                k = int(np.argmin(np.abs(tp)))
                ref = float(pose[col].iloc[k])
                notes.append(f"{col}: no log sample around the impact; reference taken "
                             f"at tau = {tp[k]:+.3f} s")  # fmt: skip
            pose[col] = pose[col] - ref


def _errors(
    sim: pd.DataFrame,
    pose: pd.DataFrame,
    motors: pd.DataFrame,
    windows: tuple[float, ...],
    have_quats: bool,
) -> pd.DataFrame:
    """The error table: per window, group and quantity, the run minus the log on the log's
    samples (RMS, largest, count), each group's all-quantity row and the rotation angle."""
    rows: list[dict[str, Any]] = []
    for w in windows:
        for group, (unit, quantities) in GROUPS.items():
            src = motors if group == "motors" else pose
            sel = src[(src["tau_s"] >= 0.0) & (src["tau_s"] <= w)]
            all_err: list[np.ndarray] = []
            for qname, col, _wrapped in quantities:
                if col not in sel or col not in sim:
                    continue
                y_log = sel[col].to_numpy(dtype=float)
                y_sim = np.interp(sel["tau_s"].to_numpy(), sim["tau_s"], sim[col],
                                  left=np.nan, right=np.nan)  # fmt: skip
                err = y_sim - y_log  # roll, yaw: both unwrapped, on the same branch
                err = err[np.isfinite(err)]
                all_err.append(err)
                rows.append(_row(group, qname, unit, w, err))
            cat = np.concatenate(all_err) if all_err else np.zeros(0)
            rows.append(_row(group, "all", unit, w, cat))
            if group == "attitude" and have_quats:
                rows.append(_row(group, "rotation", unit, w, _rotation_error(sim, sel)))
    return pd.DataFrame(rows, columns=["group", "quantity", "unit", "window_s", "rms",
                                       "max_abs", "n"])  # fmt: skip


def _unwrap_onto(tau: np.ndarray, angle_deg: np.ndarray, reference_deg: float) -> np.ndarray:
    """A logged angle unwrapped (its finite samples), moved by whole turns near ``reference_deg``
    at the impact (``tau = 0``)."""
    out = unwrap_deg(angle_deg)
    ok = np.isfinite(out)
    if not ok.any():
        return out
    at_impact = out[ok][int(np.argmin(np.abs(tau[ok])))]
    if math.isfinite(reference_deg):
        out[ok] += 360.0 * round((reference_deg - at_impact) / 360.0)
    return out


def _rotation_error(sim: pd.DataFrame, sel: pd.DataFrame) -> np.ndarray:
    """Angle (deg) of the rotation between the simulated and logged attitudes."""
    tau = sel["tau_s"].to_numpy()
    qs = np.column_stack([np.interp(tau, sim["tau_s"], sim[c], left=np.nan, right=np.nan)
                          for c in ("q0", "q1", "q2", "q3")])  # fmt: skip
    ql = sel[["q0", "q1", "q2", "q3"]].to_numpy(dtype=float)
    qs = qs / norm(qs)[:, None]
    ql = ql / norm(ql)[:, None]
    # relative rotation conj(q_log) * q_sim; angle = 2 atan2(|vector|, |scalar|) (stable near 0)
    w1, v1 = ql[:, 0], -ql[:, 1:]
    w2, v2 = qs[:, 0], qs[:, 1:]
    w = w1 * w2 - np.sum(v1 * v2, axis=1)
    v = w1[:, None] * v2 + w2[:, None] * v1 + np.cross(v1, v2)
    err = np.degrees(2.0 * libm.arctan2(norm(v), np.abs(w)))
    return err[np.isfinite(err)]


def _row(group: str, quantity: str, unit: str, w: float, err: np.ndarray) -> dict[str, Any]:
    n = int(err.size)
    rms = float(np.sqrt(np.mean(err**2))) if n else math.nan
    mx = float(np.max(np.abs(err))) if n else math.nan
    return {"group": group, "quantity": quantity, "unit": unit, "window_s": float(w),
            "rms": rms, "max_abs": mx, "n": n}  # fmt: skip
