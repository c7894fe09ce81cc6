"""Run the compiled estimators on a synthetic IMU stream (the estimator tests' harness).

A stream is the truth at each sample (attitude, rates, specific force,
optionally position and velocity) and what the sensors read; the harness
writes each sample into a run's measurement record as the sensor stage does
and calls the loop's own estimator stage (``core.estimators.estimate_sample``),
so the filters run exactly as in a simulation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadimpact.core import estimator_slots as ESL
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.estimators import estimate_sample, init_estimate
from quadimpact.core.estimators import older_sensors as OS
from quadimpact.core.estimators.ekf import covariance, ekf_dimension
from quadimpact.core.records import new_data, new_output, new_work
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.core.sensors import measurement_slots as MSS
from quadimpact.inputs.scenarios import FlightScenario
from quadimpact.rotations import quat_to_matrix
from quadimpact.simulation.setup import prepare

G = 9.81


def expmap(phi: np.ndarray) -> np.ndarray:
    """The quaternion ``exp(phi)`` of a rotation vector (rad)."""
    a = float(np.linalg.norm(phi))
    if a == 0.0:
        return np.array([1.0, 0.0, 0.0, 0.0])
    return np.concatenate([[np.cos(a / 2)], np.sin(a / 2) * np.asarray(phi) / a])


def qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product."""
    a0, av = a[0], np.asarray(a[1:])
    b0, bv = b[0], np.asarray(b[1:])
    return np.concatenate([[a0 * b0 - av @ bv], a0 * bv + b0 * av + np.cross(av, bv)])


def error_vector(q_hat: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``phi`` with ``q = q_hat (x) exp(phi)``."""
    d = qmul(np.array([q_hat[0], *(-np.asarray(q_hat[1:]))]), q)
    if d[0] < 0:
        d = -d
    v = np.linalg.norm(d[1:])
    return np.zeros(3) if v == 0 else 2.0 * np.arctan2(v, d[0]) * d[1:] / v


def angle_deg(q_hat: np.ndarray, q: np.ndarray) -> float:
    return float(np.degrees(np.linalg.norm(error_vector(q_hat, q))))


@dataclass
class Stream:
    """Truth and readings at each sample (N samples)."""

    t: np.ndarray  # (N,) s
    q: np.ndarray  # (N, 4) true attitude
    w_true: np.ndarray  # (N, 3) true rates, rad/s
    f: np.ndarray  # (N, 3) measured specific force
    w: np.ndarray  # (N, 3) measured rates
    mag: np.ndarray | None = None  # (N, 3) magnetometer readings
    pos: np.ndarray | None = None  # (N, 3) true position
    vel: np.ndarray | None = None  # (N, 3) true inertial velocity
    pose: np.ndarray | None = None  # (N, 3) measured position (NaN: none at that sample)
    bias: np.ndarray | None = None  # (N, 3) true gyro bias


def constant_rotation(rate: np.ndarray, q0: np.ndarray, n: int, dt: float, g: float = G) -> Stream:
    """A rigid body turning at a constant body rate, hovering (``f = -g C^T e_Z``); ideal IMU."""
    t = np.arange(n) * dt
    step = expmap(np.asarray(rate) * dt)
    q = np.empty((n, 4))
    q[0] = q0
    for i in range(1, n):
        q[i] = qmul(q[i - 1], step)
        q[i] /= np.linalg.norm(q[i])
    f = np.array([-g * quat_to_matrix(qi)[2] for qi in q])
    w = np.tile(rate, (n, 1)).astype(float)
    return Stream(t=t, q=q, w_true=w.copy(), f=f, w=w)


class Harness:
    """A run's records with an estimator, fed sample by sample."""

    def __init__(self, estimator: str, n: int, *, params=None, imu="ideal", magnetometer=None,
                 pose_sensor=None, q0=None, dt=0.005, g=G, pos0=(0.0, 0.0, -5.0),
                 instruments=None):  # fmt: skip
        scenario = FlightScenario(
            estimator=estimator, estimator_params=params or {}, imu=imu,
            magnetometer=magnetometer, pose_sensor=pose_sensor, final_time_s=max(n * dt, 0.01),
            position_m=pos0, instruments=instruments or {},
        )  # fmt: skip
        setup = prepare(scenario)
        self.setup = setup
        self.m = setup.model()
        self.m.veh[VS.V_GRAVITY] = g
        self.d = new_data(self.m)
        self.o = new_output(self.m, n, 4)
        self.w = new_work(self.m.pairs.shape[0])
        if q0 is not None:
            self.d.x[L.X_QUAT : L.X_QUAT + 4] = q0
        self.d.x[L.X_VEL : L.X_VEL + 3] = 0.0
        self.d.x[L.X_OMEGA : L.X_OMEGA + 3] = 0.0
        self.o.stats[:] = 0.0
        self.o.stats[L.ST_ONSET_T] = np.nan
        self.o.stats[L.ST_STAGE_T : L.ST_STAGE_T + L.N_STAGES] = np.nan
        self.d.meas[OS.MAG_T] = np.nan
        self.d.meas[OS.POSE_T] = np.nan
        init_estimate(self.m, self.d)
        self.i = 0

    @property
    def est(self) -> np.ndarray:
        return self.d.est

    def q_hat(self) -> np.ndarray:
        return self.d.est[ESL.ES_Q : ESL.ES_Q + 4].copy()

    def bias_hat(self) -> np.ndarray:
        return self.d.est[ESL.ES_BIAS : ESL.ES_BIAS + 3].copy()

    def P(self) -> np.ndarray:
        return covariance(self.d.est, ekf_dimension(self.m.ecfg))

    def sample(self, t: float, f, w, q_true, mag=None, pose=None, pos=None, vel=None):
        """One sample at ``t`` (s): the readings into the record, then the estimator's update."""
        meas = self.d.meas
        meas[MSS.MS_IMU_F : MSS.MS_IMU_F + 3] = f
        meas[MSS.MS_IMU_W : MSS.MS_IMU_W + 3] = w
        meas[MSS.MS_IMU_T] = t
        if mag is not None:
            meas[OS.MAG : OS.MAG + 3] = mag
            meas[OS.MAG_T] = t
        if pose is not None and np.all(np.isfinite(pose)):
            meas[OS.POSE : OS.POSE + 3] = pose
            meas[OS.POSE + 3 : OS.POSE + 7] = q_true
            meas[OS.POSE_T] = t
        xs = self.d.x.copy()
        xs[L.X_QUAT : L.X_QUAT + 4] = q_true
        if pos is not None:
            xs[L.X_POS : L.X_POS + 3] = pos
        C = np.ascontiguousarray(quat_to_matrix(np.asarray(q_true, float)))
        if vel is not None:
            xs[L.X_VEL : L.X_VEL + 3] = C.T @ vel
        self.i += 1
        self.d.sst[IMS.SS_N] = self.i
        estimate_sample(float(t), xs, C, self.m, self.d, self.o, self.w)

    def run(self, s: Stream) -> np.ndarray:
        """Feed a whole stream; the attitude error (deg) after each sample."""
        err = np.empty(len(s.t))
        for i in range(len(s.t)):
            self.sample(
                s.t[i], s.f[i], s.w[i], s.q[i],
                None if s.mag is None else s.mag[i],
                None if s.pose is None else s.pose[i],
                None if s.pos is None else s.pos[i],
                None if s.vel is None else s.vel[i],
            )  # fmt: skip
            err[i] = angle_deg(self.q_hat(), s.q[i])
        return err
