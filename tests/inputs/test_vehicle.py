"""Vehicle parameters: the bundled Spiri (docs/MODEL.md section 3), bumper geometry
(docs/MODEL.md section 4) and the one-line errors for bad vehicle files."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from quadimpact.errors import InputError
from quadimpact.inputs.vehicle import Vehicle, bundled_vehicles, load_vehicle

from helpers import SPIRI_TOML


@pytest.fixture(scope="module")
def spiri() -> Vehicle:
    return load_vehicle()


def test_bundled_spiri_has_model_values(spiri: Vehicle) -> None:
    assert bundled_vehicles() == ["navi", "spiri"]
    assert load_vehicle("spiri") == spiri
    assert spiri.name == "spiri"
    assert spiri.mass_kg == 0.933
    np.testing.assert_allclose(
        spiri.inertia,
        [
            [8.737e-3, -4.20e-7, -5.289e-5],
            [-4.20e-7, 8.988e-3, -1.14e-6],
            [-5.289e-5, -1.14e-6, 1.7143e-2],
        ],
        rtol=0,
        atol=0,
    )
    np.testing.assert_array_equal(
        spiri.rotor_positions,
        [
            [0.13192, 0.12652, -0.02416],
            [-0.12122, 0.12652, -0.02416],
            [-0.12122, -0.12662, -0.02416],
            [0.13192, -0.12662, -0.02416],
        ],
    )
    assert spiri.spin_directions == (-1, 1, -1, 1)
    assert spiri.thrust_coefficient == 6.3969e-6
    assert spiri.drag_torque_coefficient == 8.7633e-8
    assert spiri.rotor_inertia_kg_m2 == 2.20751e-5
    assert spiri.gravity_m_s2 == 9.81
    assert spiri.bumper_radius_m == 0.11
    assert spiri.bumper_tilt_deg == 11.0
    assert spiri.bumper_directions_deg == (45.0, 135.0, 225.0, 315.0)
    assert (spiri.contact_stiffness, spiri.contact_exponent, spiri.restitution) == (
        40.0,
        0.54,
        0.9,
    )
    assert spiri.rotor_speed_range_rpm == (3000.0, 8000.0)
    assert spiri.motor_time_constant_s == 0.02


def test_coefficients_match_rpm_forms(spiri: Vehicle) -> None:
    rpm = 2 * math.pi / 60  # rad/s per RPM
    assert spiri.thrust_coefficient * rpm**2 == pytest.approx(7.015e-8, rel=1e-3)
    assert spiri.drag_torque_coefficient * rpm**2 == pytest.approx(9.61e-10, rel=1e-3)


def test_hover_speed(spiri: Vehicle) -> None:
    assert spiri.hover_speed_rad_s == pytest.approx(598.08, abs=0.01)
    assert spiri.hover_speed_rad_s * 60 / (2 * math.pi) == pytest.approx(5711, abs=1)
    thrust = 4 * spiri.thrust_coefficient * spiri.hover_speed_rad_s**2
    assert thrust == pytest.approx(spiri.mass_kg * spiri.gravity_m_s2, rel=1e-12)


def test_bumper_frames_rotor1(spiri: Vehicle) -> None:
    centres, u, n = spiri.bumper_frames()
    assert centres.shape == u.shape == n.shape == (4, 3)
    np.testing.assert_array_equal(centres, spiri.rotor_positions)
    np.testing.assert_allclose(u[0], [0.694, 0.694, -0.191], atol=1e-3)
    np.testing.assert_allclose(n[0], [-0.135, -0.135, -0.982], atol=1e-3)


def test_bumper_frames_are_orthonormal_and_point_outward(spiri: Vehicle) -> None:
    centres, u, n = spiri.bumper_frames()
    np.testing.assert_allclose(np.linalg.norm(u, axis=1), 1.0, rtol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, rtol=1e-14)
    np.testing.assert_allclose(np.sum(u * n, axis=1), 0.0, atol=1e-15)
    # outward: the in-plane direction has the sign of the rotor's x and y
    assert np.all(np.sign(u[:, :2]) == np.sign(centres[:, :2]))
    # rims raised (z up is negative in FRD) and normals pointing up
    assert np.all(u[:, 2] < 0) and np.all(n[:, 2] < 0)


def test_with_overrides_revalidates(spiri: Vehicle) -> None:
    soft = spiri.with_overrides(contact_stiffness=20.0, restitution=0.5)
    assert (soft.contact_stiffness, soft.restitution) == (20.0, 0.5)
    assert spiri.contact_stiffness == 40.0  # the original is unchanged
    with pytest.raises(InputError, match=r"restitution: must be <= 1 \(got 1.5\)"):
        spiri.with_overrides(restitution=1.5)
    with pytest.raises(InputError, match="colour: unknown vehicle field"):
        spiri.with_overrides(colour="red")


def test_vehicle_is_frozen(spiri: Vehicle) -> None:
    with pytest.raises(ValueError, match="frozen"):
        spiri.mass_kg = 2.0  # type: ignore[misc]


def test_user_file_without_name_takes_stem(tmp_path: Path) -> None:
    text = SPIRI_TOML.read_text().replace('name = "spiri"', "")
    path = tmp_path / "my_quad.toml"
    path.write_text(text)
    vehicle = load_vehicle(path)
    assert vehicle.name == "my_quad"
    assert vehicle.mass_kg == 0.933
    assert load_vehicle(str(path)) == vehicle


# ------------------------------------------------------------------ errors
def _assert_one_line(message: str, *fragments: str) -> None:
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, f"{fragment!r} not in {message!r}"


def _write_variant(tmp_path: Path, old: str, new: str) -> Path:
    text = SPIRI_TOML.read_text()
    assert old in text
    path = tmp_path / "bad.toml"
    path.write_text(text.replace(old, new, 1))
    return path


BAD_VEHICLES = [
    # (old text, new text, expected fragments of the message)
    (
        "[-4.20e-7,   8.988e-3",
        "[-4.30e-7,   8.988e-3",
        ["inertia_kg_m2", "symmetric positive definite", "not symmetric"],
    ),
    (
        "1.7143e-2]",
        "-1.7143e-2]",
        ["inertia_kg_m2", "symmetric positive definite", "smallest eigenvalue"],
    ),
    ("restitution = 0.9", "restitution = 0.0", ["restitution: must be > 0 (got 0.0)"]),
    ("restitution = 0.9", "restitution = 1.2", ["restitution: must be <= 1 (got 1.2)"]),
    (
        "  [ 0.13192, -0.12662, -0.02416],  # rotor 4: port front\n",
        "",
        ["rotor_positions_m: must have 4 to 8 rows", "(got 3)"],
    ),
    (
        "spin_directions = [-1, 1, -1, 1]",
        "spin_directions = [-1, 2, -1, 1]",
        ["spin_directions: each entry must be +1 or -1", "(got [-1, 2, -1, 1])"],
    ),
    (
        "spin_directions = [-1, 1, -1, 1]",
        "spin_directions = [-1, 1, 1, 1]",
        ["spin_directions: must sum to 0"],
    ),
    ("mass_kg = 0.933", "mass_kg = -0.933", ["mass_kg: must be >= 0.001 (got -0.933)"]),
    ("mass_kg = 0.933", 'mass_kg = "heavy"', ["mass_kg: must be a number (got 'heavy')"]),
    ("mass_kg = 0.933", "mass_kg = nan", ["mass_kg: must be a finite number"]),
    ("bumper_tilt_deg = 11.0", "bumper_tilt_deg = 90.0", ["bumper_tilt_deg: must be < 90"]),
    (
        "rotor_speed_range_rpm = [3000.0, 8000.0]",
        "rotor_speed_range_rpm = [8000.0, 3000.0]",
        ["rotor_speed_range_rpm: must be [min, max] with min < max"],
    ),
    (
        "motor_time_constant_s = 0.02",
        "motor_time_constant_s = 0.0",
        ["motor_time_constant_s: must be > 0"],
    ),
    ("mass_kg = 0.933", "mass_kg = 0.933\nmass_kilograms = 1.0", ["mass_kilograms: unknown key"]),
    ("mass_kg = 0.933\n", "", ["mass_kg: is required"]),
]


@pytest.mark.parametrize(("old", "new", "fragments"), BAD_VEHICLES)
def test_bad_vehicle_file_gives_one_line(
    tmp_path: Path, old: str, new: str, fragments: list[str]
) -> None:
    path = _write_variant(tmp_path, old, new)
    with pytest.raises(InputError) as info:
        load_vehicle(path)
    _assert_one_line(str(info.value), f"vehicle {path}: ", *fragments)


def test_unknown_key_suggests_the_field(tmp_path: Path) -> None:
    path = _write_variant(tmp_path, "restitution = 0.9", "restitution = 0.9\nrestitutoin = 1")
    with pytest.raises(InputError, match="restitutoin: unknown key; did you mean 'restitution'"):
        load_vehicle(path)


def test_bad_toml_syntax_names_file_and_line(tmp_path: Path) -> None:
    path = _write_variant(tmp_path, "restitution = 0.9", "restitution 0.9")
    with pytest.raises(InputError) as info:
        load_vehicle(path)
    message = str(info.value)
    _assert_one_line(message, f"vehicle {path}: invalid TOML")
    line = SPIRI_TOML.read_text().splitlines().index("restitution = 0.9") + 1
    assert re.search(rf"line {line}\b", message)


def test_unknown_name_and_missing_file(tmp_path: Path) -> None:
    with pytest.raises(
        InputError, match=r"vehicle 'spirit': unknown vehicle name \(bundled: navi, spiri"
    ):
        load_vehicle("spirit")
    missing = tmp_path / "nope.toml"
    with pytest.raises(InputError, match=rf"vehicle {re.escape(str(missing))}: file not found"):
        load_vehicle(missing)
    with pytest.raises(InputError, match="is a directory"):
        load_vehicle(tmp_path)


def test_validation_accepts_numpy_inputs(spiri: Vehicle) -> None:
    modified = spiri.with_overrides(
        inertia_kg_m2=np.diag([0.01, 0.01, 0.02]),
        spin_directions=np.array([1, -1, 1, -1]),
        mass_kg=np.float32(1.5),
    )
    assert modified.inertia_kg_m2 == ((0.01, 0.0, 0.0), (0.0, 0.01, 0.0), (0.0, 0.0, 0.02))
    assert modified.spin_directions == (1, -1, 1, -1)
    assert modified.mass_kg == 1.5


def test_symmetry_tolerance_is_relative(spiri: Vehicle) -> None:
    inertia = spiri.inertia.copy()
    inertia[0, 1] *= 1 + 1e-12  # within 1e-9 of the largest entry
    assert spiri.with_overrides(inertia_kg_m2=inertia).inertia[0, 1] == inertia[0, 1]
    inertia[0, 1] += 1e-9  # about 6e-8 relative to the largest entry
    with pytest.raises(InputError, match="not symmetric"):
        spiri.with_overrides(inertia_kg_m2=inertia)
