"""Figures 5 and 6: the lines drawn carry the data; files are written."""

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest

from quadimpact.results.figures import break_wraps, make_fig5, make_fig6, plot_fig5, plot_fig6


def make_ts(n: int = 400) -> pd.DataFrame:
    t = np.linspace(0.0, 3.0, n)
    hit = np.clip(t - 0.5, 0.0, None)
    return pd.DataFrame(
        {
            "t_s": t,
            "x_m": 1.3 + 0.2 * np.sin(5 * t),
            "y_m": 0.01 * t,
            "altitude_m": 2.0 - 0.3 * hit**2,
            "roll_deg": 30.0 * np.sin(4 * t),
            "pitch_deg": -15.0 + 5.0 * np.cos(3 * t),
            "yaw_deg": 45.0 + 20.0 * np.sin(2 * t),
            "delta1_m": 0.001 * np.abs(np.sin(7 * t)),
            "delta2_m": 0.010 * np.abs(np.sin(5 * t)),
            "delta3_m": 0.002 * np.abs(np.sin(3 * t)),
            "delta4_m": 0.030 * np.abs(np.sin(2 * t)),
        }
    )


REFS = {
    "roll_rad": 0.0,
    "pitch_rad": math.radians(-15.0),
    "yaw_rad": math.radians(45.0),
    "altitude_m": 2.0,
}


def test_fig5_lines_are_the_deflections_in_mm() -> None:
    ts = make_ts()
    fig = make_fig5(ts, title="test")
    (ax,) = fig.axes
    assert len(ax.lines) == 4
    for j, line in enumerate(ax.lines, start=1):
        np.testing.assert_array_equal(line.get_xdata(), ts["t_s"].to_numpy())
        np.testing.assert_allclose(line.get_ydata(), 1e3 * ts[f"delta{j}_m"].to_numpy())
        assert line.get_label() == f"Bumper {j}"
    assert "mm" in ax.get_ylabel() and "s" in ax.get_xlabel()
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        f"Bumper {j}" for j in range(1, 5)
    ]


def test_fig6_panels_carry_states_and_references() -> None:
    ts = make_ts()
    fig = make_fig6(ts, REFS, wall_x_m=1.5)
    ax_x, ax_roll, ax_y, ax_pitch, ax_alt, ax_yaw = fig.axes
    t = ts["t_s"].to_numpy()
    for ax, col in [
        (ax_x, "x_m"),
        (ax_y, "y_m"),
        (ax_alt, "altitude_m"),
        (ax_roll, "roll_deg"),
        (ax_pitch, "pitch_deg"),
        (ax_yaw, "yaw_deg"),
    ]:
        np.testing.assert_array_equal(ax.lines[0].get_xdata(), t)
        np.testing.assert_allclose(ax.lines[0].get_ydata(), ts[col].to_numpy())
    # Reference / wall lines: horizontal, dashed, at the right value.
    for ax, value in [
        (ax_x, 1.5),
        (ax_alt, 2.0),
        (ax_roll, 0.0),
        (ax_pitch, -15.0),
        (ax_yaw, 45.0),
    ]:
        ref = ax.lines[1]
        assert ref.get_linestyle() == "--"
        np.testing.assert_allclose(ref.get_ydata(), [value, value])
    assert len(ax_y.lines) == 1  # no reference for Y
    assert ax_x.lines[1].get_label() == "wall"
    assert "deg" in ax_yaw.get_ylabel() and "(m)" in ax_alt.get_ylabel()


def test_fig6_without_wall_or_references() -> None:
    fig = make_fig6(
        make_ts(), {"roll_rad": None, "pitch_rad": 0.0, "yaw_rad": 0.0, "altitude_m": float("nan")}
    )
    ax_x, ax_roll, _, _, ax_alt, _ = fig.axes
    assert len(ax_x.lines) == 1 and len(ax_alt.lines) == 1 and len(ax_roll.lines) == 1


def test_wrapped_yaw_is_broken_not_joined() -> None:
    t = np.array([0.0, 1.0, 2.0, 3.0])
    yaw = np.array([170.0, 179.0, -178.0, -170.0])
    tt, yy = break_wraps(t, yaw)
    np.testing.assert_array_equal(tt[[0, 1, 3, 4]], t)
    np.testing.assert_array_equal(yy[[0, 1, 3, 4]], yaw)
    assert np.isnan(yy[2]) and np.isnan(tt[2])
    t2, y2 = break_wraps(t, np.array([0.0, 10.0, 20.0, 30.0]))
    np.testing.assert_array_equal(y2, [0.0, 10.0, 20.0, 30.0])


def test_fig6_draws_roll_and_yaw_unwrapped() -> None:
    """Yaw from 170 through 180 to -170 deg: one continuous line 170..190, reference on it."""
    ts = make_ts()
    n = len(ts)
    ts["yaw_deg"] = ((np.linspace(170.0, 190.0, n) + 180.0) % 360.0) - 180.0
    fig = make_fig6(ts, {**REFS, "yaw_rad": np.radians(-175.0)})
    ax_yaw = fig.axes[5]
    y = ax_yaw.lines[0].get_ydata()
    np.testing.assert_allclose(y, np.linspace(170.0, 190.0, n), atol=1e-9)
    assert ax_yaw.lines[1].get_ydata()[0] == pytest.approx(185.0)  # -175 on the line's branch


def test_files_written_and_no_pyplot_state(tmp_path: Path) -> None:
    before = plt.get_fignums()
    ts = make_ts()
    p5 = plot_fig5(ts, tmp_path / "fig5.png", title="ψ = 45°")
    p6 = plot_fig6(ts, REFS, tmp_path / "fig6.png", wall_x_m=1.5, title="ψ = 45°")
    for p in (p5, p6):
        assert p.exists()
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert p.stat().st_size > 20_000
    assert plt.get_fignums() == before
    assert sorted(f.name for f in tmp_path.iterdir()) == ["fig5.png", "fig6.png"]
