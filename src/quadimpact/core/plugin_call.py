"""A plug-in's step called by address: the one compiled loop runs every plug-in.

A plug-in controller or estimator is a user's ``numba.njit`` function. The
loop does not compile it in: the plug-in is compiled alone, for one fixed
signature (:data:`CONTROLLER_SIGNATURE`, :data:`ESTIMATOR_SIGNATURE`), and
the address of its compiled entry point is written into its run's arrays
(``ctrl[C_STEP]``, ``ecfg[EC_STEP]``; an address below 2**53 is exact in a
float64). The loop calls it through that address (:func:`call_controller`,
:func:`call_estimator`). So the loop is compiled once, cached on disk, and the
same for the built-ins and for every plug-in; a plug-in costs the compile of
its own code.

This is what Numba's first-class function type (``types.FunctionType``) does
when a compiled function is passed as an argument: the call goes through the
entry point's address, with Numba's calling convention, so an exception the
plug-in raises reaches the caller. Passing such a value in the run's records
would cost a Python-side typing of the record at every call of the loop
(about 60 microseconds, against 1 for arrays only), so the address travels as
a number instead.

An address is valid in the process that compiled the plug-in only: it is set
when a run is prepared (``simulation.setup``) and a run's arrays are not sent
to another process. An address of 0 means none: the loop runs the built-in
dispatch (a controller's ``hold_step``; no estimator update).
"""

from __future__ import annotations

from typing import Any

from numba import types
from numba.core import cgutils
from numba.core.errors import TypingError
from numba.extending import intrinsic

__all__ = [
    "CONTROLLER_SIGNATURE",
    "ESTIMATOR_SIGNATURE",
    "call_controller",
    "call_estimator",
    "entry_address",
]

_VECTOR = types.Array(types.float64, 1, "C")

CONTROLLER_SIGNATURE = types.none(
    types.float64, _VECTOR, _VECTOR, _VECTOR, _VECTOR, types.float64, _VECTOR
)
"""``step(t, meas, ctrl, mem, veh, dt, cmd) -> None`` (``core/controllers/__init__.py``)."""

ESTIMATOR_SIGNATURE = types.none(types.float64, types.float64, _VECTOR, _VECTOR, _VECTOR)
"""``estimator(t, dt, meas, ecfg, est) -> None`` (``core/estimators/__init__.py``)."""


def _check(name: str, signature: Any, address: Any, args: tuple) -> None:
    if not isinstance(address, types.Integer):
        raise TypingError(f"{name}: the address must be an integer, got {address}")
    if tuple(args) != tuple(signature.args):
        raise TypingError(f"{name}: arguments {args}, expected {signature.args}")


def _codegen(signature: Any) -> Any:
    """Code calling the entry point at the first argument with the others (Numba's convention)."""

    def codegen(context: Any, builder: Any, sig: Any, llargs: Any) -> Any:
        callconv = context.call_conv
        fnty = callconv.get_function_type(signature.return_type, signature.args)
        address = context.cast(builder, llargs[0], sig.args[0], types.intp)
        callee = builder.inttoptr(address, fnty.as_pointer())
        status, _ = callconv.call_function(
            builder, callee, signature.return_type, signature.args, llargs[1:]
        )
        with cgutils.if_unlikely(builder, status.is_error):
            callconv.return_status_propagate(builder, status)  # the plug-in raised
        return context.get_dummy_value()

    return codegen


@intrinsic
def call_controller(typingctx, address, t, meas, ctrl, mem, veh, dt, cmd):
    """``call_controller(address, t, meas, ctrl, mem, veh, dt, cmd)``: a plug-in controller."""
    args = (t, meas, ctrl, mem, veh, dt, cmd)
    _check("call_controller", CONTROLLER_SIGNATURE, address, args)
    return types.none(address, *args), _codegen(CONTROLLER_SIGNATURE)


@intrinsic
def call_estimator(typingctx, address, t, dt, meas, ecfg, est):
    """``call_estimator(address, t, dt, meas, ecfg, est)``: a plug-in estimator's step."""
    args = (t, dt, meas, ecfg, est)
    _check("call_estimator", ESTIMATOR_SIGNATURE, address, args)
    return types.none(address, *args), _codegen(ESTIMATOR_SIGNATURE)


def entry_address(fn: Any, signature: Any) -> int:
    """Compile the ``njit`` function ``fn`` for ``signature`` alone; its entry point's address.

    The compiled code stays owned by ``fn`` (keep a reference to it while the
    address is used). Raises Numba's typing error if ``fn`` does not compile
    for these arguments, and ``TypeError`` if it returns a value.
    """
    fn.compile(signature.args)
    cres = fn.overloads[tuple(signature.args)]
    if cres.signature.return_type != signature.return_type:
        raise TypeError(f"returns {cres.signature.return_type}; it must return nothing")
    return int(cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name))
