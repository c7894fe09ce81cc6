"""quadimpact against its peers, MuJoCo and RotorPy, timed in one process and one run.

Run: ``python benchmarks/bench_peers.py [--rounds 5] [--json PATH]``. MuJoCo
and RotorPy are never dependencies of quadimpact: a peer that is not
installed is skipped with a one-line message. To measure them without
touching the project's environment, install them in a separate one and put
its packages after the project's on the path (docs/PERFORMANCE.md, "Against
the peers").

What is timed, in rounds that alternate the three (each figure is the best
of its rounds, and every ratio is also given as the median of the ratios
within a round, which a loaded machine moves less):

* **quadimpact**: ``simulate()`` of the paper's example (the ``default``
  model; psi = 45 deg, iota = 15 deg, V_c = 0.75 m/s; it stops at the crash,
  about 1.3 s) and its kernel alone (``core.kernel.execute`` without the IMU,
  as ``bench_run.py``), each the best of ``--calls`` calls a round.
* **MuJoCo**: a 3-s wall impact of a Spiri-like vehicle. The Spiri's mass
  and inertia, its four rotor hubs, four bumper rings (radius 0.11 m, tilted
  11 deg) each made of 16 capsules (64 capsules), a constant hover thrust
  on the four hubs, gravity, a wall plane; 0.75 m/s towards the wall, yawed
  45 deg and pitched 15 deg (nose up, so it bounces off: one contact
  episode, as in the paper's example); RK4 at 0.2 ms (15,000 steps, one
  ``mj_step(..., nstep=15000)`` call after ``mj_resetData``).
* **RotorPy**: the contact-free 3-s flight of ``bench_rotorpy.py`` (its
  ``Environment.run`` of the Crazyflie at 200 Hz; the same function).

The physics differ (MuJoCo's soft contact of capsules against a plane, not
the paper's Hunt-Crossley rings; RotorPy's Crazyflie without contact), so
the ratios compare tools: the time each needs for a run of the kind it is
used for.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_rotorpy import quadimpact_times, rotorpy_flight  # noqa: E402

EXAMPLE = {"heading_deg": 45.0, "inclination_deg": 15.0, "speed_m_s": 0.75, "model": "default"}
TARGET_MUJOCO = 100.0  # simulate() at least this many times faster than MuJoCo's impact
TARGET_ROTORPY = 500.0  # ... and than RotorPy's flight

# The Spiri (src/quadimpact/inputs/vehicles/spiri.toml), in MuJoCo's z-up frame.
SPIRI_MASS_KG = 0.933
SPIRI_INERTIA = (8.737e-3, 8.988e-3, 1.7143e-2)  # principal part, kg m^2
SPIRI_HUBS_FRD = ((0.13192, 0.12652, -0.02416), (-0.12122, 0.12652, -0.02416),
                  (-0.12122, -0.12662, -0.02416), (0.13192, -0.12662, -0.02416))  # fmt: skip
BUMPER_RADIUS_M = 0.11
BUMPER_TILT_DEG = 11.0
BUMPER_DIRS_DEG = (45.0, 135.0, 225.0, 315.0)
CAPSULES_PER_RING = 16
CAPSULE_RADIUS_M = 0.005
MUJOCO_DT_S = 2e-4
MUJOCO_SPAN_S = 3.0
MUJOCO_SPEED_M_S = 0.75
MUJOCO_START_X_M = -0.32  # the CM's distance to the wall plane x = 0 at the start


def spiri_mjcf() -> str:
    """The MJCF text of the Spiri-like vehicle before a wall (z up, the wall's normal -x)."""
    capsules, sites = [], []
    for j, ((hx, hy, hz), bdir) in enumerate(zip(SPIRI_HUBS_FRD, BUMPER_DIRS_DEG, strict=True)):
        cx, cy, cz = hx, -hy, -hz  # FRD -> FLU (z up)
        # outward direction in the body plane (FRD angle -> FLU: y flips), raised by the tilt
        b = math.radians(-bdir)
        a = math.radians(BUMPER_TILT_DEG)
        u = (math.cos(b) * math.cos(a), math.sin(b) * math.cos(a), math.sin(a))
        t = (-math.sin(b), math.cos(b), 0.0)
        pts = []
        for k in range(CAPSULES_PER_RING + 1):
            th = 2 * math.pi * k / CAPSULES_PER_RING
            c, s = BUMPER_RADIUS_M * math.cos(th), BUMPER_RADIUS_M * math.sin(th)
            pts.append(
                tuple(h + c * ui + s * ti for h, ui, ti in zip((cx, cy, cz), u, t, strict=True))
            )
        for k in range(CAPSULES_PER_RING):
            p, q = pts[k], pts[k + 1]
            capsules.append(
                f'<geom type="capsule" size="{CAPSULE_RADIUS_M}" mass="0" '
                f'fromto="{p[0]:.6f} {p[1]:.6f} {p[2]:.6f} {q[0]:.6f} {q[1]:.6f} {q[2]:.6f}"/>'
            )
        sites.append(f'<site name="hub{j + 1}" pos="{cx} {cy} {cz}"/>')
    motors = "".join(f'<motor site="hub{j + 1}" gear="0 0 1 0 0 0"/>' for j in range(4))
    ix, iy, iz = SPIRI_INERTIA
    return f"""<mujoco model="spiri-like">
  <option timestep="{MUJOCO_DT_S}" integrator="RK4" gravity="0 0 -9.81"/>
  <worldbody>
    <geom name="wall" type="plane" size="5 5 0.1" zaxis="-1 0 0"/>
    <body name="spiri" pos="{MUJOCO_START_X_M} 0 1" euler="0 -15 45">
      <freejoint/>
      <inertial pos="0 0 0" mass="{SPIRI_MASS_KG}" diaginertia="{ix} {iy} {iz}"/>
      {"".join(sites)}
      {"".join(capsules)}
    </body>
  </worldbody>
  <actuator>{motors}</actuator>
</mujoco>"""


def mujoco_impact() -> tuple[Callable[[], None], dict] | None:
    """MuJoCo's 3-s wall impact as a callable, or ``None`` if MuJoCo is not installed.

    Returns ``(run, info)``; ``info`` holds the version, the number of capsules
    and steps, and (from one checking run stepped a millisecond at a time) when
    the bumpers touched the wall, for how long and the rebound speed.
    """
    try:
        import mujoco
    except ImportError:
        return None
    model = mujoco.MjModel.from_xml_string(spiri_mjcf())
    data = mujoco.MjData(model)
    n_steps = round(MUJOCO_SPAN_S / MUJOCO_DT_S)
    thrust = SPIRI_MASS_KG * 9.81 / 4

    def reset() -> None:
        mujoco.mj_resetData(model, data)
        data.qvel[0] = MUJOCO_SPEED_M_S
        data.ctrl[:] = thrust

    def run() -> None:
        reset()
        mujoco.mj_step(model, data, nstep=n_steps)

    reset()  # the checking run: the impact happens, and ends
    chunk = round(1e-3 / MUJOCO_DT_S)
    touching = []
    for i in range(n_steps // chunk):
        mujoco.mj_step(model, data, nstep=chunk)
        if data.ncon:
            touching.append((i + 1) * chunk * MUJOCO_DT_S)
    info = {
        "version": mujoco.__version__,
        "capsules": int(model.ngeom - 1),
        "steps": n_steps,
        "first_contact_s": touching[0] if touching else float("nan"),
        "contact_ms": 1e3 * len(touching) * chunk * MUJOCO_DT_S,
        "final_vx_m_s": float(data.qvel[0]),  # away from the wall: negative
    }
    return run, info


def quadimpact_example() -> tuple[Callable[[], None], Callable[[], None], dict]:
    """``simulate()`` of the paper's example and its kernel alone, as callables."""
    from quadimpact import WallApproach, simulate
    from quadimpact.core import layout as L
    from quadimpact.core.interval_slots import IS_N_RHS, IS_N_STEPS
    from quadimpact.core.kernel import execute
    from quadimpact.simulation.setup import prepare

    sc = WallApproach(**EXAMPLE)
    m = prepare(sc).model(scfg=None, noise=None)  # the run without its IMU, as bench_run.py
    r = simulate(sc)
    st = execute(m).stats
    info = {
        "status": r.summary["status"],
        "crash_time_s": r.summary["crash_time_s"],
        "rhs_evaluations": int(st[L.ST_STEPS + IS_N_RHS]),
        "steps": int(st[L.ST_STEPS + IS_N_STEPS]),
    }
    return (lambda: simulate(sc)), (lambda: execute(m)), info


def best_of(fn: Callable[[], object], calls: int) -> float:
    """Best wall time (s) of ``calls`` calls of ``fn``."""
    best = math.inf
    for _ in range(calls):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def machine() -> str:
    cpu = "unknown CPU"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} CPUs, Python {sys.version.split()[0]}"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rounds", type=int, default=5, help="alternated rounds (default 5)")
    p.add_argument("--calls", type=int, default=20, help="quadimpact calls a round (default 20)")
    p.add_argument("--json", type=Path, help="also write the figures to this JSON file")
    a = p.parse_args(argv)
    if a.rounds < 1 or a.calls < 1:
        p.error("--rounds and --calls must be >= 1")

    load0 = os.getloadavg()[0]
    sim, kernel, qinfo = quadimpact_example()
    peers: dict[str, tuple[Callable[[], None], dict] | None] = {}
    mj = mujoco_impact()
    if mj is None:
        print("MuJoCo not installed (pip install mujoco, not a dependency): skipped")
    else:
        peers["mujoco"] = mj
    rp = rotorpy_flight()
    if rp is None:
        print("RotorPy not installed (pip install rotorpy, not a dependency): skipped")
    else:
        rp[0]()  # warm-up (imports, SciPy's first solve)
        peers["rotorpy"] = (rp[0], rp[1])

    times: dict[str, list[float]] = {"simulate": [], "kernel": [], **{k: [] for k in peers}}
    for _ in range(a.rounds):
        times["simulate"].append(best_of(sim, a.calls))
        times["kernel"].append(best_of(kernel, a.calls))
        for name, (fn, _info) in peers.items():
            times[name].append(best_of(fn, 1))
    flight = quadimpact_times(a.calls)  # bench_rotorpy.py's own 3-s flight in quadimpact
    load1 = os.getloadavg()[0]

    s_best, k_best = min(times["simulate"]), min(times["kernel"])
    print(f"machine: {machine()}; 1-min load {load0:.1f} at the start, {load1:.1f} at the end")
    print(f"rounds: {a.rounds} (quadimpact: best of {a.calls} calls a round); best of the rounds")
    print(
        f"quadimpact simulate() of the paper's example {s_best * 1e3:7.2f} ms "
        f"(kernel {k_best * 1e3:.2f} ms, {qinfo['rhs_evaluations']} RHS evaluations, "
        f"{k_best / qinfo['rhs_evaluations'] * 1e9:.0f} ns each; simulate() {s_best / k_best:.2f}x "
        f"the kernel; crash at {qinfo['crash_time_s']:.3f} s)"
    )
    out = {"machine": machine(), "load": [load0, load1], "rounds": a.rounds, "calls": a.calls,
           "quadimpact": {**qinfo, "simulate_s": times["simulate"], "kernel_s": times["kernel"],
                          "flight_3s": flight}}  # fmt: skip
    targets = {"mujoco": TARGET_MUJOCO, "rotorpy": TARGET_ROTORPY}
    for name, (_fn, info) in peers.items():
        t = min(times[name])
        per_round = [pt / st for pt, st in zip(times[name], times["simulate"], strict=True)]
        ratio, median_ratio = t / s_best, statistics.median(per_round)
        verdict = "met" if ratio >= targets[name] else "MISSED"
        if name == "mujoco":
            what = (
                f"MuJoCo {info['version']} 3-s wall impact ({info['capsules']} capsules, "
                f"{info['steps']} RK4 steps; contact at {info['first_contact_s']:.3f} s for "
                f"{info['contact_ms']:.0f} ms)"
            )
        else:
            what = f"RotorPy 3-s contact-free flight (final roll {info['roll']:.3f} deg)"
        print(
            f"{what}: {t * 1e3:.1f} ms = {ratio:.0f}x simulate() (median of the rounds' ratios "
            f"{median_ratio:.0f}x; target {targets[name]:.0f}x: {verdict}), "
            f"{t / k_best:.0f}x its kernel"
        )
        out[name] = {
            **info,
            "run_s": times[name],
            "ratio_best": ratio,
            "ratio_median": median_ratio,
        }
    print(
        "quadimpact's own 3-s flight (bench_rotorpy.py): "
        f"simulate() {flight['simulate_s'] * 1e3:.2f} ms, "
        f"kernel {flight['kernel_s'] * 1e3:.2f} ms"
    )
    if a.json:
        a.json.write_text(json.dumps(out, indent=2, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
