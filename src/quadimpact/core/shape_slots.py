"""The obstacle shapes' slots ``shapes``: declared with their owner (no compiled code).

A shape is one obstacle of the world (a plane, a cylinder, a sphere, a box
or a plug-in kind, ``SHAPE_*``), in the inertial frame: one row of
``shapes`` (``SH_*``, :data:`NSHAPE` numbers). ``core/geometry`` owns them:
its dispatch reads each row's kind, and each kind reads the slots it needs
(``core/geometry/<kind>.py``). ``core/records.py`` and the packer
(``packing/world_block.py``) size ``shapes`` from :data:`NSHAPE`. The
declaration lives in ``core/``, not in ``core/geometry/``, whose package
loads compiled code, so that neither loads Numba. Every slot keeps the
offset and the name it had in ``core/layout.py``.
"""

from quadimpact.core.block import Block

# ---- world shapes shapes (n_shapes, NSHAPE), inertial frame; each kind
# reads the slots it needs (core/geometry/<kind>.py)
_shape = Block("shapes", "SH_")
SH_KIND = _shape.slot("SH_KIND")  # SHAPE_*
SH_IS_GROUND = _shape.slot("SH_IS_GROUND")  # 1: the ground (its first onset is the crash)
SH_POINT = _shape.slot("SH_POINT", 3)  # a point: on a plane, on an axis, a centre (m)
SH_NORMAL = _shape.slot("SH_NORMAL", 3)  # a unit vector: a plane's outward normal, an axis
SH_RADIUS = _shape.slot("SH_RADIUS")  # m: a radius (cylinder, sphere)
SH_LENGTH = _shape.slot("SH_LENGTH")  # m: a length along SH_NORMAL (inf: unbounded)
SH_HALF = _shape.slot("SH_HALF", 3)  # m: half-extents along the shape's own axes (box)
SH_ROT = _shape.slot("SH_ROT", 9)  # the shape's axes in inertial components: row i is axis i
NSHAPE = _shape.end("NSHAPE")
