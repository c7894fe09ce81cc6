"""Compiled core of quadimpact (Numba ``njit``).

One module per pipeline stage: ``rigid_body`` (Newton-Euler and quaternion
kinematics), ``rotors`` (thrust, reaction and gyroscopic moments),
``contact`` (bumper geometry and the Hunt-Crossley law), ``dynamics`` (the
right-hand side that sums them), ``control`` (the controllers and the
allocation), ``integrator`` (Dormand-Prince 5(4) with dense output),
``events`` (root location on the dense output) and ``run`` (the loop that
ties them). Array slots are named in ``layout``.

Numba's on-disk cache checks only the file of each cached function, not the
files of the functions it calls and inlines: an edited ``control.py`` would
leave ``run.py``'s cached loop stale. ``ensure_fresh_cache`` (run on import)
keeps a hash of all the core sources next to the cache and clears the core's
cache files when it changes.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

_HERE = Path(__file__).resolve().parent
_STAMP = "quadimpact-core-sources.sha256"


def _cache_dirs() -> list[Path]:
    dirs = [_HERE / "__pycache__"]
    custom = os.environ.get("NUMBA_CACHE_DIR")
    if custom:
        # Numba mirrors the source folder's absolute path below NUMBA_CACHE_DIR
        dirs.append(Path(custom) / _HERE.relative_to(_HERE.anchor))
    return dirs


def ensure_fresh_cache() -> None:
    """Clear the core's Numba cache files if any core source changed since they were made."""
    digest = hashlib.sha256()
    for src in sorted(_HERE.glob("*.py")):
        digest.update(src.name.encode())
        digest.update(src.read_bytes())
    current = digest.hexdigest()
    for folder in _cache_dirs():
        stamp = folder / _STAMP
        try:
            if stamp.read_text() == current:
                continue
        except OSError:
            pass
        try:
            folder.mkdir(parents=True, exist_ok=True)
            for f in folder.iterdir():
                if f.suffix in (".nbi", ".nbc"):
                    f.unlink()
            stamp.write_text(current)
        except OSError:  # read-only install: Numba then compiles in memory
            continue


ensure_fresh_cache()
