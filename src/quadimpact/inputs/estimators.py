"""The estimator registry: every state estimator a scenario can name, and its parameters.

An estimator is a stage of the compiled loop between the sensors and the
controller (docs/ESTIMATION.md): it predicts at each IMU sample and corrects
when a measurement arrives; the controllers and the detector's wall-normal
estimate read only its estimate. A scenario names one (``estimator = "ekf"``)
and may set its parameters (``[estimator_params]``). Built in:

* ``ideal`` (the default): the true state, the gyro as measured for the rates;
  every result as before estimators, bit for bit;
* ``complementary``: a Mahony-type nonlinear complementary filter
  (:class:`ComplementaryParams`);
* ``ekf``: a multiplicative error-state extended Kalman filter
  (:class:`EkfParams`);
* ``ekf-additive``: the authors' 7-state EKF on an additive quaternion, with
  its transition matrix as written or correct (:class:`AdditiveEkfParams`);
* ``nav-ekf``: the navigation filter, fusing the magnetometer, barometer,
  rangefinder and optical flow (:class:`NavEkfParams`).

A user's compiled estimator plugs in like a controller:
``register_estimator(name, step=..., params=..., pack=...)`` (the step's
interface in ``quadimpact.core.estimators.plugin_estimator``); the step is
then compiled alone once per process and the cached loop calls it by its
address (``core/plugin_call.py``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, Field, StrictBool, field_validator

from quadimpact.core import estimator_slots as ESL
from quadimpact.core import layout as L
from quadimpact.inputs.registry import Registry
from quadimpact.inputs.types import MODEL_CONFIG, Real, Vec3, Vec4

__all__ = [
    "AdditiveEkfParams",
    "ComplementaryParams",
    "EkfParams",
    "EstimatorContext",
    "EstimatorEntry",
    "EstimatorParams",
    "NavEkfParams",
    "estimator_entry",
    "estimator_names",
    "register_estimator",
    "resolve_estimator_params",
    "settings_text",
    "unregister_estimator",
    "validate_estimator_params",
]

# floors of the EKF's noise figures, so that an ideal sensor (noise 0) does not make
# its covariance singular
GYRO_NOISE_FLOOR = 1e-4  # rad/s
WALK_FLOOR = 1e-6  # rad/s/sqrt(s)
ACCEL_NOISE_FLOOR = 1e-2  # m/s^2
GRAVITY_NOISE_FLOOR = 0.1  # m/s^2
MAG_NOISE_FLOOR = 1e-3  # unit field
POSITION_NOISE_FLOOR = 1e-4  # m
ATTITUDE_NOISE_FLOOR_DEG = 0.01
BIAS_STD_FLOOR = 1e-3  # rad/s
INITIAL_ATTITUDE_STD_DEG = 0.5
VELOCITY_STD_FLOOR = 0.01  # m/s
POSITION_STD_FLOOR = 0.01  # m
BARO_NOISE_FLOOR = 0.01  # m
BARO_WALK_FLOOR = 1e-4  # m/sqrt(s)
ACCEL_BIAS_STD_FLOOR = 0.01  # m/s^2


class EstimatorParams(BaseModel):
    """What every built-in filter shares: the initial estimate's seeded error.

    The initial estimate is the true initial state, gyro bias included (the
    vehicle has flown before: a filter's bias estimate has converged), plus
    an error drawn once per run from the run's seed: a rotation vector of
    standard deviation ``initial_attitude_error_deg`` per axis, and velocity,
    position and gyro-bias errors of the given standard deviations per axis
    (0: exact).
    """

    model_config = MODEL_CONFIG

    initial_attitude_error_deg: Real = Field(0.0, ge=0, description="Std per axis, deg.")
    initial_velocity_error_m_s: Real = Field(0.0, ge=0, description="Std per axis, m/s.")
    initial_position_error_m: Real = Field(0.0, ge=0, description="Std per axis, m.")
    initial_bias_error_rad_s: Real = Field(0.0, ge=0, description="Std per axis, rad/s.")
    initial_euler_error_deg: Vec3 = Field(
        (0.0, 0.0, 0.0),
        description="Std of ZYX Euler-angle errors (roll, pitch, yaw), deg (the authors' "
        "study: 2, 2, 5).",
    )
    initial_bias: Literal["true", "zero"] = Field(
        "true", description="The gyro bias estimate starts at the true bias or at 0."
    )

    @field_validator("initial_euler_error_deg")
    @classmethod
    def _non_negative(cls, value: tuple[float, float, float]) -> tuple[float, float, float]:
        if min(value) < 0:
            raise ValueError("standard deviations must be >= 0")
        return value


class ComplementaryParams(EstimatorParams):
    """Gains of the complementary filter (the authors' simulation values by default)."""

    k_acc_1_s: Real = Field(0.25, ge=0, description="Accelerometer gain k_P, 1/s.")
    k_mag_1_s: Real = Field(0.15, ge=0, description="Magnetometer gain, 1/s.")
    k_bias_1_s2: Real = Field(0.25, ge=0, description="Bias (integral) gain k_I, 1/s^2.")
    gate_m_s2: Real = Field(1.0, ge=0, description="Skip the accelerometer while ||f|-g| > this.")
    k_pose_position: Real = Field(
        0.1, ge=0, le=1, description="Pose: position (and attitude) gain per measurement."
    )
    k_pose_velocity_1_s: Real = Field(
        0.5, ge=0, description="Pose: velocity gain per measurement, 1/s."
    )
    form: Literal["unit", "raw"] = Field(
        "unit",
        description="'unit': the gains above on unit vectors; 'raw': the authors' explicit "
        "filter on raw vectors with raw_gains.",
    )
    raw_gains: Vec4 = Field(
        (0.1, 0.5, 1.0, 0.05),
        description="form = 'raw': k_p, accelerometer weight, magnetometer weight, k_I "
        "(the authors' 2016 study).",
    )


class EkfParams(EstimatorParams):
    """Noise figures, gate and initial covariance of the EKF.

    A noise left ``None`` is the sensor's own setting (with a small floor, so
    that an ideal sensor does not make the covariance singular). The
    accelerometer measures gravity only when the vehicle does not accelerate:
    a quadrotor's specific force points along its thrust axis, so a tilted
    vehicle whose thrust is near ``m g`` passes the gate with an error of
    ``2 g sin(tilt/2)``; ``maneuver_accel_m_s2`` stands for it in the gravity
    measurement's noise.
    """

    gyro_noise_rad_s: Real | None = Field(None, ge=0, description="Gyro noise per sample.")
    gyro_bias_walk_rad_s_sqrt_s: Real | None = Field(
        None, ge=0, description="Gyro bias random walk, rad/s/sqrt(s)."
    )
    accel_noise_m_s2: Real | None = Field(None, ge=0, description="Accel. noise per sample.")
    gravity_noise_m_s2: Real | None = Field(
        None,
        gt=0,
        description="Std of the accelerometer as a gravity measurement, m/s^2; None: "
        "sqrt(accel_noise^2 + maneuver_accel^2).",
    )
    maneuver_accel_m_s2: Real = Field(
        4.0,
        ge=0,
        description="The vehicle's own acceleration the gate lets through, m/s^2 (a tilt of "
        "about 25 deg at hover thrust).",
    )
    magnetometer_noise: Real | None = Field(None, gt=0, description="Unit field.")
    pose_position_noise_m: Real | None = Field(None, gt=0, description="m.")
    pose_attitude_noise_deg: Real | None = Field(None, gt=0, description="deg.")
    gate_m_s2: Real = Field(0.5, ge=0, description="Gate on ||f| - g|, m/s^2 (authors: 0.5).")
    gate: Literal["skip", "deweight"] = Field(
        "skip", description="Beyond the gate: skip the update, or de-weight it."
    )
    deweight: Real = Field(
        1.0, gt=0, description="De-weighting: variance times this (||f|-g| / gate)^2."
    )
    initial_attitude_std_deg: Real | None = Field(
        None, gt=0, description="Initial std, deg; None: the initial error's std, at least 0.5."
    )
    initial_bias_std_rad_s: Real | None = Field(
        None, gt=0, description="Initial bias std, rad/s; None: the initial error's, >= 1e-3."
    )
    initial_velocity_std_m_s: Real | None = Field(
        None, gt=0, description="m/s (with a pose sensor); None: the initial error's, >= 0.01."
    )
    initial_position_std_m: Real | None = Field(
        None, gt=0, description="m (with a pose sensor); None: the initial error's, >= 0.01."
    )
    impact_noise: Literal["sensor", "none"] = Field(
        "sensor",
        description="'sensor': the IMU's impact disturbance (when it has one) in the gyro and "
        "accelerometer noise after each impact the filter sees; 'none': not modelled.",
    )
    impact_threshold_g: Real = Field(
        0.5, gt=0, description="|(f_x, f_y)| that marks an impact for the noise model, in g."
    )


class AdditiveEkfParams(EstimatorParams):
    """The authors' 7-state EKF (an additive quaternion and the gyro bias).

    Defaults: their 2016 study's figures, as matrix entries (variances):
    measurement noise ``diag(1, 1, 1, 7e-4, 7e-4, 7e-4)``, process noise
    ``dt diag(1.8e-3 I4, 1e-3 I3)``, ``P0 = diag(0.1 I4, 1e-4 I3)``, the
    accelerometer gate 0.5 m/s^2. ``transition``: ``"correct"``
    (``I + dt/2 Omega``) or ``"as-written"`` (their code's ``-dt/2 (I + Omega)``).
    """

    transition: Literal["correct", "as-written"] = Field(
        "correct", description="The quaternion block of the transition matrix."
    )
    accel_variance: Real = Field(1.0, gt=0, description="Accelerometer noise variance.")
    magnetometer_variance: Real = Field(7e-4, gt=0, description="Magnetometer noise variance.")
    quaternion_process: Real = Field(1.8e-3, ge=0, description="Quaternion process noise / s.")
    bias_process: Real = Field(1e-3, ge=0, description="Bias process noise / s, (rad/s)^2.")
    initial_quaternion_variance: Real = Field(0.1, gt=0, description="P0, quaternion.")
    initial_bias_variance: Real = Field(1e-4, gt=0, description="P0, bias, (rad/s)^2.")
    gate_m_s2: Real = Field(0.5, ge=0, description="Skip the accelerometer while ||f|-g| > this.")


class NavEkfParams(EstimatorParams):
    """Noise figures, gates and initial covariance of the navigation filter ``nav-ekf``.

    A noise left ``None`` is the sensor's own setting (with the ``ekf``'s
    floors). The rangefinder's and the flow's noises are each sample's own
    (the ``noise_m`` and ``noise_rad_s`` they deliver), at least the floors
    below. The gates are PX4 EKF2's defaults (``EKF2_MAG_GATE`` 3,
    ``EKF2_BARO_GATE`` 5, ``EKF2_RNG_GATE`` 5, ``EKF2_OF_GATE`` 3), in sigma:
    a sample is refused when its normalised innovation squared exceeds the
    gate squared times its rows. docs/ESTIMATION.md 2.6 describes the filter.
    """

    gyro_noise_rad_s: Real | None = Field(None, ge=0, description="Gyro noise per sample.")
    gyro_bias_walk_rad_s_sqrt_s: Real | None = Field(
        None, ge=0, description="Gyro bias random walk, rad/s/sqrt(s)."
    )
    accel_noise_m_s2: Real | None = Field(None, ge=0, description="Accel. noise per sample.")
    accel_bias_walk_m_s2_sqrt_s: Real = Field(
        3e-3, gt=0, description="Accel. bias random walk, m/s^2/sqrt(s) (PX4 EKF2_ACC_B_NOISE)."
    )
    gravity_noise_m_s2: Real | None = Field(
        None,
        gt=0,
        description="Std of the accelerometer as a gravity measurement, m/s^2; None: "
        "sqrt(accel_noise^2 + maneuver_accel^2).",
    )
    maneuver_accel_m_s2: Real = Field(
        4.0, ge=0, description="The vehicle's own acceleration the gate lets through, m/s^2."
    )
    gate_m_s2: Real = Field(0.5, ge=0, description="Gate on ||f| - g|, m/s^2 (as the ekf).")
    gate: Literal["skip", "deweight"] = Field(
        "skip", description="Beyond the gate: skip the gravity update, or de-weight it."
    )
    deweight: Real = Field(
        1.0, gt=0, description="De-weighting: variance times this (||f|-g| / gate)^2."
    )
    magnetometer_noise: Real | None = Field(None, gt=0, description="Unit field.")
    barometer_noise_m: Real | None = Field(None, gt=0, description="m; None: the barometer's.")
    barometer_bias_walk_m_sqrt_s: Real | None = Field(
        None, ge=0, description="m/sqrt(s); None: the barometer's, at least 1e-4."
    )
    range_noise_floor_m: Real = Field(0.01, gt=0, description="Least rangefinder noise, m.")
    flow_noise_floor_rad_s: Real = Field(
        0.8,
        gt=0,
        description="Least flow noise the filter fuses with, rad/s: above the sensor's "
        "(0.15-0.5), a smoother velocity for the law to hold (docs/ESTIMATION.md 9).",
    )
    mag_gate_sigma: Real = Field(3.0, ge=0, description="Magnetometer gate (0: none).")
    baro_gate_sigma: Real = Field(5.0, ge=0, description="Barometer gate (0: none).")
    range_gate_sigma: Real = Field(5.0, ge=0, description="Rangefinder gate (0: none).")
    flow_gate_sigma: Real = Field(3.0, ge=0, description="Optical-flow gate (0: none).")
    reacquire_after_s: Real = Field(
        0.5,
        gt=0,
        description="A source unfused this long is re-acquired at its next sample: the gate "
        "is lifted once and its states' variance raised by the innovation, s.",
    )
    max_tilt_deg: Real = Field(
        45.0, gt=0, lt=90, description="Range and flow fused only within this tilt, deg."
    )
    min_flow_height_m: Real = Field(0.1, ge=0, description="Flow fused only above this, m.")
    imu_lever_arm: Literal["sensor", "none"] = Field(
        "sensor",
        description="'sensor': the IMU's offset from the CM removed from its specific force "
        "(the rotation's centripetal and tangential parts); 'none': the IMU taken at the CM.",
    )
    reacquire_inflation: Literal["excess", "innovation"] = Field(
        "excess",
        description="At a re-acquisition, raise the states' variance by the innovation's "
        "excess over its predicted spread ('excess': nothing when the estimate is still "
        "consistent) or by the whole innovation squared ('innovation').",
    )
    flow_delay_compensation: StrictBool = Field(
        False,
        description="Predict each flow sample from the current estimate carried back to its "
        "image's capture time (the correction applied now); false: from the current estimate "
        "(the default: no measured gain, docs/ESTIMATION.md 2.6).",
    )
    initial_attitude_std_deg: Real | None = Field(
        None, gt=0, description="Initial std, deg; None: the initial error's std, at least 0.5."
    )
    initial_bias_std_rad_s: Real | None = Field(
        None, gt=0, description="Initial gyro bias std, rad/s; None: the initial error's, >= 1e-3."
    )
    initial_velocity_std_m_s: Real | None = Field(
        None, gt=0, description="m/s; None: the initial error's, >= 0.01."
    )
    initial_position_std_m: Real | None = Field(
        None, gt=0, description="m; None: the initial error's, >= 0.01."
    )
    initial_accel_bias_std_m_s2: Real | None = Field(
        None,
        gt=0,
        description="m/s^2; None: 0.01, or the IMU's bias std when the estimate starts at 0.",
    )
    initial_baro_bias_std_m: Real = Field(0.1, gt=0, description="Initial baro bias std, m.")
    impact_noise: Literal["sensor", "none"] = Field(
        "sensor",
        description="'sensor': the IMU's impact disturbance in the gyro and accelerometer "
        "noise after each impact the filter sees (as the ekf); 'none': not modelled.",
    )
    impact_threshold_g: Real = Field(
        0.5, gt=0, description="|(f_x, f_y)| that marks an impact for the noise model, in g."
    )


class _NoParams(BaseModel):
    model_config = MODEL_CONFIG


@dataclass(frozen=True)
class EstimatorContext:
    """What a packer may need besides its parameters: the run's sensors.

    ``imu``: :class:`~quadimpact.inputs.sensors.ResolvedImu`; ``magnetometer``
    and ``pose_sensor``: their settings or ``None``; ``vehicle``;
    ``instruments``: the sensor components' settings, by name.
    """

    imu: Any
    magnetometer: Any = None
    pose_sensor: Any = None
    vehicle: Any = None
    instruments: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class EstimatorEntry:
    """One registered estimator.

    Attributes
    ----------
    name : str
        As written in scenario files and on the command line.
    kind : int
        ``ecfg[EC_KIND]``: a built-in ``EST_*`` id, or ``EST_USER`` for a plug-in.
    params : type of pydantic.BaseModel
        Its parameters (``[estimator_params]``), with defaults.
    pack : callable or None
        ``pack(params, context) -> ndarray (NECFG,)``: its settings (the kind and
        the initial error are filled in by the caller); ``None`` for a built-in,
        whose packer is in ``quadimpact.packing.estimator_block``.
    step : callable or None
        The compiled step of a plug-in (``None`` for built-ins).
    description : str
        One line for help texts.
    """

    name: str
    kind: int
    params: type[BaseModel]
    pack: Callable[[BaseModel, EstimatorContext], np.ndarray] | None
    step: Callable | None = None
    description: str = ""
    kernel_cache: dict = field(default_factory=dict, compare=False, repr=False)


def _empty(params: BaseModel, ctx: EstimatorContext) -> np.ndarray:
    return np.zeros(ESL.NECFG)


BUILTIN = ("ideal", "complementary", "ekf", "ekf-additive", "nav-ekf")
_REGISTRY: Registry[EstimatorEntry] = Registry(
    "estimator",
    BUILTIN,
    entry_type=EstimatorEntry,
    user_kind=L.EST_USER,
    no_params=_NoParams,
    empty_pack=_empty,
)


def register_estimator(
    name: str,
    step: Callable | None = None,
    *,
    params: type[BaseModel] | None = None,
    pack: Callable[[BaseModel, EstimatorContext], np.ndarray] | None = None,
    kind: int | None = None,
    description: str = "",
    replace: bool = False,
) -> EstimatorEntry:
    """Make an estimator selectable by ``name`` in scenarios, sweeps and the CLI.

    Parameters
    ----------
    name : str
        Its name (letters, digits, ``-`` and ``_``).
    step : callable, optional
        A Numba ``njit`` step ``step(t, dt, meas, ecfg, est)`` (a plug-in,
        ``quadimpact.core.estimators.plugin_estimator``); omit for a built-in
        (then give ``kind``).
    params : pydantic model class, optional
        Its parameters with defaults (default: none).
    pack : callable, optional
        ``pack(params, context) -> ndarray (NECFG,)``; a plug-in's own
        parameters go to ``ecfg[EC_USER : EC_USER + N_USER_ECFG]`` (default: zeros).
    kind : int, optional
        A built-in ``EST_*`` id of the cached kernel.
    description : str, optional
        One line for help texts.
    replace : bool, optional
        Replace an entry of the same name instead of refusing.
    """
    return _REGISTRY.register(
        name, step, params=params, pack=pack, kind=kind, description=description, replace=replace
    )


def unregister_estimator(name: str) -> None:
    """Remove a registered estimator (built-ins cannot be removed)."""
    _REGISTRY.remove(name)


def estimator_names() -> tuple[str, ...]:
    """Names of every registered estimator, built-ins first."""
    return _REGISTRY.names()


def estimator_entry(name: str) -> EstimatorEntry:
    """The registry entry of ``name`` (``InputError`` for an unknown one)."""
    return _REGISTRY.entry(name)


def validate_estimator_params(name: str, values: Mapping[str, Any] | BaseModel | None):
    """The validated parameters of estimator ``name`` (defaults for what is not given)."""
    return _REGISTRY.params(name, values)


def _given_or(value: float | None, sensor: float, floor: float) -> float:
    """A noise or spread the user gave, else the sensor's own, at least ``floor``."""
    return float(value) if value is not None else max(float(sensor), floor)


def _filter_noises(p: Any, ctx: EstimatorContext) -> dict[str, float]:
    """The noises and initial spreads the ``ekf`` and the ``nav-ekf`` share, resolved."""
    imu, mag = ctx.imu, ctx.magnetometer
    grav = math.hypot(imu.accel_noise_m_s2, p.maneuver_accel_m_s2)
    return {
        "gyro_noise_rad_s": _given_or(p.gyro_noise_rad_s, imu.gyro_noise_rad_s, GYRO_NOISE_FLOOR),
        "gyro_bias_walk_rad_s_sqrt_s": _given_or(
            p.gyro_bias_walk_rad_s_sqrt_s, imu.gyro_bias_walk_rad_s_sqrt_s, WALK_FLOOR
        ),
        "accel_noise_m_s2": _given_or(p.accel_noise_m_s2, imu.accel_noise_m_s2, ACCEL_NOISE_FLOOR),
        "gravity_noise_m_s2": _given_or(p.gravity_noise_m_s2, grav, GRAVITY_NOISE_FLOOR),
        "magnetometer_noise": _given_or(
            p.magnetometer_noise, mag.noise if mag else 0.0, MAG_NOISE_FLOOR
        ),
        "initial_attitude_std_deg": _given_or(
            p.initial_attitude_std_deg, p.initial_attitude_error_deg, INITIAL_ATTITUDE_STD_DEG
        ),
        "initial_bias_std_rad_s": _given_or(
            p.initial_bias_std_rad_s, p.initial_bias_error_rad_s, BIAS_STD_FLOOR
        ),
        "initial_velocity_std_m_s": _given_or(
            p.initial_velocity_std_m_s, p.initial_velocity_error_m_s, VELOCITY_STD_FLOOR
        ),
        "initial_position_std_m": _given_or(
            p.initial_position_std_m, p.initial_position_error_m, POSITION_STD_FLOOR
        ),
    }


def _resolve_ekf(p: Any, ctx: EstimatorContext) -> dict[str, float]:
    pose = ctx.pose_sensor
    return {
        **_filter_noises(p, ctx),
        "pose_position_noise_m": _given_or(
            p.pose_position_noise_m, pose.position_noise_m if pose else 0.0, POSITION_NOISE_FLOOR
        ),
        "pose_attitude_noise_deg": _given_or(
            p.pose_attitude_noise_deg,
            pose.attitude_noise_deg if pose else 0.0,
            ATTITUDE_NOISE_FLOOR_DEG,
        ),
    }


def _resolve_nav_ekf(p: Any, ctx: EstimatorContext) -> dict[str, float]:
    baro = ctx.instruments.get("barometer")
    acc0 = ctx.imu.accel_bias_m_s2 if p.initial_bias == "zero" else 0.0
    return {
        **_filter_noises(p, ctx),
        "barometer_noise_m": _given_or(
            p.barometer_noise_m, baro.noise_m if baro else 0.0, BARO_NOISE_FLOOR
        ),
        "barometer_bias_walk_m_sqrt_s": _given_or(
            p.barometer_bias_walk_m_sqrt_s,
            baro.bias_walk_m_sqrt_s if baro else 0.0,
            BARO_WALK_FLOOR,
        ),
        "initial_accel_bias_std_m_s2": _given_or(
            p.initial_accel_bias_std_m_s2, acc0, ACCEL_BIAS_STD_FLOOR
        ),
    }


_RESOLVERS: dict[int, Callable[[Any, EstimatorContext], dict[str, float]]] = {
    L.EST_EKF: _resolve_ekf,
    L.EST_NAV_EKF: _resolve_nav_ekf,
}


def resolve_estimator_params(kind: int, params: BaseModel, ctx: EstimatorContext) -> BaseModel:
    """An estimator's parameters with every ``None`` noise and spread a number.

    The ``ekf``'s and the ``nav-ekf``'s noises left ``None`` take the run's
    sensor's own setting, their initial spreads the initial error's, each at
    least its floor (so that an ideal sensor does not make the covariance
    singular). The only place these defaults are decided; the packers
    (``packing/estimator_block.py``) write the numbers. Other kinds' and
    plug-ins' parameters are returned as they are.

    Parameters
    ----------
    kind : int
        The estimator's ``EST_*`` kind.
    params : pydantic.BaseModel
        Its validated parameters.
    ctx : EstimatorContext
        The run's sensors.
    """
    resolver = _RESOLVERS.get(kind)
    if resolver is None or not isinstance(params, (EkfParams, NavEkfParams)):
        return params
    return params.model_copy(update=resolver(params, ctx))


def settings_text(params: BaseModel) -> str:
    """The parameters as one line ``name=value, ...`` (the summary's ``estimator_settings``)."""
    return ", ".join(f"{k}={v}" for k, v in params.model_dump(mode="json").items())


register_estimator(
    "ideal", kind=L.EST_IDEAL, description="the true state (the default; results as before)"
)
register_estimator(
    "complementary",
    kind=L.EST_COMPLEMENTARY,
    params=ComplementaryParams,
    description="Mahony-type complementary filter with the accelerometer gate",
)
register_estimator(
    "ekf",
    kind=L.EST_EKF,
    params=EkfParams,
    description="multiplicative error-state EKF: attitude, gyro bias (+ velocity, position)",
)
register_estimator(
    "ekf-additive",
    kind=L.EST_EKF_ADDITIVE,
    params=AdditiveEkfParams,
    description="the authors' 7-state EKF on an additive quaternion (their 2016 study)",
)
register_estimator(
    "nav-ekf",
    kind=L.EST_NAV_EKF,
    params=NavEkfParams,
    description="navigation EKF: attitude, velocity, position, IMU biases; baro, range, flow",
)
