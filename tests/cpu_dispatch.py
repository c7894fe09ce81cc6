"""NumPy's SIMD dispatch limited to what an x86-64 CPU with AVX2 and no AVX-512 runs.

``python tests/cpu_dispatch.py`` prints the value of ``NPY_DISABLE_CPU_FEATURES``
that switches off every AVX-512 target of the installed NumPy (empty when it has
none): ``make test-avx2`` runs the pinned tests under it, so an AVX-512 machine
checks what an AVX2-only machine computes.
"""

from __future__ import annotations


def avx2_limit() -> str:
    """The AVX-512 targets NumPy can dispatch to, space-separated ('' when none)."""
    try:
        from numpy._core import _multiarray_umath as umath
    except ImportError:  # NumPy 1.x
        from numpy.core import _multiarray_umath as umath  # type: ignore[no-redef]
    targets = getattr(umath, "__cpu_dispatch__", [])
    return " ".join(t for t in targets if "AVX512" in t or t == "X86_V4")


if __name__ == "__main__":
    print(avx2_limit())
