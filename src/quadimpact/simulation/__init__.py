"""One run, Python side: inputs to packed arrays, the compiled loop, tables and summary.

* (the blocks themselves are packed by :mod:`quadimpact.packing`, one module each);
* :mod:`~quadimpact.simulation.resolve`: ``resolve(scenario)``, the run's frozen
  resolved description (every default applied, once);
* :mod:`~quadimpact.simulation.trim`: the rotor speeds of a thrust without torque;
* :mod:`~quadimpact.simulation.approach`: the wall approach's attitude and shooting;
* :mod:`~quadimpact.simulation.setup`: :class:`RunSetup`, ``prepare(scenario)``
  (resolve, pack, the run's loop);
* :mod:`~quadimpact.simulation.tables`: raw kernel arrays -> episodes and time series;
* :mod:`~quadimpact.simulation.metrics`: impacts, metrics, response types;
* :mod:`~quadimpact.simulation.summary`: the summary of a run;
* :mod:`~quadimpact.simulation.recovery_metrics`: detection and recovery metrics;
* :mod:`~quadimpact.simulation.simulate`: :func:`simulate` and :func:`run_setup`;
* :mod:`~quadimpact.simulation.stepping`: :class:`Simulation`, a run advanced
  one control interval at a time from Python.

Its public names are imported on first use, so that a part of it (the
checks of a scenario) can be imported without the whole
simulator: the command line checks its inputs before loading the kernel.
"""

from __future__ import annotations

import sys
import types
from importlib import import_module
from typing import Any

_EXPORTS = {
    "Simulation": "quadimpact.simulation.stepping",
    "build_summary": "quadimpact.simulation.summary",
    "run_setup": "quadimpact.simulation.simulate",
    "simulate": "quadimpact.simulation.simulate",
    "simulate_batch": "quadimpact.simulation.batch",
}

__all__ = sorted(_EXPORTS)


class _Package(types.ModuleType):
    """This package, whose functions are not shadowed by the submodules of the same name.

    Importing the submodule ``quadimpact.simulation.simulate`` would set the
    package's attribute ``simulate`` to that module; the function
    :func:`simulate` is kept instead (the module stays in ``sys.modules``).
    """

    def __getattr__(self, name: str) -> Any:
        if name in _EXPORTS:
            value = getattr(import_module(_EXPORTS[name]), name)
            types.ModuleType.__setattr__(self, name, value)
            return value
        raise AttributeError(f"module {self.__name__!r} has no attribute {name!r}")

    def __setattr__(self, name: str, value: Any) -> None:
        if name in _EXPORTS and isinstance(value, types.ModuleType):
            return
        types.ModuleType.__setattr__(self, name, value)

    def __dir__(self) -> list[str]:
        return sorted({*types.ModuleType.__dir__(self), *_EXPORTS})


sys.modules[__name__].__class__ = _Package
