"""Shared test helpers: run packed setups through the compiled kernel."""

from __future__ import annotations

import numpy as np

from quadimpact.core import layout as L
from quadimpact.core.run import execute
from quadimpact.scenario import RunSetup


def run_packed(setup: RunSetup, **changes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Run ``setup`` (with some packed arrays replaced) on its output grid."""
    arrays = {k: getattr(setup, k) for k in ("x0", "veh", "surf", "opts", "ctrl")}
    arrays.update(changes)
    return execute(
        arrays["x0"],
        setup.t0,
        setup.tf,
        arrays["veh"],
        arrays["surf"],
        arrays["opts"],
        arrays["ctrl"],
        setup.output_times(),
    )


def states(out: np.ndarray) -> np.ndarray:
    """The NX state columns of an output array."""
    return out[:, L.OUT_X : L.OUT_X + L.NX]
