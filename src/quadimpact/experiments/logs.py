"""Flight logs of real crashes: a small reader interface and the Spiri crash-set format.

A :class:`FlightLog` presents one recorded flight in quadimpact's units and
frames (SI, inertial NED with X toward the wall, body FRD, quaternion scalar
first body -> inertial, ZYX Euler angles), on one reference clock:

- :attr:`FlightLog.signals`: every recorded topic as a table with a ``t_s``
  column (reference clock) and units in the column names (``_raw`` where the
  unit could not be established);
- :attr:`FlightLog.impact_time_s`: the wall impact, reference clock;
- :meth:`FlightLog.pre_impact`: heading, speed, inclination, roll, pitch and
  altitude just before the impact, with uncertainties (:class:`PreImpact`);
- :meth:`FlightLog.motors`: rotor speeds in rad/s with power-off marked;
- :meth:`FlightLog.pose`: the motion-capture position, attitude and body
  rates in quadimpact's frames.

:class:`SpiriMatLog` reads ``spiri-crash-set-1/crash_N.mat`` (MATLAB v5
files converted from ROS bags). What was established from the data, the
frames and the estimation methods are written in ``docs/EXPERIMENTS.md``;
the constants below are the methods' parameters.

The data are never copied into the project: :func:`data_dir` finds them.
"""

from __future__ import annotations

import math
import os
import tomllib
from abc import ABC, abstractmethod
from dataclasses import asdict, dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from quadimpact.rotations import (
    inclination_deg,
    matrix_to_euler_zyx_deg,
    matrix_to_quat,
    matrix_to_rotvec,
    quat_xyzw_to_matrix,
    wrap_angle_deg,
)

__all__ = [
    "ATTITUDE_SYSTEMATIC_DEG",
    "ATTITUDE_WINDOW_S",
    "BURST_DT_S",
    "CONTACT_MIN_DECELERATION_M_S2",
    "DATA_ENV_VAR",
    "FIT_WINDOW_S",
    "FIT_WINDOWS_SPREAD_S",
    "IMPACT_RATE_THRESHOLD",
    "IMPACT_SEARCH_AFTER_S",
    "IMPACT_SEARCH_BEFORE_S",
    "LOOKBACK_S",
    "MAX_EXTRAPOLATION_S",
    "MOCAP_TO_NED",
    "POWER_OFF_RPM",
    "REST_HOLD_S",
    "REST_RATE_THRESHOLD",
    "SET1_MOCAP_CLOCK_OFFSET_S",
    "SET1_WALL_X_M",
    "FlightLog",
    "PreImpact",
    "SpiriMatLog",
    "bumper_rim_extent",
    "crash_set_1",
    "data_dir",
    "rpm_to_rad_s",
]

# --------------------------------------------------------------------------- data
#: Environment variable naming the data folder (holding ``spiri-crash-set-1/``).
DATA_ENV_VAR = "QUADIMPACT_DATA"


def data_dir() -> Path | None:
    """The shared data folder, or None when it is absent.

    ``$QUADIMPACT_DATA`` when set (and then only it); otherwise
    ``../shared/data`` beside the project (the checkout's parent folder), then
    ``/work/shared/data``. A folder counts only if it holds
    ``spiri-crash-set-1/``.
    """
    candidates: list[Path] = []
    env = os.environ.get(DATA_ENV_VAR)
    if env:
        p = Path(env).resolve()
        return p if (p / "spiri-crash-set-1").is_dir() else None
    here = Path(__file__).resolve()
    if len(here.parents) > 3:  # .../<checkout>/src/quadimpact/experiments/logs.py
        candidates.append(here.parents[3] / ".." / "shared" / "data")
    candidates.append(Path("/work/shared/data"))
    for c in candidates:
        c = c.resolve()
        if (c / "spiri-crash-set-1").is_dir():
            return c
    return None


def crash_set_1(folder: str | Path | None = None) -> dict[str, dict[str, Any]]:
    """The crash set's description file (``spiri_crash_set_1.toml``), by flight name.

    Parameters
    ----------
    folder : path, optional
        The data folder (default :func:`data_dir`).

    Raises
    ------
    FileNotFoundError
        When the data folder or the file is absent.
    """
    base = Path(folder) if folder is not None else data_dir()
    if base is None:
        raise FileNotFoundError(f"no data folder (set ${DATA_ENV_VAR})")
    with open(base / "spiri_crash_set_1.toml", "rb") as fh:
        return dict(tomllib.load(fh)["crash"])


def rpm_to_rad_s(rpm: Any) -> Any:
    """Revolutions per minute to rad/s."""
    return np.asarray(rpm, dtype=float) * (2.0 * math.pi / 60.0)


# --------------------------------------------------------------------- constants
#: Motion-capture world (x, y, z up; the wall's normal is +x) to NED: a rotation
#: of 180 deg about x. Positions: ``p_NED = MOCAP_TO_NED p_mocap``; attitude:
#: ``C = MOCAP_TO_NED R(q_mocap)`` (the motion-capture body frame is FRD).
MOCAP_TO_NED = np.diag([1.0, -1.0, -1.0])

#: Impact rule: first on-board sample whose x-y magnitude of the ``accel``
#: topic exceeds this (the topic's own unit, most likely deg/s: see the docs).
IMPACT_RATE_THRESHOLD = 100.0
#: The impact search window around the first motor power-off (RPM == 1), s.
IMPACT_SEARCH_BEFORE_S = 0.25
IMPACT_SEARCH_AFTER_S = 0.15
#: A motor speed at or below this (RPM) is off: 1 = powered off by the motor
#: controller (stall protection), 0 = disarmed.
POWER_OFF_RPM = 1.0
#: On-board samples closer than this to the previous one arrived in a burst
#: after a radio stall and are re-timed (spread back at the topic's period).
BURST_DT_S = 0.003

#: Wall contact on the motion capture: the approach speed (local linear fit over
#: +-STOP_HALF_WINDOW_S) first falls below STOP_FRACTION of its median over
#: [t - STOP_REF_S[0], t - STOP_REF_S[1]] within +-CONTACT_SEARCH_S of the
#: on-board impact (the clocks differ by up to ~0.1 s).
STOP_HALF_WINDOW_S = 0.03
STOP_FRACTION = 0.5
STOP_REF_S = (0.20, 0.05)
STOP_MIN_APPROACH_M_S = 0.2
CONTACT_SEARCH_S = 0.2
#: Change-point fit around the stop: X(t) = c0 + c1 tau + c2 tau^2 - a/2 max(tau - tau_c, 0)^2
#: over [t_stop - CHANGEPOINT_BEFORE_S - FIT_WINDOW_S, t_stop + CHANGEPOINT_AFTER_S],
#: tau_c on a grid of CHANGEPOINT_STEP_S over [t_stop - CHANGEPOINT_BEFORE_S, t_stop].
CHANGEPOINT_BEFORE_S = 0.08
CHANGEPOINT_AFTER_S = 0.02
CHANGEPOINT_STEP_S = 0.001
#: The change point counts as the wall contact only with at least this deceleration.
CONTACT_MIN_DECELERATION_M_S2 = 15.0
#: Pre-impact velocity: quadratic fit of the position over [t_c - FIT_WINDOW_S, t_c],
#: differentiated at t_c; the spread over FIT_WINDOWS_SPREAD_S enters the uncertainty.
FIT_WINDOW_S = 0.20
FIT_WINDOWS_SPREAD_S = (0.15, 0.25)
#: The speed is also reported this long before the contact (``speed_lookback_m_s``).
LOOKBACK_S = 0.10
#: Pre-impact attitude: linear fit of each angle over [t_c - ATTITUDE_WINDOW_S, t_c].
ATTITUDE_WINDOW_S = 0.10
#: Systematic attitude uncertainty of the motion-capture body frame (it reads a
#: tilt of about 2 deg with the vehicle at rest on the floor).
ATTITUDE_SYSTEMATIC_DEG = 2.0
#: Largest extrapolation of the position fit past the last motion-capture sample, s.
MAX_EXTRAPOLATION_S = 0.15
#: Motion-capture gaps longer than this split the data (no differentiation across), s.
MOCAP_GAP_S = 0.05
#: At rest after the impact: the on-board ``accel`` magnitude stays below
#: REST_RATE_THRESHOLD (its unit) for REST_HOLD_S.
REST_RATE_THRESHOLD = 20.0
REST_HOLD_S = 0.5

#: Crash set I: the wall plane X (motion-capture x, m), median over the flights
#: whose contact is observed (leading bumper rim at the contact), and the median
#: clock offset (motion-capture contact minus on-board impact, s). Used only
#: when a flight's own contact is not observed (see ``PreImpact.method``).
SET1_WALL_X_M = 1.14
SET1_MOCAP_CLOCK_OFFSET_S = 0.016

# Spiri bumper geometry (MODEL.md section 3 and 4), for the leading bumper and
# the wall contact: rotor hubs (body FRD, m), bumper radius and tilt.
_ROTORS = np.array(
    [
        [0.13192, 0.12652, -0.02416],
        [-0.12122, 0.12652, -0.02416],
        [-0.12122, -0.12662, -0.02416],
        [0.13192, -0.12662, -0.02416],
    ]
)
_BUMPER_R = 0.11
_BUMPER_TILT = math.radians(11.0)


def bumper_rim_extent(
    C: np.ndarray,
    direction: np.ndarray,
    rotors: np.ndarray = _ROTORS,
    radius: float = _BUMPER_R,
    tilt_rad: float = _BUMPER_TILT,
) -> np.ndarray:
    """Farthest reach of each bumper rim along ``direction``, from the CM.

    Parameters
    ----------
    C : numpy.ndarray, shape (..., 3, 3)
        Attitude matrices, body FRD -> inertial.
    direction : numpy.ndarray, shape (3,)
        Unit vector (inertial), e.g. the wall normal into the wall (+X).
    rotors, radius, tilt_rad
        Bumper circles (centres, radius, tilt): MODEL.md section 4.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        ``max over the rim of (point - CM) . direction`` per bumper, m.
    """
    psi = np.deg2rad([45.0, 135.0, 225.0, 315.0])
    d = np.stack([np.cos(psi), np.sin(psi), np.zeros(4)], axis=1)
    n = -math.sin(tilt_rad) * d - math.cos(tilt_rad) * np.array([0.0, 0.0, 1.0])
    m = np.asarray(direction, dtype=float)
    centres = np.einsum("...ij,kj->...ki", C, rotors)  # (..., 4, 3)
    normals = np.einsum("...ij,kj->...ki", C, n)
    w = m - np.einsum("...k,...ki->...ki", normals @ m, normals)
    wn = np.linalg.norm(w, axis=-1)
    return centres @ m + radius * wn  # (w/|w|).m = |w|


# ------------------------------------------------------------------ the interface
@dataclass(frozen=True)
class PreImpact:
    """Conditions just before the wall impact, in quadimpact's conventions.

    Angles in degrees, the attitude of the log's body frame in NED with X the
    wall normal (into the wall). ``nan`` where not observable (see ``notes``).

    Attributes
    ----------
    heading_deg : float
        Yaw of the body x axis from the wall normal, (-180, 180]
        (STUDIES.md section 1; 0 = nose at the wall).
    speed_m_s : float
        CM velocity toward the wall (along X) at the contact.
    inclination_deg : float
        Angle of the body z axis projected on the X-Z plane from Z, positive
        when the vehicle leans toward the wall (STUDIES.md section 1).
    roll_deg, pitch_deg, yaw_deg : float
        ZYX Euler angles at the contact (``yaw_deg`` = ``heading_deg``).
    altitude_m : float
        Height of the motion-capture origin of the body above the floor.
    uncertainty : dict
        One standard uncertainty per quantity (same keys, same units).
    time_s : float
        The contact, reference (on-board) clock.
    velocity_m_s : tuple
        CM velocity (NED) at the contact.
    acceleration_m_s2 : tuple
        CM acceleration (NED) over the fit window.
    speed_lookback_m_s : float
        Speed toward the wall ``LOOKBACK_S`` before the contact (same fit).
    heading_front_equiv_deg : float
        The heading of the equivalent front-first approach: a rear-first
        approach (|heading| > 90) seen in the body frame turned 180 deg about
        z_B (the Spiri is symmetric under that turn up to ~1 cm).
    rear_first : bool
        True when the vehicle's rear faced the wall.
    leading_bumper : int or None
        Bumper (log numbering) whose rim is nearest the wall at the contact.
    wall_x_m : float
        Wall plane X (NED, = motion-capture x) from the leading rim at the contact.
    contact_observed : bool
        True when the motion capture shows the contact itself.
    method : str
        How the contact time was found: ``"changepoint"`` (observed),
        ``"wall-extrapolation"`` (fit extrapolated to the set's wall plane),
        ``"clock-offset"`` (on-board impact plus the set's clock offset),
        ``"none"`` (no motion capture near the impact).
    notes : tuple of str
        Anything the reader should know (gaps, extrapolation, doubts).
    """

    heading_deg: float
    speed_m_s: float
    inclination_deg: float
    roll_deg: float
    pitch_deg: float
    yaw_deg: float
    altitude_m: float
    uncertainty: dict[str, float] = field(default_factory=dict)
    time_s: float = math.nan
    velocity_m_s: tuple[float, float, float] = (math.nan, math.nan, math.nan)
    acceleration_m_s2: tuple[float, float, float] = (math.nan, math.nan, math.nan)
    speed_lookback_m_s: float = math.nan
    heading_front_equiv_deg: float = math.nan
    rear_first: bool = False
    leading_bumper: int | None = None
    wall_x_m: float = math.nan
    contact_observed: bool = False
    method: str = "none"
    notes: tuple[str, ...] = ()

    def as_dict(self) -> dict[str, Any]:
        """Plain dict (JSON-friendly)."""
        return asdict(self)


class FlightLog(ABC):
    """One recorded flight, in quadimpact's units and frames (module docstring).

    Subclasses implement a format; everything is on one reference clock
    (``t_s``, seconds). ``name`` identifies the flight.
    """

    name: str = ""

    @property
    @abstractmethod
    def signals(self) -> dict[str, pd.DataFrame]:
        """Every recorded topic: a table with ``t_s`` and unit-suffixed columns."""

    @property
    @abstractmethod
    def impact_time_s(self) -> float:
        """The wall impact, reference clock, s."""

    @abstractmethod
    def pre_impact(self) -> PreImpact:
        """Heading, speed, inclination, attitude and altitude just before the impact."""

    @abstractmethod
    def motors(self) -> pd.DataFrame:
        """``t_s, omega1..4_rad_s, off1..4``: rotor speeds (nan while off), power-off flags."""

    @abstractmethod
    def pose(self) -> pd.DataFrame:
        """Motion capture in quadimpact's frames.

        Columns ``t_s, x_m, y_m, z_m`` (NED), ``q0..q3`` (body FRD -> NED,
        scalar first), ``roll_deg, pitch_deg, yaw_deg`` (ZYX), ``altitude_m``,
        ``vx_m_s, vy_m_s, vz_m_s`` (NED) and ``p_rad_s, q_rad_s, r_rad_s``
        (body), nan where not defined.
        """

    @property
    def wall_x_m(self) -> float:
        """The wall plane's X in the pose frame (nan if unknown)."""
        return self.pre_impact().wall_x_m

    @property
    def rest_time_s(self) -> float | None:
        """When the vehicle is at rest after the impact (None if unknown)."""
        return None


# ------------------------------------------------------------------ helpers
def _segments(t: np.ndarray, gap: float) -> np.ndarray:
    """Segment id per sample: a new segment after every gap longer than ``gap``."""
    if len(t) == 0:
        return np.zeros(0, dtype=int)
    return np.concatenate([[0], np.cumsum(np.diff(t) > gap)])


def _retime_bursts(t: np.ndarray, burst_dt: float = BURST_DT_S) -> tuple[np.ndarray, np.ndarray]:
    """Spread samples that arrived in a burst back over the gap before it.

    A burst is a run of samples each within ``burst_dt`` of the previous one
    (a radio stall delivers its backlog at once, all stamped on arrival). The
    last sample of the run keeps its stamp; the others are placed back at the
    topic's median period (or less, to stay after the sample before the run).

    Returns
    -------
    t_new, retimed : numpy.ndarray
    """
    t = np.asarray(t, dtype=float).copy()
    retimed = np.zeros(len(t), dtype=bool)
    if len(t) < 3:
        return t, retimed
    dt = np.diff(t)
    period = float(np.median(dt[dt > burst_dt])) if np.any(dt > burst_dt) else 0.05
    i = 1
    while i < len(t):
        if t[i] - t[i - 1] < burst_dt:
            j = i
            while j + 1 < len(t) and t[j + 1] - t[j] < burst_dt:
                j += 1
            first = i - 1  # the run is first..j
            k = j - first + 1
            t_end = t[j]
            before = t[first - 1] if first > 0 else t_end - k * period
            step = min(period, (t_end - before) / k)
            t[first : j + 1] = t_end - step * np.arange(k - 1, -1, -1)
            retimed[first:j] = True
            i = j + 1
        else:
            i += 1
    return t, retimed


def _polyfit_at(t: np.ndarray, y: np.ndarray, deg: int) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares polynomial (np.polyfit order) and its covariance; t already centred."""
    A = np.vander(t, deg + 1)
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    r = y - A @ coef
    dof = max(len(t) - (deg + 1), 1)
    s2 = float(r @ r) / dof
    cov = s2 * np.linalg.pinv(A.T @ A)
    return coef, cov


# ------------------------------------------------------------------ Spiri .mat
_ONBOARD_TOPICS = {
    # key in signals: (mat prefix, {column: mat suffix})
    "accel": ("v_accel", {"x_raw": "x", "y_raw": "y", "z_raw": "z"}),
    "gyros": ("v_gyros", {"x_raw": "x", "y_raw": "y", "z_raw": "z"}),
    "angles": ("vangles", {"x_deg": "x", "y_deg": "y", "z_raw": "z"}),
    "motors": ("v_motors", {"rpm1": "z", "rpm2": "w", "rpm3": "x", "rpm4": "y"}),
    "cmd": ("v_cmd", {"x_raw": "x", "y_raw": "y", "z_raw": "z", "w_raw": "w"}),
}


class SpiriMatLog(FlightLog):
    """A flight of Spiri crash set I (``crash_N.mat``), see ``docs/EXPERIMENTS.md``.

    Parameters
    ----------
    path : path
        The ``.mat`` file.
    front_first : bool
        Express the body frame turned 180 deg about z_B (x_B, y_B reversed)
        and renumber the motors and bumpers 1<->3, 2<->4, so that a rear-first
        approach (all of this set) reads as the equivalent front-first one,
        the form quadimpact's wall approach simulates. Default False: the
        body frame of the motion capture, which is the vehicle's FRD frame
        with the log's motor numbering.
    wall_x_m : float
        The wall plane (motion-capture x, m), used only when the flight's own
        contact is not observed.
    mocap_clock_offset_s : float
        Motion-capture minus on-board clock, used only when neither the
        contact nor the wall extrapolation is available.

    Notes
    -----
    Reference clock: the on-board one (accel, gyros, angles, motors, cmd are
    stamped together). The motion capture runs on its own clock; it is shifted
    so that its observed wall contact falls on :attr:`impact_time_s` (column
    ``t_raw_s`` keeps its own stamps; ``mocap_clock_offset_s`` the shift).
    """

    def __init__(
        self,
        path: str | Path,
        *,
        front_first: bool = False,
        wall_x_m: float = SET1_WALL_X_M,
        mocap_clock_offset_s: float = SET1_MOCAP_CLOCK_OFFSET_S,
    ) -> None:
        from scipy.io import loadmat

        self.path = Path(path)
        self.name = self.path.stem
        self.front_first = bool(front_first)
        self._wall_x_default = float(wall_x_m)
        self._offset_default = float(mocap_clock_offset_s)
        self._mat = loadmat(self.path, squeeze_me=True)
        self._raw = self._read_raw()
        self._impact, self._impact_bracket, self._power_off = self._find_impact()

    # ----------------------------------------------------------- reading
    def _read_raw(self) -> dict[str, pd.DataFrame]:
        m = self._mat
        out: dict[str, pd.DataFrame] = {}
        for key, (prefix, cols) in _ONBOARD_TOPICS.items():
            tkey = f"{prefix}___time"
            if tkey not in m:
                continue
            t_raw = np.atleast_1d(np.asarray(m[tkey], dtype=float))
            t, retimed = _retime_bursts(t_raw)
            data = {"t_s": t, "t_raw_s": t_raw, "retimed": retimed}
            for col, suffix in cols.items():
                data[col] = np.atleast_1d(np.asarray(m[f"{prefix}_{suffix}"], dtype=float))
            out[key] = pd.DataFrame(data)
        vk = "v_vicon__pose___time"
        if vk in m and np.size(m[vk]) > 0:
            P = "v_vicon__pose_pose_"
            data = {"t_raw_s": np.atleast_1d(np.asarray(m[vk], dtype=float))}
            for c in "xyz":
                data[f"{c}_m"] = np.atleast_1d(np.asarray(m[f"{P}position_{c}"], dtype=float))
            for c in "xyzw":
                data[f"q{c}"] = np.atleast_1d(np.asarray(m[f"{P}orientation_{c}"], dtype=float))
            out["vicon"] = pd.DataFrame(data)
        return out

    def _find_impact(self) -> tuple[float, tuple[float, float], float | None]:
        acc = self._raw.get("accel")
        mot = self._raw.get("motors")
        if acc is None or acc.empty:
            raise ValueError(f"{self.path.name}: no accel topic, cannot find the impact")
        t = acc["t_s"].to_numpy()
        mag = np.hypot(acc["x_raw"].to_numpy(), acc["y_raw"].to_numpy())
        t_off: float | None = None
        if mot is not None and not mot.empty:
            rpm = mot[["rpm1", "rpm2", "rpm3", "rpm4"]].to_numpy()
            flying = np.maximum.accumulate(rpm.max(axis=1) > 1000.0)
            off = flying & (rpm == POWER_OFF_RPM).any(axis=1)
            if off.any():
                t_off = float(mot["t_s"].to_numpy()[np.argmax(off)])
        if t_off is not None:
            window = (t >= t_off - IMPACT_SEARCH_BEFORE_S) & (t <= t_off + IMPACT_SEARCH_AFTER_S)
        else:
            window = np.ones(len(t), dtype=bool)
        hits = np.flatnonzero(window & (mag > IMPACT_RATE_THRESHOLD))
        if hits.size == 0:
            raise ValueError(f"{self.path.name}: no accelerometer spike above the threshold")
        i = int(hits[0])
        before = float(t[i - 1]) if i > 0 else float(t[i])
        return float(t[i]), (before, float(t[i])), t_off

    # ----------------------------------------------------------- interface
    @property
    def impact_time_s(self) -> float:
        """First on-board sample with ``|accel_xy| > IMPACT_RATE_THRESHOLD`` near the power-off.

        The search runs over [t_off - IMPACT_SEARCH_BEFORE_S, t_off +
        IMPACT_SEARCH_AFTER_S] around the first motor power-off t_off (a motor
        at RPM == 1 after take-off: the motor controllers cut a stalled motor,
        which the impact causes); the whole log without one. The true impact
        lies in :attr:`impact_bracket_s` (after the previous, quiet, sample).
        """
        return self._impact

    @property
    def impact_bracket_s(self) -> tuple[float, float]:
        """(last quiet on-board sample, first spike sample): the impact lies between."""
        return self._impact_bracket

    @property
    def power_off_time_s(self) -> float | None:
        """First on-board sample with a motor powered off (RPM == 1), None if none."""
        return self._power_off

    @property
    def mocap_clock_offset_s(self) -> float:
        """Motion-capture stamp minus reference stamp of the same instant, s."""
        return self._contact["offset"]

    @property
    def has_mocap(self) -> bool:
        """Whether the log holds motion capture."""
        return "vicon" in self._raw and not self._raw["vicon"].empty

    @cached_property
    def signals(self) -> dict[str, pd.DataFrame]:
        """Every topic on the reference clock (see ``docs/EXPERIMENTS.md`` for units).

        ``accel``, ``gyros`` (``x_raw..``: the same quantity, angular-rate-like,
        most likely deg/s, board axes), ``angles`` (``x_deg, y_deg``: on-board
        attitude estimate, ``z_raw``: yaw-rate-like), ``motors`` (``rpm1..4``,
        log numbering), ``cmd`` (pilot commands, raw), ``vicon`` (motion
        capture, its own world frame: ``x_m, y_m, z_m`` z up, quaternion
        ``qx, qy, qz, qw`` of the FRD body). Each has ``t_s`` (reference
        clock) and ``t_raw_s`` (the topic's own stamps); on-board topics flag
        ``retimed`` samples (burst arrivals).
        """
        out = {k: v.copy() for k, v in self._raw.items()}
        if "vicon" in out:
            v = out["vicon"]
            v.insert(0, "t_s", v["t_raw_s"] - self.mocap_clock_offset_s)
        return out

    def motors(self) -> pd.DataFrame:
        """Rotor speeds, rad/s, nan while off; ``off1..4`` where RPM <= ``POWER_OFF_RPM``.

        RPM 1 is the motor controller's power-off (stall protection), RPM 0 the
        disarmed motor; either way the speed is not measured (a powered-off
        rotor spins down unrecorded), hence nan. With ``front_first`` the
        motors are renumbered 1<->3, 2<->4.
        """
        mot = self._raw["motors"]
        rpm = mot[["rpm1", "rpm2", "rpm3", "rpm4"]].to_numpy()
        if self.front_first:
            rpm = rpm[:, [2, 3, 0, 1]]
        off = rpm <= POWER_OFF_RPM
        omega = np.where(off, np.nan, rpm_to_rad_s(rpm))
        data: dict[str, Any] = {"t_s": mot["t_s"].to_numpy()}
        for j in range(4):
            data[f"omega{j + 1}_rad_s"] = omega[:, j]
        for j in range(4):
            data[f"off{j + 1}"] = off[:, j]
        return pd.DataFrame(data)

    # ----------------------------------------------------------- motion capture
    @cached_property
    def _mocap(self) -> dict[str, np.ndarray] | None:
        """Motion capture in NED on its own clock: t, p (n,3), C (n,3,3)."""
        if not self.has_mocap:
            return None
        v = self._raw["vicon"]
        t = v["t_raw_s"].to_numpy()
        p = v[["x_m", "y_m", "z_m"]].to_numpy() @ MOCAP_TO_NED.T
        C = MOCAP_TO_NED @ quat_xyzw_to_matrix(v[["qx", "qy", "qz", "qw"]].to_numpy())
        if self.front_first:
            C = C @ np.diag([-1.0, -1.0, 1.0])
        return {"t": t, "p": p, "C": C}

    def pose(self) -> pd.DataFrame:
        """Motion capture in NED (X = wall normal), reference clock; see :class:`FlightLog`.

        Velocities: central differences within gap-free segments (gaps >
        ``MOCAP_GAP_S``), one-sided at segment ends. Body rates: the rotation
        between the neighbouring samples, ``log(C_{k-1}^T C_{k+1}) / dt``.
        No further filtering.
        """
        cols = ["t_s", "x_m", "y_m", "z_m", "q0", "q1", "q2", "q3", "roll_deg", "pitch_deg",
                "yaw_deg", "altitude_m", "vx_m_s", "vy_m_s", "vz_m_s", "p_rad_s", "q_rad_s",
                "r_rad_s"]  # fmt: skip
        mc = self._mocap
        if mc is None:
            return pd.DataFrame(columns=cols)
        t, p, C = mc["t"], mc["p"], mc["C"]
        n = len(t)
        seg = _segments(t, MOCAP_GAP_S)
        prev = np.arange(n) - 1
        nxt = np.arange(n) + 1
        prev[0] = 0
        nxt[-1] = n - 1
        prev = np.where(seg[prev] == seg, prev, np.arange(n))
        nxt = np.where(seg[nxt] == seg, nxt, np.arange(n))
        dt = t[nxt] - t[prev]
        ok = dt > 0
        safe = np.where(ok, dt, 1.0)
        vel = np.where(ok[:, None], (p[nxt] - p[prev]) / safe[:, None], np.nan)
        rel = np.einsum("nji,njk->nik", C[prev], C[nxt])  # C_prev^T C_next
        w = np.where(ok[:, None], matrix_to_rotvec(rel) / safe[:, None], np.nan)
        q = matrix_to_quat(C)
        roll, pitch, yaw = matrix_to_euler_zyx_deg(C)
        df = pd.DataFrame(
            {
                "t_s": t - self.mocap_clock_offset_s,
                "x_m": p[:, 0], "y_m": p[:, 1], "z_m": p[:, 2],
                "q0": q[:, 0], "q1": q[:, 1], "q2": q[:, 2], "q3": q[:, 3],
                "roll_deg": roll, "pitch_deg": pitch, "yaw_deg": yaw,
                "altitude_m": -p[:, 2],
                "vx_m_s": vel[:, 0], "vy_m_s": vel[:, 1], "vz_m_s": vel[:, 2],
                "p_rad_s": w[:, 0], "q_rad_s": w[:, 1], "r_rad_s": w[:, 2],
            }
        )  # fmt: skip
        return df[cols]

    # ----------------------------------------------------------- the contact
    def _approach_speed(self, t: np.ndarray, x: np.ndarray) -> np.ndarray:
        v = np.full(len(t), np.nan)
        for k in range(len(t)):
            s = np.abs(t - t[k]) <= STOP_HALF_WINDOW_S
            if s.sum() >= 3:
                v[k] = np.polyfit(t[s] - t[k], x[s], 1)[0]
        return v

    @cached_property
    def _contact(self) -> dict[str, Any]:
        """Locate the wall contact on the motion capture (see ``pre_impact``)."""
        res: dict[str, Any] = {"offset": self._offset_default, "t_mocap": math.nan,
                               "method": "none", "observed": False, "notes": [],
                               "a_dec": math.nan, "stop": math.nan}  # fmt: skip
        mc = self._mocap
        if mc is None:
            res["notes"].append("no motion capture in this log")
            return res
        t, p = mc["t"], mc["p"]
        ti = self._impact
        near = np.flatnonzero(np.abs(t - ti) <= CONTACT_SEARCH_S)
        x = p[:, 0]
        stop = None
        if near.size:
            lo = max(near[0] - 60, 0)
            sl = slice(lo, near[-1] + 1)
            ts, xs = t[sl], x[sl]
            vloc = self._approach_speed(ts, xs)
            for k in range(len(ts)):
                if abs(ts[k] - ti) > CONTACT_SEARCH_S:
                    continue
                ref = (ts >= ts[k] - STOP_REF_S[0]) & (ts <= ts[k] - STOP_REF_S[1])
                if ref.sum() < 5 or np.isnan(vloc[ref]).all():
                    continue
                vr = float(np.nanmedian(vloc[ref]))
                if vr > STOP_MIN_APPROACH_M_S and vloc[k] < STOP_FRACTION * vr:
                    stop = float(ts[k])
                    break
        if stop is not None:
            f = (t >= stop - CHANGEPOINT_BEFORE_S - FIT_WINDOW_S) & (
                t <= stop + CHANGEPOINT_AFTER_S
            )
            tf, xf = t[f], x[f]
            best: tuple[float, float, np.ndarray] | None = None
            sse0 = None
            grid = np.arange(stop - CHANGEPOINT_BEFORE_S, stop + 0.5 * CHANGEPOINT_STEP_S,
                             CHANGEPOINT_STEP_S)  # fmt: skip
            for tc in grid:
                tau = tf - tc
                A = np.column_stack([np.ones_like(tau), tau, tau**2,
                                     -0.5 * np.maximum(tau, 0.0) ** 2])  # fmt: skip
                co, *_ = np.linalg.lstsq(A, xf, rcond=None)
                sse = float(np.sum((xf - A @ co) ** 2))
                if sse0 is None:
                    c0, *_ = np.linalg.lstsq(A[:, :3], xf, rcond=None)
                    sse0 = float(np.sum((xf - A[:, :3] @ c0) ** 2))
                if co[3] < 0:
                    continue
                if best is None or sse < best[1]:
                    best = (float(tc), sse, co)
            res["stop"] = stop
            if best is not None and best[2][3] >= CONTACT_MIN_DECELERATION_M_S2:
                res.update(t_mocap=best[0], method="changepoint", observed=True,
                           a_dec=float(best[2][3]))  # fmt: skip
                res["offset"] = best[0] - ti
                return res
            res["notes"].append(
                f"a stop at {stop - ti:+.3f} s (mocap clock - impact) without a clear "
                "deceleration; not taken as the contact"
            )
        # not observed: extrapolate to the set's wall plane, or use the clock offset
        t_lim = ti + self._offset_default
        # usable approach: the gap-free segment holding the last sample before the
        # expected contact, up to its end (at most CONTACT_SEARCH_S later) or the stop
        seg = _segments(t, MOCAP_GAP_S)
        before = np.flatnonzero(t <= t_lim)
        if before.size == 0:
            res["notes"].append("no motion capture before the impact")
            return res
        usable = (seg == seg[before[-1]]) & (t <= t_lim + CONTACT_SEARCH_S)
        if stop is not None:
            usable &= t < stop
        last = int(np.flatnonzero(usable)[-1]) if usable.any() else int(before[-1])
        f = usable & (t >= t[last] - FIT_WINDOW_S) & (t <= t[last])
        if f.sum() >= 6:
            tau = t[f] - t[last]
            cx, _ = _polyfit_at(tau, x[f], 2)
            reach = bumper_rim_extent(mc["C"][last][None], np.array([1.0, 0.0, 0.0]))[0].max()
            # solve x_fit(tau) + reach = wall for tau in [0, MAX_EXTRAPOLATION_S]
            taus = np.linspace(0.0, MAX_EXTRAPOLATION_S, 1501)
            gap = np.polyval(cx, taus) + reach - self._wall_x_default
            if x[last] + reach >= self._wall_x_default - 0.05 or np.any(gap >= 0):
                k = int(np.argmax(gap >= 0)) if np.any(gap >= 0) else 0
                tcm = float(t[last] + taus[k])
                res.update(t_mocap=tcm, method="wall-extrapolation", offset=tcm - ti)
                res["notes"].append(
                    f"contact not observed: position fit extrapolated {taus[k]:.3f} s past "
                    f"the last usable sample to the set's wall plane X = {self._wall_x_default} m"
                )
                return res
        tcm = t_lim
        if t[last] < tcm - MAX_EXTRAPOLATION_S:
            res["notes"].append(
                f"motion capture ends {tcm - t[last]:.3f} s before the impact: no estimate"
            )
            return res
        res.update(t_mocap=tcm, method="clock-offset")
        reach = bumper_rim_extent(mc["C"][last][None], np.array([1.0, 0.0, 0.0]))[0].max()
        far = self._wall_x_default - (x[last] + reach)
        res["notes"].append(
            "contact not observed: impact placed at the on-board impact plus the set's clock "
            f"offset; the vehicle is {far:.2f} m short of the set's wall plane there"
        )
        return res

    def pre_impact(self) -> PreImpact:
        """Pre-impact conditions from the motion capture (method in ``docs/EXPERIMENTS.md``).

        1. Contact time t_c on the motion-capture clock: the approach speed
           (linear fit over +-``STOP_HALF_WINDOW_S``) drops below
           ``STOP_FRACTION`` of its recent median (the stop), then a
           change-point fit of X(t) (quadratic before, extra constant
           deceleration after) over the stop's neighbourhood gives t_c; it is
           accepted with a deceleration >= ``CONTACT_MIN_DECELERATION_M_S2``.
           Otherwise the position fit is extrapolated to ``SET1_WALL_X_M``
           (at most ``MAX_EXTRAPOLATION_S``) or, failing that, t_c is the
           on-board impact plus ``SET1_MOCAP_CLOCK_OFFSET_S``.
        2. Velocity and acceleration: quadratic fit of each position component
           over [t_c - ``FIT_WINDOW_S``, t_c] (samples before t_c only),
           differentiated at t_c; ``speed_m_s`` is its X component. Its
           uncertainty combines the fit's standard error, the spread over
           ``FIT_WINDOWS_SPREAD_S`` and the acceleration times the contact-time
           uncertainty (half the local sample interval, or the extrapolated
           span).
        3. Attitude: linear fit of each angle over [t_c - ``ATTITUDE_WINDOW_S``,
           t_c] evaluated at t_c; uncertainty: residual scatter, slope times
           the contact-time uncertainty, and ``ATTITUDE_SYSTEMATIC_DEG``.
        """
        return self._pre_impact

    @cached_property
    def _pre_impact(self) -> PreImpact:
        c = self._contact
        notes = list(c["notes"])
        nan = math.nan
        mc = self._mocap
        if mc is None or not math.isfinite(c["t_mocap"]):
            return PreImpact(nan, nan, nan, nan, nan, nan, nan, time_s=self._impact,
                             method=c["method"], notes=tuple(notes))  # fmt: skip
        t, p, C = mc["t"], mc["p"], mc["C"]
        tc = float(c["t_mocap"])
        pre = t < tc
        last = int(np.flatnonzero(pre)[-1])
        # contact-time uncertainty
        if c["observed"]:
            local = np.diff(t[max(last - 3, 0) : last + 2])
            dtc = 0.5 * float(np.median(local)) if local.size else 0.01
        else:
            dtc = max(tc - t[last], 0.01)

        def fit(window: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            s = pre & (t >= tc - window)
            tau = t[s] - tc
            vel = np.empty(3)
            acc = np.empty(3)
            var = np.empty(3)
            for i in range(3):
                co, cov = _polyfit_at(tau, p[s, i], 2)
                vel[i], acc[i], var[i] = co[1], 2.0 * co[0], cov[1, 1]
            return vel, acc, var

        n_fit = int((pre & (t >= tc - FIT_WINDOW_S)).sum())
        if n_fit < 6:
            notes.append(f"only {n_fit} samples in the fit window: no estimate")
            return PreImpact(nan, nan, nan, nan, nan, nan, nan, time_s=self._impact,
                             method=c["method"], notes=tuple(notes))  # fmt: skip
        vel, acc, var = fit(FIT_WINDOW_S)
        spread = [fit(w)[0][0] for w in FIT_WINDOWS_SPREAD_S
                  if (pre & (t >= tc - w)).sum() >= 6]  # fmt: skip
        sp = float(np.ptp(spread + [vel[0]]) / 2.0) if spread else 0.0
        u_speed = math.sqrt(var[0] + sp**2 + (acc[0] * dtc) ** 2)
        speed_lookback = float(vel[0] - acc[0] * LOOKBACK_S)
        # altitude at t_c from the same fit
        s = pre & (t >= tc - FIT_WINDOW_S)
        cz, _ = _polyfit_at(t[s] - tc, p[s, 2], 2)
        altitude = float(-cz[-1])

        # attitude
        sa = pre & (t >= tc - ATTITUDE_WINDOW_S)
        if sa.sum() < 3:
            sa = pre & (t >= t[last] - ATTITUDE_WINDOW_S)
        Ca = C[sa]
        roll, pitch, yaw = matrix_to_euler_zyx_deg(Ca)
        yaw_u = np.degrees(np.unwrap(np.radians(yaw)))
        incl = inclination_deg(Ca)
        tau_a = t[sa] - tc
        ang: dict[str, float] = {}
        unc: dict[str, float] = {}
        for key, series in (("roll_deg", roll), ("pitch_deg", pitch), ("yaw_deg", yaw_u),
                            ("inclination_deg", incl)):  # fmt: skip
            if len(tau_a) >= 3:
                co, cov = _polyfit_at(tau_a, series, 1)
                val = float(co[1])
                resid = float(np.sqrt(cov[1, 1]))
                slope = float(co[0])
            else:
                val, resid, slope = float(np.mean(series)), float(np.std(series)), 0.0
            ang[key] = val
            unc[key] = math.sqrt(resid**2 + (slope * dtc) ** 2 + ATTITUDE_SYSTEMATIC_DEG**2)
        heading = float(wrap_angle_deg(ang["yaw_deg"]))
        rear = abs(heading) > 90.0
        equiv = float(wrap_angle_deg(heading - 180.0)) if rear else heading
        # leading bumper and wall plane at the contact (the last sample before it,
        # moved to t_c with the fitted velocity)
        reach = bumper_rim_extent(C[last][None], np.array([1.0, 0.0, 0.0]))[0]
        x_c = float(p[last, 0] + vel[0] * (tc - t[last]))
        lead = int(np.argmax(reach)) + 1
        wall_x = x_c + float(reach.max()) if c["observed"] else self._wall_x_default
        if c["method"] == "clock-offset":
            wall_x = math.nan
        unc.update(
            speed_m_s=u_speed,
            heading_deg=unc["yaw_deg"],
            heading_front_equiv_deg=unc["yaw_deg"],
            altitude_m=math.sqrt(0.005**2 + (vel[2] * dtc) ** 2),
            time_s=dtc,
        )
        if c["observed"] and abs(wall_x - self._wall_x_default) > 0.05:
            notes.append(
                f"leading rim at the contact at X = {wall_x:.3f} m, "
                f"{wall_x - self._wall_x_default:+.3f} m from the set's wall plane"
            )
        return PreImpact(
            heading_deg=heading,
            speed_m_s=float(vel[0]),
            inclination_deg=ang["inclination_deg"],
            roll_deg=ang["roll_deg"],
            pitch_deg=ang["pitch_deg"],
            yaw_deg=heading,
            altitude_m=altitude,
            uncertainty=unc,
            time_s=tc - c["offset"],
            velocity_m_s=(float(vel[0]), float(vel[1]), float(vel[2])),
            acceleration_m_s2=(float(acc[0]), float(acc[1]), float(acc[2])),
            speed_lookback_m_s=speed_lookback,
            heading_front_equiv_deg=equiv,
            rear_first=rear,
            leading_bumper=lead,
            wall_x_m=wall_x,
            contact_observed=bool(c["observed"]),
            method=str(c["method"]),
            notes=tuple(notes),
        )

    @property
    def wall_x_m(self) -> float:
        """Wall plane X (NED = motion-capture x) of this flight, nan if unknown."""
        return self._pre_impact.wall_x_m

    @cached_property
    def rest_time_s(self) -> float | None:  # type: ignore[override]
        """First on-board time after the impact from which ``|accel|`` stays below
        ``REST_RATE_THRESHOLD`` for ``REST_HOLD_S`` (None: not before the log ends)."""
        acc = self._raw["accel"]
        t = acc["t_s"].to_numpy()
        mag = np.sqrt((acc[["x_raw", "y_raw", "z_raw"]].to_numpy() ** 2).sum(axis=1))
        after = np.flatnonzero(t > self._impact)
        for k in after:
            w = (t >= t[k]) & (t <= t[k] + REST_HOLD_S)
            if t[w][-1] - t[k] >= 0.9 * REST_HOLD_S and np.all(mag[w] < REST_RATE_THRESHOLD):
                return float(t[k])
        return None
