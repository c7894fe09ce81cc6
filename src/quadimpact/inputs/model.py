"""Model options: the switches between the physically consistent model and the
authors' simulators, and the four named model variants (docs/VARIANTS.md)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal

from pydantic import BaseModel, Field, StrictBool, ValidationError, field_validator

from quadimpact.errors import InputError, input_error_from_validation
from quadimpact.inputs.types import MODEL_CONFIG, Real, Vec4

__all__ = [
    "MODEL_VARIANTS",
    "CLASSIC_LAW",
    "RECOVERY_LAWS",
    "ModelName",
    "ModelOptions",
    "recovery_law_params",
    "resolve_model_options",
]

ModelName = Literal["default", "classic", "paper-replica", "recovery-replica", "pole-replica"]


class ModelOptions(BaseModel):
    """Switches between the physically consistent model and the authors' simulator.

    Each field left ``None`` takes the value of the chosen model variant
    (:data:`MODEL_VARIANTS`); set it to change that single behaviour. The
    ``default`` variant is the physically consistent model (docs/MODEL.md);
    ``paper-replica`` reproduces the code behind the paper's figures and
    ``recovery-replica`` the authors' later recovery simulator, errors
    included (docs/VARIANTS.md), so that published numbers can be checked and
    each correction's effect seen on its own; ``pole-replica`` is the default
    model with the staged recovery law retuned as in the authors' pole study.

    Attributes
    ----------
    yaw_reaction : {"physical", "paper"} or None
        Sense of the rotor drag torque on the body. ``"physical"`` (default):
        ``-s_j dt Omega_j^2``, the motor torque reacting on the body, consistent
        with the gyroscopic term. ``"paper"`` (both replicas): ``+s_j dt Omega_j^2``.
        The controller's allocation yaw row follows the model in use.
    spinup_reaction : {"physical", "paper"} or None
        Rotor spin-up reaction on the body. ``"physical"`` (default and the
        recovery replica): ``-s_j Jr dOmega_j/dt``. ``"paper"`` (paper replica):
        ``-Jr sum_j dOmega_j/dt``, without the spin sign.
    bumper1_yaw_twice : bool or None
        ``True`` (replica) counts bumper 1's contact yaw moment (body z
        component) twice, as the authors' code did; ``False`` (default) once.
    initial_rotor_speeds : {"trimmed", "level-hover"} or None
        ``"trimmed"`` (default): initial rotor speeds from the allocation of
        thrust ``m g / (cos(roll) cos(pitch))`` with zero torques.
        ``"level-hover"`` (replica): all four at ``sqrt(m g / (4 kt))`` whatever
        the tilt.
    attitude_mapping : {"exact", "paper-fit"} or None
        How a wall approach's heading and inclination become roll and pitch.
        ``"exact"`` (default): ZYX Euler angles with yaw = heading and the body
        z axis in the inertial X-Z plane at the inclination from Z.
        ``"paper-fit"`` (replica): the authors' fitted mapping, for heading 0
        roll 0 and pitch ``-inclination``; for heading +-45 deg
        ``roll = pitch = -(incl - 0.0042477) / 1.3836686`` (rad); other
        headings as ``"exact"``.
    crash_rule : {"cm-ground", "paper-ticks", "ground-ticks"} or None
        ``"cm-ground"`` (default): crash when the CM reaches altitude 0,
        located exactly as an integrator event. ``"paper-ticks"`` (replica):
        crash when the altitude is at or below -0.3 m, tested at the control
        ticks after the start. ``"ground-ticks"`` (the authors' crash runs of
        Table III): at or below altitude 0, tested at the control ticks after
        the start.
    approach_start : {"late-start", "paper"} or None
        ``"late-start"`` (default): when the vehicle would have to start
        moving away from the wall (needed initial speed < 0), it starts at rest
        later, at the time that brings it to the wall at the requested time
        and speed. ``"paper"`` (replica): it starts at t = 0 even moving away
        from the wall, and later at rest only when the start point would lie
        beyond the wall. Control ticks run at ``t0 + k dt`` from the start.
    detection_tick_reference : {"tilt-away", "level"} or None
        The ``recovery`` controller's target at the tick of detection.
        ``"tilt-away"`` (default): stage 1's push away from the wall from that
        tick on. ``"level"`` (recovery replica): a level target at that tick,
        the tilt away from the next tick on.
    contact_gate_m : float or None
        ``0`` (default): contact forces wherever a bumper penetrates. ``> 0``
        (recovery replica: 0.30 m): contact forces act only while the CM is
        within this distance of the surface (the authors' broad-phase test),
        so a bumper may already be ~16 mm deep when its force switches on; the
        gate crossing is a located event.
    pre_impact : {"scenario", "spin-down", "hold"} or None
        ``"scenario"`` (default): the ``recovery`` controller's pre-impact
        behaviour is the scenario's ``pre_impact``. ``"spin-down"`` (recovery
        replica): always spin-down, as in the authors' Monte Carlo code.
        ``"hold"`` (pole replica): always hold, the rotor speeds at their
        trimmed values until the detection.
    recovery_law : {"lean-cut", "classic", "pole-replica"} or None
        The tuning of the ``recovery`` controller's staged law: the values its
        parameters take when ``[controller_params]`` does not set them
        (:data:`RECOVERY_LAWS`). ``"lean-cut"`` (the default model, since the
        benchmark, issue #45): the controller's own defaults (docs/RECOVERY.md
        3.5). ``"classic"`` (the ``classic`` variant and the replicas): the law
        that was the default until then (:data:`CLASSIC_LAW`; named
        ``"default"`` before, a name still read as ``"classic"``).
        ``"pole-replica"``: the authors' pole branch
        (a_mag 4.8 m/s^2, stage 1 test 0.15 and 2 rad/s, stage 2's Euler-angle
        test at 0.2 rad and 2 rad/s, stage 3 ends at w < 0.2 m/s) on the
        classic law.
    cut_step_motors : tuple of int or None
        Motors (1-4) that a power-off schedule cuts at the first control tick
        after its trigger, as a one-tick command step: the motor keeps its
        speed from the trigger to that tick, is then at 0 and stays off, and
        the spin-up reaction sees ``-Omega / dt`` over that tick's interval (a
        yaw kick of about 2.6 N m for 5 ms at hover speed). ``()`` (every
        variant): none, the schedule alone drives the motors. The authors'
        crash runs of Table III: ``(2,)`` (docs/EXPERIMENTS.md).
    bumper_force_scale : 4 floats or None
        Factor on each bumper's contact force (bumpers 1-4), ``> 0``.
        ``(1, 1, 1, 1)`` (every variant): the contact law. The authors' run
        of crash I-03 (Table III row 1) had ``(1, 2, 1, 1)``, an undocumented
        hand modification (docs/EXPERIMENTS.md).
    """

    model_config = MODEL_CONFIG

    yaw_reaction: Literal["physical", "paper"] | None = Field(
        None, description="Rotor yaw reaction torque: 'physical' or the authors' 'paper' signs."
    )
    bumper1_yaw_twice: StrictBool | None = Field(
        None, description="Count bumper 1's contact yaw moment twice (authors' code)."
    )
    initial_rotor_speeds: Literal["trimmed", "level-hover"] | None = Field(
        None, description="Initial rotor speeds: trimmed for the tilt, or all at level hover."
    )
    attitude_mapping: Literal["exact", "paper-fit"] | None = Field(
        None, description="Heading/inclination -> roll/pitch: exact, or the authors' fit."
    )
    crash_rule: Literal["cm-ground", "paper-ticks", "ground-ticks"] | None = Field(
        None,
        description="Crash: CM at h = 0 (event), h <= -0.3 m at control ticks, or h <= 0 "
        "at control ticks.",
    )
    approach_start: Literal["late-start", "paper"] | None = Field(
        None,
        description="Wall-approach start rule when v0 would be < 0: start later at rest, "
        "or the authors' rule.",
    )
    spinup_reaction: Literal["physical", "paper"] | None = Field(
        None, description="Rotor spin-up reaction: with the spin sign, or the paper's without."
    )
    detection_tick_reference: Literal["tilt-away", "level"] | None = Field(
        None, description="Recovery target at the detection tick: tilt away, or level."
    )
    contact_gate_m: Real | None = Field(
        None, ge=0, le=10, description="Contact forces only with the CM this close, m; 0: off."
    )
    pre_impact: Literal["scenario", "spin-down", "hold"] | None = Field(
        None, description="Recovery pre-impact behaviour: the scenario's, spin-down or hold."
    )
    recovery_law: Literal["lean-cut", "classic", "pole-replica"] | None = Field(
        None,
        description="Staged recovery law's parameters not set in [controller_params]: the "
        "default law's (lean-cut), the classic law's (named 'default' before), or the "
        "authors' pole branch's.",
    )
    cut_step_motors: tuple[int, ...] | None = Field(
        None,
        description="Motors (1-4) a power-off schedule cuts at the first tick after its "
        "trigger as a one-tick command step.",
    )
    bumper_force_scale: Vec4 | None = Field(
        None, description="Factor (> 0) on the contact force of bumpers 1-4."
    )

    @field_validator("recovery_law", mode="before")
    @classmethod
    def _classic_law_old_name(cls, value: Any) -> Any:
        # "default" was the classic law's name while it was the default (before issue #45);
        # files written then still read, as the law they meant
        return "classic" if value == "default" else value

    @field_validator("cut_step_motors")
    @classmethod
    def _motor_numbers(cls, value: tuple[int, ...] | None) -> tuple[int, ...] | None:
        if value is not None and (
            any(m not in (1, 2, 3, 4) for m in value) or len(set(value)) != len(value)
        ):
            raise ValueError("distinct motor numbers 1-4")
        return value

    @field_validator("bumper_force_scale")
    @classmethod
    def _positive_scales(cls, value: tuple[float, ...] | None) -> tuple[float, ...] | None:
        if value is not None and not min(value) > 0:
            raise ValueError("every factor must be > 0")
        return value


MODEL_VARIANTS: dict[str, dict[str, Any]] = {
    "default": {
        "yaw_reaction": "physical",
        "bumper1_yaw_twice": False,
        "initial_rotor_speeds": "trimmed",
        "attitude_mapping": "exact",
        "crash_rule": "cm-ground",
        "approach_start": "late-start",
        "spinup_reaction": "physical",
        "detection_tick_reference": "tilt-away",
        "contact_gate_m": 0.0,
        "pre_impact": "scenario",
        "recovery_law": "classic",
        "cut_step_motors": (),
        "bumper_force_scale": (1.0, 1.0, 1.0, 1.0),
    },
    "paper-replica": {
        "yaw_reaction": "paper",
        "bumper1_yaw_twice": True,
        "initial_rotor_speeds": "level-hover",
        "attitude_mapping": "paper-fit",
        "crash_rule": "paper-ticks",
        "approach_start": "paper",
        "spinup_reaction": "paper",
        "detection_tick_reference": "tilt-away",
        "contact_gate_m": 0.0,
        "pre_impact": "scenario",
        "recovery_law": "classic",
        "cut_step_motors": (),
        "bumper_force_scale": (1.0, 1.0, 1.0, 1.0),
    },
    "recovery-replica": {
        "yaw_reaction": "paper",
        "bumper1_yaw_twice": False,
        "initial_rotor_speeds": "trimmed",
        "attitude_mapping": "exact",
        "crash_rule": "cm-ground",
        "approach_start": "late-start",
        "spinup_reaction": "physical",
        "detection_tick_reference": "level",
        "contact_gate_m": 0.30,
        "pre_impact": "spin-down",
        "recovery_law": "classic",
        "cut_step_motors": (),
        "bumper_force_scale": (1.0, 1.0, 1.0, 1.0),
    },
}
# the previous default model: the default physics with the staged law quadimpact had as its
# default before the benchmark's (issue #45), so that earlier numbers reproduce; the default
# model flies the benchmark's law (the controller's own defaults)
MODEL_VARIANTS["classic"] = dict(MODEL_VARIANTS["default"])
MODEL_VARIANTS["default"]["recovery_law"] = "lean-cut"
# the pole replica: the default model with the authors' retuned pole law and held rotors
MODEL_VARIANTS["pole-replica"] = {
    **MODEL_VARIANTS["default"],
    "pre_impact": "hold",
    "recovery_law": "pole-replica",
}
"""Every switch of :class:`ModelOptions` for each named model variant."""

CLASSIC_LAW: dict[str, Any] = {
    "a_mag_m_s2": None,
    "k_z_1_s": (0.0, 0.0, 10.0, 10.0),
    "rate_tol_rad_s": 0.5,
    "lean_cut_deg": None,
    "lean_cut_force_m_s2": 0.0,
}
"""The staged law's values before issue #45 where they differ from today's defaults
(docs/RECOVERY.md 3.5): the ``classic`` law of the ``classic`` variant and of the replicas."""

RECOVERY_LAWS: dict[str, dict[str, Any]] = {
    "lean-cut": {},
    "classic": CLASSIC_LAW,
    "pole-replica": {
        **CLASSIC_LAW,
        "a_mag_m_s2": 4.8,
        "tilt_error_tol": 0.15,
        "rate_tol_rad_s": 2.0,
        "level_test": "euler",
        "euler_tol_rad": 0.2,
        "w_tol_m_s": 0.2,
    },
}
"""The staged recovery law's tunings (switch ``recovery_law``): the ``recovery``
controller's parameters (``RecoveryParams``) each sets; a parameter a tuning
does not name keeps its own default (docs/RECOVERY.md 3.5, docs/VARIANTS.md 8)."""


def recovery_law_params(law: str, given: Mapping[str, Any]) -> dict[str, Any]:
    """The ``recovery`` controller's parameters under tuning ``law``.

    Parameters
    ----------
    law : {"lean-cut", "classic", "pole-replica"}
        The ``recovery_law`` switch.
    given : mapping
        The scenario's ``[controller_params]``; they win over the tuning.

    Returns
    -------
    dict
        The tuning's values (:data:`RECOVERY_LAWS`) with ``given`` on top.
    """
    tuning = RECOVERY_LAWS[law]
    if not tuning:
        return dict(given)
    return {**tuning, **given}


def resolve_model_options(
    model: str, overrides: ModelOptions | Mapping[str, Any] | None = None
) -> ModelOptions:
    """All model switches for a variant, with some of them overridden.

    Parameters
    ----------
    model : {"default", "paper-replica", "recovery-replica", "pole-replica"}
        The model variant.
    overrides : ModelOptions or mapping or None, optional
        Switches to change; ``None`` values (or missing keys) keep the variant's.

    Returns
    -------
    ModelOptions
        Every field set (none is ``None``).

    Raises
    ------
    InputError
        Unknown variant, unknown switch or invalid value.
    """
    if model not in MODEL_VARIANTS:
        known = ", ".join(repr(name) for name in MODEL_VARIANTS)
        raise InputError(f"model: must be one of {known} (got {model!r})")
    if isinstance(overrides, ModelOptions) or overrides is None:
        key = (model, overrides)  # frozen models hash by their values
        hit = _RESOLVED.get(key)
        if hit is None:
            hit = _resolve(model, overrides)
            if len(_RESOLVED) < 256:
                _RESOLVED[key] = hit
        return hit
    return _resolve(model, overrides)


_RESOLVED: dict[Any, ModelOptions] = {}


def _resolve(model: str, overrides: ModelOptions | Mapping[str, Any] | None) -> ModelOptions:
    values = dict(MODEL_VARIANTS[model])
    if overrides is not None:
        if not isinstance(overrides, ModelOptions):
            try:
                overrides = ModelOptions.model_validate(dict(overrides))
            except ValidationError as exc:
                raise input_error_from_validation(
                    exc, prefix=("model_options",), model=ModelOptions
                ) from None
        values.update(overrides.model_dump(exclude_none=True))
    return ModelOptions(**values)
