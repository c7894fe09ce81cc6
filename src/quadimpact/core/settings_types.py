"""The settings types a component module declares its settings model with.

``Real`` is a finite float that refuses booleans and strings (TOML ``true`` or
``"1.0"`` are mistakes, not numbers); NumPy scalars are accepted.
``MODEL_CONFIG`` refuses unknown keys and non-finite numbers and freezes the
model. They live in ``core`` so that a component (``core/sensors/``) can
declare its settings next to its slots; ``inputs/types.py`` re-exports them.
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BeforeValidator, ConfigDict

__all__ = ["MODEL_CONFIG", "Real"]

MODEL_CONFIG = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)
"""The settings of every input model: unknown keys refused, immutable, finite numbers only."""


def _real(value: Any) -> Any:
    if hasattr(value, "item") and not isinstance(value, (list, tuple)):
        value = value.item()
    if isinstance(value, (bool, str)):
        raise ValueError("must be a number")
    return value


Real = Annotated[float, BeforeValidator(_real)]
"""A finite float (finiteness is enforced by ``allow_inf_nan=False`` on the models)."""
