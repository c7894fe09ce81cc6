"""Checks of a prepared run before it runs: the initial state must not start inside a surface.

:func:`check_initial_contact` is called once by ``simulation.setup.prepare``
(so by ``simulate``, ``Simulation``, sweeps and the learning environment):

* an **impact trial** starts its vehicle away from the wall (docs/RECOVERY.md
  5.1): a bumper already touching or in the wall at the start (depth > 0) is
  an input error;
* **any scenario** whose initial state has a bumper deeper than
  :data:`INITIAL_PENETRATION_TOL_M` (1 mm) in a contact surface is an input
  error: the contact law would start from an onset it never saw (``v_i``
  taken at first sight) and push the vehicle out with a force of a
  deflection nobody asked for.

The messages say which bumper, which surface and how deep, and name the
field to change. A sweep records such a run as failed with this message
(its ``reason``); the recovery study classes it ``invalid: started in
contact`` (:data:`STARTED_IN_CONTACT` is the phrase it looks for).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from quadimpact.core import layout as L
from quadimpact.errors import InputError
from quadimpact.simulation.approach import bumper_depths

__all__ = ["INITIAL_PENETRATION_TOL_M", "STARTED_IN_CONTACT", "check_initial_contact"]

#: Deepest bumper penetration into a surface that an initial state may have, m.
INITIAL_PENETRATION_TOL_M = 1e-3
#: The phrase of the impact trial's error (what the recovery study's classes look for).
STARTED_IN_CONTACT = "starts in contact with the wall"


def check_initial_contact(scenario: Any, setup: Any) -> None:
    """Refuse an initial state that starts in contact (impact trial) or inside a surface.

    Parameters
    ----------
    scenario : WallApproach or FlightScenario or ImpactTrial
        The validated scenario (its kind and fields name the problem).
    setup : RunSetup
        Its prepared run (``x0``, ``veh``, ``surf``, ``surface_names``).

    Raises
    ------
    InputError
        One line: the bumper, the surface, the depth and what to change.
    """
    kind = getattr(scenario, "kind", "scenario")
    x0 = np.asarray(setup.x0, dtype=float)
    for s, name in enumerate(setup.surface_names):
        depths = bumper_depths(x0, setup.veh, setup.surf, s)
        bumper = int(np.argmax(depths))
        depth = float(depths[bumper])
        ground = setup.surf[s, L.S_IS_GROUND] > 0.5
        if kind == "impact-trial" and not ground and depth > 0.0:
            raise InputError(
                f"impact trial: {STARTED_IN_CONTACT}: bumper {bumper + 1} is "
                f"{depth * 1e3:.1f} mm into it at the start (start_distance_m = "
                f"{float(scenario.start_distance_m):g} m is too short for this attitude; "
                "the trial must start before the first contact)"
            )
        if depth > INITIAL_PENETRATION_TOL_M:
            raise InputError(
                f"{kind}: the initial state has bumper {bumper + 1} {depth * 1e3:.1f} mm "
                f"inside the {name}, more than the {INITIAL_PENETRATION_TOL_M * 1e3:g} mm "
                "tolerance for a start in contact (move the start away from it)"
            )
