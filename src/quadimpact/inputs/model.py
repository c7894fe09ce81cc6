"""Model options: the switches between the physically consistent model and the
authors' simulator (MODEL.md section 8), and the two named model variants."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal

from pydantic import BaseModel, Field, ValidationError

from quadimpact.errors import InputError, input_error_from_validation
from quadimpact.inputs.types import MODEL_CONFIG

__all__ = ["MODEL_VARIANTS", "ModelName", "ModelOptions", "resolve_model_options"]

ModelName = Literal["default", "paper-replica"]


class ModelOptions(BaseModel):
    """Switches between the physically consistent model and the authors' simulator.

    Each field left ``None`` takes the value of the chosen model variant
    (:data:`MODEL_VARIANTS`); set it to change that single behaviour. The
    ``default`` variant is the physically consistent model of MODEL.md
    sections 2-7; the ``paper-replica`` variant reproduces the code behind the
    paper's figures, errors included (MODEL.md section 8), so that published
    numbers can be checked and each correction's effect seen on its own.

    Attributes
    ----------
    yaw_reaction : {"physical", "paper"} or None
        Rotor yaw reaction on the body. ``"physical"`` (default): drag torque
        ``-s_j dt Omega_j^2`` and spin-up term ``-s_j Jr dOmega_j/dt``, the motor
        torque reacting on the body, consistent with the gyroscopic term.
        ``"paper"`` (replica): drag torque ``+s_j dt Omega_j^2`` and spin-up
        ``-Jr sum_j dOmega_j/dt`` (no ``s_j``); the controller's allocation yaw row
        follows the model in use.
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
    crash_rule : {"cm-ground", "paper-ticks"} or None
        ``"cm-ground"`` (default): crash when the CM reaches altitude 0,
        located exactly as an integrator event. ``"paper-ticks"`` (replica):
        crash when the altitude is at or below -0.3 m, tested at the control
        ticks only.
    approach_start : {"late-start", "paper"} or None
        ``"late-start"`` (default): when the vehicle would have to start
        moving away from the wall (needed initial speed < 0), it starts at rest
        later, at the time that brings it to the wall at the requested time
        and speed. ``"paper"`` (replica): it starts at t = 0 even moving away
        from the wall, and later at rest only when the start point would lie
        beyond the wall. Control ticks run at ``t0 + k dt`` from the start.
    """

    model_config = MODEL_CONFIG

    yaw_reaction: Literal["physical", "paper"] | None = Field(
        None, description="Rotor yaw reaction torque: 'physical' or the authors' 'paper' signs."
    )
    bumper1_yaw_twice: bool | None = Field(
        None, description="Count bumper 1's contact yaw moment twice (authors' code)."
    )
    initial_rotor_speeds: Literal["trimmed", "level-hover"] | None = Field(
        None, description="Initial rotor speeds: trimmed for the tilt, or all at level hover."
    )
    attitude_mapping: Literal["exact", "paper-fit"] | None = Field(
        None, description="Heading/inclination -> roll/pitch: exact, or the authors' fit."
    )
    crash_rule: Literal["cm-ground", "paper-ticks"] | None = Field(
        None, description="Crash: CM at h = 0 (event), or h <= -0.3 m at control ticks."
    )
    approach_start: Literal["late-start", "paper"] | None = Field(
        None,
        description="Wall-approach start rule when v0 would be < 0: start later at rest, "
        "or the authors' rule.",
    )


MODEL_VARIANTS: dict[str, dict[str, Any]] = {
    "default": {
        "yaw_reaction": "physical",
        "bumper1_yaw_twice": False,
        "initial_rotor_speeds": "trimmed",
        "attitude_mapping": "exact",
        "crash_rule": "cm-ground",
        "approach_start": "late-start",
    },
    "paper-replica": {
        "yaw_reaction": "paper",
        "bumper1_yaw_twice": True,
        "initial_rotor_speeds": "level-hover",
        "attitude_mapping": "paper-fit",
        "crash_rule": "paper-ticks",
        "approach_start": "paper",
    },
}
"""Every switch of :class:`ModelOptions` for each named model variant."""


def resolve_model_options(
    model: str, overrides: ModelOptions | Mapping[str, Any] | None = None
) -> ModelOptions:
    """All model switches for a variant, with some of them overridden.

    Parameters
    ----------
    model : {"default", "paper-replica"}
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
