"""Imported once by the forkserver of sweep worker pools (see ``sweep._pool_context``).

Loads the simulator and the compiled kernel (from Numba's disk cache) in the
server process, so that every worker forked from it starts ready. Errors are
swallowed: a worker that finds the kernel not loaded loads it itself.
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # workers are one process per core already

try:
    from quadimpact.sweep import warm_up

    warm_up()
except BaseException:  # never break the forkserver (Ctrl-C during start-up included)
    pass
