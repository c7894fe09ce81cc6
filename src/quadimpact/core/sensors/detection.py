"""Impact detection from the IMU samples alone, and the wall-normal estimate.

Never reads the simulator's contact state: it sees what the measurement
record holds after each IMU sample (``imu.imu_sample``).

Rule (the authors'): an impact is detected at the first sample whose
horizontal specific force reaches a threshold (default 0.5 g), measured in
body axes ``|(f_x, f_y)|`` or, as an option, in world axes ``|(C f)_XY|``;
optionally only after N consecutive samples at or above it. In free flight
without drag the body-horizontal specific force at the CM is exactly zero, so
the rule responds to contact (and to lever-arm terms when the IMU is off the
CM, and to noise).

Wall-normal estimate at detection: the horizontal part of the measured
inertial acceleration ``C f + g e_Z`` (``C`` the estimated attitude),
normalised. It points roughly away from the obstacle; the thrust's horizontal
part is in it too.

Recorded: the first detection's time, the state there and the normal
(``ST_T_DETECT``, ``ST_DETECT_X``, ``ST_DETECT_NORMAL``), and the number of
times the condition rose (``ST_N_DETECTIONS``: rising edges of "N consecutive
samples at or above the threshold"), from which a false-detection rate on
contact-free flight is measured.
"""

import math

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.layout import (
    N_DETECTOR_CFG,
    NX,
    ST_DETECT_NORMAL,
    ST_DETECT_X,
    ST_N_DETECTIONS,
    ST_T_DETECT,
    Block,
)
from quadimpact.core.records import Data, Model, Output
from quadimpact.core.sensors.imu_slots import (
    I_DETECTOR,
    SC_DETECTOR,
    SS_DETECTOR,
    SS_N,
)
from quadimpact.core.sensors.measurement_slots import MS_DETECTED, MS_IMU_F, MS_NORMAL, MS_T_DETECT

# ---- its blocks, in the regions core/sensors/imu_slots.py keeps for it in scfg, sst and imu
_cfg = Block("scfg.detector", "SC_DET_", start=SC_DETECTOR, capacity=SC_DETECTOR + N_DETECTOR_CFG)
SC_DET_THRESHOLD = _cfg.slot("SC_DET_THRESHOLD")  # m/s^2, detecting specific force (<= 0: off)
SC_DET_WORLD = _cfg.slot("SC_DET_WORLD")  # 1: world-horizontal |(C f)_XY|, else body |(f_x, f_y)|
SC_DET_PERSIST = _cfg.slot("SC_DET_PERSIST")  # consecutive samples at or above the threshold
_st = Block("sst.detector", "SS_", start=SS_DETECTOR, capacity=SS_DETECTOR + 1)
SS_COUNT = _st.slot("SS_COUNT")  # consecutive samples at or above the detection threshold
_rec = Block("imu.detector", "I_", start=I_DETECTOR, capacity=I_DETECTOR + 1)
I_HORIZONTAL = _rec.slot("I_HORIZONTAL")  # the detector's horizontal measure, m/s^2


@compiled
def detect(t: float, x: np.ndarray, C_hat: np.ndarray, m: Model, d: Data, o: Output) -> None:
    """Apply the detection rule to the sample just taken at time ``t`` (s).

    ``C_hat`` is the estimated attitude at the sample (the estimator's, never
    the simulator's truth unless the estimator is ideal); ``x``, the true
    state, is only recorded (``ST_DETECT_X``) for the analysis.
    """
    C = C_hat
    scfg = m.scfg
    sst = d.sst
    meas = d.meas
    imu_out = o.imu
    stats = o.stats
    fx = meas[MS_IMU_F]
    fy = meas[MS_IMU_F + 1]
    fz = meas[MS_IMU_F + 2]
    # inertial components of the measured specific force
    ix = C[0, 0] * fx + C[0, 1] * fy + C[0, 2] * fz
    iy = C[1, 0] * fx + C[1, 1] * fy + C[1, 2] * fz
    if scfg[SC_DET_WORLD] > 0.5:
        hm = math.sqrt(ix * ix + iy * iy)
    else:
        hm = math.sqrt(fx * fx + fy * fy)
    i = int(sst[SS_N]) - 1
    if 0 <= i < imu_out.shape[0]:
        imu_out[i, I_HORIZONTAL] = hm
    threshold = scfg[SC_DET_THRESHOLD]
    if threshold <= 0.0:
        return
    if hm >= threshold:
        sst[SS_COUNT] += 1.0
    else:
        sst[SS_COUNT] = 0.0
    if sst[SS_COUNT] != max(1.0, scfg[SC_DET_PERSIST]):
        return
    stats[ST_N_DETECTIONS] += 1.0
    if meas[MS_DETECTED] > 0.5:
        return
    # the first detection: time, state and the wall-normal estimate
    meas[MS_DETECTED] = 1.0
    meas[MS_T_DETECT] = t
    stats[ST_T_DETECT] = t
    for k in range(NX):
        stats[ST_DETECT_X + k] = x[k]
    # horizontal part of the inertial acceleration C f + g e_Z: gravity is vertical, so
    # it is the horizontal part of C f
    n = math.sqrt(ix * ix + iy * iy)
    nx = ix / n if n > 0.0 else 0.0
    ny = iy / n if n > 0.0 else 0.0
    meas[MS_NORMAL] = nx
    meas[MS_NORMAL + 1] = ny
    meas[MS_NORMAL + 2] = 0.0
    stats[ST_DETECT_NORMAL] = nx
    stats[ST_DETECT_NORMAL + 1] = ny
    stats[ST_DETECT_NORMAL + 2] = 0.0
