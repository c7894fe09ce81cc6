"""The compiled attitude excursion: the pruned pass equals the full evaluation bit for bit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadimpact.rotations import euler_zyx_to_quat, quat_to_matrix
from quadimpact.simulation.attitude import excursion_from_quaternions, excursion_full


def _same(a: tuple[float, ...], b: tuple[float, ...]) -> bool:
    return all(x == y or (math.isnan(x) and math.isnan(y)) for x, y in zip(a, b, strict=True))


def _random_walk(rng: np.random.Generator, n: int, step: float) -> np.ndarray:
    """Unnormalised quaternions wandering over the sphere (tumbles, returns, long drifts)."""
    return np.cumsum(rng.normal(size=(n, 4)) * step, axis=0) + rng.normal(size=4)


@pytest.mark.parametrize("step", [1e-4, 1e-2, 0.3])
def test_pruned_excursion_equals_full_evaluation_on_tumbles(step: float) -> None:
    rng = np.random.default_rng(7)
    for _ in range(40):
        q = _random_walk(rng, int(rng.integers(1, 2000)), step)
        refs = rng.uniform(-math.pi, math.pi, 3)
        refs[1] = rng.uniform(-0.5 * math.pi, 0.5 * math.pi)
        z = quat_to_matrix(euler_zyx_to_quat(*refs))[:, 2]
        args = (q, *refs, np.ascontiguousarray(z))
        assert _same(excursion_from_quaternions(*args), excursion_full(*args))


def test_pruned_excursion_near_gimbal_lock_and_wrapping_references() -> None:
    """Pitch within 1e-7 rad of +-90 deg (full evaluation), references at +-180 deg, a
    pitch reference beyond 90 deg (no pruning of pitch), a NaN row."""
    rng = np.random.default_rng(3)
    h = math.sqrt(0.5)
    for sign in (1.0, -1.0):
        a = rng.normal(size=500) * 1e-7
        q = np.stack([np.full(500, h), a, sign * np.full(500, h), 0.3 * a], axis=1)
        q = np.concatenate([q, _random_walk(rng, 500, 0.05)])
        for refs in ((math.pi, 0.2, -math.pi), (math.pi * (1 - 1e-12), 2.0, 0.5), (0.0, -2.5, 3.0)):
            args = (q, *refs, np.array([0.0, 0.0, 1.0]))
            assert _same(excursion_from_quaternions(*args), excursion_full(*args))
        q[250] = np.nan
        args = (q, 0.1, 0.2, 0.3, np.array([0.0, 0.0, 1.0]))
        assert _same(excursion_from_quaternions(*args), excursion_full(*args))


def test_excursion_of_a_known_rotation() -> None:
    """Roll 30 deg then back: roll excursion 30 deg, tilt 30 deg, pitch and yaw 0."""
    roll = np.radians(np.concatenate([np.linspace(0.0, 30.0, 301), np.linspace(30.0, 0.0, 301)]))
    q = euler_zyx_to_quat(roll, np.zeros_like(roll), np.zeros_like(roll))
    out = excursion_from_quaternions(np.ascontiguousarray(q), 0.0, 0.0, 0.0, np.array([0, 0, 1.0]))
    assert out[0] == pytest.approx(30.0, abs=1e-12)
    assert out[1] == pytest.approx(0.0, abs=1e-12)
    assert out[2] == pytest.approx(0.0, abs=1e-12)
    assert out[3] == pytest.approx(30.0, abs=1e-6)


def test_a_settled_step_leaves_the_excursion_as_it_is() -> None:
    """``excursion.settled``: where it proves that no rotation within ``dc`` of ``C`` (each
    entry) can change the excursion, adding any such rotation leaves it bit for bit; it
    proves it for small moves near the references after a tumble, not for large ones."""
    from quadimpact.core import layout as L
    from quadimpact.core.excursion import excursion_add, excursion_start, settled

    rng = np.random.default_rng(11)
    proved = refused = 0
    for _ in range(60):
        refs = rng.uniform(-0.5, 0.5, 3)
        q_ref = euler_zyx_to_quat(*refs)
        z = np.ascontiguousarray(quat_to_matrix(q_ref)[:, 2])
        e = np.zeros(L.NEX)
        excursion_start(*refs, e)
        for q in q_ref + np.cumsum(rng.normal(size=(int(rng.integers(1, 60)), 4)) * 0.05, axis=0):
            excursion_add(np.ascontiguousarray(quat_to_matrix(q)), *refs, z, e)
        q0 = q_ref + rng.normal(size=4) * 0.02
        C0 = np.ascontiguousarray(quat_to_matrix(q0))
        dc = 10.0 ** rng.uniform(-4, 0.3)
        if not settled(C0, dc, refs[1], z, e):
            refused += 1
            continue
        proved += 1
        for _ in range(200):
            q = q0 + rng.normal(size=4) * dc * 0.3
            C = np.ascontiguousarray(quat_to_matrix(q))
            if np.max(np.abs(C - C0)) > dc:
                continue
            after = e.copy()
            excursion_add(C, *refs, z, after)
            assert np.array_equal(after, e)
    assert proved >= 10 and refused >= 10
