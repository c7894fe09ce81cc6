"""Compiled core of quadimpact (Numba ``njit``).

No Python objects inside: a run is a few named records of ``float64`` arrays
(``records``: ``Model``, ``Data``, ``Output``, ``Work``) whose slots are
declared in ``layout`` (the contract with the Python side). One module per
pipeline stage:

* ``layout``: every slot of every array, in checked blocks; the kinds;
* ``records``: the records, their factories and row views, the raw record;
* ``rigid_body``: Newton-Euler in body axes, quaternion kinematics;
* ``rotors``: thrust, rotor reaction torques, gyroscopic moment;
* ``actuators``: rotor command limits and slew, rotor modes, power-off schedules;
* ``geometry/``: the contact-geometry table keyed on (feature kind, shape
  kind) and its contact record (point, normal, depth, velocity); one module
  per shape kind;
* ``contact``: the force laws (Hunt-Crossley, friction) and the contact wrench;
* ``dynamics``: the right-hand side that sums gravity, rotors and contact;
* ``sensors/``: the measurement record, the IMU, impact detection, the sensor stage;
* ``estimators/``: the estimation stage (the ideal estimator);
* ``controllers/``: one module per built-in controller, their dispatch;
* ``integrator``: Dormand-Prince 5(4) with dense output;
* ``events``: event functions and their location on the dense output;
* ``interval``: one control interval: steps, events, contact onsets and ends;
* ``recording``: output rows, episodes and peaks, extremes, the crash;
* ``step``: one control tick, the pipeline of the stages above;
* ``run``: a whole run, the kernels (plug-ins), the Python entry;
* ``approach``: the wall approach's shooting (free-flight runs of the loop,
  the late start's search with ``roots``, Brent's method as compiled steps);
* ``batch``: many runs stepped together under external commands (learning);
  ``env_layout``, ``env_actions``, ``env_observation``, ``env_reward``: its
  record and slots, action maps, observations and reward.

Numba's on-disk cache checks only the file of each cached function, not the
files of the functions it calls and inlines: an edited ``controllers/paper.py``
would leave ``run.py``'s cached loop stale. ``ensure_fresh_cache`` (run on import)
keeps a hash of all the core sources next to the cache and clears the core's
cache files when it changes. ``cache_is_warm`` says whether a first run will
compile (the command line announces it).
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

_HERE = Path(__file__).resolve().parent
_STAMP = "quadimpact-core-sources.sha256"


def _numba_dir(package: Path) -> Path:
    """Where Numba caches the functions of one source folder.

    ``<folder>/__pycache__``; with ``NUMBA_CACHE_DIR``, the folder Numba names
    there: ``<name>_<sha1 of the folder's absolute path>``.
    """
    custom = os.environ.get("NUMBA_CACHE_DIR")
    if custom:
        digest = hashlib.sha1(os.path.abspath(package).encode()).hexdigest()
        return Path(custom) / f"{package.name}_{digest}"
    return package / "__pycache__"


def _cache_dirs() -> list[Path]:
    packages = [_HERE] + sorted(p.parent for p in _HERE.rglob("__init__.py") if p.parent != _HERE)
    return [_numba_dir(p) for p in packages]


def cache_is_warm() -> bool:
    """Whether the compiled loop is in Numba's on-disk cache (else the first run compiles it).

    Cheap: looks for the index file of ``kernel.run`` (no Numba import).
    """
    return any(_numba_dir(_HERE).glob("kernel.run-*.nbi"))


def ensure_fresh_cache() -> None:
    """Clear the core's Numba cache files if any core source changed since they were made."""
    digest = hashlib.sha256()
    for src in sorted(_HERE.rglob("*.py")):
        digest.update(str(src.relative_to(_HERE)).encode())
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
