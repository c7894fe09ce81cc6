"""Spiri crash set I: the reader of ``spiri-crash-set-1/crash_N.mat`` and the set's description.

:class:`SpiriMatLog` reads one flight (MATLAB v5 files converted from ROS
bags) as a :class:`~quadimpact.experiments.logs.FlightLog`; what was
established from the data and the frames are written in
``docs/EXPERIMENTS.md``. The estimates (impact, contact, pre-impact
conditions) are :mod:`~quadimpact.experiments.log_estimates`'s.
"""

from __future__ import annotations

from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from quadimpact.experiments.log_estimates import (
    MOCAP_GAP_S,
    POWER_OFF_RPM,
    estimate_pre_impact,
    find_impact,
    locate_contact,
    rest_time,
    segments,
)
from quadimpact.experiments.logs import DATA_ENV_VAR, FlightLog, PreImpact, data_dir, rpm_to_rad_s
from quadimpact.inputs.toml_files import read_toml_file
from quadimpact.rotations import (
    matrix_to_euler_zyx_deg,
    matrix_to_quat,
    matrix_to_rotvec,
    quat_xyzw_to_matrix,
)

__all__ = [
    "BURST_DT_S",
    "MOCAP_TO_NED",
    "SET1_MOCAP_CLOCK_OFFSET_S",
    "SET1_WALL_X_M",
    "SpiriMatLog",
    "crash_set_1",
]

#: Motion-capture world (x, y, z up; the wall's normal is +x) to NED: a rotation
#: of 180 deg about x. Positions: ``p_NED = MOCAP_TO_NED p_mocap``; attitude:
#: ``C = MOCAP_TO_NED R(q_mocap)`` (the motion-capture body frame is FRD).
MOCAP_TO_NED = np.diag([1.0, -1.0, -1.0])
#: On-board samples closer than this to the previous one arrived in a burst
#: after a radio stall and are re-timed (spread back at the topic's period).
BURST_DT_S = 0.003
#: Crash set I: the wall plane X (motion-capture x, m), median over the flights
#: whose contact is observed (leading bumper rim at the contact), and the median
#: clock offset (motion-capture contact minus on-board impact, s). Used only
#: when a flight's own contact is not observed (see ``PreImpact.method``).
SET1_WALL_X_M = 1.14
SET1_MOCAP_CLOCK_OFFSET_S = 0.016


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
    path = base / "spiri_crash_set_1.toml"
    if not path.is_file():
        raise FileNotFoundError(f"{path}: file not found")
    return dict(read_toml_file(path)["crash"])


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

    Raises
    ------
    InputError
        The file is not a MATLAB file of the set's layout (one line naming it).

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
        try:
            self._mat = loadmat(self.path, squeeze_me=True)
            self._raw = self._read_raw()
        except Exception as exc:  # scipy's MatReadError, a missing or malformed variable...
            from quadimpact.errors import InputError, one_line

            raise InputError(
                f"{self.path}: not a readable crash log of the set ({type(exc).__name__}: "
                f"{one_line(str(exc))})"
            ) from None
        self._impact, self._impact_bracket, self._power_off = find_impact(
            self._raw.get("accel"), self._raw.get("motors"), self.path.name
        )

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
        # the products with the diagonal sign matrices as sign flips (exact, and no BLAS)
        signs = np.diag(MOCAP_TO_NED)
        p = v[["x_m", "y_m", "z_m"]].to_numpy() * signs  # MOCAP_TO_NED p
        C = signs[:, None] * quat_xyzw_to_matrix(v[["qx", "qy", "qz", "qw"]].to_numpy())
        if self.front_first:
            C = C * np.array([-1.0, -1.0, 1.0])  # C diag(-1, -1, 1)
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
        seg = segments(t, MOCAP_GAP_S)
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
    @cached_property
    def _contact(self) -> dict[str, Any]:
        """The wall contact on the motion capture (:func:`estimation.locate_contact`)."""
        return locate_contact(self._mocap, self._impact, self._wall_x_default, self._offset_default)

    def pre_impact(self) -> PreImpact:
        """Pre-impact conditions from the motion capture
        (:func:`~quadimpact.experiments.log_estimates.estimate_pre_impact`: method in
        ``docs/EXPERIMENTS.md``; the set's wall plane ``SET1_WALL_X_M`` and clock
        offset ``SET1_MOCAP_CLOCK_OFFSET_S`` serve where the contact is not observed)."""
        return self._pre_impact

    @cached_property
    def _pre_impact(self) -> PreImpact:
        return estimate_pre_impact(self._mocap, self._contact, self._impact, self._wall_x_default)

    @property
    def wall_x_m(self) -> float:
        """Wall plane X (NED = motion-capture x) of this flight, nan if unknown."""
        return self._pre_impact.wall_x_m

    @cached_property
    def rest_time_s(self) -> float | None:  # type: ignore[override]
        """First on-board time after the impact from which ``|accel|`` stays below
        ``REST_RATE_THRESHOLD`` for ``REST_HOLD_S`` (None: not before the log ends)."""
        return rest_time(self._raw["accel"], self._impact)
