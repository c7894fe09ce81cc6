"""A study's folder: claimed with its first file, resumed, finished.

Every study (``quadimpact recovery``, ``pole``, ``experiments``,
``reproduce``...) writes into one folder. :class:`StudyFolder` is what they
share of it:

* **claimed from the first file**: before any work, :meth:`StudyFolder.claim`
  checks the folder (:func:`quadimpact.results.files.check_out_dir`) and
  writes ``study.json`` first, with the study's kind and its *identity* (the
  options that decide its runs). From then on the folder is the study's own,
  whatever was interrupted: the same command resumes it, and a command with
  other options is refused in one line that names them (``--n 1000 here,
  2000 asked``);
* **finished**: :meth:`StudyFolder.finish` writes ``study.json`` again, whole
  (what ran, every invocation that ran runs, the numbers) and ``report.md``,
  each atomically (no temporary file is left, whatever stops it);
* **up to date**: a rerun with nothing left to run reads the numbers of the
  finished ``study.json`` instead of drawing everything again
  (:meth:`StudyFolder.finished_numbers`).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from quadimpact import __version__
from quadimpact.errors import InputError, one_line
from quadimpact.results.files import (
    STUDY_JSON,
    atomic_write,
    check_out_dir,
    kind_words,
    remove_stale_temporaries,
    to_jsonable,
)

__all__ = [
    "REPORT_MD",
    "STUDY_JSON",
    "SWEEP_DIR",
    "TRIALS_PARQUET",
    "StudyFolder",
    "describe_run",
    "read_study_json",
]

REPORT_MD = "report.md"
SWEEP_DIR = "sweep"
TRIALS_PARQUET = "trials.parquet"
#: ``status`` of ``study.json`` while the study runs, and once it is finished.
RUNNING, FINISHED = "running", "finished"


def read_study_json(folder: Path) -> dict[str, Any] | None:
    """The folder's ``study.json`` (None when absent or unreadable)."""
    try:
        data = json.loads((folder / STUDY_JSON).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def _plain(value: Any) -> Any:
    """``value`` as ``study.json`` holds it (JSON types)."""
    return json.loads(json.dumps(value, default=to_jsonable))


@dataclass
class StudyFolder:
    """The folder of one study.

    Parameters
    ----------
    path : Path
        The folder (created when claimed).
    kind : str
        The study's kind (``"recovery"``, ``"pole"``...:
        :data:`quadimpact.results.files.FOLDER_MARKERS`).
    identity : mapping
        The options that decide the study's runs (JSON-able): a rerun resumes
        the folder only with the same.
    where : str
        How the folder was given, for messages (``"--out"``; ``""`` from Python).
    flags : mapping
        Identity key -> its name in messages (``{"n": "--n"}``); default the key.
    """

    path: Path
    kind: str
    identity: Mapping[str, Any]
    where: str = "--out"
    flags: Mapping[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.path = Path(self.path)
        self.identity = _plain(dict(self.identity))

    # ------------------------------------------------------------- claiming
    def check(self) -> None:
        """Refuse, before any work, a folder this study cannot use (nothing is written).

        Raises
        ------
        InputError
            The folder cannot be written, holds another kind of output, or holds
            this kind of study with other options (naming them).
        """
        check_out_dir(self.path, self.kind, where=self.where)
        held = read_study_json(self.path)
        if held is None or held.get("kind", self.kind) != self.kind:
            return
        theirs = held.get("identity")
        if not isinstance(theirs, dict) or theirs == self.identity:
            return
        label = f"{self.where} {self.path}" if self.where else str(self.path)
        raise InputError(
            f"{label}: holds {kind_words(self.kind)} with other options "
            f"({'; '.join(self._differences(theirs))}); "
            "use a new folder, or the same options to resume it"
        )

    def _differences(self, theirs: Mapping[str, Any]) -> list[str]:
        """Each option that differs, by its flag, with both values in full.

        Nested options (a mapping) are compared part by part (``approach.hover_s``);
        of several that share a flag (a value and what it implies), the one the flag
        is named after is said.
        """
        held, asked = _flat(theirs), _flat(self.identity)
        said: dict[str, tuple[str, str]] = {}
        for key in sorted(set(held) | set(asked)):
            if held.get(key) == asked.get(key):
                continue
            flag = self._flag(key)
            if flag in said and said[flag][0] == _key_of_flag(flag):
                continue  # the option the flag is named after is said already
            said[flag] = (
                key,
                f"{flag} {_full(held.get(key))} there, {_full(asked.get(key))} asked",
            )
        return [text for _, text in said.values()]

    def _flag(self, key: str) -> str:
        """An identity key's name in messages: its flag, else its parent's flag (and
        the part), else the key."""
        if key in self.flags:
            return self.flags[key]
        top, _, rest = key.partition(".")
        if rest and top in self.flags:
            return f"{self.flags[top]} ({rest})"
        return key

    def claim(self) -> Path:
        """Check the folder, create it and mark it as this study's (``study.json`` first)."""
        self.check()
        self.path.mkdir(parents=True, exist_ok=True)
        remove_stale_temporaries(self.path)  # left by a process killed while writing
        if read_study_json(self.path) is None:
            self._write({"status": RUNNING})
        return self.path

    def _write(self, content: Mapping[str, Any]) -> Path:
        data = {
            "kind": self.kind,
            "identity": self.identity,
            "quadimpact_version": __version__,
            **content,
        }
        text = json.dumps(data, indent=1, sort_keys=True, default=to_jsonable) + "\n"
        return atomic_write(
            self.path / STUDY_JSON, lambda tmp: tmp.write_text(text, encoding="utf-8")
        )

    # ------------------------------------------------------------ finishing
    def sweep_history(self, run: Mapping[str, Any]) -> list[dict[str, Any]]:
        """The invocations that ran runs of this study: ``study.json``'s, then this one's.

        ``run`` holds this invocation's ``n_already_done``, ``n_ran``,
        ``sweep_s`` (s) and ``backend``; an invocation that ran nothing adds
        nothing.
        """
        history: list[dict[str, Any]] = []
        held = read_study_json(self.path)
        if run["n_already_done"] and held is not None:
            history = list(held.get("sweeps") or [])
        if run["n_ran"]:
            history.append({k: run[k] for k in ("n_ran", "sweep_s", "backend")})
        return history

    def finish(self, description: Mapping[str, Any], markdown: str | None = None) -> Path:
        """Write ``study.json`` (``description``, marked finished) and ``report.md``.

        Without ``markdown`` (a study that writes its own report), only
        ``study.json``. Returns the report's path.
        """
        self._write({**description, "status": FINISHED})
        if markdown is not None:
            atomic_write(
                self.path / REPORT_MD, lambda tmp: tmp.write_text(markdown, encoding="utf-8")
            )
        return self.path / REPORT_MD

    def finished_description(self, *files: str) -> dict[str, Any] | None:
        """A finished study's ``study.json``, if it and ``report.md`` and ``files`` are there.

        What a rerun with nothing left to run returns instead of drawing its
        figures and report again (None: draw them).
        """
        held = read_study_json(self.path)
        if held is None or held.get("status") != FINISHED or held.get("identity") != self.identity:
            return None
        if not all((self.path / name).exists() for name in (REPORT_MD, *files)):
            return None
        return held

    def report_path(self) -> Path:
        """Where ``report.md`` is."""
        return self.path / REPORT_MD


def _key_of_flag(flag: str) -> str:
    """The identity key a flag is named after (``--initial-error``: ``initial_error``)."""
    return flag.removeprefix("--").replace("-", "_")


def _flat(identity: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """``{"a": {"b": 1}}`` as ``{"a.b": 1}`` (an empty mapping stays a value)."""
    flat: dict[str, Any] = {}
    for key, value in identity.items():
        if isinstance(value, Mapping) and value:
            flat.update(_flat(value, f"{prefix}{key}."))
        else:
            flat[f"{prefix}{key}"] = value
    return flat


def _full(value: Any) -> str:
    """A value for the message, whole (strings quoted, on one line)."""
    if isinstance(value, tuple):
        value = list(value)
    return one_line(repr(value) if isinstance(value, str) else str(value))


def describe_run(info: Mapping[str, Any]) -> dict[str, Any]:
    """What an invocation ran, from :func:`quadimpact.sweep.run_sweep`'s information."""
    run = {k: info[k] for k in ("n_runs", "n_already_done", "n_ran", "backend")}
    run["sweep_s"] = float(info["elapsed_s"])
    return run
