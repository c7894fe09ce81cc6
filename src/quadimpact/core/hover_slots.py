"""The hover tests' slots: two parts of the run's stats, declared by their owner.

``core/hover_tracking.py`` keeps, for the time to hover (``track_hover``),
the first tick of the current run of the hover condition and the first tick
of the first run that lasted long enough (``HV_*``, :data:`NHOVER` numbers at
``stats[ST_HOVER]``), and for the held hover of suite 2
(``track_held_hover``) the same two ticks and the CM position at each
(``HH_*``, :data:`NHELD` numbers at ``stats[ST_HELD]``). ``core/layout.py``
places both in ``stats`` from their declared sizes (an address computed from a
size, as MJX places a sensor's data at ``sensor_adr`` from ``sensor_dim``).
The declaration lives in this module, which imports no compiled code, so that
``layout.py`` can size ``stats`` without loading Numba. The slots keep the
names they had in ``stats`` (``HV_T_HOVER`` was ``ST_T_HOVER``), so the
stepping front end's ``Simulation.stats`` keeps its fields (``t_hover``...).
"""

from quadimpact.core.block import Block

# ---- the time to hover (NHOVER): stats[ST_HOVER + HV_*]
_hv = Block("stats.hover", "HV_")
HV_HOVER_RUN_T = _hv.slot("HV_HOVER_RUN_T")  # s, first tick of the hover condition's run (NaN)
HV_T_HOVER = _hv.slot("HV_T_HOVER")  # s, first tick of its first run of HOVER_HOLD_S (NaN)
NHOVER = _hv.end("NHOVER")

# ---- the held hover of the benchmark's suite 2 (NHELD): stats[ST_HELD + HH_*]
_hh = Block("stats.held", "HH_")
HH_HELD_RUN_T = _hh.slot("HH_HELD_RUN_T")  # s, first tick of the held-hover condition's run (NaN)
HH_HELD_RUN_X = _hh.slot("HH_HELD_RUN_X", 3)  # m, CM position at that tick, inertial
HH_T_HELD = _hh.slot("HH_T_HELD")  # s, first tick of its first run of HOVER_HOLD_S (NaN)
HH_HELD_X = _hh.slot("HH_HELD_X", 3)  # m, CM position there (the hover point), inertial
NHELD = _hh.end("NHELD")
