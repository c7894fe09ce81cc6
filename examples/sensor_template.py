"""A plug-in sensor component: copy this file to add a sensor of your own.

This one is a variometer: the CM's climb rate (m/s, up positive) with white
noise, sampled with the IMU. A sensor is one module like this one: its slot
blocks (with units), its settings model, its pack function and its compiled
sample function, then one call of ``register_sensor``. A built-in sensor is
the same module in ``src/quadimpact/core/sensors/`` and one line of that
folder's ``registry.py`` instead of the call (``barometer.py`` is one).

Fly it::

    import examples.sensor_template  # registers "variometer"
    from quadimpact import simulate
    from quadimpact.inputs.scenarios import scenario_from_dict

    r = simulate(scenario_from_dict({"kind": "flight", "controller": "cascade-pid",
                                     "instruments": {"variometer": {"noise_m_s": 0.05}}}))
    r.imu["variometer_climb_m_s"]

A run naming a plug-in sensor compiles a loop of its own around it (once per
process). Its noise is drawn from the run's seed, on a stream of its own.

Studies and the benchmark name presets of sensors: this file registers
``variometer-impact`` (the impact IMU and the variometer), so that::

    quadimpact recovery --plugin sensor_template.py --sensors variometer-impact ...
    quadimpact benchmark --quick --plugin sensor_template.py --sensors ideal,variometer-impact
"""

from __future__ import annotations

from numba import njit
from pydantic import BaseModel, ConfigDict, Field

from quadimpact.core.layout import X_QUAT, X_VEL
from quadimpact.core.sensors.component import SensorComponent, Slot, offsets
from quadimpact.core.sensors.registry import register_sensor
from quadimpact.inputs.sensors import register_sensor_preset


class VariometerSettings(BaseModel):
    """``[instruments.variometer]`` of a scenario file."""

    model_config = ConfigDict(extra="forbid", frozen=True)
    noise_m_s: float = Field(0.05, ge=0, le=10, description="White-noise std, m/s.")


CONFIG = (Slot("on"), Slot("noise_m_s", 1, "m/s"))
MEASUREMENT = (Slot("climb_m_s", 1, "m/s"), Slot("t_s", 1, "s"))
NOISE = (Slot("white"),)
RECORD = (Slot("climb_m_s", 1, "m/s"), Slot("climb_true_m_s", 1, "m/s"))

C_ON, C_NOISE = offsets(CONFIG)["on"], offsets(CONFIG)["noise_m_s"]
M_CLIMB, M_T = offsets(MEASUREMENT)["climb_m_s"], offsets(MEASUREMENT)["t_s"]
R_CLIMB, R_TRUE = offsets(RECORD)["climb_m_s"], offsets(RECORD)["climb_true_m_s"]


def pack(settings: VariometerSettings, context: object) -> list[float]:
    """The config block: on, noise (m/s)."""
    return [1.0, float(settings.noise_m_s)]


@njit
def sample(t, x, xdot, C, veh, cfg, st, meas, noise, rec):
    """The climb rate ``-(C v)_z`` (m/s) at the IMU sample ``t`` (s)."""
    if cfg[C_ON] < 0.5:
        return
    q0, q1, q2, q3 = x[X_QUAT], x[X_QUAT + 1], x[X_QUAT + 2], x[X_QUAT + 3]
    # the third row of the body-to-inertial rotation, times the body velocity
    vz = (
        2.0 * (q1 * q3 - q0 * q2) * x[X_VEL]
        + 2.0 * (q2 * q3 + q0 * q1) * x[X_VEL + 1]
        + (q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3) * x[X_VEL + 2]
    )
    climb = -vz
    y = climb + (cfg[C_NOISE] * noise[0] if noise.shape[0] > 0 else 0.0)
    meas[M_CLIMB] = y
    meas[M_T] = t
    if rec.shape[0] > 0:
        rec[R_CLIMB] = y
        rec[R_TRUE] = climb


SENSOR = SensorComponent(
    name="variometer",
    settings=VariometerSettings,
    pack=pack,
    sample=sample,
    config=CONFIG,
    measurement=MEASUREMENT,
    noise=NOISE,
    record=RECORD,
    doc="climb rate with white noise",
)
register_sensor(SENSOR)
# a preset of sensors that holds it, for the studies and the benchmark (after the sensor)
register_sensor_preset("variometer-impact", {"imu": "impact", "instruments": {"variometer": {}}})
