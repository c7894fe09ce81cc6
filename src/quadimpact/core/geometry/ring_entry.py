"""The ring's certified search against a cylinder or a box, compiled once and called by address.

:func:`ring_solid` (``ring.py``) is the largest code of the contact geometry:
about 20 compiled functions. Linked into its callers the usual way, its
machine code was generated again in every compiled function that reaches
:func:`~quadimpact.core.geometry.pair_contact` (the loop's spine, the
recording, the events: some 17 of them), about 20 s of the simulator's cold
compile (docs/PERFORMANCE.md). So ``pair_contact`` calls it through its
entry point's address (:func:`call_ring_solid`), read at each call from one
process-wide variable whose address LLVM knows by name
(:data:`SYMBOL`). The code cached on disk names the symbol, not the address:
each process sets the variable when it first needs the search
(:func:`ensure_ring_solid`, called by ``pair_table`` for a table with a
ring-solid pair, and by ``quadimpact compile``). A run with no ring against a
cylinder or a box never compiles the search.
"""

from __future__ import annotations

import ctypes
from typing import Any

from llvmlite import binding as ll
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.core.errors import TypingError
from numba.extending import intrinsic

__all__ = ["RING_SOLID_SIGNATURE", "SYMBOL", "call_ring_solid", "ensure_ring_solid"]

_F64 = types.float64
_VECTOR = types.Array(_F64, 1, "C")
_MATRIX = types.Array(_F64, 2, "C")

RING_SOLID_SIGNATURE = types.UniTuple(_F64, 11)(
    _VECTOR, _MATRIX, _MATRIX, types.int64, _MATRIX, types.int64
)
"""``ring_solid(x, C, feat, f, shapes, s) -> ContactRecord``."""

SYMBOL = "quadimpact_ring_solid_entry"
"""The name the compiled code reads the entry point's address from."""

_ENTRY = ctypes.c_void_p(0)  # 0: not compiled in this process yet
ll.add_symbol(SYMBOL, ctypes.addressof(_ENTRY))


def ensure_ring_solid() -> None:
    """Compile (or load from the disk cache) :func:`ring_solid` and publish its entry point."""
    if _ENTRY.value:
        return
    from quadimpact.core.geometry.ring import ring_solid

    ring_solid.compile(RING_SOLID_SIGNATURE.args)
    cres = ring_solid.overloads[RING_SOLID_SIGNATURE.args]
    if cres.signature.return_type != RING_SOLID_SIGNATURE.return_type:
        raise TypeError(f"ring_solid returns {cres.signature.return_type}")
    _KEEP.append(cres)  # the code stays owned by the dispatcher; kept here as well
    _ENTRY.value = cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name)


_KEEP: list[Any] = []


@intrinsic
def call_ring_solid(typingctx, x, C, feat, f, shapes, s):
    """``ring_solid(x, C, feat, f, shapes, s)`` through the published entry point."""
    args = (x, C, feat, f, shapes, s)
    if tuple(args) != tuple(RING_SOLID_SIGNATURE.args):
        raise TypingError(
            f"call_ring_solid: arguments {args}, expected {RING_SOLID_SIGNATURE.args}"
        )
    sig = RING_SOLID_SIGNATURE

    def codegen(context: Any, builder: Any, signature: Any, llargs: Any) -> Any:
        callconv = context.call_conv
        fnty = callconv.get_function_type(sig.return_type, sig.args)
        module = builder.module
        slot = module.globals.get(SYMBOL)
        if slot is None:
            slot = ir.GlobalVariable(module, ir.IntType(8).as_pointer(), name=SYMBOL)
            slot.linkage = "external"
        entry = builder.load(slot)
        with cgutils.if_unlikely(builder, cgutils.is_null(builder, entry)):
            callconv.return_user_exc(
                builder,
                RuntimeError,
                ("ring_solid: not compiled in this process (core.geometry.ring_entry)",),
            )
        callee = builder.bitcast(entry, fnty.as_pointer())
        status, out = callconv.call_function(builder, callee, sig.return_type, sig.args, llargs)
        with cgutils.if_unlikely(builder, status.is_error):
            callconv.return_status_propagate(builder, status)
        return out

    return sig, codegen
