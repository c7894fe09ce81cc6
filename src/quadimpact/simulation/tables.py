"""Raw kernel arrays -> tables: the episodes and time-series tables of a run.

Pure functions of plain arrays, testable on hand-made inputs. Raw arrays come
from the compiled kernel with the layout of :mod:`quadimpact.core.layout`
(``OUT_*`` time-series columns, ``E_*`` episode columns); the tables' columns
are :data:`~quadimpact.results.files.EPISODE_COLUMNS` and
:data:`~quadimpact.results.files.TIMESERIES_COLUMNS` (docs/RESULTS.md). Frames
and units follow docs/MODEL.md section 1 (inertial NED, body FRD, SI).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from quadimpact.core import layout as L
from quadimpact.core.recording_slots import (
    E_FEATURE,
    E_OPEN,
    E_PEAK_DELTA,
    E_PEAK_FORCE,
    E_SHAPE,
    E_T_END,
    E_T_PEAK,
    E_T_PEAK_FORCE,
    E_T_START,
    E_V_I,
    NEP,
    OUT_CMD,
    OUT_DELTA,
    OUT_STAGE,
    OUT_T,
    OUT_X,
    out_width,
)
from quadimpact.core.sensors import detection as DET
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.core.sensors.registry import record_address, record_columns
from quadimpact.inputs.features import feature_column
from quadimpact.results.files import BUMPERS, EPISODE_COLUMNS, IMU_COLUMNS
from quadimpact.rotations import body_to_inertial, quat_to_euler_zyx
from quadimpact.simulation.metrics import EpisodeLists

if TYPE_CHECKING:  # pandas is imported where a DataFrame is built
    import pandas as pd

__all__ = [
    "episode_columns",
    "episode_lists_of",
    "episodes_frame",
    "imu_columns",
    "imu_frame",
    "timeseries_columns",
    "timeseries_frame",
]

# Raw episode columns -> table columns (float-valued ones).
_EPISODE_FLOAT_SOURCES: tuple[tuple[str, int], ...] = (
    ("t_start_s", E_T_START),
    ("t_end_s", E_T_END),
    ("v_i_m_s", E_V_I),
    ("peak_delta_m", E_PEAK_DELTA),
    ("t_peak_s", E_T_PEAK),
    ("peak_force_n", E_PEAK_FORCE),
    ("t_peak_force_s", E_T_PEAK_FORCE),
)


def _rows(raw: np.ndarray, n: int, width: int, what: str) -> np.ndarray:
    """First ``n`` rows of a 2-D raw kernel array, checked against its layout width."""
    a = np.asarray(raw, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] < width:
        raise ValueError(f"{what}: expected a 2-D array with {width} columns (got {a.shape})")
    n = int(n)
    if not 0 <= n <= a.shape[0]:
        raise ValueError(f"{what}: row count must be in [0, {a.shape[0]}] (got {n})")
    return a[:n]


def _empty_episodes() -> pd.DataFrame:
    import pandas as pd

    data: dict[str, Any] = {
        "bumper": pd.Series([], dtype="int64"),
        "surface": pd.Series([], dtype=object).astype(str),
    }
    for name, _ in _EPISODE_FLOAT_SOURCES:
        data[name] = pd.Series([], dtype="float64")
    data["open"] = pd.Series([], dtype=bool)
    return pd.DataFrame(data, columns=list(EPISODE_COLUMNS))


def episode_columns(
    raw: np.ndarray, n: int, surface_names: Sequence[str], n_features: int = len(BUMPERS)
) -> dict[str, np.ndarray]:
    """The columns of :func:`episodes_frame` as NumPy arrays (no DataFrame), same order."""
    rows = _rows(raw, n, NEP, "episodes")
    bumper_idx = np.rint(rows[:, E_FEATURE]).astype(np.int64)
    if np.any((bumper_idx < 0) | (bumper_idx >= n_features)):
        got = sorted(set(bumper_idx.tolist()))
        raise ValueError(f"episodes: feature index outside 0..{n_features - 1} (got {got})")
    surf_idx = np.rint(rows[:, E_SHAPE]).astype(np.int64)
    names = list(surface_names)
    if np.any((surf_idx < 0) | (surf_idx >= len(names))):
        got = sorted(set(surf_idx.tolist()))
        raise ValueError(f"episodes: surface index outside 0..{len(names) - 1} (got {got})")
    # sorted by start, then bumper; ties keep the kernel's order (a stable sort)
    order = np.lexsort((bumper_idx, rows[:, E_T_START]))
    data: dict[str, np.ndarray] = {
        "bumper": bumper_idx[order] + 1,
        "surface": np.array([str(names[i]) for i in surf_idx[order]], dtype=object),
    }
    for name, col in _EPISODE_FLOAT_SOURCES:
        data[name] = rows[order, col].copy()
    data["open"] = rows[order, E_OPEN] > 0.5
    return {name: data[name] for name in EPISODE_COLUMNS}


def episode_lists_of(
    raw: np.ndarray, n: int, surface_names: Sequence[str], n_features: int = len(BUMPERS)
) -> EpisodeLists:
    """The columns of :func:`episode_columns` as Python lists, same order and values.

    What a run's summary reads: a run has a handful of episodes, and lists of
    them (one conversion of the raw rows) cost less than NumPy columns.
    ``surface`` holds names, ``bumper`` the feature 1-based, ``open`` bools.
    """
    rows = _rows(raw, n, NEP, "episodes").tolist()
    names = [str(name) for name in surface_names]
    start = [r[E_T_START] for r in rows]
    if any(t != t for t in start):  # NaN starts: sorted as NumPy sorts them
        cols = episode_columns(raw, n, surface_names, n_features)
        return EpisodeLists({k: v.tolist() for k, v in cols.items()})
    feature = [_index(r[E_FEATURE], n_features, "feature", rows, E_FEATURE) for r in rows]
    surface = [_index(r[E_SHAPE], len(names), "surface", rows, E_SHAPE) for r in rows]
    # by start, then feature; ties keep the kernel's order (a stable sort)
    order = sorted(range(len(rows)), key=lambda i: (start[i], feature[i]))
    data: dict[str, list[Any]] = {
        "bumper": [feature[i] + 1 for i in order],
        "surface": [names[surface[i]] for i in order],
    }
    for name, col in _EPISODE_FLOAT_SOURCES:
        data[name] = [rows[i][col] for i in order]
    data["open"] = [rows[i][E_OPEN] > 0.5 for i in order]
    return EpisodeLists({name: data[name] for name in EPISODE_COLUMNS})


def _index(value: float, count: int, what: str, rows: list[list[float]], col: int) -> int:
    """A feature's or a surface's index in a raw episode (a whole float), checked to be in range."""
    if value == value and abs(value) < 2.0**62:
        k = round(value)  # half to even, as numpy.rint
        if 0 <= k < count:
            return k
    got = sorted({int(np.rint(r[col])) if r[col] == r[col] else r[col] for r in rows})
    raise ValueError(f"episodes: {what} index outside 0..{count - 1} (got {got})")


def episodes_frame(
    raw: np.ndarray, n: int, surface_names: Sequence[str], n_features: int = len(BUMPERS)
) -> pd.DataFrame:
    """Contact-episode table from the kernel's episode array.

    Parameters
    ----------
    raw : numpy.ndarray, shape (max_episodes, NEP)
        Episode records with the ``E_*`` columns of :mod:`quadimpact.core.recording_slots`
        (feature 0-based, surface as an index into the run's shapes).
    n : int
        Number of valid rows (``stats[ST_N_EPISODES]``, capped by the buffer).
    surface_names : sequence of str
        Name of each surface, in the order of the kernel's shape array.
    n_features : int
        The vehicle's number of contact features (four bumper rings).

    Returns
    -------
    pandas.DataFrame
        Columns :data:`EPISODE_COLUMNS`: ``bumper`` (the feature, 1-based: the
        bumper 1-4 of a ring vehicle), ``surface`` (name),
        times in s, ``v_i_m_s`` (penetration rate at onset, m/s),
        ``peak_delta_m`` (m), ``peak_force_n`` (N), ``open`` (bool: still in
        contact when the run stopped; ``t_end_s`` is then the run end).
        Sorted by ``t_start_s`` then ``bumper``, with a fresh 0..n-1 index.
    """
    import pandas as pd

    data = episode_columns(raw, n, surface_names, n_features)
    if len(data["bumper"]) == 0:
        return _empty_episodes()
    data["surface"] = list(data["surface"])
    return pd.DataFrame(data, columns=list(EPISODE_COLUMNS))


_RINGS = tuple(str(j) for j in BUMPERS)


def timeseries_frame(
    raw: np.ndarray, n: int, feature_names: Sequence[str] = _RINGS, rotors: int = 4
) -> pd.DataFrame:
    """Time-series table from the kernel's output samples.

    Parameters
    ----------
    raw : numpy.ndarray, shape (max_out, out_width(n_features))
        Output samples with the ``OUT_*`` columns of :mod:`quadimpact.core.recording_slots`.
    n : int
        Number of valid rows (``stats[ST_N_OUT]``).
    feature_names : sequence of str
        The vehicle's contact features (default: the four bumpers ``"1"``..``"4"``).
    rotors : int
        The vehicle's rotor count ``n`` (default a quadrotor's 4): the columns
        ``omega1..n_rad_s`` and ``omega_cmd1..n_rad_s``.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`TIMESERIES_COLUMNS`: time (s); CM position ``x/y/z_m``
        (inertial NED, m); CM velocity in body axes ``u/v/w_m_s`` and in
        inertial axes ``vx/vy/vz_m_s`` (m/s, ``C(q) [u, v, w]``); quaternion
        ``q0..q3`` (scalar first, body -> inertial, as integrated); body rates
        ``p/q/r_rad_s``; rotor speeds and commands of rotors 1 to n (rad/s); ZYX Euler angles
        ``roll/pitch/yaw_deg`` (degrees; roll and yaw wrapped to (-180, 180],
        pitch in [-90, 90]; not unwrapped); ``altitude_m = -z_m``; per contact
        feature its deflection (``delta1..4_m`` for the four bumpers, m, max
        over surfaces) and normal force (``force1..4_n``, N, sum over
        surfaces); ``stage``, the controller's stage in force (0 for
        controllers without stages).
    """
    import pandas as pd

    return pd.DataFrame(timeseries_columns(raw, n, feature_names, rotors))


def timeseries_columns(
    raw: np.ndarray, n: int, feature_names: Sequence[str] = _RINGS, rotors: int = 4
) -> dict[str, np.ndarray]:
    """The columns of :func:`timeseries_frame` as NumPy arrays (no DataFrame)."""
    names = list(feature_names)
    nf = len(names)
    rows = _rows(raw, n, out_width(nf), "timeseries")
    x0 = OUT_X
    pos = rows[:, x0 + L.X_POS : x0 + L.X_POS + 3]
    vel_b = rows[:, x0 + L.X_VEL : x0 + L.X_VEL + 3]
    quat = rows[:, x0 + L.X_QUAT : x0 + L.X_QUAT + 4]
    omega = rows[:, x0 + L.X_OMEGA : x0 + L.X_OMEGA + 3]
    rotor = rows[:, x0 + L.X_ROTOR : x0 + L.X_ROTOR + rotors]
    if rows.shape[0] > 0:
        vel_i = body_to_inertial(quat, vel_b)
        roll, pitch, yaw = quat_to_euler_zyx(quat)
    else:
        vel_i = np.empty((0, 3))
        roll = pitch = yaw = np.empty(0)
    data: dict[str, np.ndarray] = {
        "t_s": rows[:, OUT_T],
        "x_m": pos[:, 0],
        "y_m": pos[:, 1],
        "z_m": pos[:, 2],
        "u_m_s": vel_b[:, 0],
        "v_m_s": vel_b[:, 1],
        "w_m_s": vel_b[:, 2],
        "vx_m_s": vel_i[:, 0],
        "vy_m_s": vel_i[:, 1],
        "vz_m_s": vel_i[:, 2],
        "q0": quat[:, 0],
        "q1": quat[:, 1],
        "q2": quat[:, 2],
        "q3": quat[:, 3],
        "p_rad_s": omega[:, 0],
        "q_rad_s": omega[:, 1],
        "r_rad_s": omega[:, 2],
    }
    for j in range(1, rotors + 1):
        data[f"omega{j}_rad_s"] = rotor[:, j - 1]
    for j in range(1, rotors + 1):
        data[f"omega_cmd{j}_rad_s"] = rows[:, OUT_CMD + j - 1]
    data["roll_deg"] = np.degrees(roll)
    data["pitch_deg"] = np.degrees(pitch)
    data["yaw_deg"] = np.degrees(yaw)
    data["altitude_m"] = -pos[:, 2]
    for f, name in enumerate(names):
        data[feature_column("delta", name, "m")] = rows[:, OUT_DELTA + f]
    for f, name in enumerate(names):
        data[feature_column("force", name, "n")] = rows[:, OUT_DELTA + nf + f]
    data["stage"] = rows[:, OUT_STAGE]
    return {k: np.array(v, dtype=np.float64) for k, v in data.items()}


# the magnetometer's and the pose sensor's columns (sensor components whose columns
# are among the table's fixed ones, at their place: ``mx``..., ``pose_x_m``...)
_MAG = record_address("magnetometer")
_POSE = record_address("pose_sensor")


def imu_columns(raw: np.ndarray, scfg: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """The columns of :func:`imu_frame` as NumPy arrays (no DataFrame).

    ``scfg``: the run's sensor settings; the sensor components it has add
    their record columns (``<name>_<slot>``) after the fixed ones.
    """
    rows = np.asarray(raw, dtype=np.float64)
    rows = rows.reshape(-1, rows.shape[-1] if rows.ndim == 2 else IMS.NIMU)
    sources = (
        IMS.I_T, IMS.I_F, IMS.I_F + 1, IMS.I_F + 2, IMS.I_W, IMS.I_W + 1, IMS.I_W + 2,
        IMS.I_F_TRUE, IMS.I_F_TRUE + 1, IMS.I_F_TRUE + 2,
        IMS.I_W_TRUE, IMS.I_W_TRUE + 1, IMS.I_W_TRUE + 2,
        DET.I_HORIZONTAL,
        *range(_MAG, _MAG + 3), *range(_POSE, _POSE + 7),
        *range(IMS.I_Q_HAT, IMS.I_Q_HAT + 4), *range(IMS.I_BIAS_HAT, IMS.I_BIAS_HAT + 3),
        *range(IMS.I_VEL_HAT, IMS.I_VEL_HAT + 3), *range(IMS.I_POS_HAT, IMS.I_POS_HAT + 3),
        *range(IMS.I_BIAS_TRUE, IMS.I_BIAS_TRUE + 3), *range(IMS.I_ERR, IMS.I_ERR + 4),
    )  # fmt: skip
    out = {
        name: rows[:, col].copy() if col < rows.shape[1] else np.full(len(rows), np.nan)
        for name, col in zip(IMU_COLUMNS, sources, strict=True)
    }
    if scfg is not None:
        for name, col, _unit in record_columns(scfg):
            out[name] = rows[:, col].copy() if col < rows.shape[1] else np.full(len(rows), np.nan)
    return out


def imu_frame(raw: np.ndarray, scfg: np.ndarray | None = None) -> pd.DataFrame:
    """IMU table from the kernel's IMU samples (layout ``I_*``).

    Returns
    -------
    pandas.DataFrame
        Columns :data:`~quadimpact.results.files.IMU_COLUMNS`: time (s); measured
        specific force ``fx/fy/fz_m_s2`` (body FRD, m/s^2) and angular rate
        ``p/q/r_rad_s``; the true values (``*_true_*``); the detector's horizontal
        measure ``f_horizontal_m_s2``; the magnetometer and the pose sensor (NaN
        where absent); the estimate after the sample (``*_hat*``), the gyro's true
        bias and the estimate's errors (docs/RESULTS.md); then the columns of the
        run's sensor components (``barometer_altitude_m``...), when ``scfg`` is given.
    """
    import pandas as pd

    return pd.DataFrame(imu_columns(raw, scfg))
