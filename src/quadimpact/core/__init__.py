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
keeps a hash of all the core sources (but this file, which compiles nothing) next
to the cache and clears the core's cache files when it changes. ``cache_is_warm``
says whether a first run will compile, and ``announce_compilation`` says so once
per process, before the compilation starts (the Python entry points and the
commands call it).
"""

from __future__ import annotations

import hashlib
import logging
import os
from collections.abc import Callable
from pathlib import Path

_THIS = Path(__file__).resolve()
_HERE = _THIS.parent
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


def cache_is_warm(*entries: str) -> bool:
    """Whether compiled entry points are in Numba's on-disk cache (else their first use compiles).

    ``entries``: functions named by their module under ``quadimpact.core`` and
    their name, ``"step.advance"`` (the default: the run loop) or
    ``"envs.stacked.step_batch"``. Cheap: looks for each one's index file
    (no Numba import).
    """
    for entry in entries or ("step.advance",):
        module, _, function = entry.rpartition(".")
        *packages, stem = module.split(".")
        if not any(_numba_dir(_HERE.joinpath(*packages)).glob(f"{stem}.{function}-*.nbi")):
            return False
    return True


#: What compiles on first use: each part's entry points (:func:`cache_is_warm`), what it
#: is in words and about how much CPU its compilation takes on a 2-core machine, s (the
#: simulator: the loop with its estimators, obstacle shapes and features; the learning
#: environments: their own loop, with the simulator's functions already in the cache;
#: measured by ``quadimpact compile`` on a fresh clone, 2026-12-08: 179 and 34 s).
COMPILED_PARTS: dict[str, tuple[tuple[str, ...], str, int]] = {
    "simulator": (("step.advance",), "the simulator", 180),
    "environments": (
        ("envs.stacked.reset_slot", "envs.stacked.step_batch"),
        "the learning environments' loop",
        35,
    ),
}
#: The parts a part's first use compiles: the environments run the simulator's functions.
_NEEDS = {"simulator": ("simulator",), "environments": ("simulator", "environments")}
#: The command that compiles every part ahead of time.
WARM_COMMAND = "quadimpact compile"

_checked: set[str] = set()  # the parts this process has looked at (said, or found warm)
_log = logging.getLogger("quadimpact")


def compilation_notice(parts: tuple[str, ...] = ("simulator",)) -> str:
    """The one-line notice that ``parts`` (keys of :data:`COMPILED_PARTS`) are being compiled."""
    what = " and ".join(COMPILED_PARTS[p][1] for p in parts)
    seconds = sum(COMPILED_PARTS[p][2] for p in parts)
    return (
        f"quadimpact: compiling {what} (first use only: about {seconds} s of CPU on a 2-core "
        f"machine, more on a slower one; Numba keeps it in its disk cache for every later "
        f"process, and `{WARM_COMMAND}` does it ahead of time) ..."
    )


def announce_compilation(part: str = "simulator", say: Callable[[str], None] | None = None) -> bool:
    """Say, once per process, that the first use of ``part`` compiles it; True if said.

    Called before the first compiled call (``simulation.setup.prepare``, the
    learning environments, a sweep or a study about to hand runs to worker
    processes, which compile in their turn): it looks at the on-disk cache
    (:func:`cache_is_warm`) once per part and process, and, if cold, gives
    :func:`compilation_notice` to ``say`` (default: a warning of the
    ``quadimpact`` logger, which Python prints on stderr when logging is not
    configured). ``part``: a key of :data:`COMPILED_PARTS`.
    """
    todo = [p for p in _NEEDS[part] if p not in _checked]
    if not todo:
        return False
    _checked.update(todo)
    cold = tuple(p for p in todo if not cache_is_warm(*COMPILED_PARTS[p][0]))
    if not cold:
        return False
    (say or _log.warning)(compilation_notice(cold))
    return True


def silence_compilation_notice() -> None:
    """Never announce a compilation in this process (a worker: the process it works for
    announces it)."""
    _checked.update(COMPILED_PARTS)


def ensure_fresh_cache() -> None:
    """Clear the core's Numba cache files if any core source changed since they were made."""
    digest = hashlib.sha256()
    for src in sorted(_HERE.rglob("*.py")):
        if src == _THIS:  # this file compiles nothing: its notices may change freely
            continue
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
