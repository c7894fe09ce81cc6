"""The attitude excursion's slots (``EX_*``): a part of the run's stats, declared by its owner.

``core/excursion.py`` folds each output sample's attitude into these
:data:`NEX` numbers; ``core/layout.py`` places them in ``stats`` at
``ST_EXCURSION`` from their declared size (an address computed from a size,
as MJX places a sensor's data at ``sensor_adr`` from ``sensor_dim``). The
declaration lives in this module, which imports no compiled code, so that
``layout.py`` can size ``stats`` without loading Numba.
"""

from quadimpact.core.block import Block

# ---- attitude excursion over the output samples (NEX): stats[ST_EXCURSION + EX_*]
_ex = Block("stats.excursion", "EX_")
EX_DEV = _ex.slot("EX_DEV", 3)  # rad, largest roll, pitch, yaw departures from the references
EX_COS_TILT = _ex.slot("EX_COS_TILT")  # lowest cos of the body z axis from the reference's
EX_DEV_TRIG = _ex.slot("EX_DEV_TRIG", 6)  # cos, sin of each largest departure so far
EX_REF_TRIG = _ex.slot("EX_REF_TRIG", 6)  # cos, sin of the roll, pitch, yaw references
NEX = _ex.end("NEX")
