"""The impact detector on hand-made IMU samples (it never sees the contact state)."""

from __future__ import annotations

import numpy as np

from quadimpact.core import controller_slots as CTL
from quadimpact.core import feature_slots as FS
from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.geometry import pair_table
from quadimpact.core.records import model, new_data, new_output
from quadimpact.core.sensors import detection as DET
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.core.sensors import measurement_slots as MSS
from quadimpact.core.sensors.detection import detect
from quadimpact.rotations import euler_zyx_to_quat, quat_to_matrix

G = 9.81


def _feed(samples, *, threshold=0.5 * G, persist=1, world=False, yaw=0.0, pitch=0.0):
    """Run the detector over specific-force samples (body, m/s^2) at 200 Hz."""
    scfg = np.zeros(IMS.NSCFG)
    scfg[IMS.SC_RATE] = 200.0
    scfg[DET.SC_DET_THRESHOLD] = threshold
    scfg[DET.SC_DET_PERSIST] = persist
    scfg[DET.SC_DET_WORLD] = 1.0 if world else 0.0
    x = np.zeros(L.NX)
    x[L.X_QUAT : L.X_QUAT + 4] = euler_zyx_to_quat(0.0, pitch, yaw)
    C = np.ascontiguousarray(quat_to_matrix(x[L.X_QUAT : L.X_QUAT + 4]))
    veh = np.zeros(VS.NVEH)
    veh[VS.V_GRAVITY] = G
    feat = np.zeros((0, FS.NFEAT))
    shapes = np.zeros((0, SHP.NSHAPE))
    m = model(x0=x, t0=0.0, tf=1.0, veh=veh, feat=feat, shapes=shapes,
              pairs=pair_table(feat, shapes), opts=np.zeros(L.NOPT), ctrl=np.zeros(CTL.NCTRL),
              t_out=np.zeros(0), scfg=scfg)  # fmt: skip
    d = new_data(m)
    o = new_output(m, len(samples), 0)
    meas, sst, stats = d.meas, d.sst, o.stats
    meas[MSS.MS_T_DETECT] = np.nan
    stats[L.ST_T_DETECT] = np.nan
    for i, f in enumerate(samples):
        meas[MSS.MS_IMU_F : MSS.MS_IMU_F + 3] = f
        sst[IMS.SS_N] = i + 1
        detect(i * 0.005, x, C, m, d, o)
    imu_out = o.imu
    return meas, stats, imu_out


def test_quiet_samples_never_detect():
    meas, stats, imu = _feed([(0.0, 0.0, -G)] * 50 + [(3.0, 3.0, -G)] * 5)  # |f_xy| = 4.24 < 4.905
    assert meas[MSS.MS_DETECTED] == 0.0
    assert np.isnan(stats[L.ST_T_DETECT])
    assert stats[L.ST_N_DETECTIONS] == 0
    np.testing.assert_allclose(imu[-1, DET.I_HORIZONTAL], np.hypot(3.0, 3.0))


def test_first_sample_at_threshold_detects_and_estimates_the_normal():
    samples = [(0.0, 0.0, -G)] * 10 + [(-0.5 * G, 0.0, -G), (-20.0, 1.0, -G)]
    meas, stats, _ = _feed(samples)
    assert meas[MSS.MS_DETECTED] == 1.0
    assert stats[L.ST_T_DETECT] == 10 * 0.005  # the sample that reaches the threshold
    np.testing.assert_allclose(stats[L.ST_DETECT_NORMAL : L.ST_DETECT_NORMAL + 3], (-1, 0, 0))


def test_persistence_counts_consecutive_samples_and_rising_edges():
    hit = (-6.0, 0.0, -G)
    quiet = (0.0, 0.0, -G)
    meas, stats, _ = _feed([hit, quiet, hit, hit, quiet, hit, hit, hit, quiet], persist=2)
    assert stats[L.ST_T_DETECT] == 3 * 0.005  # second of two consecutive samples
    assert stats[L.ST_N_DETECTIONS] == 2  # samples 2-3 and 5-7 each count once


def test_world_horizontal_variant_and_the_normal_in_inertial_axes():
    # pitched up 30 deg and yawed 90 deg: a body specific force along -z_B (thrust) has a
    # horizontal world part; the body-horizontal rule sees none
    f = (0.0, 0.0, -12.0)
    meas_b, _, _ = _feed([f], pitch=np.radians(30), yaw=np.radians(90))
    assert meas_b[MSS.MS_DETECTED] == 0.0
    meas_w, stats, _ = _feed([f], world=True, pitch=np.radians(30), yaw=np.radians(90))
    assert meas_w[MSS.MS_DETECTED] == 1.0
    n = stats[L.ST_DETECT_NORMAL : L.ST_DETECT_NORMAL + 3]
    assert abs(np.linalg.norm(n) - 1.0) < 1e-12 and n[2] == 0.0
    # body -z tilted back by the pitch, then yawed to +Y: the horizontal part points to -Y
    np.testing.assert_allclose(n, (0.0, -1.0, 0.0), atol=1e-12)
