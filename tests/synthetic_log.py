"""Test double: a simulated run presented as a flight log (the FlightLog interface).

Compared with itself a run has zero error; with offsets or a time shift, the
errors are known (``tests/experiments/test_compare.py``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd

from quadimpact.experiments.log_estimates import POWER_OFF_RPM, bumper_rim_extent
from quadimpact.experiments.logs import FlightLog, PreImpact, rpm_to_rad_s
from quadimpact.rotations import quat_to_matrix

__all__ = ["SyntheticLog", "synthetic_log"]


class SyntheticLog(FlightLog):
    """A :class:`FlightLog` made of a simulated run (see :func:`synthetic_log`)."""

    def __init__(
        self,
        timeseries: pd.DataFrame,
        impact_time_s: float,
        *,
        wall_x_m: float = math.nan,
        name: str = "synthetic",
        time_shift_s: float = 0.0,
        offsets: dict[str, float] | None = None,
    ) -> None:
        ts = timeseries.copy()
        ts["t_s"] = ts["t_s"] + time_shift_s
        for col, value in (offsets or {}).items():
            ts[col] = ts[col] + value
        self._ts = ts.reset_index(drop=True)
        self._impact = float(impact_time_s)
        self._wall = float(wall_x_m)
        self.name = name

    @property
    def signals(self) -> dict[str, pd.DataFrame]:
        return {"pose": self.pose(), "motors": self.motors()}

    @property
    def impact_time_s(self) -> float:
        return self._impact

    def pose(self) -> pd.DataFrame:
        cols = ["t_s", "x_m", "y_m", "z_m", "q0", "q1", "q2", "q3", "roll_deg", "pitch_deg",
                "yaw_deg", "altitude_m", "vx_m_s", "vy_m_s", "vz_m_s", "p_rad_s", "q_rad_s",
                "r_rad_s"]  # fmt: skip
        return self._ts[[c for c in cols if c in self._ts.columns]].copy()

    def motors(self) -> pd.DataFrame:
        data: dict[str, Any] = {"t_s": self._ts["t_s"].to_numpy()}
        omega = self._ts[[f"omega{j}_rad_s" for j in range(1, 5)]].to_numpy()
        off = omega <= float(rpm_to_rad_s(POWER_OFF_RPM))
        for j in range(4):
            data[f"omega{j + 1}_rad_s"] = np.where(off[:, j], np.nan, omega[:, j])
        for j in range(4):
            data[f"off{j + 1}"] = off[:, j]
        return pd.DataFrame(data)

    def pre_impact(self) -> PreImpact:
        ts, t0 = self._ts, self._impact

        def at(col: str) -> float:
            return float(np.interp(t0, ts["t_s"], ts[col]))

        q = np.array([at(c) for c in ("q0", "q1", "q2", "q3")])
        C = quat_to_matrix(q)
        incl = math.degrees(math.atan2(-C[0, 2], C[2, 2]))
        yaw = float(np.degrees(np.arctan2(C[1, 0], C[0, 0])))
        rear = abs(yaw) > 90.0
        equiv = (yaw - 180.0 if yaw > 0 else yaw + 180.0) if rear else yaw
        reach = bumper_rim_extent(C[None], np.array([1.0, 0.0, 0.0]))[0]
        return PreImpact(
            heading_deg=yaw,
            speed_m_s=at("vx_m_s"),
            inclination_deg=incl,
            roll_deg=float(np.degrees(np.arctan2(C[2, 1], C[2, 2]))),
            pitch_deg=float(np.degrees(np.arctan2(-C[2, 0], np.hypot(C[0, 0], C[1, 0])))),
            yaw_deg=yaw,
            altitude_m=at("altitude_m"),
            uncertainty={},
            time_s=t0,
            velocity_m_s=(at("vx_m_s"), at("vy_m_s"), at("vz_m_s")),
            heading_front_equiv_deg=equiv,
            rear_first=rear,
            leading_bumper=int(np.argmax(reach)) + 1,
            wall_x_m=self._wall,
            contact_observed=True,
            method="simulation",
        )

    @property
    def wall_x_m(self) -> float:
        return self._wall

    @property
    def rest_time_s(self) -> float | None:
        return None


def synthetic_log(
    result: Any,
    *,
    time_shift_s: float = 0.0,
    offsets: dict[str, float] | None = None,
) -> SyntheticLog:
    """A flight log made of a simulated run (same interface as a real one).

    Parameters
    ----------
    result : SimulationResult
        A run (``timeseries``, ``summary["first_contact_s"]``, ``wall_x_m``).
    time_shift_s : float
        Delay every sample by this much while keeping the impact time: a
        deliberately misaligned copy.
    offsets : dict, optional
        Constants added to time-series columns (e.g. ``{"roll_deg": 2.0}``).
    """
    t0 = result.summary.get("first_contact_s")
    if t0 is None:
        raise ValueError("the run has no first contact: nothing to align on")
    wall = getattr(result, "wall_x_m", None)
    if callable(wall):
        wall = wall()
    if wall is None:
        wall = result.summary.get("wall_distance_m")
    return SyntheticLog(
        result.timeseries,
        float(t0),
        wall_x_m=float(wall) if wall is not None else math.nan,
        time_shift_s=time_shift_s,
        offsets=offsets,
    )
