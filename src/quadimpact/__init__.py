"""quadimpact: simulator of bumper-protected quadrotors colliding with walls.

The public names are imported lazily, so that ``import quadimpact`` (and the
command line's ``--help``) stays fast until the simulator is actually used.

Examples
--------
>>> from quadimpact import WallApproach, simulate
>>> result = simulate(WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75))
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

__version__ = "0.1.0"

_EXPORTS = {
    "WallApproach": "quadimpact.inputs.scenarios",
    "FlightScenario": "quadimpact.inputs.scenarios",
    "ImpactTrial": "quadimpact.inputs.scenarios",
    "ImuSettings": "quadimpact.inputs.sensors",
    "DetectionSettings": "quadimpact.inputs.sensors",
    "register_controller": "quadimpact.inputs.controllers",
    "Plane": "quadimpact.inputs.world",
    "ModelOptions": "quadimpact.inputs.model",
    "load_scenario_file": "quadimpact.inputs.scenarios",
    "Vehicle": "quadimpact.inputs.vehicle",
    "load_vehicle": "quadimpact.inputs.vehicle",
    "InputError": "quadimpact.errors",
    "simulate": "quadimpact.simulation",
    "Simulation": "quadimpact.simulation",
    "simulate_batch": "quadimpact.simulation",
    "read_result": "quadimpact.results.result",
}

__all__ = ["__version__", *_EXPORTS]


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        value = getattr(import_module(_EXPORTS[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'quadimpact' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
