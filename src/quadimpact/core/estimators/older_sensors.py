"""Where the built-in filters read the magnetometer and the pose sensor.

Both are sensor components (``core/sensors/magnetometer.py``, ``pose.py``):
their measurement and config slots sit in the tails of ``meas`` and
``scfg``, at addresses the registry computes from the components' declared
sizes (``core.sensors.registry``), as the navigation filter reads the
barometer's. These are those addresses, for the complementary filter and
the EKFs.
"""

from quadimpact.core.sensors.registry import config_address, measurement_address

__all__ = ["MAG", "MAG_FIELD_I", "MAG_T", "POSE", "POSE_ATT", "POSE_T"]

MAG = measurement_address("magnetometer", "field")  # meas: the sample, body FRD (unit field)
MAG_T = measurement_address("magnetometer", "t_s")  # meas: its time, s (NaN: none)
MAG_FIELD_I = config_address("magnetometer", "field")  # scfg: the Earth field m_I, NED
POSE = measurement_address("pose_sensor", "pose")  # meas: position (NED, m), quaternion
POSE_T = measurement_address("pose_sensor", "t_s")  # meas: the sample it arrived at, s
POSE_ATT = config_address("pose_sensor", "attitude")  # scfg: 1 when it measures attitude
