"""A new per-run array costs a field, its stage and nothing else (``core/records.py``).

The test adds, to a copy of the package, a fake barometer: its state (the
last altitude it read, and when) carried in :class:`Data` and its samples in
:class:`Output`, sampled with the IMU. It touches three files: the records
(the fields, their factories and row functions), the sensor's module, and
the sensor stage that calls it. The copy then runs an impact trial, and the
barometer's samples are the altitude at the IMU's sample times.

The records' other guarantees: the compiled factories and the Python side
allocate the same shapes; a row of stacked records is a view of the stack.
"""

from __future__ import annotations

import filecmp
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import quadimpact
from quadimpact.core import layout as L
from quadimpact.core.contact_slots import NCS
from quadimpact.core.records import data_row, new_data, set_row, stacked
from quadimpact.inputs.scenarios import ImpactTrial
from quadimpact.simulation.setup import prepare

PACKAGE = Path(quadimpact.__file__).resolve().parent

# (file, anchor, replacement): the whole change, as a developer would type it
EDITS: list[tuple[str, str, str]] = [
    (
        "core/records.py",
        "    sst: np.ndarray  # (NSST + state tail,) sensor state\n",
        "    sst: np.ndarray  # (NSST + state tail,) sensor state\n"
        "    baro: np.ndarray  # (2,) the barometer's last altitude (m) and its time (s)\n",
    ),
    (
        "core/records.py",
        "        np.zeros(NSST + tail_size(m.scfg, SC_TAIL_ST)),\n",
        "        np.zeros(NSST + tail_size(m.scfg, SC_TAIL_ST)),\n        np.zeros(2),\n",
    ),
    ("core/records.py", "D.meas[k], D.sst[k])", "D.meas[k], D.sst[k], D.baro[k])"),
    (
        "core/records.py",
        "    stats: np.ndarray  # (NSTAT,) status, counters, records\n",
        "    stats: np.ndarray  # (NSTAT,) status, counters, records\n"
        "    baro: np.ndarray  # (n_imu, 2) barometer samples: time (s), altitude (m)\n",
    ),
    (
        "core/records.py",
        "        np.zeros(NSTAT),\n",
        "        np.zeros(NSTAT),\n        np.zeros((max(n_imu, 0), 2)),\n",
    ),
    ("core/records.py", "O.episodes[k], O.stats[k])", "O.episodes[k], O.stats[k], O.baro[k])"),
    (
        "core/sensing.py",
        "from quadimpact.core.sensors.imu import imu_sample\n",
        "from quadimpact.core.sensors.baro import baro_sample\n"
        "from quadimpact.core.sensors.imu import imu_sample\n",
    ),
    (
        "core/sensing.py",
        "    plugin_sensor(t, xs, xd, w.C, m, d)\n",
        "    plugin_sensor(t, xs, xd, w.C, m, d)\n    baro_sample(t, xs, d, o)\n",
    ),
]
NEW_FILES = {
    "core/sensors/baro.py": '''
        """A barometer: the altitude of the CM at each IMU sample (a test's fake sensor)."""

        import numpy as np
        from numba import njit

        from quadimpact.core.layout import X_POS
        from quadimpact.core.records import Data, Output
        from quadimpact.core.sensors.imu_slots import SS_N


        @njit(cache=True)
        def baro_sample(t: float, x: np.ndarray, d: Data, o: Output) -> None:
            """The altitude (m) of the state ``x`` at the sample ``t`` (s): state and output."""
            d.baro[0] = -x[X_POS + 2]
            d.baro[1] = t
            i = int(d.sst[SS_N]) - 1
            if 0 <= i < o.baro.shape[0]:
                o.baro[i, 0] = t
                o.baro[i, 1] = d.baro[0]
        ''',
}

CHECK = """
import numpy as np
from quadimpact.core import layout as L
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.core.recording_slots import OUT_X
from quadimpact.core.records import new_data, new_output
from quadimpact.core.step import advance, start
from quadimpact.inputs.scenarios import ImpactTrial
from quadimpact.simulation.setup import prepare

setup = prepare(ImpactTrial(pitch_deg=-20, speed_m_s=1.5, final_time_s={tf}))
m = setup.model()
d = new_data(m)
o = new_output(m, setup.n_imu, 64)
start(m, d, o)
advance(-1, m, d, o)
n = int(o.stats[L.ST_N_IMU])
assert n > 2 and o.baro.shape == (setup.n_imu, 2)
assert np.array_equal(o.baro[:n, 0], o.imu[:n, IMS.I_T]), "sampled with the IMU"
assert o.baro[0, 1] == 5.0, "the trial starts at 5 m"
assert d.baro[1] == o.baro[n - 1, 0] and d.baro[0] == o.baro[n - 1, 1], "the state is the last"
# the altitude at the final output row (the run's end) is the last sample's
assert abs(o.baro[n - 1, 1] + o.out[-1, OUT_X + L.X_POS + 2]) < 1e-12
print("ok", n)
"""


def _copy_package(dest: Path) -> Path:
    root = dest / "src" / "quadimpact"
    shutil.copytree(PACKAGE, root, ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
    return root


def _touched(a: Path, b: Path) -> set[str]:
    """Files that differ between two package trees, or exist in one only."""
    out: set[str] = set()

    def walk(cmp: filecmp.dircmp, prefix: str) -> None:
        out.update(prefix + n for n in cmp.diff_files + cmp.left_only + cmp.right_only)
        for name, sub in cmp.subdirs.items():
            walk(sub, f"{prefix}{name}/")

    walk(filecmp.dircmp(a, b, ignore=["__pycache__"]), "")
    return out


@pytest.mark.parametrize(
    "jit", [False, pytest.param(True, marks=pytest.mark.slow, id="compiled")], ids=str
)
def test_a_new_per_run_array_touches_three_files(tmp_path: Path, jit: bool):
    root = _copy_package(tmp_path)
    for rel, anchor, replacement in EDITS:
        path = root / rel
        text = path.read_text()
        assert text.count(anchor) == 1, f"{rel}: the recipe's anchor {anchor!r} is not unique"
        path.write_text(text.replace(anchor, replacement))
    for rel, text in NEW_FILES.items():
        (root / rel).write_text(textwrap.dedent(text).lstrip())
    touched = _touched(PACKAGE, root)
    assert touched == {"core/records.py", "core/sensing.py", "core/sensors/baro.py"}
    env = dict(os.environ, PYTHONPATH=str(root.parent), NUMBA_CACHE_DIR=str(tmp_path / "nb"))
    if not jit:
        env["NUMBA_DISABLE_JIT"] = "1"  # the same code, run by Python (seconds, not a compile)
    script = CHECK.format(tf=0.3 if jit else 0.03)
    proc = subprocess.run(
        [sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=900
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout.startswith("ok")


def test_compiled_factories_and_stacked_rows_agree():
    m = prepare(ImpactTrial(pitch_deg=-10, speed_m_s=1.0, final_time_s=0.1)).model()
    d = new_data(m)
    assert np.array_equal(d.x, m.x0) and d.cs.shape == (m.pairs.shape[0], NCS)
    stack = stacked(d, 3)
    assert type(stack) is type(d) and stack.x.shape == (3, L.NX)
    set_row(stack, 1, d)
    row = data_row(stack, 1)
    row.x[0] = 123.0  # a row is a view of the stack
    assert stack.x[1, 0] == 123.0 and np.array_equal(stack.x[0], np.zeros(L.NX))
