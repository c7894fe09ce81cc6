"""The controller registry: every controller a scenario can name, with its parameters.

A controller is a compiled step (``quadimpact.core.controllers``), a model of
its parameters (validated, with defaults; units in the names) and a packer
that writes them into the kernel's parameter block (``ctrl[C_PARAMS:]``). One
:func:`register_controller` call makes a controller selectable by name in
scenario files (``controller = "..."``, ``[controller_params]``), in sweeps
and in ``quadimpact run --controller``.

Built-in controllers (``paper``, ``cascade-pid``, ``recovery``) have a kind id
that the cached kernel dispatches on. A controller registered with a ``step``
(a Numba ``njit`` function ``step(t, meas, ctrl, mem, veh, dt, cmd)``, see
``quadimpact.core.controllers``) runs in a kernel compiled for it
(``core.kernel.make_kernel``, once per process).

The registry lives in the process: a sweep's local worker processes see a
plug-in only when the registration runs on import of the main script (or of
a module it imports), not under ``if __name__ == "__main__":``
(docs/CONTROLLERS.md, "Plugging in a controller").
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, Field, StrictBool, field_validator

from quadimpact.core import controller_slots as CTL
from quadimpact.core import layout as L
from quadimpact.errors import InputError
from quadimpact.inputs.registry import Registry
from quadimpact.inputs.types import MODEL_CONFIG, Real, Vec3, Vec4

__all__ = [
    "CASCADE_GAINS",
    "CascadePidParams",
    "ControllerEntry",
    "PAPER_GAINS",
    "PackContext",
    "PaperParams",
    "RecoveryParams",
    "controller_entry",
    "controller_names",
    "param_index",
    "param_slots",
    "register_controller",
    "unregister_controller",
]

# Paper gains (docs/MODEL.md section 6.1): (P, I, D) for altitude, climb rate,
# heading, roll/pitch and yaw rate.
PAPER_GAINS = {
    "altitude_pid": (2.0, 0.0, 0.4),  # altitude h -> climb-rate reference
    "climb_pid": (1.6, 60.0, 0.0),  # climb rate -> vertical acceleration
    "heading_pid": (1.2, 1.0, 0.2),  # heading -> yaw-rate reference
    "attitude_pid": (7.2, 4.0, 4.2),  # roll and pitch -> angular acceleration
    "yaw_rate_pid": (1.8, 2.0, 0.0),  # yaw rate -> yaw acceleration
}
# cascade-pid gains: the paper's, retuned where a running integral changes the
# loop (linearised analysis in docs/CONTROLLERS.md): climb rate P 4, I 4 (the
# paper's 1.6 and 60 give damping 0.05 with a true integral); heading I 0 (the
# yaw-rate integral already removes steady yaw errors; paper 1) and yaw rate
# P 3, I 1 (paper 1.8, 2: damping 0.26 with running integrals). Every loop then
# has damping >= 0.7.
CASCADE_GAINS = {
    "altitude_pid": (2.0, 0.0, 0.4),
    "climb_pid": (4.0, 4.0, 0.0),
    "heading_pid": (1.2, 0.0, 0.2),
    "attitude_pid": (7.2, 4.0, 4.2),
    "yaw_rate_pid": (3.0, 1.0, 0.0),
}
_PID_FIELDS = ("altitude_pid", "climb_pid", "heading_pid", "attitude_pid", "yaw_rate_pid")


# ------------------------------------------------------------------ params
class PaperParams(BaseModel):
    """Gains of the ``paper`` controller: (P, I, D) of each loop (docs/MODEL.md 6.1)."""

    model_config = MODEL_CONFIG

    altitude_pid: Vec3 = Field(PAPER_GAINS["altitude_pid"], description="h -> climb rate.")
    climb_pid: Vec3 = Field(PAPER_GAINS["climb_pid"], description="climb rate -> accel.")
    heading_pid: Vec3 = Field(PAPER_GAINS["heading_pid"], description="heading -> yaw rate.")
    attitude_pid: Vec3 = Field(PAPER_GAINS["attitude_pid"], description="roll, pitch -> accel.")
    yaw_rate_pid: Vec3 = Field(PAPER_GAINS["yaw_rate_pid"], description="yaw rate -> accel.")

    def gains(self) -> np.ndarray:
        """The 15 gains in the kernel's order (``common.G_*`` blocks)."""
        return np.array([g for name in _PID_FIELDS for g in getattr(self, name)], dtype=float)


class CascadePidParams(PaperParams):
    """Gains of ``cascade-pid`` (retuned, docs/CONTROLLERS.md) and its tilt floor."""

    altitude_pid: Vec3 = Field(CASCADE_GAINS["altitude_pid"], description="h -> climb rate.")
    climb_pid: Vec3 = Field(CASCADE_GAINS["climb_pid"], description="climb rate -> accel.")
    heading_pid: Vec3 = Field(CASCADE_GAINS["heading_pid"], description="heading -> yaw rate.")
    attitude_pid: Vec3 = Field(CASCADE_GAINS["attitude_pid"], description="roll, pitch -> accel.")
    yaw_rate_pid: Vec3 = Field(CASCADE_GAINS["yaw_rate_pid"], description="yaw rate -> accel.")
    thrust_cos_floor: Real = Field(
        0.5, gt=0, le=1, description="Floor of cos(roll) cos(pitch) in the thrust compensation."
    )


class RecoveryParams(BaseModel):
    """Gains and thresholds of the ``recovery`` controller's staged law (docs/RECOVERY.md 3).

    The defaults are the default law since the benchmark (issue #45,
    docs/BENCHMARK.md 4): a push of 4.8 m/s^2 away from the contact, stage 1's
    rate test at 1 rad/s, a vertical-velocity gain of 2.5 1/s in stages 1 and 2
    and the lean cut at 40 deg with g/4 of push; the law before it is the
    ``recovery_law = "classic"`` tuning (:data:`quadimpact.inputs.model.CLASSIC_LAW`,
    model variant ``classic``). The pre-impact behaviour and the nominal
    controller are scenario fields (``pre_impact``, ``nominal_controller``).
    """

    model_config = MODEL_CONFIG

    k_att_1_s: Real = Field(20.0, ge=0, description="Tilt error -> rate reference, 1/s.")
    k_rate_1_s: Vec3 = Field(
        (20.0, 20.0, 2.0), description="Rate error -> angular acceleration (p, q, r), 1/s."
    )
    a_mag_m_s2: Real | None = Field(
        4.8, ge=0, description="Stage 1 push away from the wall, m/s^2; None: the vehicle's g."
    )
    k_z_1_s: Vec4 = Field(
        (2.5, 2.5, 10.0, 10.0), description="Vertical-velocity gain of stages 1-4, 1/s."
    )
    tilt_error_tol: Real = Field(
        0.3, gt=0, le=1, description="|q_e,x|, |q_e,y| below this end stages 1 and 2."
    )
    rate_tol_rad_s: Real = Field(1.0, gt=0, description="|p|, |q| below this end stages 1-2.")
    level_test: Literal["tilt-error", "euler"] = Field(
        "tilt-error",
        description="Stage 2's tilt test: the tilt error as stage 1's, or ZYX Euler roll, pitch.",
    )
    euler_tol_rad: Real = Field(
        0.2, gt=0, le=1.5, description="|roll|, |pitch| below this end stage 2 (euler test), rad."
    )
    w_tol_m_s: Real = Field(0.3, description="Body z velocity below this ends stage 3, m/s.")
    lean_cut_deg: Real | None = Field(
        40.0,
        ge=0,
        le=90,
        description="Stage 1 idles the rotors while the up axis leans toward the obstacle by "
        "more than this, deg; None: never.",
    )
    lean_cut_force_m_s2: Real = Field(
        2.4525,
        ge=0,
        description="The lean cut also needs a body-horizontal specific force of at least "
        "this (the contact still pushing), m/s^2; 0: whatever it is.",
    )
    hover: StrictBool = Field(
        True, description="Stage 5 after stage 4: return to hover, hold position and yaw."
    )
    hover_kp_1_s: Real = Field(1.5, ge=0, description="Stage 5 position -> velocity, 1/s.")
    hover_kv_1_s: Real = Field(4.0, ge=0, description="Stage 5 velocity -> acceleration, 1/s.")
    hover_v_max_m_s: Real = Field(1.0, gt=0, description="Stage 5 speed limit (XY, Z), m/s.")
    hover_a_max_m_s2: Real | None = Field(
        None, gt=0, description="Stage 5 acceleration limit (each of |a_XY|, |a_Z|); None: g/2."
    )
    hover_k_yaw_1_s: Real = Field(2.0, ge=0, description="Stage 5 yaw gain, 1/s.")
    hover_hold: Literal["stop", "entry"] = Field(
        "stop",
        description="Stage 5 holds where the vehicle stops, or the position at stage 4's entry.",
    )
    hover_set_point_m: Vec3 | None = Field(
        None, description="Stage 5 position set-point (inertial NED, m); None: hover_hold's."
    )
    policy: str | None = Field(
        None,
        description="A learned residual on the law from the detection on (to the recovery, or "
        "the hover too, as its file says): "
        "'learned' (the policy shipped with quadimpact) or a .npz policy file; None: the law "
        "alone.",
    )

    @field_validator("policy")
    @classmethod
    def _policy_file(cls, value: str | None) -> str | None:
        if value is None:
            return None
        from quadimpact.inputs.policy_file import load_policy, policy_ref

        try:
            load_policy(value)
        except InputError as exc:
            # "policy: FILE: rule" -> "rule" (the error names the field and the value given)
            raise ValueError(str(exc).removeprefix("policy: ").partition(": ")[2]) from None
        return policy_ref(value)


# ------------------------------------------------------------------ registry
@dataclass(frozen=True)
class PackContext:
    """What a packer may need besides its parameters (as resolved: ``simulation/resolve.py``).

    Attributes
    ----------
    vehicle : quadimpact.inputs.vehicle.Vehicle
    options : quadimpact.inputs.model.ModelOptions
        Every model switch of the run.
    pre_impact : str
        The recovery controller's pre-impact behaviour in force.
    nominal_controller : str
        The nominal controller's name (the wall approach's, or recovery's pre-impact).
    """

    vehicle: Any
    options: Any
    pre_impact: str
    nominal_controller: str


@dataclass(frozen=True)
class ControllerEntry:
    """One registered controller.

    Attributes
    ----------
    name : str
        As written in scenario files and on the command line.
    kind : int
        ``ctrl[C_KIND]``: a built-in ``CTRL_*`` id, or ``CTRL_USER`` for a plug-in.
    params : type of pydantic.BaseModel
        Its parameters (``[controller_params]``), with defaults.
    pack : callable or None
        ``pack(params, context) -> ndarray (NPARAM,)``: the parameter block;
        ``None``: a built-in's packer (``quadimpact.packing.controller_block``), or
        for a plug-in the default packing (the fields in order, :func:`param_slots`).
    step : callable or None
        The compiled step of a plug-in (``None`` for built-ins).
    description : str
        One line for help texts.
    """

    name: str
    kind: int
    params: type[BaseModel]
    pack: Callable[[BaseModel, PackContext], np.ndarray] | None
    step: Callable | None = None
    description: str = ""
    kernel_cache: dict = field(default_factory=dict, compare=False, repr=False)


class _NoParams(BaseModel):
    model_config = MODEL_CONFIG


def param_slots(params: type[BaseModel]) -> dict[str, tuple[int, int]]:
    """Where the default packing puts each field of a parameter model: ``{name: (offset,
    width)}`` in the controller's parameter block (``quadimpact.core.named.params(ctrl)``).

    The fields in their declared order: a number or a flag takes one slot, a
    tuple or list of ``n`` numbers ``n`` slots (its default's length).

    Raises
    ------
    TypeError
        A field of another kind (text, a table), or more than ``NPARAM`` slots.
    """
    slots: dict[str, tuple[int, int]] = {}
    offset = 0
    for name, info in params.model_fields.items():
        default = info.get_default(call_default_factory=True)
        if isinstance(default, (bool, int, float)) and not isinstance(default, str):
            width = 1
        elif isinstance(default, (tuple, list)) and all(
            isinstance(v, (int, float)) for v in default
        ):
            width = len(default)
        else:
            raise TypeError(
                f"{params.__name__}.{name}: the default packing takes numbers, flags and tuples "
                f"of numbers (got {default!r}); give register_controller a pack function"
            )
        slots[name] = (offset, width)
        offset += width
    if offset > CTL.NPARAM:
        raise TypeError(f"{params.__name__}: {offset} parameter slots, more than {CTL.NPARAM}")
    return slots


def param_index(params: type[BaseModel], name: str) -> int:
    """The offset of field ``name`` of a parameter model in its packed block (see
    :func:`param_slots`): ``named.params(ctrl)[param_index(MyParams, "k_p")]``."""
    return param_slots(params)[name][0]


PRE_IMPACT_CHOICES: tuple[str, ...] = ("nominal", "hold", "spin-down", "immediate")
"""The recovery controller's pre-impact behaviours (their ids: ``PRE_IMPACT_KINDS`` of
``core/controllers/recovery.py``)."""


_REGISTRY: Registry[ControllerEntry] = Registry(
    "controller",
    ("paper", "cascade-pid", "recovery"),
    entry_type=ControllerEntry,
    user_kind=L.CTRL_USER,
    no_params=_NoParams,
    empty_pack=None,
)


def register_controller(
    name: str,
    step: Callable | None = None,
    *,
    params: type[BaseModel] | None = None,
    pack: Callable[[BaseModel, PackContext], np.ndarray] | None = None,
    kind: int | None = None,
    description: str = "",
    replace: bool = False,
) -> ControllerEntry:
    """Make a controller selectable by ``name`` in scenarios, sweeps and the CLI.

    Parameters
    ----------
    name : str
        Its name (letters, digits, ``-`` and ``_``).
    step : callable, optional
        A Numba ``njit`` step ``step(t, meas, ctrl, mem, veh, dt, cmd)`` (a plug-in);
        omit for a built-in (then give ``kind``).
    params : pydantic model class, optional
        Its parameters with defaults (default: none).
    pack : callable, optional
        ``pack(params, context) -> ndarray (NPARAM,)``, the parameter block at
        ``ctrl[C_PARAMS:]`` (default: the model's fields in order,
        :func:`param_slots`; a step reads them by :func:`param_index`).
    kind : int, optional
        A built-in ``CTRL_*`` id of the cached kernel.
    description : str, optional
        One line for help texts.
    replace : bool, optional
        Replace an entry of the same name instead of refusing.

    Returns
    -------
    ControllerEntry
    """
    if pack is None and params is not None and kind is None:
        param_slots(params)  # the default packing can pack it (TypeError now, not at a run)
    return _REGISTRY.register(
        name, step, params=params, pack=pack, kind=kind, description=description, replace=replace
    )


def unregister_controller(name: str) -> None:
    """Remove a registered controller (built-ins cannot be removed)."""
    _REGISTRY.remove(name)


def controller_names() -> tuple[str, ...]:
    """Names of every registered controller, built-ins first."""
    return _REGISTRY.names()


def controller_entry(name: str) -> ControllerEntry:
    """The registry entry of ``name``.

    Raises
    ------
    InputError
        Unknown name (with the registered names and a near miss).
    """
    return _REGISTRY.entry(name)


def validate_params(name: str, values: Mapping[str, Any] | BaseModel | None) -> BaseModel:
    """The validated parameters of controller ``name`` (defaults for what is not given)."""
    return _REGISTRY.params(name, values)


register_controller(
    "paper",
    kind=L.CTRL_PAPER,
    params=PaperParams,
    description="the authors' discrete PID as they ran it (quirks included)",
)
register_controller(
    "cascade-pid",
    kind=L.CTRL_CASCADE_PID,
    params=CascadePidParams,
    description="the same loops with running integrals, anti-windup and rotor limits",
)
register_controller(
    "recovery",
    kind=L.CTRL_RECOVERY,
    params=RecoveryParams,
    description="pre-impact behaviour, then the staged recovery law after detection",
)
