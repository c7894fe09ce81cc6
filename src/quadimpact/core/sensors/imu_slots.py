"""The IMU's slots: its configuration ``scfg``, its state ``sst``, its draws and its rows.

``core/sensors/imu.py`` samples the IMU on the dense output. It reads its
configuration from ``scfg`` (``SC_*``, :data:`NSCFG` numbers: rate, mounting,
noise, bias, saturation, filter, the impact disturbance, the detector's
slots and the sensor components' tail sizes), keeps its state in ``sst``
(``SS_*``, :data:`NSST` numbers: the sample count and the next sample's
time, which schedule every sample, the filter's state, the bias walk, and
the detector's slot), takes its impact noise and bias-walk increments from
its row of ``snoise`` (``SN_*``, :data:`NSN` columns, with the frozen
columns of the magnetometer and the pose sensor) and writes one row of
``imu`` per sample (``I_*``, :data:`NIMU` columns: the measured and true
signals, the detector's column, the estimate after the sample and its
errors). The declaration lives in this module, which imports no compiled
code, so that ``core/records.py`` can size the ``imu`` table and the packer
can fill ``scfg`` and draw ``snoise`` without loading Numba. Every slot
keeps the offset and the name it had in ``core/layout.py``.
"""

from quadimpact.core.block import Block
from quadimpact.core.layout import N_DETECTOR_CFG

# ---- sensors scfg (NSCFG): the IMU and the impact detector; noise, bias,
# saturation and filtering are off when their slots are 0
_scfg = Block("scfg", "SC_")
SC_RATE = _scfg.slot("SC_RATE")  # Hz, IMU sample rate (0: no IMU, no detection)
SC_POS = _scfg.slot("SC_POS", 3)  # IMU position from the CM, body FRD, m
SC_NOISE_F = _scfg.slot("SC_NOISE_F")  # accelerometer white-noise std per axis, m/s^2
SC_NOISE_W = _scfg.slot("SC_NOISE_W")  # gyro white-noise std per axis, rad/s
SC_BIAS = _scfg.slot("SC_BIAS", 6)  # constant biases (f_x, f_y, f_z, w_x, w_y, w_z)
SC_RANGE_F = _scfg.slot("SC_RANGE_F")  # m/s^2, accelerometer range (<= 0: none)
SC_RANGE_W = _scfg.slot("SC_RANGE_W")  # rad/s, gyro range (<= 0: none)
SC_FILTER = _scfg.slot("SC_FILTER")  # FILTER_*
SC_FILTER_PARAM = _scfg.slot("SC_FILTER_PARAM")  # first-order: tau, s; moving average: window
SC_DETECTOR = _scfg.slot("SC_DETECTOR", N_DETECTOR_CFG)  # the detector's (sensors/detection.py)
# the IMU's impact disturbance: from each contact onset t_c, extra white noise of std
# a0 exp(-(t - t_c)/tau) (accelerometer) and g0 exp(-(t - t_c)/tau) (gyro); off when tau <= 0
SC_IMPACT_F = _scfg.slot("SC_IMPACT_F")  # a0, m/s^2
SC_IMPACT_W = _scfg.slot("SC_IMPACT_W")  # g0, rad/s
SC_IMPACT_TAU = _scfg.slot("SC_IMPACT_TAU")  # tau, s (<= 0: off)
SC_BIAS_WALK = _scfg.slot("SC_BIAS_WALK")  # gyro bias random walk, rad/s/sqrt(s) (0: off)
SC_IMPACT_REPLACE = _scfg.slot("SC_IMPACT_REPLACE")  # 1: the impact noise replaces the nominal
#   noise while it is the larger, restarting at each onset (the authors' model); 0: added
# the sensor components' tails (core/sensors/registry.py): their sizes in this run's arrays
SC_TAIL_ST = _scfg.slot("SC_TAIL_ST")  # numbers after NSST in sst
SC_TAIL_MEAS = _scfg.slot("SC_TAIL_MEAS")  # numbers after NMEAS in meas
SC_TAIL_REC = _scfg.slot("SC_TAIL_REC")  # columns after NIMU in each imu row
NSCFG = _scfg.end("NSCFG")

# ---- IMU samples imu (n_imu, NIMU)
_imu = Block("imu", "I_")
I_T = _imu.slot("I_T")  # s
I_F = _imu.slot("I_F", 3)  # measured specific force, body FRD, m/s^2
I_W = _imu.slot("I_W", 3)  # measured angular velocity, body FRD, rad/s
I_F_TRUE = _imu.slot("I_F_TRUE", 3)  # true specific force at the IMU position, m/s^2
I_W_TRUE = _imu.slot("I_W_TRUE", 3)  # true angular velocity, rad/s
I_DETECTOR = _imu.slot("I_DETECTOR")  # the detector's column (core/sensors/detection.py)
I_Q_HAT = _imu.slot("I_Q_HAT", 4)  # attitude estimate after this sample
I_BIAS_HAT = _imu.slot("I_BIAS_HAT", 3)  # gyro bias estimate, rad/s
I_VEL_HAT = _imu.slot("I_VEL_HAT", 3)  # velocity estimate, inertial, m/s
I_POS_HAT = _imu.slot("I_POS_HAT", 3)  # position estimate, inertial, m
I_BIAS_TRUE = _imu.slot("I_BIAS_TRUE", 3)  # the gyro's true bias (constant + walk), rad/s
I_ERR = _imu.slot("I_ERR", 4)  # errors: attitude deg, velocity m/s, bias rad/s, position m
NIMU = _imu.end("NIMU")

MAX_AVERAGE_WINDOW = 64  # samples: the moving-average filter's longest window

# ---- sensor state sst (NSST): the IMU's schedule, filter and bias walk, the detector's slot
_sst = Block("sst", "SS_")
SS_N = _sst.slot("SS_N")  # samples taken
SS_NEXT_T = _sst.slot("SS_NEXT_T")  # s, time of the next sample
SS_DETECTOR = _sst.slot("SS_DETECTOR")  # the detector's state (core/sensors/detection.py)
SS_FILT = _sst.slot("SS_FILT", 6)  # low-pass state (first-order) / running sum (moving average)
SS_RING = _sst.slot("SS_RING", 6 * MAX_AVERAGE_WINDOW)  # moving-average window
SS_WALK = _sst.slot("SS_WALK", 3)  # gyro bias random walk so far, rad/s
NSST = _sst.end("NSST")

# ---- the added sensors' standard normal draws snoise (n_imu, NSN): row i for IMU sample i.
# Frozen for good (every seeded run stays bit for bit): the magnetometer and the pose sensor,
# now sensor components (core/sensors/magnetometer.py, pose.py), read their columns as a
# legacy noise stream (LegacyColumns); a new sensor draws from a stream of its own (cnoise)
_sn = Block("snoise", "SN_")
SN_IMPACT = _sn.slot("SN_IMPACT", 6)  # impact disturbance (f_x, f_y, f_z, w_x, w_y, w_z)
SN_WALK = _sn.slot("SN_WALK", 3)  # gyro bias random-walk increments
SN_MAG = _sn.slot("SN_MAG", 3)  # magnetometer noise
SN_POSE = _sn.slot("SN_POSE", 6)  # pose sensor: position (3), attitude rotation vector (3)
NSN = _sn.end("NSN")
