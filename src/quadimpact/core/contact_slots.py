"""The contact law's per-pair state ``cs``: its slots, declared with its owner (no compiled code).

``core/contact.py`` applies the force of a pair while ``cs[c, CS_ACTIVE]`` is set,
with the damping coefficient fixed at its onset; the event locator
(``core/events.py``, ``core/interval.py``) sets and clears them; the recording
(``core/recording.py``) closes the pair's episode row. ``core/records.py``
allocates ``cs`` from :data:`NCS`. The declaration lives in this module, which
imports no compiled code, so that ``records.py`` can size the array while
``contact.py`` imports ``records.py`` (no import cycle).
"""

from quadimpact.core.block import Block

# ---- contact pairs cs (n_pairs, NCS); changed only at located events
_cs = Block("cs", "CS_")
CS_ACTIVE = _cs.slot("CS_ACTIVE")  # 1 while the pair is in a contact episode (force applied)
CS_LAMBDA = _cs.slot("CS_LAMBDA")  # damping coefficient fixed at the episode's onset, N s/m^(n+1)
CS_EPISODE = _cs.slot("CS_EPISODE")  # row of its episode in `episodes` (-1: none / dropped)
NCS = _cs.end("NCS")
