"""Vehicle parameters: a validated, immutable description of a multirotor with bumpers.

Vehicles are data: the Spiri of the paper ships as ``inputs/vehicles/spiri.toml``
and a user can write another file with the same keys (see that file for
units and sources). Frames and conventions are those of docs/MODEL.md section 1:
body frame FRD (x forward, y right, z down) with its origin at the centre of
mass; SI units, rotor speeds in rad/s.

Examples
--------
>>> from quadimpact.inputs.vehicle import load_vehicle
>>> spiri = load_vehicle()                      # the bundled Spiri
>>> round(spiri.hover_speed_rad_s, 1)
598.1
>>> stiff = spiri.with_overrides(contact_stiffness=80.0)
"""

from __future__ import annotations

import functools
import json
import math
import os
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel, Field, ValidationError, field_validator, model_validator

from quadimpact.errors import InputError, input_error_from_validation, near_miss
from quadimpact.inputs.features import ContactFeature
from quadimpact.inputs.toml_files import read_toml_file
from quadimpact.inputs.types import (
    MODEL_CONFIG,
    Mat3,
    Mat4x3,
    Real,
    RotorReals,
    RotorRows,
    RotorSigns,
    Vec2,
    Vec3,
    Vec4,
)
from quadimpact.linalg import norm

__all__ = ["Vehicle", "load_vehicle", "bundled_vehicles"]

_SYMMETRY_RTOL = 1e-9


class Vehicle(BaseModel):
    """A multirotor with bumpers: mass properties, rotors, bumpers and contact law.

    All vectors are in the body frame (FRD: x forward, y right, z down, origin
    at the centre of mass). The vehicle has ``n`` rotors (4 to
    ``core.layout.MAX_ROTORS`` = 8: the rows of ``rotor_positions_m``); rotor
    ``j`` (1-n) is row ``j-1``. A quadrotor may describe its four bumper rings
    with the ``bumper_*`` keys (bumper ``j`` centred on rotor ``j`` unless
    ``bumper_centres_m`` says otherwise); a vehicle with another rotor count
    lists its contact ``features``. The model is frozen; derive variants with
    :meth:`with_overrides`.

    Attributes
    ----------
    name : str
        Label of the vehicle (e.g. ``"spiri"``).
    mass_kg : float
        Total mass m, kg.
    inertia_kg_m2 : tuple of 3 tuples of 3 floats
        Inertia tensor about the CM in body axes, kg m^2; symmetric positive definite.
    rotor_positions_m : tuple of n tuples of 3 floats
        Rotor hub positions r_Tj from the CM, body FRD, m; 4 to 8 rows.
    spin_directions : tuple of n ints
        Spin sense s_j of each rotor about +z_B (down): +1 or -1, as many of each.
    thrust_coefficient : float or tuple of n floats
        kt, thrust per rotor ``kt_j Omega_j^2``, N/(rad/s)^2: one value for
        every rotor, or one per rotor.
    drag_torque_coefficient : float or tuple of n floats
        dt, aerodynamic drag torque per rotor ``dt_j Omega_j^2``, N m/(rad/s)^2:
        one value for every rotor, or one per rotor.
    rotor_inertia_kg_m2 : float
        Jr, rotor and propeller inertia about the spin axis, kg m^2; 0 for a
        model without rotor gyroscopics (no gyroscopic, no spin-up moment).
    gravity_m_s2 : float
        Gravitational acceleration g, m/s^2 (along +Z of the NED inertial frame).
    bumper_radius_m : float
        Rb, radius of each bumper circle, m.
    bumper_tilt_deg : float
        alpha, tilt of the bumper circles, deg in [0, 90): the outer rim is raised.
    bumper_directions_deg : tuple of 4 floats
        psi_j, outward direction of bumper j in the body x-y plane, deg from +x_B
        toward +y_B.
    contact_stiffness : float
        k, Hunt-Crossley stiffness, N/m^n.
    contact_exponent : float
        n, Hunt-Crossley exponent, dimensionless.
    restitution : float
        e, coefficient of restitution in (0, 1].
    rotor_speed_range_rpm : tuple of 2 floats
        Hardware rotor speed range [min, max], rpm: the limits of the
        ``cascade-pid`` and ``recovery`` controllers' commands (and optional
        loop limits).
    motor_time_constant_s : float
        tau_m, motor time constant, s (first-order rotor mode only).
    bumper_centres_m : tuple of 4 tuples of 3 floats or None
        Bumper circle centres from the CM, body FRD, m, row j-1 for bumper j;
        ``None`` (the Spiri): on the rotor hubs.
    imu_position_m : tuple of 3 floats
        IMU position from the CM, body FRD, m (default the CM).
    rotor_slew_limit_rpm_per_s : float or None
        Largest rate of change of a rotor speed command, rpm/s; ``None``: not
        known (no limit). In force in impact trials.
    features : tuple of ContactFeature or None
        The vehicle's contact features (``[[features]]`` in a file: rings,
        spheres, points, each with its own contact law and name), instead of
        the four bumper rings; ``None`` (the Spiri, the Navi): the four rings
        of ``bumper_*`` with ``contact_stiffness``, ``contact_exponent`` and
        ``restitution``, which are then required.
    """

    model_config = MODEL_CONFIG

    name: str = Field(min_length=1, description="Label of the vehicle.")
    mass_kg: Real = Field(ge=1e-3, le=1e3, description="Total mass m, kg (1 g to 1 t).")
    inertia_kg_m2: Mat3 = Field(
        description="Inertia tensor about the CM, body FRD axes, kg m^2 (symmetric, PD)."
    )
    rotor_positions_m: RotorRows = Field(
        description="Rotor hub positions from the CM, body FRD, m; row j-1 is rotor j (4 to 8)."
    )
    spin_directions: RotorSigns = Field(
        description="Spin sense of each rotor about +z_B (down): +1 or -1, summing to 0."
    )
    thrust_coefficient: Real | RotorReals = Field(
        description="kt: thrust = kt Omega^2, N/(rad/s)^2; one for all rotors or one per rotor."
    )
    drag_torque_coefficient: Real | RotorReals = Field(
        description="dt: rotor drag torque = dt Omega^2, N m/(rad/s)^2; one or one per rotor."
    )
    rotor_inertia_kg_m2: Real = Field(
        ge=0,
        description="Jr: rotor + propeller inertia about the spin axis, kg m^2 (0: no rotor "
        "gyroscopics).",
    )
    gravity_m_s2: Real = Field(gt=0, description="Gravitational acceleration g, m/s^2.")
    bumper_radius_m: Real | None = Field(
        None, gt=0, description="Rb: bumper circle radius, m (at most 2 m)."
    )
    bumper_tilt_deg: Real | None = Field(
        None, ge=0, lt=90, description="alpha: bumper tilt, deg; the outer rim is raised."
    )
    bumper_directions_deg: Vec4 = Field(
        (45.0, 135.0, 225.0, 315.0),
        description="Outward direction of each bumper in the body x-y plane, deg from +x_B.",
    )
    contact_stiffness: Real | None = Field(
        None, gt=0, description="k: Hunt-Crossley stiffness, N/m^n."
    )
    contact_exponent: Real | None = Field(None, gt=0, description="n: Hunt-Crossley exponent.")
    restitution: Real | None = Field(
        None, gt=0, le=1, description="e: coefficient of restitution, (0, 1]."
    )
    rotor_speed_range_rpm: Vec2 = Field(
        (3000.0, 8000.0), description="Hardware rotor speed range [min, max], rpm."
    )
    motor_time_constant_s: Real = Field(
        0.02, gt=0, description="tau_m: motor time constant, s (first-order rotor mode)."
    )
    bumper_centres_m: Mat4x3 | None = Field(
        None,
        description="Bumper circle centres from the CM, body FRD, m; None: on the rotor hubs.",
    )
    imu_position_m: Vec3 = Field(
        (0.0, 0.0, 0.0), description="IMU position from the CM, body FRD, m."
    )
    rotor_slew_limit_rpm_per_s: Real | None = Field(
        None, gt=0, description="Rotor speed command slew limit, rpm/s; None: not known."
    )
    features: tuple[ContactFeature, ...] | None = Field(
        None,
        description="Contact features ([[features]]: rings, spheres, points), replacing the "
        "four bumper rings; None: the four rings of the bumper_* and contact_* keys.",
    )

    # ------------------------------------------------------------------ checks
    @field_validator("inertia_kg_m2")
    @classmethod
    def _check_inertia(cls, value: tuple) -> tuple:
        mat = np.asarray(value, dtype=float)
        scale = float(np.max(np.abs(mat)))
        if scale > 1e9:
            raise ValueError(f"entries must be at most 1e9 kg m^2 in magnitude (got {scale:.4g})")
        if scale == 0.0 or np.max(np.abs(mat - mat.T)) > _SYMMETRY_RTOL * scale:
            raise ValueError("must be symmetric positive definite (not symmetric)")
        eig = np.linalg.eigvalsh(0.5 * (mat + mat.T))
        if eig[0] <= 0.0:
            raise ValueError(
                "must be symmetric positive definite "
                f"(not positive definite: smallest eigenvalue {eig[0]:.4g})"
            )
        return value

    @field_validator("features")
    @classmethod
    def _check_features(cls, value: tuple | None) -> tuple | None:
        if value is None:
            return value
        if not value:
            raise ValueError("must list at least one feature")
        names = [f.name for f in value]
        for name in names:
            if names.count(name) > 1:
                raise ValueError(f"feature names must be unique ({name!r} repeats)")
        return value

    @model_validator(mode="after")
    def _rings_or_features(self) -> Vehicle:
        if self.features is None:
            for key in (
                "bumper_radius_m",
                "bumper_tilt_deg",
                "contact_stiffness",
                "contact_exponent",
                "restitution",
            ):
                if getattr(self, key) is None:
                    raise ValueError(
                        f"{key}: is required (a vehicle without [[features]] has four bumper rings)"
                    )
        return self

    @field_validator("bumper_radius_m")
    @classmethod
    def _check_bumper_radius(cls, value: float | None) -> float | None:
        if value is None:
            return value
        if value > 2.0:
            raise ValueError(
                f"must be at most 2 m, a bumper around one rotor (got {value:g}; "
                "millimetres typed as metres?)"
            )
        return value

    @field_validator("spin_directions")
    @classmethod
    def _check_spins(cls, value: tuple) -> tuple:
        if any(s not in (1, -1) for s in value):
            raise ValueError("each entry must be +1 or -1")
        if sum(value) != 0:
            raise ValueError("must sum to 0 (as many rotors each way, for balanced yaw)")
        return value

    @field_validator("thrust_coefficient", "drag_torque_coefficient")
    @classmethod
    def _check_coefficients(cls, value: float | tuple) -> float | tuple:
        values = value if isinstance(value, tuple) else (value,)
        if not all(c > 0 for c in values):
            raise ValueError("must be > 0 (each rotor's)")
        return value

    @model_validator(mode="after")
    def _rotor_counts(self) -> Vehicle:
        n = len(self.rotor_positions_m)
        for key in ("spin_directions", "thrust_coefficient", "drag_torque_coefficient"):
            value = getattr(self, key)
            if isinstance(value, tuple) and len(value) != n:
                raise ValueError(
                    f"{key}: {len(value)} entries for the {n} rotors of rotor_positions_m "
                    "(one per rotor)"
                )
        if self.features is None and n != 4:
            raise ValueError(
                f"features: required for a vehicle with {n} rotors (the bumper_* keys describe "
                "the four rings of a quadrotor; list [[features]] instead)"
            )
        return self

    @field_validator("rotor_speed_range_rpm")
    @classmethod
    def _check_range(cls, value: tuple) -> tuple:
        lo, hi = value
        if lo <= 0:
            raise ValueError("minimum must be > 0")
        if not lo < hi:
            raise ValueError("must be [min, max] with min < max")
        return value

    @model_validator(mode="after")
    def _physically_consistent(self) -> Vehicle:
        """Rules no real vehicle breaks (errors); see :meth:`plausibility_warnings` for the
        merely unusual."""
        moments = np.linalg.eigvalsh(np.asarray(self.inertia_kg_m2, dtype=float))
        a, b, c = (float(m) for m in moments)  # ascending
        if c > (a + b) * (1.0 + 1e-9):
            raise ValueError(
                f"inertia_kg_m2: its principal moments ({a:.4g}, {b:.4g}, {c:.4g} kg m^2) break "
                "the triangle inequality (the largest exceeds the sum of the other two): no "
                "rigid body has this inertia"
            )
        if not (1e-12 <= a and c <= 1e9):
            raise ValueError(
                f"inertia_kg_m2: principal moments must lie in [1e-12, 1e9] kg m^2 "
                f"(got {a:.4g} to {c:.4g})"
            )
        arms = norm(np.asarray(self.rotor_positions_m, dtype=float)[:, :2])
        if not (arms.min() >= 0.005 and arms.max() <= 5.0):
            raise ValueError(
                "rotor_positions_m: rotor arms (horizontal distance from the CM) must lie in "
                f"[0.005, 5] m (got {arms.min():.4g} to {arms.max():.4g} m)"
            )
        if self.features is None and self.bumper_radius_m >= arms.min():
            raise ValueError(
                f"bumper_radius_m: {self.bumper_radius_m:g} m is not less than the shortest "
                f"rotor arm ({arms.min():.3g} m): a bumper ring around a rotor would enclose "
                "the CM and cross the other rotors (each bumper is a circle around one rotor)"
            )
        reach = self.reach_m()
        imu = float(norm(np.asarray(self.imu_position_m, dtype=float)))
        if imu > reach:
            raise ValueError(
                f"imu_position_m: {imu:.3g} m from the CM, off the vehicle (its rotors and "
                f"bumpers reach {reach:.3g} m): the IMU must sit on it"
            )
        hover_rpm = self.hover_speed_rad_s * 60.0 / (2.0 * math.pi)
        lo, hi = self.rotor_speed_range_rpm
        if not lo <= hover_rpm <= hi:
            in_rad_s = lo <= self.hover_speed_rad_s <= hi  # the range reads as rad/s
            hint = " (rad/s typed as rpm?)" if in_rad_s else ""
            raise ValueError(
                f"rotor_speed_range_rpm: hovering needs {hover_rpm:.4g} rpm per rotor, outside "
                f"[{lo:g}, {hi:g}] rpm: the rotors cannot hold the vehicle up{hint}"
            )
        kt = self.thrust_coefficients
        r = np.asarray(self.rotor_positions_m, dtype=float)
        spins = np.asarray(self.spin_directions, dtype=float)
        alloc = np.vstack([kt, -kt * r[:, 1], kt * r[:, 0],
                           -self.drag_torque_coefficients * spins])  # fmt: skip
        if np.linalg.cond(alloc) > 1e12:
            raise ValueError(
                "rotor_positions_m, spin_directions: the rotors cannot produce thrust and the "
                "three torques independently (the allocation is singular: rotors on one "
                "line or point, or neighbouring rather than diagonal rotors spinning alike)"
            )
        return self

    def plausibility_warnings(self) -> list[str]:
        """Valid but unusual values for a bumper-protected quadrotor (one sentence each).

        Computed once per vehicle object (the model is frozen).
        """
        cached = _PLAUSIBILITY.get(id(self))
        if cached is not None and cached[0] is self:
            return list(cached[1])
        out = self._plausibility_warnings()
        if len(_PLAUSIBILITY) >= _CACHE_LIMIT:
            _PLAUSIBILITY.pop(next(iter(_PLAUSIBILITY)))
        _PLAUSIBILITY[id(self)] = (self, tuple(out))  # the reference keeps the id unique
        return list(out)

    def _plausibility_warnings(self) -> list[str]:
        out = []
        arms = norm(self.rotor_positions[:, :2])
        rings = self.features is None
        if rings and self.bumper_radius_m < 0.3 * arms.mean():
            out.append(
                f"bumper_radius_m {self.bumper_radius_m:g} m is unusual for rotor arms of "
                f"{arms.mean():.3g} m (a bumper circle around each rotor)"
            )
        r = self.rotor_positions[:, :2]
        n = self.rotor_count
        gaps = [float(norm(r[i] - r[j])) for i in range(n) for j in range(i + 1, n)]
        if rings and 2.0 * self.bumper_radius_m > min(gaps):
            out.append(
                f"bumper rings overlap: 2 x bumper_radius_m = {2 * self.bumper_radius_m:.3g} m "
                f"is more than the {min(gaps):.3g} m between the nearest rotor hubs (each ring "
                "is still treated as a separate bumper)"
            )
        hi = self.rotor_speed_range_rpm[1] * 2.0 * math.pi / 60.0
        ratio = (hi / self.hover_speed_rad_s) ** 2
        if not 1.2 <= ratio <= 10.0:
            out.append(
                f"thrust-to-weight ratio at the top rotor speed is {ratio:.3g} "
                "(multirotors fly with about 1.5 to 5)"
            )
        for f in self.contact_features():
            if f.restitution < 0.3:
                what = "a bumper" if self.features is None else f"feature {f.name!r}"
                out.append(f"restitution {f.restitution:g} is unusually low for {what}")
                break
        return out

    # ------------------------------------------------------------ derived data
    @property
    def inertia(self) -> np.ndarray:
        """Inertia tensor about the CM, body FRD axes, kg m^2, shape (3, 3)."""
        return np.array(self.inertia_kg_m2, dtype=float)

    @property
    def rotor_count(self) -> int:
        """The number of rotors ``n`` (4 to 8)."""
        return len(self.rotor_positions_m)

    @property
    def rotor_positions(self) -> np.ndarray:
        """Rotor hub positions from the CM, body FRD, m, shape (n, 3); row j-1 is rotor j."""
        return np.array(self.rotor_positions_m, dtype=float)

    @property
    def spins(self) -> np.ndarray:
        """Spin senses s_j about +z_B as floats (+1.0 or -1.0), shape (n,)."""
        return np.array(self.spin_directions, dtype=float)

    @property
    def thrust_coefficients(self) -> np.ndarray:
        """Each rotor's thrust coefficient kt_j, N/(rad/s)^2, shape (n,)."""
        return _per_rotor(self.thrust_coefficient, self.rotor_count)

    @property
    def drag_torque_coefficients(self) -> np.ndarray:
        """Each rotor's drag-torque coefficient dt_j, N m/(rad/s)^2, shape (n,)."""
        return _per_rotor(self.drag_torque_coefficient, self.rotor_count)

    @property
    def hover_speed_rad_s(self) -> float:
        """Level-hover rotor speed ``sqrt(m g / (n kt))``, rad/s (about 598 for the Spiri).

        With coefficients that differ between rotors: ``sqrt(m g / sum_j kt_j)``,
        the speed the rotors would share (the trim gives each its own).
        """
        kt = self.thrust_coefficients
        total = float(self.rotor_count) * float(kt[0]) if np.all(kt == kt[0]) else float(kt.sum())
        return math.sqrt(self.mass_kg * self.gravity_m_s2 / total)

    def bumper_frames(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Geometry of the four bumper circles in the body frame (docs/MODEL.md section 4).

        With ``d_j = (cos psi_j, sin psi_j, 0)``, ``a`` the tilt and ``e_z`` the
        body z axis (down)::

            u_j = cos(a) d_j - sin(a) e_z     in-plane outward unit vector (rim raised)
            n_j = -sin(a) d_j - cos(a) e_z    unit normal of the circle plane (up, inward)

        Returns
        -------
        centres : numpy.ndarray, shape (4, 3)
            Circle centres, body FRD, m (``bumper_centres_m``, else the rotor positions).
        u : numpy.ndarray, shape (4, 3)
            In-plane outward unit vectors, body FRD.
        n : numpy.ndarray, shape (4, 3)
            Plane unit normals, body FRD.
        """
        psi = np.deg2rad(np.asarray(self.bumper_directions_deg, dtype=float))
        a = math.radians(self.bumper_tilt_deg)
        d = np.stack([np.cos(psi), np.sin(psi), np.zeros(4)], axis=1)
        e_z = np.array([0.0, 0.0, 1.0])
        u = math.cos(a) * d - math.sin(a) * e_z
        n = -math.sin(a) * d - math.cos(a) * e_z
        centres = (
            np.array(self.bumper_centres_m, dtype=float)
            if self.bumper_centres_m is not None
            else self.rotor_positions
        )
        return centres, u, n

    def contact_features(self) -> tuple[ContactFeature, ...]:
        """The vehicle's contact features: ``features``, or its four bumper rings ``"1"``-``"4"``.

        Each ring has the geometry of :meth:`bumper_frames` (centre, plane
        normal, radius ``bumper_radius_m``) and the vehicle's contact law
        (``contact_stiffness``, ``contact_exponent``, ``restitution``); its
        friction coefficient is the scenario's. Computed once per vehicle
        object (the model is frozen).
        """
        if self.features is not None:
            return self.features
        cached = _FEATURES.get(id(self))
        if cached is not None and cached[0] is self:
            return cached[1]
        if len(_FEATURES) >= _CACHE_LIMIT:
            _FEATURES.pop(next(iter(_FEATURES)))
        features = self._rings()
        _FEATURES[id(self)] = (self, features)  # the reference keeps the id unique
        return features

    def feature_names(self) -> tuple[str, ...]:
        """Names of :meth:`contact_features`, in order (the output columns' suffixes)."""
        return tuple(f.name for f in self.contact_features())

    def reach_m(self) -> float:
        """How far the vehicle reaches from its CM, m: the longest rotor arm plus the bumper
        radius, or the farthest of its rotors and its features' extents."""
        arm = float(norm(np.asarray(self.rotor_positions_m, float)).max())
        if self.features is None:
            return arm + float(self.bumper_radius_m)
        extents = [
            float(norm(np.asarray(f.centre_m, float))) + float(f.radius_m) for f in self.features
        ]
        return max([arm, *extents])

    def valid_depth_m(self) -> float:
        """Deepest penetration the contact model covers, m: the shallowest feature's limit.

        The bumper radius of a ring vehicle; a deeper run is flagged
        (``bumper_model_valid``).
        """
        if self.features is None:
            return self.bumper_radius_m
        return min(f.depth_limit_m for f in self.features)

    def _rings(self) -> tuple[ContactFeature, ...]:
        centres, _, n = self.bumper_frames()
        return tuple(
            ContactFeature(
                name=str(j + 1),
                kind="ring",
                centre_m=tuple(centres[j]),
                normal=tuple(n[j]),
                radius_m=self.bumper_radius_m,
                stiffness=self.contact_stiffness,
                exponent=self.contact_exponent,
                restitution=self.restitution,
            )
            for j in range(4)
        )

    # ---------------------------------------------------------------- variants
    def with_overrides(self, **fields: Any) -> Vehicle:
        """Return a copy with some fields replaced, validated again.

        Parameters
        ----------
        **fields
            Field name to new value, e.g. ``restitution=0.5``.

        Returns
        -------
        Vehicle
            The new vehicle.

        Raises
        ------
        InputError
            For an unknown field or a value that breaks a rule.
        """
        if not fields:  # the vehicle itself (a frozen model), its message unformatted
            return self
        return self.apply_overrides(fields, where=f"vehicle {self.name} overrides")

    def apply_overrides(
        self, fields: dict[str, Any], where: str, prefix: tuple[str, ...] = ()
    ) -> Vehicle:
        """Like :meth:`with_overrides`, with the error location given explicitly.

        Parameters
        ----------
        fields : dict
            Field name to new value.
        where : str
            Start of any error message (e.g. ``"scenario.toml"``).
        prefix : tuple of str, optional
            Field-path prefix in error messages (e.g. ``("vehicle_overrides",)``).

        Returns
        -------
        Vehicle
            The new vehicle.
        """
        if not fields:
            return self
        for key in fields:
            if key not in type(self).model_fields:
                field = ".".join((*prefix, str(key)))
                known = ", ".join(type(self).model_fields)
                close = near_miss(str(key), list(type(self).model_fields))
                hint = f"; did you mean {close!r}?" if close else ""
                raise InputError(f"{where}: {field}: unknown vehicle field{hint} (known: {known})")
        try:
            key = (id(self), json.dumps(fields, sort_keys=True, default=repr))
        except (TypeError, ValueError):
            key = None
        cached = _OVERRIDDEN.get(key) if key is not None else None
        if cached is not None and cached[0] is self:
            return cached[1]
        data = self.model_dump()
        data.update(fields)
        try:
            vehicle = type(self).model_validate(data)
        except ValidationError as exc:
            raise input_error_from_validation(exc, where, prefix=prefix) from None
        if key is not None:
            if len(_OVERRIDDEN) >= _CACHE_LIMIT:
                _OVERRIDDEN.pop(next(iter(_OVERRIDDEN)))
            _OVERRIDDEN[key] = (self, vehicle)  # holds self, so its id stays its own
        return vehicle


def _per_rotor(value: float | tuple, n: int) -> np.ndarray:
    """A coefficient as one value per rotor: a single value repeated ``n`` times."""
    if isinstance(value, tuple):
        return np.array(value, dtype=float)
    return np.full(n, float(value))


# -------------------------------------------------------------------- loading
def bundled_vehicles() -> list[str]:
    """Names of the vehicles shipped with quadimpact (files ``inputs/vehicles/*.toml``).

    Returns
    -------
    list of str
        Sorted names, e.g. ``["spiri"]``.
    """
    folder = _vehicle_folder()
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


_BUNDLED: list[str] = []


def _bundled_names() -> list[str]:
    """:func:`bundled_vehicles`, listed once per process (the package's own files)."""
    if not _BUNDLED:
        _BUNDLED.extend(bundled_vehicles())
    return _BUNDLED


@functools.cache
def _vehicle_folder() -> Any:
    """The package folder of bundled vehicle files (an importlib.resources Traversable).

    Looked up once per process (about 0.3 ms a time).
    """
    return resources.files("quadimpact.inputs").joinpath("vehicles")


_CACHE: dict[tuple[str, int, int], Vehicle] = {}
_FEATURES: dict[int, tuple[Vehicle, tuple[ContactFeature, ...]]] = {}
_PLAUSIBILITY: dict[int, tuple[Vehicle, tuple[str, ...]]] = {}
_OVERRIDDEN: dict[tuple[int, str], tuple[Vehicle, Vehicle]] = {}
_CACHE_LIMIT = 64


@functools.cache
def _bundled_file(name: str) -> Any:
    """The file of the bundled vehicle ``name``: its absolute path (a ``str``) where the
    package is a folder, else its importlib.resources Traversable. Once per process per
    name (``pathlib`` and ``os.path.abspath`` cost more than the ``stat`` that follows)."""
    resource = _vehicle_folder().joinpath(f"{name}.toml")
    try:
        return os.path.abspath(os.fspath(resource))
    except TypeError:  # not a file system path (a zipped package): read through resources
        return resource


def _file_key(path: Any) -> tuple[str, int, int] | None:
    """(absolute path, modification time ns, size) of a real file, else ``None``."""
    try:
        st = os.stat(path)
    except (OSError, TypeError, ValueError):
        return None
    return (os.path.abspath(str(path)), st.st_mtime_ns, st.st_size)


def _read_vehicle(path: Any, where: str, default_name: str) -> Vehicle:
    """Parse and validate a vehicle file, once per process while the file is unchanged."""
    key = _file_key(path)
    if key is not None and key in _CACHE:
        return _CACHE[key]
    vehicle = _parse_vehicle(path, where, default_name)
    if key is not None:
        if len(_CACHE) >= _CACHE_LIMIT:
            _CACHE.pop(next(iter(_CACHE)))
        _CACHE[key] = vehicle  # a frozen model: safe to share
    return vehicle


def _parse_vehicle(path: Any, where: str, default_name: str) -> Vehicle:
    data = read_toml_file(path, where)
    data.setdefault("name", default_name)
    try:
        return Vehicle.model_validate(data)
    except ValidationError as exc:
        raise input_error_from_validation(exc, where, model=Vehicle) from None


def load_vehicle(name_or_path: str | Path | None = None) -> Vehicle:
    """Load a vehicle by bundled name or from a TOML file.

    A file is read and validated once per process while it is unchanged
    (keyed by its path, modification time and size); the same frozen
    :class:`Vehicle` is returned again.

    Parameters
    ----------
    name_or_path : str or pathlib.Path or None, optional
        ``None`` or ``"spiri"`` loads the bundled Spiri; any other bundled name
        (see :func:`bundled_vehicles`) loads that file; otherwise the path of a
        TOML file with the keys of :class:`Vehicle` (``name`` defaults to the
        file's stem).

    Returns
    -------
    Vehicle
        The validated vehicle.

    Raises
    ------
    InputError
        Unknown name, missing or unreadable file, invalid TOML, unknown key or
        a value that breaks a rule; the one-line message names the file and field.
    """
    if name_or_path is None:
        name_or_path = "spiri"
    if isinstance(name_or_path, str) and name_or_path in _bundled_names():
        return _read_vehicle(
            _bundled_file(name_or_path), f"vehicle {name_or_path}.toml", name_or_path
        )
    path = Path(name_or_path)
    where = f"vehicle {path}"
    if not path.is_file():
        if path.suffix == "" and len(path.parts) == 1:
            known = ", ".join(bundled_vehicles())
            raise InputError(
                f"vehicle {str(name_or_path)!r}: unknown vehicle name "
                f"(bundled: {known}; or give the path of a .toml file)"
            )
    return _read_vehicle(path, where, path.stem)
