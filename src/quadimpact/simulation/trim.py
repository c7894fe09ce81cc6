"""Trimmed rotor speeds: the ones that give a thrust and no torque (the resolve step).

Defined in :mod:`quadimpact.inputs.allocation` (with the allocation it solves);
this name stays for code that imports it from here.
"""

from __future__ import annotations

from quadimpact.inputs.allocation import trim_rotor_speeds

__all__ = ["trim_rotor_speeds"]
