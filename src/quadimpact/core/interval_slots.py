"""The integrator's step counts (``IS_*``): a part of the run's stats, declared by its owner.

``core/interval.py`` (``integrate_interval``) counts the accepted and
rejected Dormand-Prince steps and the right-hand-side evaluations of a run
in these :data:`NSTEPS` numbers; ``core/layout.py`` places them in
``stats`` at ``ST_STEPS`` from their declared size, as it places the
excursion and the hover tests. They sit at the offsets they had as
``ST_N_STEPS``, ``ST_N_REJECTED`` and ``ST_N_RHS``, and keep their field
names in the stepping front end's ``Simulation.stats`` (``n_steps``...).
The declaration lives in this module, which imports no compiled code, so
that ``layout.py`` can size ``stats`` without loading Numba.
"""

from quadimpact.core.block import Block

# ---- the integrator's step counts (NSTEPS): stats[ST_STEPS + IS_*]
_is = Block("stats.steps", "IS_")
IS_N_STEPS = _is.slot("IS_N_STEPS")  # accepted steps
IS_N_REJECTED = _is.slot("IS_N_REJECTED")  # rejected steps
IS_N_RHS = _is.slot("IS_N_RHS")  # right-hand-side evaluations (the integrator's own)
NSTEPS = _is.end("NSTEPS")
