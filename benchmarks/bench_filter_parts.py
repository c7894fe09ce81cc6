"""CPU per IMU sample of the ``ekf`` (the ``lab`` set) and the ``nav-ekf`` (``onboard``), by part.

Run: ``python benchmarks/bench_filter_parts.py [--before /path/to/other/checkout]
[--rounds R]``.

Each filter is run for 400 samples of a seeded synthetic stream (the
estimator tests' harness, ``tests/core/estimator_streams.py``) to reach a
realistic covariance. Then, each in a compiled loop: the prediction from that
covariance, a 3-row update with an attitude-and-bias ``H`` (the gravity
measurement's shape) from that covariance (the covariance copied back before
each call; the copy's own cost is subtracted), and the whole estimator stage
(``estimators.estimate_sample``) with the ``lab`` mix of measurements (the
magnetometer at every sample, the pose sensor at every 2nd) or the
``onboard`` mix (the magnetometer at every sample, the flow at every 2nd, the
barometer at every 4th, the rangefinder at every 5th). Times are CPU time
(``time.process_time``), the least of 9 repetitions, in ns per call.

With ``--before`` the other checkout is measured too (its ``src``, in a
fresh interpreter), the two alternated ``--rounds`` times; each part's time
is its least over the rounds, and the ratio after / before is printed.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parents[1]
PARTS = (
    "ekf: predict",
    "ekf: 3-row update",
    "ekf: whole sample (lab)",
    "nav-ekf: predict",
    "nav-ekf: 3-row update",
    "nav-ekf: whole sample (onboard)",
)


def compiled_loops() -> tuple:
    """The compiled loops that time the parts (imported here: the checkout measured)."""
    from numba import njit

    from quadimpact.core import estimator_slots as ESL
    from quadimpact.core.estimators import ekf as E
    from quadimpact.core.estimators import estimate_sample
    from quadimpact.core.estimators import nav_ekf as N
    from quadimpact.core.estimators import older_sensors as OS
    from quadimpact.core.sensors import measurement_slots as MS

    @njit
    def stream(n, dt, xs, C, m, d, o, w, addresses, pose_every, z):
        meas = d.meas
        baro_n, flow_n, rng_n = addresses
        t0 = d.est[ESL.ES_T]
        for i in range(n):
            t = t0 + (i + 1) * dt
            meas[MS.MS_IMU_T] = t
            meas[OS.MAG_T] = t
            k = i % z.shape[0]
            for a in range(3):
                meas[MS.MS_IMU_W + a] = 0.3 * z[k, a]
                meas[MS.MS_IMU_F + a] = 0.5 * z[k, 3 + a]
            meas[MS.MS_IMU_F + 2] += -9.81
            if pose_every > 0 and i % pose_every == 0:
                meas[OS.POSE_T] = t
            if baro_n >= 0:
                if i % 4 == 0:
                    meas[baro_n] += 1.0
                if i % 2 == 0:
                    meas[flow_n] += 1.0
                if i % 5 == 0:
                    meas[rng_n] += 1.0
            estimate_sample(t, xs, C, m, d, o, w)

    @njit
    def copies(n, P, P0):
        for _ in range(n):
            P[:, :] = P0

    @njit
    def ekf_predict(n, est, W, P0, ecfg, w, f, C):
        for _ in range(n):
            W[0, :, :] = P0
            E.ekf_predict(est, W, 12, ecfg, w, f, 0.005, C, 0.0)

    @njit
    def ekf_update(n, est, W, P0, H0, y):
        for _ in range(n):
            W[0, :, :] = P0
            W[4, 0:4, :] = H0
            E.kalman_update(est, W, 12, y, 0.25)

    @njit
    def nav_predict(n, est, W, P0, ecfg, scfg, w, f, C):
        for _ in range(n):
            W[0, :, :] = P0
            N.nav_predict(est, W[0], W[1], ecfg, scfg, w, f, 0.005, C, 0.0)

    @njit
    def nav_update(n, est, W, Wu, P0, H0):
        for _ in range(n):
            W[0, :, :] = P0
            Wu[0:5, :] = H0
            N.nav_update(est, W[0], Wu, 3, 0.0)

    return stream, copies, ekf_predict, ekf_update, nav_predict, nav_update


def measure_here() -> dict[str, float]:
    """Each part's CPU (ns per call) with the ``quadimpact`` this interpreter imports."""
    sys.path.insert(0, str(Path.cwd() / "tests" / "core"))
    from estimator_streams import Harness

    from quadimpact.core.estimators import ekf as E
    from quadimpact.core.estimators import nav_ekf as N
    from quadimpact.core.estimators import older_sensors as OS

    stream, copies, ekf_predict, ekf_update, nav_predict, nav_update = compiled_loops()

    def least(fn, n: int) -> float:
        fn(2)
        best = np.inf
        for _ in range(9):
            t0 = time.process_time()
            fn(n)
            best = min(best, (time.process_time() - t0) / n)
        return best * 1e9

    z = np.random.default_rng(1).standard_normal((400, 6))
    w = np.array([0.1, -0.2, 0.05])
    f = np.array([0.3, -0.1, -9.7, 0.3, -0.1, -9.7])
    C = np.eye(3)
    out: dict[str, float] = {}
    # the ekf with the pose sensor (12 states), as the lab set flies it
    h = Harness("ekf", 10, pos0=(0, 0, -1.5), magnetometer={}, pose_sensor={}, imu="impact")
    h.d.meas[OS.MAG : OS.MAG + 3] = (0.5, 0.0, 0.866)
    h.d.meas[OS.POSE : OS.POSE + 7] = (0.0, 0.0, -1.5, 1.0, 0.0, 0.0, 0.0)
    xs = h.d.x.copy()
    args = (xs, np.eye(3), h.m, h.d, h.o, h.w, (-1, -1, -1), 2, z)
    stream(400, 0.005, *args)
    est = h.d.est.copy()
    P0 = est[E.ES_P : E.ES_P + 144].reshape((12, 12)).copy()
    W = np.zeros((6, 12, 12))
    H0 = np.zeros((4, 12))
    H0[0, 1], H0[0, 2], H0[1, 0], H0[1, 2], H0[2, 0], H0[2, 1] = -0.1, 0.2, 0.1, -9.8, -0.2, 9.8
    y = np.array([0.01, -0.02, 0.03])
    base = least(lambda n: copies(n, W[0], P0), 20000)
    out[PARTS[0]] = least(lambda n: ekf_predict(n, est, W, P0, h.m.ecfg, w, f, C), 20000) - base
    out[PARTS[1]] = least(lambda n: ekf_update(n, est, W, P0, H0, y), 20000) - base
    out[PARTS[2]] = least(lambda n: stream(n, 0.005, *args), 20000)
    # the nav-ekf, as the onboard set flies it
    inst = {"barometer": {}, "rangefinder": {}, "optical_flow": {}}
    h = Harness("nav-ekf", 10, pos0=(0, 0, -1.5), magnetometer={}, imu="impact", instruments=inst)
    meas = h.d.meas
    meas[OS.MAG : OS.MAG + 3] = (0.5, 0.0, 0.866)
    meas[N.BARO_ALT] = 1.5
    meas[N.RNG_RANGE], meas[N.RNG_VALID], meas[N.RNG_NOISE] = 1.5, 1.0, 0.02
    meas[N.FLOW_QUALITY], meas[N.FLOW_NOISE] = 1.0, 0.15
    xs = h.d.x.copy()
    args = (xs, np.eye(3), h.m, h.d, h.o, h.w, (N.BARO_N, N.FLOW_N, N.RNG_N), 0, z)
    stream(400, 0.005, *args)
    est = h.d.est.copy()
    nn = 2 * N.N_NAV * N.N_NAV
    W = np.zeros((2, N.N_NAV, N.N_NAV))
    Wu = np.zeros((14, N.N_NAV))
    P0 = est[N.ES_NAV_P : N.ES_NAV_P + nn // 2].reshape((N.N_NAV, N.N_NAV)).copy()
    H0 = np.zeros((5, N.N_NAV))
    H0[0, 1], H0[0, 2], H0[1, 0], H0[1, 2], H0[2, 0], H0[2, 1] = -0.1, 0.2, 0.1, -9.8, -0.2, 9.8
    for a in range(3):
        H0[a, N.I_BA + a] = 1.0
    H0[4, 0:3] = (0.01, -0.02, 0.03)
    H0[4, 3:6] = 0.25
    base = least(lambda n: copies(n, W[0], P0), 20000)
    ecfg, scfg = h.m.ecfg, h.m.scfg
    out[PARTS[3]] = least(lambda n: nav_predict(n, est, W, P0, ecfg, scfg, w, f, C), 20000) - base
    out[PARTS[4]] = least(lambda n: nav_update(n, est, W, Wu, P0, H0), 20000) - base
    out[PARTS[5]] = least(lambda n: stream(n, 0.005, *args), 20000)
    return out


def run_in(checkout: Path) -> dict[str, float]:
    """:func:`measure_here` in a fresh interpreter importing ``checkout/src``."""
    env = dict(os.environ, PYTHONPATH=str(checkout / "src"))
    proc = subprocess.run(
        [sys.executable, str(Path(__file__).resolve()), "--here"],
        env=env, capture_output=True, text=True, cwd=checkout,
    )  # fmt: skip
    if proc.returncode != 0:
        raise SystemExit(f"{checkout}: the measurement failed:\n{proc.stderr[-3000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--before", type=Path, help="another checkout, measured alternately")
    ap.add_argument("--after", type=Path, default=HERE, help="default: this checkout")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--here", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.here:
        print(json.dumps(measure_here()))
        return
    sides = {"after": a.after} if a.before is None else {"before": a.before, "after": a.after}
    best: dict[str, dict[str, float]] = {k: {p: np.inf for p in PARTS} for k in sides}
    for _ in range(a.rounds):
        for side, checkout in sides.items():
            for part, ns in run_in(checkout).items():
                best[side][part] = min(best[side][part], ns)
    load = os.getloadavg()[0]
    print(f"CPU per call, ns (least over {a.rounds} rounds; 1-min load {load:.1f} at the end)")
    head = "part" + " " * 28 + "".join(f"{s:>10}" for s in sides)
    print(head + ("     after/before" if "before" in sides else ""))
    for p in PARTS:
        row = f"{p:32s}" + "".join(f"{best[s][p]:10.0f}" for s in sides)
        if "before" in sides:
            row += f"{best['after'][p] / best['before'][p]:17.2f}"
        print(row)


if __name__ == "__main__":
    main()
