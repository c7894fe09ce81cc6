"""What a run records: the slots of the output rows ``out`` and the contact episodes.

``core/recording.py`` writes both (a row per output time; an episode row per
contact, from its located onset to its end, with its peaks), and
``core/impacts.py`` groups the episodes into impacts. ``core/records.py``
allocates them from :data:`NOUT` (:func:`out_width`) and :data:`NEP`. The
declaration lives in this module, which imports no compiled code, so that
``records.py`` can size the arrays while ``recording.py`` imports
``records.py`` (no import cycle).
"""

from quadimpact.core.block import Block
from quadimpact.core.layout import MAX_ROTORS, NX

# ---- time series out (n_out, NOUT + 2 n_features): the fixed columns, then
# per feature its deflection (max over shapes, >= 0, m), then per feature its
# normal force (sum over shapes, N); out_width() gives the row length
_out = Block("out", "OUT_")
OUT_T = _out.slot("OUT_T")  # s
OUT_X = _out.slot("OUT_X", NX)  # state
OUT_CMD = _out.slot("OUT_CMD", MAX_ROTORS)  # rotor speed command in force (rad/s)
OUT_STAGE = _out.slot("OUT_STAGE")  # the controller's stage in force (MEM_STAGE)
NOUT = _out.end("NOUT")
OUT_DELTA = NOUT  # feature f's deflection at OUT_DELTA + f


def out_width(n_features: int) -> int:
    """Columns of an output row for ``n_features`` contact features."""
    return NOUT + 2 * n_features


# ---- contact episodes episodes (max_episodes, NEP)
_ep = Block("episodes", "E_")
E_FEATURE = _ep.slot("E_FEATURE")  # row of feat
E_SHAPE = _ep.slot("E_SHAPE")  # row of shapes
E_T_START = _ep.slot("E_T_START")  # s, located onset
E_T_END = _ep.slot("E_T_END")  # s, located end (run end if still open)
E_V_I = _ep.slot("E_V_I")  # m/s, penetration rate at onset (before the v_min floor)
E_PEAK_DELTA = _ep.slot("E_PEAK_DELTA")  # m
E_T_PEAK = _ep.slot("E_T_PEAK")  # s
E_PEAK_FORCE = _ep.slot("E_PEAK_FORCE")  # N
E_T_PEAK_FORCE = _ep.slot("E_T_PEAK_FORCE")  # s
E_OPEN = _ep.slot("E_OPEN")  # 1 if the episode had not ended when the run stopped
NEP = _ep.end("NEP")
