"""Validated number and array types shared by the input models.

``Real`` is a finite float that refuses booleans and strings (TOML ``true`` or
``"1.0"`` are mistakes, not numbers); NumPy scalars are accepted. Fixed-size
vectors and matrices check their shape first, so that a wrong length is
reported as one clear rule instead of one error per missing element. NumPy
arrays are accepted wherever a list is.
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BeforeValidator

from quadimpact.core.layout import MAX_ROTORS
from quadimpact.core.settings_types import MODEL_CONFIG, Real

__all__ = [
    "MODEL_CONFIG",
    "Real",
    "Sign",
    "SignVec4",
    "Vec2",
    "Vec3",
    "Vec4",
    "Mat3",
    "Mat4x3",
    "RotorRows",
    "RotorSigns",
    "RotorReals",
]


def _int_sign(value: Any) -> Any:
    if hasattr(value, "item") and not isinstance(value, (list, tuple)):
        value = value.item()
    if isinstance(value, (bool, str)):
        raise ValueError("must be +1 or -1")
    return value


def _vector(n: int):
    def check(value: Any) -> Any:
        if hasattr(value, "tolist"):
            value = value.tolist()
        if not isinstance(value, (list, tuple)):
            raise ValueError(f"must be a list of {n} numbers")
        if len(value) != n:
            raise ValueError(f"must have exactly {n} numbers (got {len(value)})")
        return value

    return check


def _matrix(rows: int, cols: int, row_name: str = "rows"):
    def check(value: Any) -> Any:
        if hasattr(value, "tolist"):
            value = value.tolist()
        if not isinstance(value, (list, tuple)) or not all(
            isinstance(row, (list, tuple)) for row in value
        ):
            raise ValueError(f"must be a list of {rows} rows of {cols} numbers")
        if len(value) != rows:
            raise ValueError(f"must have exactly {rows} {row_name} (got {len(value)})")
        for i, row in enumerate(value):
            if len(row) != cols:
                raise ValueError(f"row {i + 1} must have exactly {cols} numbers (got {len(row)})")
        return value

    return check


def _rotor_rows(value: Any) -> Any:
    if hasattr(value, "tolist"):
        value = value.tolist()
    if not isinstance(value, (list, tuple)) or not all(
        isinstance(row, (list, tuple)) for row in value
    ):
        raise ValueError(f"must be a list of {MIN_ROTORS} to {MAX_ROTORS} rows of 3 numbers")
    if not MIN_ROTORS <= len(value) <= MAX_ROTORS:
        raise ValueError(
            f"must have {MIN_ROTORS} to {MAX_ROTORS} rows, one per rotor (got {len(value)})"
        )
    for i, row in enumerate(value):
        if len(row) != 3:
            raise ValueError(f"row {i + 1} must have exactly 3 numbers (got {len(row)})")
    return value


def _rotor_list(value: Any) -> Any:
    if hasattr(value, "tolist"):
        value = value.tolist()
    if not isinstance(value, (list, tuple)):
        return value  # a single number: the model's union takes it
    if not MIN_ROTORS <= len(value) <= MAX_ROTORS:
        raise ValueError(
            f"must have {MIN_ROTORS} to {MAX_ROTORS} entries, one per rotor (got {len(value)})"
        )
    return value


Sign = Annotated[int, BeforeValidator(_int_sign)]
"""An integer, meant to be +1 or -1 (checked by the model)."""

Vec2 = Annotated[tuple[Real, Real], BeforeValidator(_vector(2))]
Vec3 = Annotated[tuple[Real, Real, Real], BeforeValidator(_vector(3))]
Vec4 = Annotated[tuple[Real, Real, Real, Real], BeforeValidator(_vector(4))]
SignVec4 = Annotated[tuple[Sign, Sign, Sign, Sign], BeforeValidator(_vector(4))]
"""Four integers, meant to be +1 or -1 (checked by the model)."""

#: The fewest and the most rotors a vehicle may have (``core.layout.MAX_ROTORS``).
MIN_ROTORS = 4
RotorRows = Annotated[tuple[tuple[Real, Real, Real], ...], BeforeValidator(_rotor_rows)]
"""One row of 3 numbers per rotor, MIN_ROTORS to MAX_ROTORS rows."""
RotorSigns = Annotated[tuple[Sign, ...], BeforeValidator(_rotor_list)]
"""One integer per rotor (+1 or -1, checked by the model), MIN_ROTORS to MAX_ROTORS of them."""
RotorReals = Annotated[tuple[Real, ...], BeforeValidator(_rotor_list)]
"""One number per rotor, MIN_ROTORS to MAX_ROTORS of them."""

Mat3 = Annotated[
    tuple[tuple[Real, Real, Real], tuple[Real, Real, Real], tuple[Real, Real, Real]],
    BeforeValidator(_matrix(3, 3)),
]
Mat4x3 = Annotated[
    tuple[
        tuple[Real, Real, Real],
        tuple[Real, Real, Real],
        tuple[Real, Real, Real],
        tuple[Real, Real, Real],
    ],
    BeforeValidator(_matrix(4, 3, "rows (one per rotor)")),
]
