"""The one schema of results: summary keys and table columns, with kinds, units and meaning.

Everything that describes what a run writes is defined here once:

* :data:`SUMMARY_KEYS`: the keys of ``summary.json`` (nested tables flattened
  with ``__``, as the sweep table's columns are), each with its kind, unit
  and a one-line description, as the typed summary declares them
  (:mod:`quadimpact.results.summary_record`). The sweep table's columns
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

from quadimpact.results.summary_record import Key, summary_keys

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


SUMMARY_KEYS: tuple[Key, ...] = summary_keys()
"""Every summary key, flattened, in order: derived from the typed summary
(:mod:`quadimpact.results.summary_record`), where each is declared once."""

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
