"""The run's added sensors and its estimator as the compiled core's arrays.

:func:`pack_estimation` fills the added sensors' slots of ``scfg`` (the IMU's
impact disturbance and gyro bias random walk, the magnetometer, the pose
sensor: layout ``SC_*``) and packs the estimator (``ecfg``, layout ``EC_*``);
:func:`draw_estimation` makes a run's random part from its seed: the added
sensors' noise (``snoise``, layout ``SN_*``) and the estimator's initial error.

Random draws never touch the IMU's own (``packing.sensor_block.pack_sensors``: NumPy's
PCG64 seeded with the run's seed): the added sensors draw from the stream
``SeedSequence(seed, spawn_key=(SENSOR_STREAM,))``, one row of ``NSN``
standard normal numbers per IMU sample, only when one of them needs noise;
the initial estimate's error from ``SeedSequence(seed, spawn_key=(INIT_STREAM,))``
(twelve numbers: attitude, velocity, position, gyro bias), only when it is
asked for; the initial estimate's Euler-angle errors and the magnetometer's
static bias from ``SeedSequence(seed, spawn_key=(EXTRA_STREAM,))`` (six
numbers), only when one of them is asked for.
So a run's table is the same on one core or a cluster, and adding a sensor
does not change the IMU's noise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from pydantic import BaseModel

from quadimpact.core import estimator_slots as ESL
from quadimpact.core import layout as L
from quadimpact.core.estimators import complementary as CF
from quadimpact.core.estimators import ekf as EKF
from quadimpact.core.estimators import ekf_additive as ADD
from quadimpact.core.estimators import nav_ekf as NAV
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.core.sensors.registry import config_address
from quadimpact.inputs.estimators import (
    AdditiveEkfParams,
    ComplementaryParams,
    EkfParams,
    EstimatorContext,
    EstimatorParams,
    NavEkfParams,
    settings_text,
)
from quadimpact.inputs.resolved import ResolvedShared
from quadimpact.inputs.sensors import ResolvedImu
from quadimpact.packing.controller_block import refuse_nan

__all__ = [
    "BUILTIN_PACKERS",
    "Estimation",
    "draw_estimation",
    "pack_added_sensors",
    "pack_estimation",
]

SENSOR_STREAM = 1
INIT_STREAM = 2
EXTRA_STREAM = 3


@dataclass
class Estimation:
    """The packed estimator and added sensors of a run (and what the summary reports).

    ``ecfg`` has no initial error yet and ``snoise`` no draw: those are a
    run's (:func:`draw_estimation`, from its seed).
    """

    ecfg: np.ndarray
    snoise: np.ndarray
    name: str
    settings: str
    step: Any = None  # a plug-in estimator's compiled step
    resolved: dict[str, Any] | None = None
    noisy: bool = False
    """An added sensor needs noise: ``snoise`` gets one row of draws per IMU sample."""
    entry: Any = None
    """The estimator's registry entry."""
    initial_std: np.ndarray | None = None
    """Standard deviations of the initial estimate's error (rad, m/s, m, rad/s, 3 each),
    None when no error is asked for."""
    extra_std: np.ndarray | None = None
    """Standard deviations of the initial Euler-angle errors (rad, 3) and of the
    magnetometer's static bias (3), None when neither is asked for."""


def _pack_complementary(params: BaseModel, ctx: EstimatorContext) -> np.ndarray:
    p: ComplementaryParams = params  # type: ignore[assignment]
    e = np.zeros(ESL.NECFG)
    e[CF.EC_K_ACC] = p.k_acc_1_s
    e[CF.EC_K_MAG] = p.k_mag_1_s
    e[CF.EC_K_BIAS] = p.k_bias_1_s2
    e[CF.EC_GATE] = p.gate_m_s2
    e[CF.EC_K_POS] = p.k_pose_position
    e[CF.EC_K_VEL] = p.k_pose_velocity_1_s
    if p.form == "raw":
        k_p, w_a, w_m, k_i = p.raw_gains
        e[CF.EC_CF_RAW] = 1.0
        e[CF.EC_K_ACC] = 0.5 * k_p * w_a
        e[CF.EC_K_MAG] = 0.5 * k_p * w_m
        e[CF.EC_K_BIAS] = 0.5 * k_i * w_a
        e[CF.EC_K_BIAS_MAG] = 0.5 * k_i * w_m
    return e


def _pack_additive(params: BaseModel, ctx: EstimatorContext) -> np.ndarray:
    p: AdditiveEkfParams = params  # type: ignore[assignment]
    e = np.zeros(ESL.NECFG)
    e[ADD.EC_AS_WRITTEN] = 1.0 if p.transition == "as-written" else 0.0
    e[ADD.EC_R_ACC] = p.accel_variance
    e[ADD.EC_R_MAG] = p.magnetometer_variance
    e[ADD.EC_Q_QUAT] = p.quaternion_process
    e[ADD.EC_Q_BIAS] = p.bias_process
    e[ADD.EC_P0_QUAT] = p.initial_quaternion_variance
    e[ADD.EC_P0_BIAS] = p.initial_bias_variance
    e[ADD.EC_GATE] = p.gate_m_s2
    return e


def _pack_ekf(params: BaseModel, ctx: EstimatorContext) -> np.ndarray:
    p: EkfParams = params  # type: ignore[assignment]  # resolved: every noise a number
    e = np.zeros(ESL.NECFG)
    _pack_filter_noises(p, e)
    e[EKF.EC_SIG_POS] = p.pose_position_noise_m
    e[EKF.EC_SIG_ATT] = math.radians(p.pose_attitude_noise_deg)
    e[EKF.EC_GATE] = p.gate_m_s2
    e[EKF.EC_GATE_MODE] = EKF.GATE_DEWEIGHT if p.gate == "deweight" else EKF.GATE_SKIP
    e[EKF.EC_DEWEIGHT] = p.deweight
    _pack_initial_spreads(p, e)
    e[EKF.EC_NAV] = 1.0 if ctx.pose_sensor is not None else 0.0
    _pack_impact(p, ctx, e)
    return e


def _pack_filter_noises(p: Any, e: np.ndarray) -> None:
    """The noises the ``ekf`` and the ``nav-ekf`` share (resolved by
    ``inputs.estimators.resolve_estimator_params``)."""
    e[EKF.EC_SIG_GYRO] = p.gyro_noise_rad_s
    e[EKF.EC_SIG_WALK] = p.gyro_bias_walk_rad_s_sqrt_s
    e[EKF.EC_SIG_ACC] = p.accel_noise_m_s2
    e[EKF.EC_SIG_GRAV] = p.gravity_noise_m_s2
    e[EKF.EC_SIG_MAG] = p.magnetometer_noise


def _pack_initial_spreads(p: Any, e: np.ndarray) -> None:
    """The initial covariance's spreads (attitude in rad, gyro bias, velocity, position)."""
    e[EKF.EC_P0] = math.radians(p.initial_attitude_std_deg)
    e[EKF.EC_P0 + 1] = p.initial_bias_std_rad_s
    e[EKF.EC_P0 + 2] = p.initial_velocity_std_m_s
    e[EKF.EC_P0 + 3] = p.initial_position_std_m


def _pack_impact(p: Any, ctx: EstimatorContext, e: np.ndarray) -> None:
    """The IMU's impact disturbance as the filter models it (the ``ekf``'s and ``nav-ekf``'s)."""
    dist = ctx.imu.impact_disturbance
    if p.impact_noise == "sensor" and dist is not None:
        e[EKF.EC_IMPACT_W] = dist.gyro_rad_s
        e[EKF.EC_IMPACT_F] = dist.accel_m_s2
        e[EKF.EC_IMPACT_TAU] = dist.time_constant_s
        e[EKF.EC_IMPACT_REPLACE] = 1.0 if dist.mode == "replace" else 0.0
        e[EKF.EC_IMPACT_THRESHOLD] = p.impact_threshold_g * ctx.vehicle.gravity_m_s2


def _pack_nav_ekf(params: BaseModel, ctx: EstimatorContext) -> np.ndarray:
    p: NavEkfParams = params  # type: ignore[assignment]  # resolved: every noise a number
    imu = ctx.imu
    e = np.zeros(ESL.NECFG)
    _pack_filter_noises(p, e)
    e[NAV.EC_NAV_ACC_WALK] = p.accel_bias_walk_m_s2_sqrt_s
    e[EKF.EC_GATE] = p.gate_m_s2
    e[EKF.EC_GATE_MODE] = EKF.GATE_DEWEIGHT if p.gate == "deweight" else EKF.GATE_SKIP
    e[EKF.EC_DEWEIGHT] = p.deweight
    e[NAV.EC_NAV_BARO] = p.barometer_noise_m
    e[NAV.EC_NAV_BARO + 1] = p.barometer_bias_walk_m_sqrt_s
    e[NAV.EC_NAV_RANGE] = p.range_noise_floor_m
    e[NAV.EC_NAV_FLOW] = p.flow_noise_floor_rad_s
    e[NAV.EC_NAV_GATES : NAV.EC_NAV_GATES + 4] = (
        p.mag_gate_sigma,
        p.baro_gate_sigma,
        p.range_gate_sigma,
        p.flow_gate_sigma,
    )
    e[NAV.EC_NAV_REACQUIRE] = p.reacquire_after_s
    e[NAV.EC_NAV_MAX_TILT] = math.cos(math.radians(p.max_tilt_deg))
    e[NAV.EC_NAV_MIN_HEIGHT] = p.min_flow_height_m
    if p.imu_lever_arm == "sensor":
        e[NAV.EC_NAV_LEVER : NAV.EC_NAV_LEVER + 3] = imu.position_m
    e[NAV.EC_NAV_DELAYED] = 1.0 if p.flow_delay_compensation else 0.0
    e[NAV.EC_NAV_REACQ_EXCESS] = 1.0 if p.reacquire_inflation == "excess" else 0.0
    _pack_initial_spreads(p, e)
    e[NAV.EC_NAV_P0] = p.initial_accel_bias_std_m_s2
    e[NAV.EC_NAV_P0 + 1] = p.initial_baro_bias_std_m
    _pack_impact(p, ctx, e)
    return e


def _zeros(params: BaseModel, ctx: EstimatorContext) -> np.ndarray:
    return np.zeros(ESL.NECFG)


#: The built-in estimators' packers, by kind (a plug-in's is its registry entry's).
BUILTIN_PACKERS = {
    L.EST_COMPLEMENTARY: _pack_complementary,
    L.EST_EKF: _pack_ekf,
    L.EST_EKF_ADDITIVE: _pack_additive,
    L.EST_NAV_EKF: _pack_nav_ekf,
}


def _stream(seed: int, key: int) -> np.random.Generator:
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed, spawn_key=(key,))))


def pack_added_sensors(s: Any, imu: ResolvedImu, scfg: np.ndarray) -> bool:
    """Fill ``scfg``'s slots of the IMU's added noises (in place); whether ``snoise`` is drawn.

    The IMU's impact disturbance (m/s^2, rad/s, s) and gyro bias random walk
    (rad/s/sqrt(s)). The magnetometer and the pose sensor are sensor
    components (their config is packed with the others'), but their draws are
    still columns of ``snoise``: noisy when one of the four draws random numbers.
    """
    dist = imu.impact_disturbance
    if dist is not None:
        scfg[IMS.SC_IMPACT_F] = dist.accel_m_s2
        scfg[IMS.SC_IMPACT_W] = dist.gyro_rad_s
        scfg[IMS.SC_IMPACT_TAU] = dist.time_constant_s
        scfg[IMS.SC_IMPACT_REPLACE] = 1.0 if dist.mode == "replace" else 0.0
    scfg[IMS.SC_BIAS_WALK] = imu.gyro_bias_walk_rad_s_sqrt_s
    mag = s.magnetometer
    pose = s.pose_sensor
    return (
        (dist is not None and (dist.accel_m_s2 > 0.0 or dist.gyro_rad_s > 0.0))
        or imu.gyro_bias_walk_rad_s_sqrt_s > 0.0
        or (mag is not None and mag.noise > 0.0)
        or (
            pose is not None
            and (pose.position_noise_m > 0.0 or (pose.attitude and pose.attitude_noise_deg > 0.0))
        )
    )


def _initial_errors(
    params: BaseModel, kind: int, mag: Any, ecfg: np.ndarray
) -> tuple[np.ndarray | None, np.ndarray | None]:
    """The standard deviations of the initial estimate's error and of the extra draws.

    Returns ``(initial_std, extra_std)``: twelve numbers (attitude, rad;
    velocity, m/s; position, m; gyro bias, rad/s; three each) or ``None``
    when all are zero; six (the initial Euler-angle errors, rad, and the
    magnetometer's static bias) or ``None``. Sets ``ecfg[EC_INIT_BIAS_ZERO]``.
    """
    extra = np.zeros(6)
    if mag is not None:
        extra[3:] = mag.bias
    initial_std = None
    if isinstance(params, EstimatorParams) and kind != L.EST_IDEAL:
        extra[:3] = np.radians(params.initial_euler_error_deg)
        ecfg[ESL.EC_INIT_BIAS_ZERO] = 1.0 if params.initial_bias == "zero" else 0.0
        std = np.repeat(
            [
                math.radians(params.initial_attitude_error_deg),
                params.initial_velocity_error_m_s,
                params.initial_position_error_m,
                params.initial_bias_error_rad_s,
            ],
            3,
        )
        if np.any(std > 0.0):
            initial_std = std
    return initial_std, extra if np.any(extra > 0.0) else None


def pack_estimation(r: ResolvedShared, scfg: np.ndarray) -> Estimation:
    """Fill ``scfg``'s added-sensor slots (in place) and pack the estimator (no random draw).

    ``r``: the run's resolved description (its estimator's parameters with
    every default applied, its IMU, magnetometer and pose sensor).
    """
    s = r.settings
    est = r.estimator
    imu = r.imu
    noisy = pack_added_sensors(s, imu, scfg)
    mag, pose = est.context.magnetometer, est.context.pose_sensor
    entry = est.entry
    pack = entry.pack if entry.pack is not None else BUILTIN_PACKERS.get(entry.kind, _zeros)
    ecfg = np.array(pack(est.params, est.context), dtype=float)
    if ecfg.shape != (ESL.NECFG,):
        raise ValueError(f"estimator {entry.name!r}: its pack must return ({ESL.NECFG},) floats")
    refuse_nan(ecfg, f"estimator {entry.name!r}: its settings")
    ecfg[ESL.EC_KIND] = entry.kind
    ecfg[ESL.EC_OBSERVER] = 0.0 if s.estimate_in_loop else 1.0
    if est.step_address:
        ecfg[ESL.EC_STEP] = est.step_address
    initial_std, extra_std = _initial_errors(est.params, entry.kind, mag, ecfg)
    return Estimation(
        ecfg=ecfg,
        snoise=np.zeros((0, IMS.NSN)),
        name=entry.name,
        settings=settings_text(est.given),
        step=entry.step,
        resolved={
            "estimator": entry.name,
            "estimator_params": est.given.model_dump(mode="json"),
            "magnetometer": mag.model_dump(mode="json") if mag is not None else None,
            "pose_sensor": pose.model_dump(mode="json") if pose is not None else None,
            "sensors": s.sensors,
        },
        noisy=noisy,
        entry=entry,
        initial_std=initial_std,
        extra_std=extra_std,
    )


def draw_estimation(
    est: Estimation, seed: int, n_imu: int, scfg: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """A run's ``ecfg`` (with its initial estimate's error) and ``snoise``, from its seed.

    ``scfg``: the run's sensor settings, which get the magnetometer's static
    bias in place (when it has one).

    The added sensors draw ``(n_imu, NSN)`` standard normal numbers from the
    stream ``SENSOR_STREAM`` when one of them needs noise; the initial
    error is twelve draws from ``INIT_STREAM`` times their standard
    deviations (attitude rad, velocity m/s, position m, gyro bias rad/s;
    three axes each). ``est.ecfg`` is not changed (a new array is returned).
    """
    snoise = est.snoise
    if est.noisy:
        snoise = _stream(seed, SENSOR_STREAM).standard_normal((n_imu, IMS.NSN))
    ecfg = est.ecfg
    if est.initial_std is not None:
        ecfg = ecfg.copy()
        draws = _stream(seed, INIT_STREAM).standard_normal(12) * est.initial_std
        ecfg[ESL.EC_INIT_ATT : ESL.EC_INIT_ATT + 3] = draws[0:3]
        ecfg[ESL.EC_INIT_VEL : ESL.EC_INIT_VEL + 3] = draws[3:6]
        ecfg[ESL.EC_INIT_POS : ESL.EC_INIT_POS + 3] = draws[6:9]
        ecfg[ESL.EC_INIT_BIAS : ESL.EC_INIT_BIAS + 3] = draws[9:12]
    if est.extra_std is not None:
        ecfg = ecfg.copy() if ecfg is est.ecfg else ecfg
        draws = _stream(seed, EXTRA_STREAM).standard_normal(6) * est.extra_std
        ecfg[ESL.EC_INIT_EULER : ESL.EC_INIT_EULER + 3] = draws[0:3]
        if scfg is not None:
            bias = config_address("magnetometer", "bias")
            scfg[bias : bias + 3] = draws[3:6]
    return ecfg, snoise
