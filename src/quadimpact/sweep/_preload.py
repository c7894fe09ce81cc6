"""Imported once by the forkserver of the local worker pools (``backends._pool_context``).

It only calls :func:`quadimpact.sweep.worker.preload` (a forkserver can only
be told modules to import, not functions to call); errors never leave it.
"""

try:
    from quadimpact.sweep.worker import preload
except BaseException:  # never break the forkserver
    pass
else:
    preload()
