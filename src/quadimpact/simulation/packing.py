"""The one place where validated inputs become the compiled core's flat arrays.

Slots are named in ``quadimpact.core.layout``. Nothing here integrates.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from quadimpact.core import layout as L
from quadimpact.errors import InputError
from quadimpact.inputs.controllers import ControllerEntry, PackContext
from quadimpact.inputs.features import ContactFeature
from quadimpact.inputs.sensors import DetectionSettings, ResolvedImu
from quadimpact.inputs.vehicle import Vehicle
from quadimpact.inputs.world import Box, Cylinder, Plane
from quadimpact.linalg import inverse, lu_factor, lu_solve, norm
from quadimpact.rotations import euler_zyx_to_quat, quat_to_matrix

CONTROL_RATE_HZ = 200.0
RPM = 2.0 * np.pi / 60.0  # rad/s per rpm

# Integrator defaults, chosen by measurement (docs/NUMERICS.md,
# benchmarks/bench_tolerance.py): tightening both tenfold changes delta_init
# of the paper example by far less than 1e-4 relative.
DEFAULT_RTOL = 1e-8
DEFAULT_ATOL = 1e-10
EVENT_TOL_S = 1e-12
V_MIN_M_S = 1e-3  # floor of v_i in the damping coefficient (docs/MODEL.md 4)
FRICTION_V_REG_M_S = 1e-2  # friction regularisation velocity
MAX_STEPS_PER_S = 2_000_000


_PACKED: dict[tuple[int, str], tuple[Vehicle, Any]] = {}
_PACKED_LIMIT = 128


def _memo(kind: str, v: Vehicle, make: Any) -> np.ndarray:
    """A copy of ``make()`` computed once per (frozen) vehicle object and kind."""
    return _memo_value(kind, v, make).copy()


def _memo_value(kind: str, v: Vehicle, make: Any) -> Any:
    """``make()`` computed once per (frozen) vehicle object and kind (not copied: immutable)."""
    key = (id(v), kind)
    hit = _PACKED.get(key)
    if hit is None or hit[0] is not v:
        if len(_PACKED) >= _PACKED_LIMIT:
            _PACKED.pop(next(iter(_PACKED)))
        hit = (v, make())  # holds v, so its id stays its own
        _PACKED[key] = hit
    return hit[1]


def pack_vehicle(v: Vehicle) -> np.ndarray:
    """Vehicle parameters as the ``V_*`` vector (SI, body frame); computed once per vehicle."""
    return _memo("veh", v, lambda: _pack_vehicle(v))


def _pack_vehicle(v: Vehicle) -> np.ndarray:
    veh = np.zeros(L.NVEH)
    inertia = v.inertia
    veh[L.V_MASS] = v.mass_kg
    veh[L.V_INERTIA : L.V_INERTIA + 9] = inertia.ravel()
    veh[L.V_INERTIA_INV : L.V_INERTIA_INV + 9] = inverse(inertia).ravel()
    veh[L.V_ROTOR_POS : L.V_ROTOR_POS + 12] = v.rotor_positions.ravel()
    veh[L.V_SPIN : L.V_SPIN + 4] = v.spins
    veh[L.V_KT] = v.thrust_coefficient
    veh[L.V_DT] = v.drag_torque_coefficient
    veh[L.V_JR] = v.rotor_inertia_kg_m2
    veh[L.V_GRAVITY] = v.gravity_m_s2
    veh[L.V_TAU_M] = v.motor_time_constant_s
    return veh


#: Feature kinds by their names in vehicle data (``core.layout.FeatureKind``).
FEATURE_KINDS: dict[str, int] = {
    "ring": L.FEAT_RING,
    "sphere": L.FEAT_SPHERE,
    "point": L.FEAT_POINT,
}


def pack_features(
    v: Vehicle, friction_coefficient: float, force_scale: Sequence[float] | None = None
) -> np.ndarray:
    """The vehicle's contact features as an (n, NFEAT) array (body frame, SI).

    ``friction_coefficient``: the scenario's, for the features that set none.
    ``force_scale``: a factor on each feature's normal force, in the
    vehicle's feature order (the model switch ``bumper_force_scale``: bumpers
    1-4 of a four-ring vehicle); None or all ones: the contact law itself.
    """
    feat = _memo("feat", v, lambda: _pack_features(v.contact_features()))
    feat[np.isnan(feat[:, L.F_MU]), L.F_MU] = friction_coefficient
    if force_scale is not None and any(f != 1.0 for f in force_scale):
        if len(force_scale) != feat.shape[0]:
            raise InputError(
                f"bumper_force_scale: {len(force_scale)} factors for the {feat.shape[0]} contact "
                "features of this vehicle"
            )
        feat[:, L.F_FORCE_SCALE] = force_scale
    return feat


def _pack_features(features: Sequence[ContactFeature]) -> np.ndarray:
    feat = np.zeros((len(features), L.NFEAT))
    for i, f in enumerate(features):
        feat[i, L.F_KIND] = FEATURE_KINDS[f.kind]
        feat[i, L.F_CENTRE : L.F_CENTRE + 3] = f.centre_m
        feat[i, L.F_NORMAL : L.F_NORMAL + 3] = f.normal
        feat[i, L.F_RADIUS] = f.radius_m
        feat[i, L.F_K] = f.stiffness
        feat[i, L.F_N] = f.exponent
        feat[i, L.F_E] = f.restitution
        feat[i, L.F_MU] = np.nan if f.friction_coefficient is None else f.friction_coefficient
        feat[i, L.F_FORCE_SCALE] = 1.0
    return feat


def feature_records(feat: np.ndarray, names: Sequence[str]) -> list[dict[str, Any]]:
    """The packed contact features as plain data (``scenario.json``), body FRD, SI.

    Per feature: ``name``, ``kind`` (ring, sphere, point), ``centre_m``,
    ``normal`` (rings), ``radius_m``, ``stiffness``, ``exponent``,
    ``restitution``, ``friction_coefficient`` (the one in force).
    """
    kinds = {v: k for k, v in FEATURE_KINDS.items()}
    out = []
    for name, row in zip(names, feat, strict=True):
        kind = kinds[int(row[L.F_KIND])]
        rec: dict[str, Any] = {
            "name": str(name),
            "kind": kind,
            "centre_m": [float(c) for c in row[L.F_CENTRE : L.F_CENTRE + 3]],
        }
        if kind == "ring":
            rec["normal"] = [float(c) for c in row[L.F_NORMAL : L.F_NORMAL + 3]]
        if kind != "point":
            rec["radius_m"] = float(row[L.F_RADIUS])
        rec.update(
            stiffness=float(row[L.F_K]),
            exponent=float(row[L.F_N]),
            restitution=float(row[L.F_E]),
            friction_coefficient=float(row[L.F_MU]),
        )
        out.append(rec)
    return out


def pack_surfaces(surfaces: Sequence[Plane | Cylinder | Box]) -> np.ndarray:
    """Surfaces (planes, cylinders, boxes) as an (n, NSHAPE) array of world shapes.

    Plane normals and cylinder axes are normalised (again); a box's axes are
    the columns of its ZYX rotation, stored as the rows of ``SH_ROT``; an
    infinite cylinder has ``SH_LENGTH = inf``.
    """
    surf = np.zeros((len(surfaces), L.NSHAPE))
    for i, s in enumerate(surfaces):
        surf[i, L.SH_IS_GROUND] = 1.0 if getattr(s, "is_ground", False) else 0.0
        if isinstance(s, Cylinder):
            e = np.asarray(s.axis, dtype=float)
            surf[i, L.SH_KIND] = L.SHAPE_CYLINDER
            surf[i, L.SH_POINT : L.SH_POINT + 3] = s.point_m
            surf[i, L.SH_NORMAL : L.SH_NORMAL + 3] = e / norm(e)
            surf[i, L.SH_RADIUS] = s.radius_m
            surf[i, L.SH_LENGTH] = np.inf if s.length_m is None else s.length_m
            continue
        if isinstance(s, Box):
            surf[i, L.SH_KIND] = L.SHAPE_BOX
            surf[i, L.SH_POINT : L.SH_POINT + 3] = s.centre_m
            surf[i, L.SH_HALF : L.SH_HALF + 3] = s.half_extents_m
            surf[i, L.SH_ROT : L.SH_ROT + 9] = np.asarray(s.axes(), dtype=float).ravel()
            continue
        n = np.asarray(s.normal, dtype=float)
        surf[i, L.SH_POINT : L.SH_POINT + 3] = s.point_m
        surf[i, L.SH_NORMAL : L.SH_NORMAL + 3] = n / norm(n)
        surf[i, L.SH_KIND] = L.SHAPE_PLANE
    return surf


#: Surface kinds by the names written in ``scenario.json`` (``core.layout.ShapeKind``).
SURFACE_KINDS: dict[str, int] = {
    "plane": L.SHAPE_PLANE,
    "cylinder": L.SHAPE_CYLINDER,
    "box": L.SHAPE_BOX,
}


def _floats(a: np.ndarray) -> list[float]:
    return [float(c) for c in a]


def surface_records(surf: np.ndarray, names: Sequence[str]) -> list[dict[str, Any]]:
    """The packed surfaces as plain data, as the kernel received them (``scenario.json``).

    Parameters
    ----------
    surf : numpy.ndarray, shape (n, NSHAPE)
        Packed surfaces (:func:`pack_surfaces`).
    names : sequence of str
        Their names, in the same order.

    Returns
    -------
    list of dict
        Per surface: ``name``, ``kind`` (a key of :data:`SURFACE_KINDS`),
        ``is_ground`` and its geometry (inertial NED, m): a plane's
        ``point_m`` and ``normal`` (unit, out of the obstacle); a cylinder's
        ``point_m`` (on the axis), ``axis`` (unit), ``radius_m`` and
        ``length_m`` (null: infinite); a box's ``centre_m``,
        ``half_extents_m`` and ``axes`` (its own x, y, z axes, rows).
        :func:`pack_surface_records` gives ``surf`` back bit for bit.
    """
    kinds = {v: k for k, v in SURFACE_KINDS.items()}
    out: list[dict[str, Any]] = []
    for name, row in zip(names, surf, strict=True):
        kind = kinds[int(row[L.SH_KIND])]
        if kind == "plane":
            rec: dict[str, Any] = {
                "name": str(name),
                "point_m": _floats(row[L.SH_POINT : L.SH_POINT + 3]),
                "normal": _floats(row[L.SH_NORMAL : L.SH_NORMAL + 3]),
                "is_ground": bool(row[L.SH_IS_GROUND] > 0.5),
                "kind": kind,
            }
        elif kind == "cylinder":
            length = float(row[L.SH_LENGTH])
            rec = {
                "name": str(name),
                "kind": kind,
                "point_m": _floats(row[L.SH_POINT : L.SH_POINT + 3]),
                "axis": _floats(row[L.SH_NORMAL : L.SH_NORMAL + 3]),
                "radius_m": float(row[L.SH_RADIUS]),
                "length_m": length if np.isfinite(length) else None,
                "is_ground": bool(row[L.SH_IS_GROUND] > 0.5),
            }
        else:
            rec = {
                "name": str(name),
                "kind": kind,
                "centre_m": _floats(row[L.SH_POINT : L.SH_POINT + 3]),
                "half_extents_m": _floats(row[L.SH_HALF : L.SH_HALF + 3]),
                "axes": [_floats(row[L.SH_ROT + 3 * i : L.SH_ROT + 3 * i + 3]) for i in range(3)],
                "is_ground": bool(row[L.SH_IS_GROUND] > 0.5),
            }
        out.append(rec)
    return out


def pack_surface_records(records: Sequence[Mapping[str, Any]]) -> np.ndarray:
    """The packed surfaces of :func:`surface_records`' output (no normalisation: as recorded).

    Raises
    ------
    ValueError
        A record with a kind not in :data:`SURFACE_KINDS`.
    """
    surf = np.zeros((len(records), L.NSHAPE))
    for i, r in enumerate(records):
        kind = r.get("kind", "plane")
        if kind not in SURFACE_KINDS:
            known = ", ".join(SURFACE_KINDS)
            name = r.get("name")
            raise ValueError(f"surface {name!r}: kind must be one of {known} (got {kind!r})")
        surf[i, L.SH_IS_GROUND] = 1.0 if r.get("is_ground") else 0.0
        surf[i, L.SH_KIND] = SURFACE_KINDS[kind]
        if kind == "cylinder":
            surf[i, L.SH_POINT : L.SH_POINT + 3] = [float(c) for c in r["point_m"]]
            surf[i, L.SH_NORMAL : L.SH_NORMAL + 3] = [float(c) for c in r["axis"]]
            surf[i, L.SH_RADIUS] = float(r["radius_m"])
            length = r.get("length_m")
            surf[i, L.SH_LENGTH] = np.inf if length is None else float(length)
        elif kind == "box":
            surf[i, L.SH_POINT : L.SH_POINT + 3] = [float(c) for c in r["centre_m"]]
            surf[i, L.SH_HALF : L.SH_HALF + 3] = [float(c) for c in r["half_extents_m"]]
            surf[i, L.SH_ROT : L.SH_ROT + 9] = [float(c) for row in r["axes"] for c in row]
        else:
            surf[i, L.SH_POINT : L.SH_POINT + 3] = [float(c) for c in r["point_m"]]
            surf[i, L.SH_NORMAL : L.SH_NORMAL + 3] = [float(c) for c in r["normal"]]
    return surf


def allocation_matrix(v: Vehicle, yaw_paper: bool) -> np.ndarray:
    """``A`` with ``[T, tau_x, tau_y, tau_z] = A [Omega_1^2 .. Omega_4^2]`` (docs/MODEL.md 6.1).

    Rows: ``kt``, ``-kt y_j``, ``kt x_j`` and the yaw row of the rotor-torque
    model in use: ``-s_j dt`` (physical) or ``+s_j dt`` (paper replica).
    """
    kt = v.thrust_coefficient
    r = v.rotor_positions
    yaw = v.drag_torque_coefficient * v.spins * (1.0 if yaw_paper else -1.0)
    return np.vstack([np.full(4, kt), -kt * r[:, 1], kt * r[:, 0], yaw])


def trim_rotor_speeds(v: Vehicle, thrust_n: float, yaw_paper: bool) -> np.ndarray:
    """Rotor speeds (rad/s) giving total thrust ``thrust_n`` (N) and zero torques."""
    lu = _memo_value(f"alloc-lu-{yaw_paper}", v, lambda: lu_factor(allocation_matrix(v, yaw_paper)))
    w2 = lu_solve(lu, [thrust_n, 0.0, 0.0, 0.0])  # = solve(A, b), A eliminated once per vehicle
    return np.sqrt(np.maximum(w2, 0.0))  # np.clip's bits (the -0.0 and NaN cases too), faster


def pack_controller(
    entry: ControllerEntry,
    params: object,
    context: PackContext,
    yaw_paper: bool,
) -> np.ndarray:
    """Controller settings as the ``C_*`` vector, references 0 (a run's: :func:`set_references`).

    The common head (kind, inverse allocation, the vehicle's rotor range)
    and the controller's parameter block (its registry entry's packer).
    """
    v: Vehicle = context.vehicle
    ctrl = np.zeros(L.NCTRL)
    ctrl[L.C_KIND] = entry.kind
    ctrl[L.C_ALLOC_INV : L.C_ALLOC_INV + 16] = _memo(
        f"alloc-inv-{yaw_paper}", v, lambda: inverse(allocation_matrix(v, yaw_paper)).ravel()
    )
    lo, hi = v.rotor_speed_range_rpm
    ctrl[L.C_OMEGA_MIN] = lo * RPM
    ctrl[L.C_OMEGA_MAX] = hi * RPM
    block = np.asarray(entry.pack(params, context), dtype=float)
    if block.shape != (L.NPARAM,):
        raise ValueError(f"controller {entry.name!r}: its packer must return {L.NPARAM} numbers")
    ctrl[L.C_PARAMS : L.C_PARAMS + L.NPARAM] = block
    return ctrl


def set_references(ctrl: np.ndarray, refs: Mapping[str, float]) -> None:
    """Write the references into a ``C_*`` vector, in place (m and rad).

    ``refs`` holds ``altitude_m``, ``roll_rad``, ``pitch_rad``, ``yaw_rad``;
    the only slots of the controller's vector that depend on them (with the
    reference's body z axis, :func:`reference_z_axis`).
    """
    ctrl[L.C_H_REF] = refs["altitude_m"]
    ctrl[L.C_PHI_REF] = refs["roll_rad"]
    ctrl[L.C_THETA_REF] = refs["pitch_rad"]
    ctrl[L.C_PSI_REF] = refs["yaw_rad"]
    ctrl[L.C_Z_REF : L.C_Z_REF + 3] = reference_z_axis(refs)


def pack_waypoint(ctrl: np.ndarray, waypoint: Any, start_m: Any) -> None:
    """The waypoint flight's slots of a ``C_*`` vector, in place (``waypoint``: a
    :class:`~quadimpact.inputs.waypoint.Waypoint`; ``start_m``: the position held first)."""
    ctrl[L.C_WAYPOINT_ON] = 1.0
    ctrl[L.C_HOLD_POS : L.C_HOLD_POS + 3] = start_m
    ctrl[L.C_WAYPOINT : L.C_WAYPOINT + 3] = (waypoint.x_m, waypoint.y_m, 0.0)
    ctrl[L.C_WAYPOINT_T] = waypoint.time_s
    ctrl[L.C_POS_GAINS : L.C_POS_GAINS + 4] = (
        waypoint.kp_1_s,
        waypoint.kv_1_s,
        waypoint.v_max_m_s,
        math.radians(waypoint.tilt_max_deg),
    )


def reference_z_axis(refs: Mapping[str, float]) -> np.ndarray:
    """The reference attitude's body z axis in inertial axes (NED, unit): the third column
    of ``C`` of the ZYX attitude (``roll_rad``, ``pitch_rad``, ``yaw_rad``), from which the
    summary's tilt is measured."""
    q = euler_zyx_to_quat(refs["roll_rad"], refs["pitch_rad"], refs["yaw_rad"])
    return quat_to_matrix(q)[:, 2]


def pack_options(
    *,
    yaw_paper: bool,
    spinup_paper: bool,
    contact_gate_m: float,
    bumper1_yaw_twice: bool,
    crash_rule: int,
    crash_altitude_m: float,
    stop_on_crash: bool,
    first_order_rotors: bool,
    omega_limits_rad_s: tuple[float, float] | None,
    slew_limit_rad_s2: float | None,
    rtol: float | None,
    atol: float | None,
    duration_s: float,
    cut_step_motors: Sequence[int] = (),
) -> np.ndarray:
    """Model switches and integrator settings as the ``O_*`` vector.

    ``cut_step_motors``: the motors (1-4) a power-off schedule cuts at the
    first control tick after its trigger (``O_CUT_STEP_MOTORS``, motor ``j``
    as bit ``j - 1``; docs/VARIANTS.md).
    """
    opts = np.zeros(L.NOPT)
    opts[L.O_YAW_REACTION_PAPER] = float(yaw_paper)
    opts[L.O_SPINUP_PAPER] = float(spinup_paper)
    opts[L.O_CONTACT_GATE] = float(contact_gate_m)
    opts[L.O_DOUBLE_BUMPER1_YAW] = float(bumper1_yaw_twice)
    opts[L.O_CRASH_RULE] = crash_rule
    opts[L.O_CRASH_ALTITUDE] = crash_altitude_m
    opts[L.O_STOP_ON_CRASH] = float(stop_on_crash)
    opts[L.O_ROTOR_MODE] = L.ROTOR_FIRST_ORDER if first_order_rotors else L.ROTOR_IDEAL
    if omega_limits_rad_s is not None:
        opts[L.O_OMEGA_MIN], opts[L.O_OMEGA_MAX] = omega_limits_rad_s
    opts[L.O_SLEW_MAX] = slew_limit_rad_s2 or 0.0
    opts[L.O_V_REG] = FRICTION_V_REG_M_S
    opts[L.O_V_MIN] = V_MIN_M_S
    opts[L.O_DT_CONTROL] = 1.0 / CONTROL_RATE_HZ
    opts[L.O_RTOL] = DEFAULT_RTOL if rtol is None else rtol
    opts[L.O_ATOL] = DEFAULT_ATOL if atol is None else atol
    opts[L.O_H_MAX] = 0.0
    opts[L.O_MAX_STEPS] = max(100_000, MAX_STEPS_PER_S * duration_s)
    opts[L.O_EVENT_TOL] = EVENT_TOL_S
    opts[L.O_POWER_OFF_T] = np.inf
    opts[L.O_CUT_STEP_MOTORS] = float(sum(1 << (m - 1) for m in set(cut_step_motors)))
    return opts


def schedule_rates(rates_rpm_per_s: Sequence[Sequence[float]], zero_rate: str) -> np.ndarray:
    """A power-off schedule's rates as the kernel takes them, rad/s^2.

    With ``zero_rate = "off"`` a rate of exactly 0 (or -0) is the motor
    switched off over the segment (``core.layout.MOTOR_OFF``: its speed 0
    from the segment's start); with ``"hold"`` it keeps its speed.
    """
    rpm = np.asarray(rates_rpm_per_s, dtype=float).reshape(-1, 4)
    rates = rpm * RPM
    if zero_rate == "off":
        rates[rpm == 0.0] = L.MOTOR_OFF
    return rates


def pack_sensors(
    imu: ResolvedImu,
    detection: DetectionSettings,
    v: Vehicle,
    duration_s: float,
) -> tuple[np.ndarray, int]:
    """The IMU and detector as the ``SC_*`` vector and the sample count (no random draw).

    The biases' slots stay 0 here: :func:`draw_imu_noise` fills them with the run's seed.

    Returns
    -------
    scfg : ndarray (NSCFG,)
    n_imu : int
        Samples the run takes at most: ``t0`` and every ``1/rate`` to the end.
    """
    scfg = np.zeros(L.NSCFG)
    rate = float(imu.rate_hz)
    n_imu = int(np.floor(duration_s * rate + 1e-9)) + 2
    scfg[L.SC_RATE] = rate
    scfg[L.SC_POS : L.SC_POS + 3] = imu.position_m
    scfg[L.SC_NOISE_F] = imu.accel_noise_m_s2
    scfg[L.SC_NOISE_W] = imu.gyro_noise_rad_s
    scfg[L.SC_RANGE_F] = imu.accel_range_m_s2 or 0.0
    scfg[L.SC_RANGE_W] = imu.gyro_range_rad_s or 0.0
    scfg[L.SC_FILTER] = {
        "none": L.FILTER_NONE,
        "first-order": L.FILTER_FIRST_ORDER,
        "moving-average": L.FILTER_MOVING_AVERAGE,
    }[imu.filter]
    if imu.filter == "first-order":
        scfg[L.SC_FILTER_PARAM] = float(imu.filter_time_constant_s)
    elif imu.filter == "moving-average":
        scfg[L.SC_FILTER_PARAM] = float(imu.filter_window)
    if detection.enabled:
        scfg[L.SC_DET_THRESHOLD] = detection.threshold_g * v.gravity_m_s2
    scfg[L.SC_DET_WORLD] = 1.0 if detection.frame == "world" else 0.0
    scfg[L.SC_DET_PERSIST] = float(detection.persistence)
    return scfg, n_imu


def draw_imu_noise(imu: ResolvedImu, seed: int, n_imu: int, scfg: np.ndarray) -> np.ndarray:
    """The IMU's random draws of a run: its biases (into ``scfg``, in place) and white noise.

    NumPy's PCG64 seeded with ``seed``: first the six biases (standard
    normal times the configured bias standard deviation: accelerometer
    m/s^2, gyro rad/s, body axes), then one row of six standard normal
    numbers per sample, only when the IMU has noise or bias (an ideal IMU
    draws nothing and gets a (0, 6) array).

    Returns
    -------
    noise : ndarray (n_imu, 6) or (0, 6)
    """
    if not imu.has_noise:
        return np.zeros((0, 6))
    rng = np.random.default_rng(seed)
    sigma_bias = np.array([imu.accel_bias_m_s2] * 3 + [imu.gyro_bias_rad_s] * 3)
    scfg[L.SC_BIAS : L.SC_BIAS + 6] = rng.standard_normal(6) * sigma_bias
    return rng.standard_normal((n_imu, 6))
