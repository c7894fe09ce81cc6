"""A 3-s contact-free flight in RotorPy and in quadimpact, timed in the same process.

Run: ``python benchmarks/bench_rotorpy.py [--repeat 5] [--json PATH]`` (needs
``pip install rotorpy``; without it only quadimpact's times are given).

The flight: 3 s of hover control from rest, rolled 10 deg, no contact, in
each simulator's own vehicle and controller:

* **RotorPy** (``rotorpy.environments.Environment``): the Crazyflie, its
  ``SE3Control`` and a ``HoverTraj`` at the origin, ``sim_rate = 200`` Hz (the
  controller's rate; RotorPy integrates each period with SciPy's
  ``solve_ivp``), no mocap, no plots.
* **quadimpact**: a :class:`~quadimpact.FlightScenario` of the Spiri with its
  ``paper`` controller at 200 Hz, no ground, no surfaces: ``simulate()`` (the
  summary and the tables) and the compiled kernel alone
  (``core.kernel.execute`` of the prepared setup's model).

The two vehicles and controllers differ, so the ratio is one of tools, not of
identical physics: the time each needs for 3 s of controlled flight. The best
of ``--repeat`` calls after a warm-up is reported.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

FLIGHT_S = 3.0
RATE_HZ = 200
ROLL_DEG = 10.0


def best(fn, repeat: int) -> float:
    """Best wall time (s) of ``fn()`` over ``repeat`` calls after one warm-up."""
    fn()
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def quadimpact_times(repeat: int) -> dict:
    from quadimpact import FlightScenario, simulate
    from quadimpact.core.kernel import execute
    from quadimpact.simulation.setup import prepare

    s = FlightScenario(euler_deg=(ROLL_DEG, 0.0, 0.0), attitude_ref_deg=(0.0, 0.0, 0.0),
                       final_time_s=FLIGHT_S, ground="none")  # fmt: skip
    st = prepare(s)
    run = st.model()
    result = simulate(s)
    assert result.summary["status"] == "completed", result.summary["status"]
    return {
        "simulate_s": best(lambda: simulate(s), repeat),
        "kernel_s": best(lambda: execute(run, n_imu=st.n_imu), repeat),
        "final_roll_deg": float(result.timeseries["roll_deg"].iloc[-1]),
    }


def rotorpy_flight() -> tuple[Callable[[], None], dict] | None:
    """RotorPy's 3-s flight as a callable, or ``None`` if RotorPy is not installed.

    Returns ``(fly, final)``: each ``fly()`` builds the environment and runs
    it; ``final["roll"]`` is then the last roll angle (deg).
    """
    try:
        from rotorpy.controllers.quadrotor_control import SE3Control
        from rotorpy.environments import Environment
        from rotorpy.trajectories.hover_traj import HoverTraj
        from rotorpy.vehicles.crazyflie_params import quad_params
        from rotorpy.vehicles.multirotor import Multirotor
    except ImportError:
        return None
    hover = np.sqrt(quad_params["mass"] * 9.81 / (4 * quad_params["k_eta"]))
    final: dict = {}

    def fly() -> None:
        half = np.radians(ROLL_DEG) / 2  # scalar-last quaternion of the roll
        x0 = {"x": np.zeros(3), "v": np.zeros(3), "q": np.array([np.sin(half), 0, 0, np.cos(half)]),
              "w": np.zeros(3), "wind": np.zeros(3), "rotor_speeds": np.full(4, hover)}  # fmt: skip
        env = Environment(vehicle=Multirotor(quad_params, initial_state=x0),
                          controller=SE3Control(quad_params), trajectory=HoverTraj(),
                          sim_rate=RATE_HZ)  # fmt: skip
        out = env.run(t_final=FLIGHT_S, use_mocap=False, terminate=False, plot=False)
        qx, qw = out["state"]["q"][-1][0], out["state"]["q"][-1][3]
        final["roll"] = float(np.degrees(2 * np.arctan2(qx, qw)))

    return fly, final


def rotorpy_time(repeat: int) -> dict | None:
    flight = rotorpy_flight()
    if flight is None:
        return None
    fly, final = flight
    wall = best(fly, repeat)
    return {"run_s": wall, "final_roll_deg": final["roll"]}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    q = quadimpact_times(max(5, args.repeat * 4))
    r = rotorpy_time(args.repeat)
    print(f"machine: {os.cpu_count()} CPUs, Python {sys.version.split()[0]}")
    sim, kernel = q["simulate_s"], q["kernel_s"]
    print(f"quadimpact simulate()  {sim * 1e3:7.2f} ms  "
          f"(kernel {kernel * 1e3:.2f} ms; {sim / kernel:.2f}x)")  # fmt: skip
    if r is None:
        print("RotorPy not installed (pip install rotorpy): no comparison")
    else:
        print(f"RotorPy Environment.run {r['run_s'] * 1e3:7.1f} ms  = "
              f"{r['run_s'] / q['simulate_s']:.0f}x quadimpact's simulate(), "
              f"{r['run_s'] / q['kernel_s']:.0f}x its kernel")  # fmt: skip
    print(
        f"roll after {FLIGHT_S:g} s (from {ROLL_DEG:g} deg): "
        f"quadimpact {q['final_roll_deg']:.3f} deg"
        + ("" if r is None else f", RotorPy {r['final_roll_deg']:.3f} deg")
    )
    if args.json:
        args.json.write_text(json.dumps({"quadimpact": q, "rotorpy": r}, indent=2))


if __name__ == "__main__":
    main()
