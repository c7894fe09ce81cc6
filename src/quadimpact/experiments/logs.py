"""Flight logs of real crashes: the reader interface, in quadimpact's units and frames.

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

The Spiri crash-set reader is :class:`~quadimpact.experiments.spiri_mat.SpiriMatLog`;
the estimators it uses are in :mod:`~quadimpact.experiments.log_estimates`. What
was established from the data, the frames and the estimation methods are
written in ``docs/EXPERIMENTS.md``.

The data are never copied into the project: :func:`data_dir` finds them.
"""

from __future__ import annotations

import math
import os
from abc import ABC, abstractmethod
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

__all__ = [
    "DATA_ENV_VAR",
    "DATA_SEARCH",
    "FlightLog",
    "PreImpact",
    "data_dir",
    "data_search_folders",
    "find_data_dir",
    "rpm_to_rad_s",
]

# --------------------------------------------------------------------------- data
#: Environment variable naming the data folder (holding ``spiri-crash-set-1/``).
DATA_ENV_VAR = "QUADIMPACT_DATA"


#: Where the flight logs are looked for without --data, in order (docs/EXPERIMENTS.md).
DATA_SEARCH = (
    f"${DATA_ENV_VAR} when set (then only it), else shared/data or ../shared/data under "
    "the working folder, else ../shared/data beside the source checkout quadimpact runs from"
)


def data_search_folders(cwd: Path | None = None) -> list[tuple[Path, str]]:
    """The folders searched without ``$QUADIMPACT_DATA``, in order, each with how it is named.

    Only folders relative to the working folder ``cwd`` (default: the current
    one) and, when quadimpact runs from a source checkout (``src/`` layout
    beside a ``pyproject.toml``), to that checkout: never a fixed path of any
    machine.
    """
    base = Path.cwd() if cwd is None else Path(cwd)
    folders = [
        (base / "shared" / "data", "shared/data under the working folder"),
        (base / ".." / "shared" / "data", "../shared/data beside the working folder"),
    ]
    here = Path(__file__).resolve()  # <checkout>/src/quadimpact/experiments/logs.py
    if len(here.parents) > 3 and (here.parents[3] / "pyproject.toml").is_file():
        folders.append((here.parents[3] / ".." / "shared" / "data", "beside the checkout"))
    return folders


def find_data_dir() -> tuple[Path | None, str]:
    """The data folder and how it was found (``$QUADIMPACT_DATA``, the folders searched).

    In the order of :data:`DATA_SEARCH`; a folder counts only if it holds
    ``spiri-crash-set-1/``. Returns ``(None, why)`` when there is none.
    """
    env = os.environ.get(DATA_ENV_VAR)
    if env:
        p = Path(env).resolve()
        if (p / "spiri-crash-set-1").is_dir():
            return p, f"${DATA_ENV_VAR}"
        return None, f"${DATA_ENV_VAR}={env} holds no spiri-crash-set-1/"
    for c, how in data_search_folders():
        c = c.resolve()
        if (c / "spiri-crash-set-1").is_dir():
            return c, how
    return None, f"none found ({DATA_SEARCH})"


def data_dir() -> Path | None:
    """The shared data folder, or None when it is absent (:func:`find_data_dir`)."""
    return find_data_dir()[0]


def rpm_to_rad_s(rpm: Any) -> Any:
    """Revolutions per minute to rad/s."""
    return np.asarray(rpm, dtype=float) * (2.0 * math.pi / 60.0)


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
        (docs/STUDIES.md section 1; 0 = nose at the wall).
    speed_m_s : float
        CM velocity toward the wall (along X) at the contact.
    inclination_deg : float
        Angle of the body z axis projected on the X-Z plane from Z, positive
        when the vehicle leans toward the wall (docs/STUDIES.md section 1).
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
        Speed toward the wall ``estimation.LOOKBACK_S`` before the contact (same fit).
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
