"""Named access to the records a plug-in step receives: one function per quantity.

A controller plug-in's step is ``step(t, meas, ctrl, mem, veh, dt, cmd)``
(docs/CONTROLLERS.md): flat ``float64`` arrays whose slots ``core/layout.py``
declares. Instead of indexing them by hand (``meas[MS_X + X_QUAT : ...]``), a
plug-in calls the functions here, each named after the quantity it returns,
with its unit and frame, compiled and inlined (the same machine code as the
indexing)::

    from quadimpact.core import named

    @njit
    def step(t, meas, ctrl, mem, veh, dt, cmd):
        q = named.attitude(meas)              # the estimate's quaternion
        w = named.body_rates(meas)            # rad/s, body FRD
        m, g = named.mass(veh), named.gravity(veh)
        ...

Arrays are returned as views: read them, never write them (the loop owns
them); ``cmd`` (a speed per rotor, rad/s: ``rotor_count(veh)`` of them) is
what a step writes, and ``mem``
(its own floats, kept between ticks) what it may write. Its own parameters
are ``params(ctrl)``, in the order of its parameter model's fields when the
registry packs them (``param_index`` names them: docs/CONTROLLERS.md).

The same quantities, read-only and by name, from Python: :data:`STATE_FIELDS`,
:data:`MEASUREMENT_FIELDS` (what ``Simulation.state`` and
``Simulation.measurement`` hand out, ``simulation/stepping.py``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadimpact.core.compiled import allocating
from quadimpact.core.controller_slots import (
    C_ALLOC_INV,
    C_H_REF,
    C_OMEGA_MAX,
    C_OMEGA_MIN,
    C_PARAMS,
    C_PHI_REF,
    C_PSI_REF,
    C_THETA_REF,
    N_WRENCH,
    NPARAM,
)
from quadimpact.core.layout import MAX_ROTORS, NX, X_OMEGA, X_POS, X_QUAT, X_ROTOR, X_VEL
from quadimpact.core.sensors.measurement_slots import (
    MS_BIAS_HAT,
    MS_DETECTED,
    MS_IMU_F,
    MS_IMU_T,
    MS_IMU_W,
    MS_NORMAL,
    MS_T,
    MS_T_DETECT,
    MS_W_HAT,
    MS_X,
)
from quadimpact.core.sensors.registry import measurement_address
from quadimpact.core.vehicle_slots import V_GRAVITY, V_INERTIA, V_KT, V_MASS, V_N_ROTORS

__all__ = [
    "MEASUREMENT_FIELDS",
    "STATE_FIELDS",
    "Field",
    "NamedVector",
    "block_fields",
    "allocation_inverse",
    "attitude",
    "body_rates",
    "detected",
    "detection_time",
    "gravity",
    "gyro_bias",
    "imu_body_rates",
    "imu_specific_force",
    "imu_time",
    "inertia",
    "magnetometer",
    "mass",
    "params",
    "position",
    "references",
    "rotor_count",
    "rotor_speed_range",
    "rotor_speeds",
    "thrust_coefficient",
    "thrust_coefficients",
    "tick_time",
    "velocity_body",
    "wall_normal",
]

MS_MAG = measurement_address("magnetometer", "field")  # a sensor component's slot


# ----------------------------------------------------------- the measurement
@allocating(inline="always")
def position(meas: np.ndarray) -> np.ndarray:
    """The estimate's CM position, inertial NED, m (3,)."""
    return meas[MS_X + X_POS : MS_X + X_POS + 3]


@allocating(inline="always")
def velocity_body(meas: np.ndarray) -> np.ndarray:
    """The estimate's CM velocity, body FRD, m/s (3,)."""
    return meas[MS_X + X_VEL : MS_X + X_VEL + 3]


@allocating(inline="always")
def attitude(meas: np.ndarray) -> np.ndarray:
    """The estimate's attitude quaternion, scalar first, body -> inertial (4,)."""
    return meas[MS_X + X_QUAT : MS_X + X_QUAT + 4]


@allocating(inline="always")
def body_rates(meas: np.ndarray) -> np.ndarray:
    """The estimated body rates (gyro minus the estimated bias), body FRD, rad/s (3,)."""
    return meas[MS_W_HAT : MS_W_HAT + 3]


@allocating(inline="always")
def rotor_speeds(meas: np.ndarray) -> np.ndarray:
    """The rotor speeds at the tick, rad/s (MAX_ROTORS,) (measured: the motor controllers
    report them); the entries beyond the vehicle's ``rotor_count(veh)`` are 0."""
    return meas[MS_X + X_ROTOR : MS_X + X_ROTOR + MAX_ROTORS]


@allocating(inline="always")
def tick_time(meas: np.ndarray) -> float:
    """The time of the tick, s."""
    return meas[MS_T]


@allocating(inline="always")
def imu_specific_force(meas: np.ndarray) -> np.ndarray:
    """The latest accelerometer sample (specific force), body FRD, m/s^2 (3,)."""
    return meas[MS_IMU_F : MS_IMU_F + 3]


@allocating(inline="always")
def imu_body_rates(meas: np.ndarray) -> np.ndarray:
    """The latest gyro sample, body FRD, rad/s (3,)."""
    return meas[MS_IMU_W : MS_IMU_W + 3]


@allocating(inline="always")
def imu_time(meas: np.ndarray) -> float:
    """The time of the latest IMU sample, s (NaN before the first)."""
    return meas[MS_IMU_T]


@allocating(inline="always")
def gyro_bias(meas: np.ndarray) -> np.ndarray:
    """The estimated gyro bias, body FRD, rad/s (3,)."""
    return meas[MS_BIAS_HAT : MS_BIAS_HAT + 3]


@allocating(inline="always")
def magnetometer(meas: np.ndarray) -> np.ndarray:
    """The latest magnetometer sample, body FRD, unit field (3,) (NaN without one)."""
    return meas[MS_MAG : MS_MAG + 3]


@allocating(inline="always")
def detected(meas: np.ndarray) -> bool:
    """Whether the impact detector has fired (docs/RECOVERY.md 2)."""
    return meas[MS_DETECTED] > 0.5


@allocating(inline="always")
def detection_time(meas: np.ndarray) -> float:
    """The time of the detecting IMU sample, s (NaN before a detection)."""
    return meas[MS_T_DETECT]


@allocating(inline="always")
def wall_normal(meas: np.ndarray) -> np.ndarray:
    """The estimated obstacle normal at the detection, inertial, unit (3,), away from it."""
    return meas[MS_NORMAL : MS_NORMAL + 3]


# ------------------------------------------------------------ the controller
@allocating(inline="always")
def params(ctrl: np.ndarray) -> np.ndarray:
    """The controller's own parameter block (NPARAM,): its parameter model's fields, in order."""
    return ctrl[C_PARAMS : C_PARAMS + NPARAM]


@allocating(inline="always")
def references(ctrl: np.ndarray) -> tuple[float, float, float, float]:
    """The scenario's references: altitude (m, up) and roll, pitch, yaw (rad, Z-Y-X)."""
    return ctrl[C_H_REF], ctrl[C_PHI_REF], ctrl[C_THETA_REF], ctrl[C_PSI_REF]


@allocating(inline="always")
def allocation_inverse(ctrl: np.ndarray) -> np.ndarray:
    """The (pseudo-)inverse allocation (MAX_ROTORS, 4): squared rotor speeds, (rad/s)^2, of
    thrust (N) and the body torques (N m): ``Omega^2 = A^+ [T, tau_x, tau_y, tau_z]``; the
    rows beyond the vehicle's rotor count are 0 (``controllers.common.allocate``)."""
    return ctrl[C_ALLOC_INV : C_ALLOC_INV + N_WRENCH * MAX_ROTORS].reshape((MAX_ROTORS, N_WRENCH))


@allocating(inline="always")
def rotor_speed_range(ctrl: np.ndarray) -> tuple[float, float]:
    """The vehicle's rotor speed range, rad/s (lowest, highest)."""
    return ctrl[C_OMEGA_MIN], ctrl[C_OMEGA_MAX]


# --------------------------------------------------------------- the vehicle
@allocating(inline="always")
def mass(veh: np.ndarray) -> float:
    """The vehicle's mass, kg."""
    return veh[V_MASS]


@allocating(inline="always")
def gravity(veh: np.ndarray) -> float:
    """The gravitational acceleration, m/s^2."""
    return veh[V_GRAVITY]


@allocating(inline="always")
def inertia(veh: np.ndarray) -> np.ndarray:
    """The inertia matrix about the CM, body FRD, kg m^2 (3, 3)."""
    return veh[V_INERTIA : V_INERTIA + 9].reshape((3, 3))


@allocating(inline="always")
def thrust_coefficient(veh: np.ndarray) -> float:
    """Rotor 1's thrust coefficient, N/(rad/s)^2 (every rotor's when they share one)."""
    return veh[V_KT]


@allocating(inline="always")
def thrust_coefficients(veh: np.ndarray) -> np.ndarray:
    """Each rotor's thrust coefficient, N/(rad/s)^2 (MAX_ROTORS,); 0 beyond the rotor count."""
    return veh[V_KT : V_KT + MAX_ROTORS]


@allocating(inline="always")
def rotor_count(veh: np.ndarray) -> int:
    """The vehicle's number of rotors ``n`` (4 to MAX_ROTORS)."""
    return int(veh[V_N_ROTORS])


# ------------------------------------------------------------- from Python
@dataclass(frozen=True)
class Field:
    """One named quantity of a flat record: its slots, unit and meaning."""

    name: str
    offset: int
    size: int
    unit: str
    description: str


#: The state vector (``Simulation.state``), layout ``X_*``.
STATE_FIELDS: tuple[Field, ...] = (
    Field("position", X_POS, 3, "m", "CM position, inertial NED"),
    Field("velocity_body", X_VEL, 3, "m/s", "CM velocity, body FRD"),
    Field("attitude", X_QUAT, 4, "1", "quaternion, scalar first, body -> inertial"),
    Field("body_rates", X_OMEGA, 3, "rad/s", "angular velocity, body FRD"),
    Field("rotor_speeds", X_ROTOR, MAX_ROTORS, "rad/s", "rotor speeds (0 beyond the rotor count)"),
)
assert sum(f.size for f in STATE_FIELDS) == NX

#: The measurement record (``Simulation.measurement``), layout ``MS_*``: the estimate's
#: state, then what the sensors and the detector give the controller.
MEASUREMENT_FIELDS: tuple[Field, ...] = (
    *(
        Field(f.name, MS_X + f.offset, f.size, f.unit, "estimate: " + f.description)
        for f in STATE_FIELDS
        if f.name != "body_rates"
    ),  # fmt: skip
    Field("body_rates", MS_W_HAT, 3, "rad/s", "estimated body rates (gyro minus bias)"),
    Field("tick_time", MS_T, 1, "s", "time of the tick"),
    Field("imu_time", MS_IMU_T, 1, "s", "time of the latest IMU sample (NaN: none yet)"),
    Field("imu_specific_force", MS_IMU_F, 3, "m/s^2", "accelerometer sample, body FRD"),
    Field("imu_body_rates", MS_IMU_W, 3, "rad/s", "gyro sample, body FRD"),
    Field("gyro_bias", MS_BIAS_HAT, 3, "rad/s", "estimated gyro bias, body FRD"),
    Field("magnetometer", MS_MAG, 3, "1", "magnetometer sample, body FRD (unit field)"),
    Field("detected", MS_DETECTED, 1, "1", "1 once an impact has been detected"),
    Field("detection_time", MS_T_DETECT, 1, "s", "time of the detecting sample (NaN: none)"),
    Field("wall_normal", MS_NORMAL, 3, "1", "obstacle normal estimated at detection, inertial"),
)


def block_fields(array: str, prefix: str, at: int = 0) -> tuple[Field, ...]:
    """A block's slots as fields, named after their constants (``ST_T_END`` -> ``t_end``).

    ``at``: the offset of the region the block lies in (a part of ``stats``
    declared by its owner, at ``ST_HOVER``...); its fields' offsets add it.
    """
    from quadimpact.core.layout import Block

    block = Block.registry[f"{array}:{prefix}"]
    return tuple(
        Field(name.removeprefix(prefix).lower(), at + offset, width, "", f"slot {name} of {array}")
        for name, (offset, width) in block.slots.items()
    )


class NamedVector(np.ndarray):
    """A read-only copy of a flat record whose quantities are also attributes.

    It is the record's array (``v[3]``, ``np.asarray(v)`` work as before) with
    each :class:`Field` as a read-only attribute: ``v.position`` is the
    position's three numbers, ``v.detected`` a float. :meth:`fields` lists
    them. A slice or a computed array is a plain array.
    """

    _fields: dict[str, Field] | None

    def __new__(cls, values: np.ndarray, fields: tuple[Field, ...]) -> NamedVector:
        obj = np.array(values, dtype=np.float64).view(cls)
        obj._fields = {f.name: f for f in fields}
        obj.setflags(write=False)
        return obj

    def __array_finalize__(self, obj: object) -> None:
        same = obj is not None and getattr(obj, "shape", None) == self.shape
        self._fields = getattr(obj, "_fields", None) if same else None

    def __array_wrap__(self, out: np.ndarray, context: object = None, return_scalar: bool = False):
        plain = out.view(np.ndarray)
        return plain[()] if return_scalar else plain

    def __getattr__(self, name: str) -> np.ndarray | float:
        try:
            fields = object.__getattribute__(self, "_fields")
        except AttributeError:  # not set up yet (NumPy's own construction)
            fields = None
        field = (fields or {}).get(name)
        if field is None:
            raise AttributeError(f"{type(self).__name__} has no field {name!r}")
        values = self.view(np.ndarray)[field.offset : field.offset + field.size]
        return float(values[0]) if field.size == 1 else values

    def fields(self) -> tuple[Field, ...]:
        """The named quantities, in the record's order."""
        return tuple(self._fields.values()) if self._fields else ()

    def __dir__(self) -> list[str]:
        return [*super().__dir__(), *(self._fields or {})]
