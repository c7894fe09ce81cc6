"""The vehicle's slots ``veh``: declared with their owner (no compiled code).

``veh`` holds the vehicle of a run (``V_*``, :data:`NVEH` numbers): its
mass and inertia, its rotors (count, positions, spin senses, thrust and
drag-torque coefficients, inertia, motor time constant) and gravity. The
right-hand side (``core/dynamics.py``) owns them: it sums gravity and the
rotors' wrench (``core/rotors.py``) and hands the mass and inertia to the
rigid body (``core/rigid_body.py``); the controllers and the estimators
read the same numbers. The contact features are in ``feat``
(``core/feature_slots.py``). The packer (``packing/vehicle_block.py``)
fills ``veh``. The declaration lives in this module, which imports no
compiled code, so that the packer loads no Numba. Every slot keeps the
offset and the name it had in ``core/layout.py``.
"""

from quadimpact.core.block import Block
from quadimpact.core.layout import MAX_ROTORS

# ---- vehicle veh (NVEH): mass, inertia, rotors (the contact features are in feat)
_veh = Block("veh", "V_")
V_MASS = _veh.slot("V_MASS")  # kg
V_INERTIA = _veh.slot("V_INERTIA", 9)  # kg m^2, row-major, body
V_INERTIA_INV = _veh.slot("V_INERTIA_INV", 9)  # row-major
V_N_ROTORS = _veh.slot("V_N_ROTORS")  # n, the vehicle's rotor count (4 to MAX_ROTORS)
V_ROTOR_POS = _veh.slot("V_ROTOR_POS", 3 * MAX_ROTORS)  # rotor j at V_ROTOR_POS + 3 j (body, m)
V_SPIN = _veh.slot("V_SPIN", MAX_ROTORS)  # +-1, spin sense about +z_B (0 beyond n)
V_KT = _veh.slot("V_KT", MAX_ROTORS)  # rotor j's thrust coefficient at V_KT + j, N/(rad/s)^2
V_DT = _veh.slot("V_DT", MAX_ROTORS)  # rotor j's drag-torque coefficient, N m/(rad/s)^2
V_JR = _veh.slot("V_JR")  # rotor inertia about its axis, kg m^2
V_GRAVITY = _veh.slot("V_GRAVITY")  # m/s^2
V_TAU_M = _veh.slot("V_TAU_M")  # motor time constant, s (first-order rotor mode)
NVEH = _veh.end("NVEH")
