"""The protective features' slots ``feat``: declared with their owner (no compiled code).

A feature is a part of the vehicle's protective structure (a ring, a sphere or
a point, ``FEAT_*``), in the body frame, with its own contact law
parameters: one row of ``feat`` (``F_*``, :data:`NFEAT` numbers). The contact
law (``core/contact.py``) reads each pair's feature row for its force, and
``core/geometry`` for its distance to a shape. The packer sizes ``feat``
from :data:`NFEAT` and fills it (``packing/vehicle_block.py``). The
declaration lives in this module, which imports no compiled code, so that
the packer loads no Numba. Every slot keeps the
offset and the name it had in ``core/layout.py``.
"""

from quadimpact.core.block import Block

# ---- contact features feat (n_features, NFEAT): the vehicle's protective
# structure, body frame, each with its own contact law parameters
_feat = Block("feat", "F_")
F_KIND = _feat.slot("F_KIND")  # FEAT_*
F_CENTRE = _feat.slot("F_CENTRE", 3)  # ring or sphere centre, point position (body, m)
F_NORMAL = _feat.slot("F_NORMAL", 3)  # ring plane unit normal (body)
F_RADIUS = _feat.slot("F_RADIUS")  # ring or sphere radius, m
F_K = _feat.slot("F_K")  # contact stiffness, N/m^n
F_N = _feat.slot("F_N")  # contact exponent
F_E = _feat.slot("F_E")  # coefficient of restitution
F_MU = _feat.slot("F_MU")  # friction coefficient (0: frictionless)
F_FORCE_SCALE = _feat.slot("F_FORCE_SCALE")  # factor on the normal force (<= 0 or 1: none)
NFEAT = _feat.end("NFEAT")
