"""The named records of the compiled core, and the one place that allocates them.

A run's arrays are grouped by lifetime into four records (named tuples of
NumPy arrays, which Numba compiles as typed structures and caches), in the
spirit of MuJoCo MJX's ``Model``/``Data``:

* :class:`Model`: what the run *is*, never written by the loop: the initial
  state and time span, the vehicle, its contact features, the world's
  shapes, the contact-pair table, options, controller, sensors, the IMU's
  noise draws, the power-off schedule, the output times, the estimator's
  settings and the added sensors' noise draws;
* :class:`Data`: what the loop carries from one control tick to the next
  (state, loop scalars, contact pairs, rotor inputs, controller memory,
  estimator state, measurement record, sensor state);
* :class:`Output`: what a run returns (time series, IMU samples, contact
  episodes, statistics; counters are live, so a run stopped after any tick
  can be read);
* :class:`Work`: scratch space of one control tick.

Every slot of every field is named in ``core/layout.py`` or, for a field a
stage owns, in that stage's module (``rin``: ``core/rotors.py``; ``pairs``:
``core/geometry``) or its declaration module, which holds no compiled code
(``cs``: ``core/contact_slots.py``; ``out`` and ``episodes``:
``core/recording_slots.py``). The factories
``new_data`` and ``new_work`` are compiled, so the compiled ``run`` and the
Python side allocate through the same code; ``new_output`` (what the caller
allocates) is plain NumPy;
:func:`model` builds a :class:`Model` from packed arrays (Python), and
:func:`raw_record` reads an :class:`Output` into the :class:`RawRecord` that
``quadimpact.simulation`` analyses. The ``*_row`` functions give run ``k`` of
records stacked along a first axis (the learning environments' batches).

Adding a per-run array is one field here (and in its factory and row
function, all in this file), the stage that uses it, and its packing in
``packing/``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from quadimpact.core.contact_slots import NCS
from quadimpact.core.estimator_slots import NECFG, NEST
from quadimpact.core.layout import (
    MAX_ROTORS,
    NLS,
    NMEM,
    NSPAN,
    NSTAT,
    NX,
    SPAN_T0,
    SPAN_TF,
    ST_N_EPISODES,
    ST_N_IMU,
    ST_N_OUT,
)
from quadimpact.core.recording_slots import NEP, NOUT
from quadimpact.core.rotors import NRIN
from quadimpact.core.sensors.imu_slots import (
    MAX_AVERAGE_WINDOW,
    NIMU,
    NSCFG,
    NSN,
    NSST,
    SC_TAIL_MEAS,
    SC_TAIL_REC,
    SC_TAIL_ST,
)
from quadimpact.core.sensors.measurement_slots import NMEAS

__all__ = [
    "Data",
    "Model",
    "Output",
    "RawRecord",
    "Work",
    "data_row",
    "model",
    "model_row",
    "new_data",
    "new_output",
    "new_work",
    "output_row",
    "raw_record",
]

assert MAX_AVERAGE_WINDOW > 0


class Model(NamedTuple):
    """Per-run constants (layouts in ``core/layout.py``; SI, inertial NED, body FRD)."""

    x0: np.ndarray  # (NX,) initial state
    span: np.ndarray  # (NSPAN,) start and end time, s
    veh: np.ndarray  # (NVEH,) mass, inertia, rotors
    feat: np.ndarray  # (n_features, NFEAT) contact features, body frame
    shapes: np.ndarray  # (n_shapes, NSHAPE) world shapes, inertial frame
    pairs: np.ndarray  # (n_pairs, NPAIR) int64: feature, shape, geometry function
    opts: np.ndarray  # (NOPT,) model switches, integrator settings
    ctrl: np.ndarray  # (NCTRL,) controller kind, references, parameters
    scfg: np.ndarray  # (NSCFG,) IMU and detector
    noise: np.ndarray  # (n_noise, 6) standard normal draws of the IMU
    sched_t: np.ndarray  # (K,) power-off segment starts after the trigger, s
    sched_rate: np.ndarray  # (K, MAX_ROTORS) power-off rates, rad/s^2 (0 beyond the n rotors)
    sched_stop: np.ndarray  # (MAX_ROTORS,) 1: motor stalls at the trigger
    t_out: np.ndarray  # (n_out,) output times, s
    ecfg: np.ndarray  # (NECFG,) estimator: kind, initial error, gains, noises
    snoise: np.ndarray  # (n_snoise, NSN) standard normal draws of the added sensors
    cnoise: np.ndarray  # (n_cnoise, noise tail) the sensor components' draws (sensors/registry.py)


class Data(NamedTuple):
    """What the loop carries from one control tick to the next."""

    x: np.ndarray  # (NX,) state
    ls: np.ndarray  # (NLS,) loop scalars
    cs: np.ndarray  # (n_pairs, NCS) contact pairs: in an episode, damping, episode row
    rin: np.ndarray  # (NRIN,) rotor inputs of the interval
    mem: np.ndarray  # (NMEM,) controller memory
    est: np.ndarray  # (NEST,) estimator state
    meas: np.ndarray  # (NMEAS + measurement tail,) measurement record
    sst: np.ndarray  # (NSST + state tail,) sensor state


class Output(NamedTuple):
    """What a run returns (the caller allocates it; the loop fills it)."""

    out: np.ndarray  # (n_out, out_width(n_features)) time series at t_out
    imu: np.ndarray  # (n_imu, NIMU + record tail) IMU samples
    episodes: np.ndarray  # (max_episodes, NEP) contact episodes
    stats: np.ndarray  # (NSTAT,) status, counters, records


class Work(NamedTuple):
    """Scratch arrays of one control tick (allocated once per call of ``advance``)."""

    x_new: np.ndarray  # (NX,) trial step's end
    x_b: np.ndarray  # (NX,) the accepted step's end (cut at an event)
    xs: np.ndarray  # (NX,) dense-output samples
    xd: np.ndarray  # (NX,) a derivative
    K: np.ndarray  # (7, NX) Runge-Kutta stages
    Q: np.ndarray  # (NX, 4) dense-output coefficients
    C: np.ndarray  # (3, 3) a rotation matrix
    wdot: np.ndarray  # (MAX_ROTORS,) rotor accelerations (the first n used)
    cmd: np.ndarray  # (MAX_ROTORS,) the tick's rotor command (the first n used)
    g_a: np.ndarray  # (n_pairs,) contact gaps at the step's start
    gd_a: np.ndarray  # (n_pairs,) penetration rates there
    g_b: np.ndarray  # (n_pairs,) gaps at the step's end
    gd_b: np.ndarray  # (n_pairs,) rates there
    ev_sig: np.ndarray  # (n_pairs,) located event of each pair, fraction of the step
    C_hat: np.ndarray  # (3, 3) the estimated rotation at an IMU sample
    bnd_a: np.ndarray  # (n_pairs,) 1: g_a, gd_a hold the broad phase's bounds, not values
    bnd_b: np.ndarray  # (n_pairs,) the same for g_b, gd_b
    ekf: np.ndarray  # (6, 12, 12) the ekf's covariance and scratch (estimators/ekf.py)


# ---------------------------------------------------------------- factories
@njit(cache=True, inline="always")
def tail_size(scfg: np.ndarray, slot: int) -> int:
    """A sensor-component tail's size written in ``scfg`` (0 for a run packed without one)."""
    return int(scfg[slot]) if scfg.shape[0] > slot else 0


@njit(cache=True)
def new_data(m: Model) -> Data:
    """Zeroed loop state for the run ``m`` (``step.start`` initialises it)."""
    return Data(
        m.x0.copy(),
        np.zeros(NLS),
        np.zeros((m.pairs.shape[0], NCS)),
        np.zeros(NRIN),
        np.zeros(NMEM),
        np.zeros(NEST),
        np.zeros(NMEAS + tail_size(m.scfg, SC_TAIL_MEAS)),
        np.zeros(NSST + tail_size(m.scfg, SC_TAIL_ST)),
    )


def new_output(
    m: Model, n_imu: int, max_episodes: int, contact_columns: bool = True, rows: bool = True
) -> Output:
    """Zeroed outputs of the run ``m``: a row per output time, ``n_imu`` IMU rows.

    ``contact_columns=False``: rows of ``NOUT`` columns (time, state, command,
    stage), without the features' deflections and forces, which the loop
    then does not compute (``recording.write_sample``). ``rows=False``: no
    row at all; the loop still samples at every output time for the stats
    (the attitude excursion, the last sample's state, the count of samples):
    what a summary needs.

    Plain NumPy (the caller is Python; no compiled function allocates an
    output): handing the whole :class:`Model` to a compiled factory cost
    more than its four allocations (Numba unboxes every field of the record).
    """
    width = NOUT + 2 * m.feat.shape[0] if contact_columns else NOUT  # recording_slots.out_width
    return Output(
        np.zeros((m.t_out.shape[0] if rows else 0, width)),
        np.zeros((max(n_imu, 0), NIMU + tail_size(m.scfg, SC_TAIL_REC))),
        np.zeros((max_episodes, NEP)),
        np.zeros(NSTAT),
    )


@njit(cache=True)
def new_work(n_pairs: int) -> Work:
    """Scratch space of ``step.tick`` for ``n_pairs`` contact pairs."""
    return Work(
        np.zeros(NX),
        np.zeros(NX),
        np.zeros(NX),
        np.zeros(NX),
        np.zeros((7, NX)),
        np.zeros((NX, 4)),
        np.zeros((3, 3)),
        np.zeros(MAX_ROTORS),
        np.zeros(MAX_ROTORS),
        np.zeros(n_pairs),
        np.zeros(n_pairs),
        np.zeros(n_pairs),
        np.zeros(n_pairs),
        np.zeros(n_pairs),
        np.zeros((3, 3)),
        np.zeros(n_pairs),
        np.zeros(n_pairs),
        np.zeros((6, 12, 12)),
    )


#: The shapes of a :class:`Model`'s arrays when absent (zeros): the state at rest at the
#: origin, no IMU, no power-off schedule, the ``ideal`` estimator, no added sensor.
MODEL_ABSENT: dict[str, tuple[int, ...]] = {
    "x0": (NX,),
    "scfg": (NSCFG,),
    "noise": (0, 6),
    "sched_t": (0,),
    "sched_rate": (0, MAX_ROTORS),
    "sched_stop": (MAX_ROTORS,),
    "t_out": (0,),
    "ecfg": (NECFG,),
    "snoise": (0, NSN),
    "cnoise": (0, 0),
}


def model_array(name: str, a: np.ndarray | None) -> np.ndarray:
    """Field ``name`` of a :class:`Model` as the loop takes it: contiguous float64
    (``pairs``: int64), zeros of its :data:`MODEL_ABSENT` shape when ``None``."""
    if a is None:
        return np.zeros(MODEL_ABSENT.get(name, (0,)))
    return np.ascontiguousarray(a, dtype=np.int64 if name == "pairs" else np.float64)


def model(
    *,
    x0: np.ndarray,
    t0: float,
    tf: float,
    veh: np.ndarray,
    feat: np.ndarray,
    shapes: np.ndarray,
    pairs: np.ndarray,
    opts: np.ndarray,
    ctrl: np.ndarray,
    t_out: np.ndarray,
    scfg: np.ndarray | None = None,
    noise: np.ndarray | None = None,
    sched_t: np.ndarray | None = None,
    sched_rate: np.ndarray | None = None,
    sched_stop: np.ndarray | None = None,
    ecfg: np.ndarray | None = None,
    snoise: np.ndarray | None = None,
    cnoise: np.ndarray | None = None,
) -> Model:
    """A :class:`Model` of contiguous arrays (absent sensors, schedule, estimator: none, ideal).

    ``pairs`` is the contact-pair table of ``feat`` and ``shapes``
    (``core.geometry.pair_table``); ``t0``, ``tf`` in s.
    """
    arrays = {
        "x0": x0, "veh": veh, "feat": feat, "shapes": shapes, "pairs": pairs, "opts": opts,
        "ctrl": ctrl, "scfg": scfg, "noise": noise, "sched_t": sched_t,
        "sched_rate": sched_rate, "sched_stop": sched_stop, "t_out": t_out, "ecfg": ecfg,
        "snoise": snoise, "cnoise": cnoise,
    }  # fmt: skip
    fields = {name: model_array(name, a) for name, a in arrays.items()}
    return Model(span=model_span(t0, tf), **fields)


def model_span(t0: float, tf: float) -> np.ndarray:
    """A :class:`Model`'s ``span``: start and end time (s)."""
    span = np.zeros(NSPAN)
    span[SPAN_T0] = float(t0)
    span[SPAN_TF] = float(tf)
    return span


# ---------------------------------------------------------------- batches
@njit(cache=True)
def model_row(M: Model, k: int) -> Model:
    """Run ``k`` of models stacked along a first axis."""
    return Model(
        M.x0[k],
        M.span[k],
        M.veh[k],
        M.feat[k],
        M.shapes[k],
        M.pairs[k],
        M.opts[k],
        M.ctrl[k],
        M.scfg[k],
        M.noise[k],
        M.sched_t[k],
        M.sched_rate[k],
        M.sched_stop[k],
        M.t_out[k],
        M.ecfg[k],
        M.snoise[k],
        M.cnoise[k],
    )


@njit(cache=True)
def data_row(D: Data, k: int) -> Data:
    """Run ``k`` of loop states stacked along a first axis."""
    return Data(D.x[k], D.ls[k], D.cs[k], D.rin[k], D.mem[k], D.est[k], D.meas[k], D.sst[k])


@njit(cache=True)
def output_row(O: Output, k: int) -> Output:
    """Run ``k`` of outputs stacked along a first axis."""
    return Output(O.out[k], O.imu[k], O.episodes[k], O.stats[k])


def stacked(record: NamedTuple, n: int) -> NamedTuple:
    """``n`` zeroed copies of ``record`` stacked along a new first axis (same record type)."""
    return type(record)(*(np.zeros((n, *a.shape), dtype=a.dtype) for a in record))


def set_row(stack: NamedTuple, k: int, record: NamedTuple) -> None:
    """Copy ``record`` into row ``k`` of ``stack`` (a record of the same type, stacked)."""
    for dst, src in zip(stack, record, strict=True):
        dst[k] = src


# ---------------------------------------------------------------- reading
@dataclass
class RawRecord:
    """What one compiled run returns: the filled parts of its output arrays.

    ``out`` (n_out, out_width(n_features)), ``episodes`` (n_episodes, NEP),
    ``stats`` (NSTAT) and ``imu`` (n_imu, NIMU), layouts in ``core.recording_slots``
    (``out``, ``episodes``) and ``core.layout``.
    """

    out: np.ndarray
    episodes: np.ndarray
    stats: np.ndarray
    imu: np.ndarray


def raw_record(o: Output, *, copy: bool = False) -> RawRecord:
    """The filled parts of ``o`` (copies when ``copy``: buffers about to be reused)."""

    def part(a: np.ndarray) -> np.ndarray:
        return a.copy() if copy else a

    st = o.stats
    n_imu = min(int(st[ST_N_IMU]), o.imu.shape[0])
    return RawRecord(
        part(o.out[: int(st[ST_N_OUT])]),
        part(o.episodes[: int(st[ST_N_EPISODES])]),
        st.copy() if copy else st,
        part(o.imu[:n_imu]),
    )
