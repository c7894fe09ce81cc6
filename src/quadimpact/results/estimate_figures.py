"""The estimate beside the truth: a run's estimation figure and the estimators compared.

* :func:`make_estimate` (``estimate.png`` of a run folder with an estimator
  other than ``ideal``): roll, pitch and yaw of the truth (time series) and of
  the estimate (IMU samples); the attitude error; the velocity and position
  errors; the gyro-bias estimate beside the true bias. The detection and the
  stage entries are marked.
* :func:`make_error_comparison`: one trial's attitude error over time around
  the impact, one curve per estimator (``quadimpact reproduce``).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from quadimpact.results.figures import (
    fit_title,
    mark_stages,
    new_figure,
    save_figure,
    set_time_limits,
)
from quadimpact.rotations import quat_to_euler_zyx

__all__ = ["make_error_comparison", "make_estimate", "plot_estimate"]

_AXES = (("roll", "tab:blue"), ("pitch", "tab:orange"), ("yaw", "tab:green"))


def _col(table: Any, name: str) -> np.ndarray:
    return np.asarray(table[name], dtype=np.float64)


def make_estimate(
    imu: Any, ts: Any, summary: Mapping[str, Any] | None = None, title: str | None = None
) -> Figure:
    """The estimation figure of a run (see the module docstring)."""
    fig = new_figure(8.0, 10.0)
    axes = list(fig.subplots(4, 1, sharex=True))
    t = _col(imu, "t_s")
    q_hat = np.stack([_col(imu, f"q{k}_hat") for k in range(4)], axis=1)
    euler_hat = np.degrees(np.stack(quat_to_euler_zyx(q_hat), axis=1))
    ax = axes[0]
    tt = _col(ts, "t_s")
    for k, (name, color) in enumerate(_AXES):
        ax.plot(tt, np.unwrap(_col(ts, f"{name}_deg"), period=360.0), color=color, linewidth=1.2,
                label=f"{name} (true)")  # fmt: skip
        ax.plot(t, np.unwrap(euler_hat[:, k], period=360.0), color=color, linewidth=1.0,
                linestyle="--", label=f"{name} (estimate)")  # fmt: skip
    ax.set_ylabel("Attitude (deg)")
    ax.legend(loc="best", fontsize="small", ncols=3)  # where it covers the least
    ax = axes[1]
    ax.plot(t, _col(imu, "attitude_error_deg"), color="black", linewidth=1.0)
    ax.set_ylabel("Attitude error (deg)")
    ax = axes[2]
    ax.plot(t, _col(imu, "velocity_error_m_s"), color="tab:purple", linewidth=1.0,
            label="velocity (m/s)")  # fmt: skip
    ax.plot(t, _col(imu, "position_error_m"), color="tab:brown", linewidth=1.0,
            label="position (m)")  # fmt: skip
    ax.set_ylabel("Error")
    ax.legend(loc="upper left", fontsize="small")
    ax = axes[3]
    for axis, color in zip("pqr", ("tab:blue", "tab:orange", "tab:green"), strict=True):
        ax.plot(t, _col(imu, f"bias_{axis}_true_rad_s"), color=color, linewidth=1.2,
                label=f"b_{axis} (true)")  # fmt: skip
        ax.plot(t, _col(imu, f"bias_{axis}_hat_rad_s"), color=color, linewidth=1.0,
                linestyle="--", label=f"b_{axis} (estimate)")  # fmt: skip
    ax.set_ylabel("Gyro bias (rad/s)")
    ax.set_xlabel("Time (s)")
    ax.legend(loc="best", fontsize="small", ncols=3)  # where it covers the least
    for k, ax in enumerate(axes):
        mark_stages(ax, summary, label=k == 1)
        ax.grid(True, alpha=0.4)
    axes[1].legend(loc="upper right", fontsize="small")
    set_time_limits(axes[0], t)
    name = (summary or {}).get("estimator")
    head = f"Estimate ({name}) beside the truth" if name else "Estimate beside the truth"
    fit_title(fig, f"{head}: {title}" if title else head)
    return fig


def plot_estimate(
    imu: Any,
    ts: Any,
    path: str | os.PathLike[str],
    summary: Mapping[str, Any] | None = None,
    title: str | None = None,
) -> Path:
    """Write the estimation figure (:func:`make_estimate`) to ``path`` as PNG."""
    return save_figure(make_estimate(imu, ts, summary=summary, title=title), path)


def make_error_comparison(
    runs: Mapping[str, Any], *, before_s: float = 0.2, after_s: float = 1.5, title: str = ""
) -> Figure:
    """One trial's attitude error over time around the impact, one curve per estimator.

    ``runs``: estimator name -> the trial's ``SimulationResult`` (its ``imu``
    table and summary). Time is measured from the first contact.
    """
    fig = new_figure(8.0, 4.0)
    ax = fig.subplots(1, 1)
    for name, result in runs.items():
        s = result.summary
        t0 = s.get("first_contact_s") or 0.0
        imu = result.imu
        t = np.asarray(imu["t_s"], dtype=np.float64) - t0
        keep = (t >= -before_s) & (t <= after_s)
        ax.plot(t[keep], np.asarray(imu["attitude_error_deg"])[keep], linewidth=1.2, label=name)
        t4 = s.get("t_stage4_s")
        if t4 is not None:
            ax.axvline(t4 - t0, linestyle="--", linewidth=0.8, color=ax.lines[-1].get_color())
    ax.axvline(0.0, color="black", linestyle=":", linewidth=1.0, label="first contact")
    ax.set_xlabel("Time from the first contact (s)")
    ax.set_ylabel("Attitude error (deg)")
    ax.grid(True, alpha=0.4)
    ax.legend(loc="upper right", fontsize="small")
    fit_title(fig, title or "Attitude error around the impact (dashed: stage 4)")
    return fig
