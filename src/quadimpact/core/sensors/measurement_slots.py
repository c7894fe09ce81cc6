"""The measurement record ``meas``: its slots, declared with their owner (no compiled code).

``meas`` is what a controller sees at a control tick (``MS_*``,
:data:`NMEAS` numbers): the state estimate, which ``core/sensors/measurement.py``
writes (``measure``), the latest IMU sample, the impact detector's
verdict and wall-normal estimate, the estimated rates and bias, and a
plug-in sensor's readings. The sensor components' measurements follow
at addresses the registry computes (``core/sensors/registry.py``). The
declaration lives in this module, which imports no compiled code, so that
``core/records.py`` can size ``meas`` without an import cycle. Every slot
keeps the offset and the name it had in ``core/layout.py``.
"""

from quadimpact.core.block import Block
from quadimpact.core.layout import NX

# ---- measurement record meas (NMEAS): what a controller sees at a tick
# (core/sensors/measurement.py writes the estimate; the IMU and the detector
# their fields as the samples are taken)
_ms = Block("meas", "MS_")
MS_X = _ms.slot("MS_X", NX)  # state estimate (the ideal estimator: the true state at the tick)
MS_T = _ms.slot("MS_T")  # s, time of the tick
MS_IMU_T = _ms.slot("MS_IMU_T")  # s, time of the latest IMU sample (NaN: none yet)
MS_IMU_F = _ms.slot("MS_IMU_F", 3)  # measured specific force, body FRD, m/s^2
MS_IMU_W = _ms.slot("MS_IMU_W", 3)  # measured angular velocity, body FRD, rad/s
MS_DETECTED = _ms.slot("MS_DETECTED")  # 1 once an impact has been detected
MS_T_DETECT = _ms.slot("MS_T_DETECT")  # s, time of the detecting sample (NaN: none)
MS_NORMAL = _ms.slot("MS_NORMAL", 3)  # wall-normal estimate at detection, inertial, unit
MS_W_HAT = _ms.slot("MS_W_HAT", 3)  # estimated body rates (ideal: the gyro as measured), rad/s
MS_BIAS_HAT = _ms.slot("MS_BIAS_HAT", 3)  # estimated gyro bias, rad/s
N_USER_MEAS = 8
MS_USER = _ms.slot(
    "MS_USER", N_USER_MEAS
)  # a plug-in sensor's readings (core/kernel.py, make_kernel)
NMEAS = _ms.end("NMEAS")
