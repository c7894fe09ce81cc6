"""Frame conversions: quaternion <-> rotation matrix <-> ZYX Euler (docs/MODEL.md section 1)."""

import numpy as np
import pytest

from quadimpact.rotations import (
    GIMBAL_LOCK_COS,
    body_to_inertial,
    euler_zyx_to_quat,
    inclination_deg,
    matrix_to_euler_zyx_deg,
    matrix_to_quat,
    matrix_to_rotvec,
    quat_to_euler_zyx,
    quat_to_matrix,
    quat_xyzw_to_matrix,
    wrap_angle_deg,
    wrap_angle_rad,
)

D = np.pi / 180.0


def rx(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def ry(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rz(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def test_identity_quaternion_is_identity_matrix() -> None:
    c = quat_to_matrix(np.array([[1.0, 0.0, 0.0, 0.0]]))
    assert c.shape == (1, 3, 3)
    np.testing.assert_allclose(c[0], np.eye(3), atol=1e-15)


def test_yaw_90_maps_body_x_to_inertial_y() -> None:
    q = euler_zyx_to_quat(0.0, 0.0, 90 * D)
    np.testing.assert_allclose(body_to_inertial(q, [1.0, 0.0, 0.0]), [0.0, 1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(body_to_inertial(q, [0.0, 1.0, 0.0]), [-1.0, 0.0, 0.0], atol=1e-15)


def test_negative_pitch_tilts_body_z_toward_minus_x() -> None:
    # Inclination 15 deg toward the wall (+X) at psi = 0 is pitch -15 deg: the body
    # z axis (down) leans to -X, so the thrust (-z_B) has a +X component.
    q = euler_zyx_to_quat(0.0, -15 * D, 0.0)
    z_i = body_to_inertial(q, [0.0, 0.0, 1.0])
    np.testing.assert_allclose(z_i, [-np.sin(15 * D), 0.0, np.cos(15 * D)], atol=1e-15)
    thrust_dir = body_to_inertial(q, [0.0, 0.0, -1.0])
    assert thrust_dir[0] > 0.25


def test_positive_roll_lowers_right_side() -> None:
    # Roll +30 deg about x (FRD): body y (right) gains a +Z (down) component.
    q = euler_zyx_to_quat(30 * D, 0.0, 0.0)
    np.testing.assert_allclose(
        body_to_inertial(q, [0.0, 1.0, 0.0]), [0.0, np.cos(30 * D), np.sin(30 * D)], atol=1e-15
    )


def test_matrix_matches_zyx_product() -> None:
    rng = np.random.default_rng(1)
    roll = rng.uniform(-np.pi, np.pi, 50)
    pitch = rng.uniform(-1.5, 1.5, 50)
    yaw = rng.uniform(-np.pi, np.pi, 50)
    c = quat_to_matrix(euler_zyx_to_quat(roll, pitch, yaw))
    for k in range(50):
        expected = rz(yaw[k]) @ ry(pitch[k]) @ rx(roll[k])
        np.testing.assert_allclose(c[k], expected, atol=1e-14)


def test_euler_quaternion_round_trip() -> None:
    rng = np.random.default_rng(2)
    roll = rng.uniform(-np.pi, np.pi, 200)
    pitch = rng.uniform(-np.pi / 2 + 1e-3, np.pi / 2 - 1e-3, 200)
    yaw = rng.uniform(-np.pi, np.pi, 200)
    r2, p2, y2 = quat_to_euler_zyx(euler_zyx_to_quat(roll, pitch, yaw))
    np.testing.assert_allclose(wrap_angle_rad(r2 - roll), 0.0, atol=1e-9)
    np.testing.assert_allclose(p2, pitch, atol=1e-12)
    np.testing.assert_allclose(wrap_angle_rad(y2 - yaw), 0.0, atol=1e-9)


def test_quaternion_euler_round_trip_preserves_rotation() -> None:
    rng = np.random.default_rng(3)
    q = rng.normal(size=(100, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q2 = euler_zyx_to_quat(*quat_to_euler_zyx(q))
    # Same rotation: q2 = +-q.
    np.testing.assert_allclose(np.abs(np.sum(q * q2, axis=1)), 1.0, atol=1e-12)


def test_known_euler_angles() -> None:
    roll, pitch, yaw = quat_to_euler_zyx(euler_zyx_to_quat(10 * D, -15 * D, 45 * D))
    assert float(roll) == pytest.approx(10 * D, abs=1e-14)
    assert float(pitch) == pytest.approx(-15 * D, abs=1e-14)
    assert float(yaw) == pytest.approx(45 * D, abs=1e-14)


def test_unnormalised_quaternion_is_normalised() -> None:
    q = 3.0 * euler_zyx_to_quat(0.0, 0.0, 90 * D)
    c = quat_to_matrix(q)
    np.testing.assert_allclose(c @ c.T, np.eye(3), atol=1e-14)
    assert float(quat_to_euler_zyx(q)[2]) == pytest.approx(np.pi / 2, abs=1e-14)


@pytest.mark.parametrize("pitch_deg", [90.0, -90.0])
def test_gimbal_lock_is_finite_and_consistent(pitch_deg: float) -> None:
    q = euler_zyx_to_quat(20 * D, pitch_deg * D, 50 * D)
    roll, pitch, yaw = quat_to_euler_zyx(q)
    assert np.all(np.isfinite([roll, pitch, yaw]))
    assert float(pitch) == pytest.approx(pitch_deg * D, abs=1e-7)
    # Whatever split of roll/yaw is reported, it must represent the same rotation.
    np.testing.assert_allclose(
        quat_to_matrix(euler_zyx_to_quat(roll, pitch, yaw)), quat_to_matrix(q), atol=1e-7
    )


def test_slightly_denormal_quaternion_near_lock_does_not_nan() -> None:
    # Rounding can push |C31| a hair above 1: pitch must stay finite (no asin domain error).
    q = np.array([np.sqrt(0.5), 0.0, np.sqrt(0.5) * (1 + 1e-16), 0.0])
    roll, pitch, yaw = quat_to_euler_zyx(q)
    assert np.isfinite(pitch) and float(pitch) == pytest.approx(np.pi / 2, abs=1e-7)


def test_yaw_wrapped_to_half_open_interval() -> None:
    _, _, yaw = quat_to_euler_zyx(euler_zyx_to_quat(0.0, 0.0, np.array([np.pi, -np.pi, 3.5])))
    np.testing.assert_allclose(yaw, [np.pi, np.pi, 3.5 - 2 * np.pi], atol=1e-12)
    assert np.all(yaw > -np.pi)


def test_body_to_inertial_batched() -> None:
    q = euler_zyx_to_quat(np.zeros(3), np.zeros(3), np.array([0.0, 90 * D, 180 * D]))
    v = np.tile([1.0, 0.0, 0.0], (3, 1))
    np.testing.assert_allclose(
        body_to_inertial(q, v), [[1, 0, 0], [0, 1, 0], [-1, 0, 0]], atol=1e-15
    )


# ------------------------------------------------------- matrix helpers (flight logs)
def _random_quats(n: int = 50) -> np.ndarray:
    q = np.random.default_rng(3).normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def test_ros_order_quaternion_is_the_same_rotation() -> None:
    q = _random_quats()
    ros = q[:, [1, 2, 3, 0]]  # (x, y, z, w)
    np.testing.assert_allclose(quat_xyzw_to_matrix(ros), quat_to_matrix(q), atol=1e-15)


def test_matrix_to_quat_round_trip_and_sign_continuity() -> None:
    q = _random_quats()
    back = matrix_to_quat(quat_to_matrix(q))
    np.testing.assert_allclose(quat_to_matrix(back), quat_to_matrix(q), atol=1e-12)
    assert back[0, 0] >= 0 and np.all(np.sum(back[1:] * back[:-1], axis=1) >= 0)


def test_matrix_euler_and_inclination_agree_with_the_quaternion_forms() -> None:
    q = _random_quats()
    C = quat_to_matrix(q)
    roll, pitch, yaw = matrix_to_euler_zyx_deg(C)
    r, p, y = quat_to_euler_zyx(q)
    np.testing.assert_allclose(pitch, np.degrees(p), atol=1e-9)
    np.testing.assert_allclose(wrap_angle_deg(roll - np.degrees(r)), 0.0, atol=1e-9)
    np.testing.assert_allclose(wrap_angle_deg(yaw - np.degrees(y)), 0.0, atol=1e-9)
    # leaning 10 deg toward +X (pitch -10 deg at yaw 0) is an inclination of +10 deg
    assert inclination_deg(quat_to_matrix(euler_zyx_to_quat(0.0, -10 * D, 0.0))) == pytest.approx(
        10.0
    )


def test_wrap_angle_deg_is_half_open() -> None:
    np.testing.assert_array_equal(wrap_angle_deg([-180.0, 180.0, 190.0, -190.0, 540.0]),
                                  [180.0, 180.0, -170.0, 170.0, 180.0])  # fmt: skip


def test_rotation_vector_of_a_known_rotation() -> None:
    C = rz(0.3) @ rx(0.0)
    np.testing.assert_allclose(matrix_to_rotvec(C[None]), [[0.0, 0.0, 0.3]], atol=1e-12)
    np.testing.assert_allclose(matrix_to_rotvec(np.eye(3)[None]), [[0.0, 0.0, 0.0]])


def test_single_quaternion_path_is_the_array_path_bit_for_bit() -> None:
    """One quaternion goes through Python floats; it must equal the vectorised path exactly."""
    rng = np.random.default_rng(7)
    qs = rng.normal(size=(2000, 4)) * rng.uniform(0.01, 100.0, size=(2000, 1))
    stacked = quat_to_matrix(qs)  # the array path
    for q, c in zip(qs, stacked, strict=True):
        assert np.array_equal(quat_to_matrix(q), c)
    with pytest.raises(ValueError, match="zero norm"):
        quat_to_matrix(np.zeros(4))


def test_single_attitude_path_is_the_array_path_bit_for_bit() -> None:
    """One attitude (Python floats) goes through three-element ufunc calls; it must equal
    the broadcast path exactly, for wide and for tiny angles."""
    rng = np.random.default_rng(8)
    angles = rng.uniform(-np.pi, np.pi, size=(4000, 3))
    angles[:500] *= 1e-7
    angles[500:1000] = np.round(angles[500:1000], 2)
    stacked = euler_zyx_to_quat(angles[:, 0], angles[:, 1], angles[:, 2])  # the array path
    for (r, p, y), q in zip(angles.tolist(), stacked, strict=True):
        single = euler_zyx_to_quat(r, p, y)
        assert single.shape == (4,) and single.tobytes() == q.tobytes()
    assert (
        euler_zyx_to_quat(np.float64(0.1), 0.2, 0.3).tobytes()
        == euler_zyx_to_quat(np.array(0.1), 0.2, 0.3).tobytes()
    )


def test_single_quaternion_euler_angles_are_the_array_path_bit_for_bit() -> None:
    """One quaternion's roll, pitch and yaw (Python floats, one ufunc call at a time) equal
    the broadcast path's exactly: wide and tiny angles, every norm, the gimbal lock,
    the wrap at +-180 deg."""
    rng = np.random.default_rng(9)
    qs = rng.normal(size=(4000, 4)) * rng.uniform(0.01, 100.0, size=(4000, 1))
    qs[:300] = euler_zyx_to_quat(*(rng.uniform(-1e-7, 1e-7, size=(3, 300))))
    pitch = np.where(rng.random(200) < 0.5, -1.0, 1.0) * (np.pi / 2 - rng.uniform(0, 1e-6, 200))
    pitch[::2] = np.sign(pitch[::2]) * np.pi / 2  # locked: cos(pitch) below GIMBAL_LOCK_COS
    qs[300:500] = euler_zyx_to_quat(rng.uniform(-3, 3, 200), pitch, rng.uniform(-3, 3, 200))
    qs[500:600] = euler_zyx_to_quat(0.0, 0.0, np.full(100, np.pi))
    stacked = quat_to_euler_zyx(qs)  # the array path
    for i, q in enumerate(qs):
        single = quat_to_euler_zyx(q.copy())
        for got, want in zip(single, stacked, strict=True):
            assert np.asarray(got).tobytes() == want[i].tobytes()
        assert [np.ndim(a) for a in single] == [0, 0, 0]
    c = quat_to_matrix(qs[300:500])
    assert (np.hypot(c[:, 0, 0], c[:, 1, 0]) < GIMBAL_LOCK_COS).sum() >= 50  # the lock was met
