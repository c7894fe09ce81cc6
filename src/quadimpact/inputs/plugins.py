"""Plug-in files: Python files or modules imported for what they register.

A plug-in controller or estimator is registered by running its module
(``register_controller``, ``register_estimator``: docs/CONTROLLERS.md,
docs/ESTIMATION.md). A command given ``--plugin FILE.py`` (or a module
name) imports it with :func:`load_plugin`, and names it in the environment
variable :data:`PLUGINS_ENV`, so that the worker processes of its sweeps,
forked from a server that calls :func:`load_env_plugins` when it starts,
register it too.
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import sys
from pathlib import Path
from types import ModuleType

from quadimpact.errors import InputError

__all__ = ["PLUGINS_ENV", "load_env_plugins", "load_plugin", "plugin_ref"]

#: The plug-ins a process and its sweeps' workers import: references joined by os.pathsep.
PLUGINS_ENV = "QUADIMPACT_PLUGINS"
_LOADED: dict[str, ModuleType] = {}


def plugin_ref(ref: str) -> str:
    """``ref`` as the environment names it: a file by its absolute path, a module by name."""
    path = Path(ref)
    if ref.endswith(".py") or path.is_file():
        return str(path.resolve())
    return ref


def load_plugin(ref: str, where: str = "--plugin") -> ModuleType:
    """Import a plug-in (a ``.py`` file or an importable module name) once per process.

    Raises
    ------
    InputError
        No such file or module, or it raised on import (one line, naming it).
    """
    key = plugin_ref(ref)
    if key in _LOADED:
        return _LOADED[key]
    try:
        if key.endswith(".py") or Path(key).is_file():
            path = Path(key)
            if not path.is_file():
                raise InputError(f"{where}: no such file: {ref}")
            name = f"quadimpact_plugin_{path.stem}"
            spec = importlib.util.spec_from_file_location(name, path)
            if spec is None or spec.loader is None:
                raise InputError(f"{where}: cannot import {ref}")
            module = importlib.util.module_from_spec(spec)
            sys.modules[name] = module
            spec.loader.exec_module(module)
        else:
            module = importlib.import_module(key)
    except InputError:
        raise
    except ModuleNotFoundError as exc:
        raise InputError(f"{where}: {ref}: {exc}") from None
    except Exception as exc:  # the plug-in's own error, in one line
        raise InputError(f"{where}: {ref}: {type(exc).__name__}: {exc}") from None
    _LOADED[key] = module
    return module


def add_to_env(ref: str) -> None:
    """Name ``ref`` in :data:`PLUGINS_ENV` (for the worker processes started from now on)."""
    refs = [r for r in os.environ.get(PLUGINS_ENV, "").split(os.pathsep) if r]
    key = plugin_ref(ref)
    if key not in refs:
        os.environ[PLUGINS_ENV] = os.pathsep.join([*refs, key])


def load_env_plugins() -> list[str]:
    """Import every plug-in :data:`PLUGINS_ENV` names; the references imported."""
    refs = [r for r in os.environ.get(PLUGINS_ENV, "").split(os.pathsep) if r]
    for ref in refs:
        load_plugin(ref, where=PLUGINS_ENV)
    return refs
