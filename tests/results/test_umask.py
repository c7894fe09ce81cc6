"""Every file and folder quadimpact writes follows the umask, so that a group can share them."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from helpers import run_cli


def _modes(root: Path) -> dict[str, int]:
    """Permission bits of every file and folder below ``root`` (relative names)."""
    out = {}
    for folder, dirs, files in os.walk(root):
        for name in dirs + files:
            path = Path(folder) / name
            out[str(path.relative_to(root))] = stat.S_IMODE(path.lstat().st_mode)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("umask", [0o022, 0o002])
def test_run_sweep_and_pictures_follow_the_umask(tmp_path: Path, umask: int) -> None:
    steps = [
        ["run", "--final-time", "0.8", "--output-rate", "200", "--out", "run", "--viz"],
        ["snapshots", "run", "--times", "0,0.05"],
        ["view", "run", "--rate", "50"],
        ["animate", "run", "--size", "320x180", "--fps", "10", "--gif"],
        ["sweep", "--grid", "speed_m_s=0.5,1", "--grid", "inclination_deg=0,5", "--out", "sweep",
         "--workers", "2"],
    ]  # fmt: skip
    for args in steps:
        proc = run_cli(*args, cwd=tmp_path, timeout=300, umask=umask)
        assert proc.returncode == 0, (args, proc.stderr)
    modes = _modes(tmp_path)
    expected = {
        "run/animation.gif", "run/animation.mp4", "run/viewer.html", "run/snapshots.png",
        "run/snapshots.pdf", "run/summary.json", "run/scenario.json", "run/timeseries.parquet",
        "run/episodes.csv", "run/imu.parquet", "run/fig5.png", "run/fig6.png", "run/imu.png",
        "sweep/runs.parquet", "sweep/sweep.json", "sweep/.lock", "sweep/parts", "sweep/plots",
    }  # fmt: skip
    assert expected <= set(modes), sorted(expected - set(modes))
    for name, mode in modes.items():
        want = (0o777 if (tmp_path / name).is_dir() else 0o666) & ~umask
        assert mode == want, f"{name}: {mode:o}, not {want:o} under umask {umask:03o}"
