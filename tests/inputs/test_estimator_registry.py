"""The estimator registry as an extension point: a user's compiled estimator, by name.

A test estimator registered here through ``register_estimator(name, step=...,
params=..., pack=...)`` alone is selected by name in a scenario; the run loop
calls its step by address (compiled alone, once per process: ``core/plugin_call.py``),
and the controller and the detector read its estimate. The
plug-in integrates the gyro (minus a constant bias given as a parameter) and
never corrects: on an impact trial with an ideal IMU it tracks the truth to
integration accuracy, and with a wrong bias it drifts at that rate.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit
from pydantic import BaseModel, ConfigDict, Field

from quadimpact import simulate
from quadimpact.core import estimator_slots as ESL
from quadimpact.core.sensors import measurement_slots as MSS
from quadimpact.errors import InputError
from quadimpact.inputs.estimators import (
    estimator_names,
    register_estimator,
    unregister_estimator,
)
from quadimpact.inputs.scenarios import ImpactTrial, scenario_from_dict

NAME = "test-gyro-only"


class GyroOnlyParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    bias_rad_s: float = Field(0.0, description="Bias subtracted from the gyro's z axis, rad/s.")


def _pack(params: GyroOnlyParams, ctx) -> np.ndarray:
    e = np.zeros(ESL.NECFG)
    e[ESL.EC_USER] = params.bias_rad_s
    return e


@njit
def gyro_only(t, dt, meas, ecfg, est):  # pragma: no cover - compiled
    w0 = meas[MSS.MS_IMU_W]
    w1 = meas[MSS.MS_IMU_W + 1]
    w2 = meas[MSS.MS_IMU_W + 2] - ecfg[ESL.EC_USER]
    est[ESL.ES_W] = w0
    est[ESL.ES_W + 1] = w1
    est[ESL.ES_W + 2] = w2
    a = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2) * dt
    if a == 0.0:
        return
    s = math.sin(0.5 * a) / a * dt
    c = math.cos(0.5 * a)
    q0, q1, q2, q3 = est[ESL.ES_Q], est[ESL.ES_Q + 1], est[ESL.ES_Q + 2], est[ESL.ES_Q + 3]
    bx, by, bz = s * w0, s * w1, s * w2
    est[ESL.ES_Q] = q0 * c - q1 * bx - q2 * by - q3 * bz
    est[ESL.ES_Q + 1] = q0 * bx + q1 * c + q2 * bz - q3 * by
    est[ESL.ES_Q + 2] = q0 * by - q1 * bz + q2 * c + q3 * bx
    est[ESL.ES_Q + 3] = q0 * bz + q1 * by - q2 * bx + q3 * c


@pytest.fixture(scope="module")
def registered():
    register_estimator(NAME, step=gyro_only, params=GyroOnlyParams, pack=_pack,
                       description="integrates the gyro", replace=True)  # fmt: skip
    yield NAME
    unregister_estimator(NAME)


TRIAL = {"roll_deg": 5.0, "pitch_deg": -20.0, "yaw_deg": 10.0, "speed_m_s": 1.2}


def test_a_registered_estimator_runs_by_name_and_is_read(registered):
    assert registered in estimator_names()
    truth = simulate(ImpactTrial(**TRIAL, imu={"position": "cm"})).summary
    r = simulate(ImpactTrial(**TRIAL, imu={"position": "cm"}, estimator=registered))
    s = r.summary
    assert s["estimator"] == registered and "bias_rad_s=0.0" in s["estimator_settings"]
    # a rate held over each 5-ms sample: exact in the slow approach, about a degree through
    # the impact's angular accelerations
    assert s["est_attitude_max_pre_deg"] < 1e-3 and s["est_attitude_max_crash_deg"] < 3.0
    assert s["recovered"] == truth["recovered"]
    drift = simulate(ImpactTrial(**TRIAL, estimator=registered, final_time_s=1.0,
                                 estimator_params={"bias_rad_s": 0.05})).imu  # fmt: skip
    yaw_err = drift["attitude_error_deg"].iloc[-1]
    assert yaw_err == pytest.approx(math.degrees(0.05 * drift["t_s"].iloc[-1]), rel=0.3)


def test_unknown_estimators_and_parameters_are_refused():
    with pytest.raises(InputError, match="estimator.*did you mean 'ekf'"):
        scenario_from_dict({"kind": "impact-trial", "estimator": "ekff"})
    with pytest.raises(InputError, match="gate_m_s2"):
        scenario_from_dict({"kind": "impact-trial", "estimator": "ekf",
                            "estimator_params": {"gate_m_s2": -1.0}})  # fmt: skip
    with pytest.raises(ValueError, match="built in"):
        unregister_estimator("ekf")


def test_a_plain_python_estimator_step_is_refused_when_registered():
    """The rule of the controllers: the compiled loop calls the step, so a plain Python
    function is refused at registration, not when a run starts."""

    def step(t, dt, meas, ecfg, est):  # not compiled
        return None

    with pytest.raises(TypeError, match="estimator 'plain-python': step must be compiled"):
        register_estimator("plain-python", step=step)
    with pytest.raises(ValueError, match="letters, digits"):
        register_estimator("no spaces", kind=0)
    with pytest.raises(ValueError, match="already registered"):
        register_estimator("ekf", kind=0)


def test_a_sensor_preset_fills_what_the_scenario_leaves():
    t = ImpactTrial(sensors="indoor")
    assert t.imu.preset == "impact" and t.magnetometer is not None and t.pose_sensor is not None
    mine = ImpactTrial(sensors="indoor", imu="noisy", pose_sensor=None)
    assert mine.imu.preset == "noisy" and mine.pose_sensor is None
    assert mine.magnetometer is not None
