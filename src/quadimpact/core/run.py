"""A whole run: the loop of ``step.advance`` from start to end, and its Python entries.

``run_builtin`` (cached) runs one scenario with the built-in controllers;
``make_kernel(step)`` compiles the same chain around a user's ``njit``
controller step (see ``controllers`` for its signature). Inputs are the
packed arrays of ``layout``; outputs are written into arrays the caller
allocates:

* ``out`` (n_out, NOUT): samples at the times ``t_out`` from the dense output;
* ``imu_out`` (n_imu, NIMU): the IMU samples (when the IMU is on);
* ``episodes`` (max_episodes, NEP): one row per bumper-surface contact episode;
* ``stats`` (NSTAT): status, counters, crash, first-onset, detection and
  stage records.

:func:`execute` (the classic three arrays) and :func:`execute_record` (all
of them) allocate the outputs and call the kernel; ``quadimpact.simulation``
calls them. A run that is advanced tick by tick from Python
(``quadimpact.simulation.Simulation``) uses ``step.start`` and
``step.advance`` directly on the same arrays.
"""

import inspect
import types
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numba import njit

from . import step as _step_module
from .layout import (
    MS_X,
    NCS,
    NEP,
    NIMU,
    NLS,
    NMEAS,
    NMEM,
    NOUT,
    NRIN,
    NSCFG,
    NSST,
    NSTAT,
    NX,
    ST_N_EPISODES,
    ST_N_IMU,
    ST_N_OUT,
)
from .step import advance, start


@njit(cache=True)
def run_builtin(
    x0: np.ndarray,
    t0: float,
    tf: float,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    ctrl: np.ndarray,
    scfg: np.ndarray,
    sched_t: np.ndarray,
    sched_rate: np.ndarray,
    sched_stop: np.ndarray,
    noise: np.ndarray,
    t_out: np.ndarray,
    out: np.ndarray,
    imu_out: np.ndarray,
    episodes: np.ndarray,
    stats: np.ndarray,
) -> None:
    """Run one scenario from ``(t0, x0)`` to ``tf`` (s) with the built-in controllers.

    The loop state is allocated here and dropped at the end; everything the
    caller needs is in ``out``, ``imu_out``, ``episodes`` and ``stats``.
    """
    x = x0.copy()
    ls = np.zeros(NLS)
    cs = np.zeros((4 * surf.shape[0], NCS))
    rin = np.zeros(NRIN)
    mem = np.zeros(NMEM)
    meas = np.zeros(NMEAS)
    sst = np.zeros(NSST)
    start(x, t0, tf, ls, cs, rin, mem, meas, sst, veh, surf, opts, scfg, noise, t_out, out,
          imu_out, stats)  # fmt: skip
    advance(-1, x, ls, cs, rin, mem, meas, sst, veh, surf, opts, ctrl, scfg, sched_t, sched_rate,
            sched_stop, noise, t_out, out, imu_out, episodes, stats)  # fmt: skip


def _rebound(fn: Callable, name: str, **globals_: object) -> Callable:
    """A fresh (uncached) ``njit`` copy of ``fn`` whose module globals ``globals_`` are replaced."""
    py = fn.py_func
    scope = dict(py.__globals__)
    scope.update(globals_)
    copy = types.FunctionType(py.__code__, scope, name, py.__defaults__)
    return njit(copy)


def _adapt_legacy(step: Callable) -> Callable:
    """Wrap a controller of the earlier interface ``step(x, ctrl, mem, veh, dt, cmd)``.

    The wrapped step gets the state estimate of the measurement record as ``x``.
    """
    legacy = step

    @njit
    def adapted(t, meas, ctrl, mem, veh, dt, cmd):  # pragma: no cover - compiled
        legacy(meas[MS_X : MS_X + NX], ctrl, mem, veh, dt, cmd)

    return adapted


def make_kernel(step: Callable) -> Callable:
    """Compile the run loop around a user's ``njit`` controller ``step``.

    ``step(t, meas, ctrl, mem, veh, dt, cmd)`` (the interface of
    ``core.controllers``); a step of the earlier interface
    ``step(x, ctrl, mem, veh, dt, cmd)`` is adapted (it gets the state estimate
    as ``x``). The chain ``tick -> advance -> run`` is compiled again with the
    controller bound in place of the built-in dispatch (Numba resolves globals
    at compile time). The result has the signature of :func:`run_builtin`, plus
    the attributes ``advance`` and ``step`` (for the stepping front end); it is
    compiled on first call and not cached on disk (~10 s).
    """
    n_params = len(inspect.signature(step.py_func).parameters)
    if n_params == 6:
        step = _adapt_legacy(step)
    elif n_params != 7:
        raise TypeError(
            "controller step: expected step(t, meas, ctrl, mem, veh, dt, cmd) "
            f"(or the older step(x, ctrl, mem, veh, dt, cmd)); got {n_params} parameters"
        )
    name = getattr(step, "__name__", "controller")
    tick = _rebound(_step_module.tick, "tick_" + name, controller_step=step)
    adv = _rebound(_step_module.advance, "advance_" + name, tick=tick)
    kernel = _rebound(run_builtin, "run_" + name, advance=adv)
    kernel.advance = adv
    kernel.step = step
    return kernel


@dataclass
class RawRecord:
    """What one compiled run returns: the filled parts of its output arrays.

    ``out`` (n_out, NOUT), ``episodes`` (n_episodes, NEP), ``stats`` (NSTAT) and
    ``imu`` (n_imu, NIMU), layouts in ``core.layout``.
    """

    out: np.ndarray
    episodes: np.ndarray
    stats: np.ndarray
    imu: np.ndarray


def default_sensors() -> np.ndarray:
    """Sensor configuration with no IMU (and so no detection)."""
    return np.zeros(NSCFG)


def execute_record(
    x0: np.ndarray,
    t0: float,
    tf: float,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    ctrl: np.ndarray,
    t_out: np.ndarray,
    max_episodes: int = 1024,
    kernel: Callable | None = None,
    sched_t: np.ndarray | None = None,
    sched_rate: np.ndarray | None = None,
    sched_stop: np.ndarray | None = None,
    scfg: np.ndarray | None = None,
    noise: np.ndarray | None = None,
    n_imu: int = 0,
) -> RawRecord:
    """Allocate the outputs, run the compiled loop, return the filled parts.

    ``sched_t``/``sched_rate``/``sched_stop``: the power-off schedule
    (``core/actuators.py``), triggered at ``opts[O_POWER_OFF_T]`` (< 0: the
    first contact). ``scfg``: sensor configuration (default: no IMU);
    ``noise``: (n, 6) standard normal draws for the IMU; ``n_imu``: rows of the
    IMU record to keep.
    """
    out = np.zeros((t_out.shape[0], NOUT))
    episodes = np.zeros((max_episodes, NEP))
    stats = np.zeros(NSTAT)
    imu_out = np.zeros((max(int(n_imu), 0), NIMU))
    (kernel or run_builtin)(
        np.ascontiguousarray(x0, dtype=np.float64),
        float(t0),
        float(tf),
        veh,
        surf,
        opts,
        ctrl,
        default_sensors() if scfg is None else np.ascontiguousarray(scfg, dtype=np.float64),
        np.zeros(0) if sched_t is None else np.ascontiguousarray(sched_t, dtype=np.float64),
        np.zeros((0, 4)) if sched_rate is None else np.ascontiguousarray(sched_rate, np.float64),
        np.zeros(4) if sched_stop is None else np.ascontiguousarray(sched_stop, np.float64),
        np.zeros((0, 6)) if noise is None else np.ascontiguousarray(noise, dtype=np.float64),
        np.ascontiguousarray(t_out, dtype=np.float64),
        out,
        imu_out,
        episodes,
        stats,
    )
    n_imu_taken = min(int(stats[ST_N_IMU]), imu_out.shape[0])
    return RawRecord(
        out[: int(stats[ST_N_OUT])],
        episodes[: int(stats[ST_N_EPISODES])],
        stats,
        imu_out[:n_imu_taken],
    )


def execute(
    x0: np.ndarray,
    t0: float,
    tf: float,
    veh: np.ndarray,
    surf: np.ndarray,
    opts: np.ndarray,
    ctrl: np.ndarray,
    t_out: np.ndarray,
    max_episodes: int = 1024,
    kernel: Callable | None = None,
    sched_t: np.ndarray | None = None,
    sched_rate: np.ndarray | None = None,
    sched_stop: np.ndarray | None = None,
    **sensors: object,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Like :func:`execute_record`; returns ``(out, episodes, stats)`` only."""
    rec = execute_record(
        x0, t0, tf, veh, surf, opts, ctrl, t_out, max_episodes, kernel,
        sched_t, sched_rate, sched_stop, **sensors,
    )  # fmt: skip
    return rec.out, rec.episodes, rec.stats
