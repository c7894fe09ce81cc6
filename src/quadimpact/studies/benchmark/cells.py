"""A benchmark's cells: one row's runs of one task with one sensor set, and their numbers.

A cell is a sweep (:meth:`~quadimpact.studies.benchmark.subject.Subject.spec`)
and, once run, its **trials table** (:func:`cell_table`: one row per trial or
grid point, the columns every metric needs, the same for every task) and its
**numbers** (:func:`cell_numbers`, docs/BENCHMARK.md 3). Suite 2's
(:func:`held_hover_numbers`):

* ``success``: a held hover (the true CM speed below 0.2 m/s, the tilt below
  5 deg, the body rate below 20 deg/s and no contact, for 0.5 s, from the first
  obstacle contact on) with less than 2 m of height lost, the ground never
  touched and no contact after the hover began, over the valid trials, with its
  95 % Wilson interval; ``published_success``: the task's published criterion;
* the time from the first contact to the hover and the horizontal distance
  from the first contact to the hover point, of the successes, p50 and p90;
* the height lost (the altitude at the start minus the lowest) of the valid
  trials, p50 and p90;
* missed detections (a contact never detected), false detections (a detection
  before any contact), failed and excluded runs, and the CPU time.

Suite 1's (:func:`published_numbers`) count the published criteria
(docs/BENCHMARK.md 8).

The cache (:class:`CellCache`) keeps the tables of cells that fly only
built-in code, keyed by the suite's version, quadimpact's version, a digest of
quadimpact's own files (its modules and data: a checkout whose code changed,
at the same version number, computes its reference rows again instead of
reading another code's results) and the cell's sweep (its fingerprint): a
reference row is computed once per version of the code.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from quadimpact import __version__
from quadimpact.results.files import atomic_write
from quadimpact.studies.benchmark.suite import SUITE_VERSION, Suite, Task, suite

if TYPE_CHECKING:
    import pandas as pd

    from quadimpact.sweep import SweepSpec

__all__ = [
    "CACHE_ENV",
    "CellCache",
    "cell_key",
    "code_digest",
    "cell_numbers",
    "cell_table",
    "default_cache",
]

#: Environment variable naming the cache folder (else the user's cache folder).
CACHE_ENV = "QUADIMPACT_BENCHMARK_CACHE"
#: The per-trial columns a cell of suite 1 keeps (those the sweep has).
KEPT = (
    "run_id", "status", "reason", "success", "valid", "recovered", "outcome_class",
    "roll_deg", "pitch_deg", "yaw_deg", "speed_m_s", "lateral_offset_m", "seed",
    "inclination_deg", "time_to_recover_s", "time_to_hover_s", "height_lost_m",
    "min_altitude_m", "horizontal_drift_m", "detected", "not_detected", "false_detection",
    "t_stage1_s", "max_tilt_deg", "impacts_after_detection", "cost__kernel_cpu_s",
    "cost__total_cpu_s", "integrator__steps", "integrator__rejected_steps", "n_episodes",
)  # fmt: skip
#: The per-trial columns a cell of suite 2 keeps: suite 1's, the held hover's and the crash.
KEPT_HELD = (
    *KEPT, "published_success", "held_hover", "time_to_held_hover_s", "held_hover_distance_m",
    "touched_after_hover", "crash_time_s", "first_contact_s",
)  # fmt: skip


@cache
def code_digest() -> str:
    """A digest of quadimpact's installed files (``*.py``, ``*.toml``, ``*.json``, the shipped
    policies' ``*.npz``): the code a cached cell was computed with (hex, 16 characters)."""
    root = Path(__file__).resolve().parents[2]
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*")):
        if path.suffix in (".py", ".toml", ".json", ".npz") and "__pycache__" not in path.parts:
            digest.update(path.relative_to(root).as_posix().encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def cell_key(spec: SweepSpec, version: str = SUITE_VERSION) -> str:
    """The cell's cache key: the suite's version, quadimpact's, its code, and the sweep."""
    text = json.dumps(
        {
            "suite": version,
            "quadimpact": __version__,
            "code": code_digest(),
            "sweep": spec.fingerprint(),
        },
        sort_keys=True,
    )
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def cell_table(
    runs: pd.DataFrame, spec: SweepSpec, task: Task, version: str = SUITE_VERSION
) -> pd.DataFrame:
    """The cell's trials table from its sweep's rows (see the module docstring).

    The wall's rows go through the recovery study's table (trial inputs,
    outcome classes, its success and validity); a grid's through the pole
    study's criterion (:func:`~quadimpact.studies.trial_analysis.height_lost`).
    In suite 2 ``success`` is the held hover (:func:`held_hover_success`) and
    the published criterion is kept as ``published_success``.
    """
    import pandas as pd

    from quadimpact.studies import trial_analysis as analysis

    altitude = float(spec.base.get("altitude_m", 5.0))
    if task.kind == "wall":
        t = analysis.wall_trial_table(runs, spec)
        t["success"] = analysis.success_mask(t)
        t["valid"] = analysis.valid_mask(t)
        t["outcome_class"] = t["outcome_class"].astype(str)
        final = pd.to_numeric(t["final_altitude_m"], errors="coerce").to_numpy(dtype=float)
        t["height_lost_m"] = altitude - final
    else:
        t = runs.sort_values("run_id").reset_index(drop=True)
        t["height_lost_m"], t["success"] = analysis.height_lost(t, altitude)
        t["valid"] = True
    if not suite(version).held_hover:
        return t[[c for c in KEPT if c in t.columns]].copy()
    crashed = pd.to_numeric(t["crash_time_s"], errors="coerce").notna().to_numpy()
    t["published_success"] = t["success"].to_numpy(dtype=bool) & ~crashed  # the ground is there
    t["valid"] = analysis.model_valid(t)
    lowest = pd.to_numeric(t["min_altitude_m"], errors="coerce").to_numpy(dtype=float)
    t["height_lost_m"] = altitude - lowest
    t["success"] = held_hover_success(t)
    return t[[c for c in KEPT_HELD if c in t.columns]].copy()


def held_hover_success(t: pd.DataFrame) -> np.ndarray:
    """Suite 2's success of each trial (docs/BENCHMARK.md 1.2): valid, a held hover, less
    than 2 m of height lost, the ground never touched (no crash) and no contact once the
    hover began. ``t`` has ``valid``, ``held_hover``, ``touched_after_hover``,
    ``height_lost_m`` (m: the start altitude minus the lowest) and ``crash_time_s``.
    A run that failed (``status``: the step budget exhausted, a non-finite state) is
    never a success, even after a held hover: it did not fly its whole length."""
    import pandas as pd

    from quadimpact.studies.trial_analysis import SUCCESS_LOSS_M

    lost = pd.to_numeric(t["height_lost_m"], errors="coerce").to_numpy(dtype=float)
    crashed = pd.to_numeric(t["crash_time_s"], errors="coerce").notna().to_numpy()
    failed = (t["status"] == "failed").to_numpy(dtype=bool) if "status" in t else False
    return (
        _flag(t, "valid")
        & _flag(t, "held_hover")
        & ~_flag(t, "touched_after_hover")
        & (lost < SUCCESS_LOSS_M)
        & ~crashed
        & ~failed
    )


def _flag(t: pd.DataFrame, column: str) -> np.ndarray:
    if column not in t:
        return np.zeros(len(t), dtype=bool)
    return t[column].fillna(False).to_numpy(dtype=bool)


def _spread(values: Any) -> tuple[float, float]:
    import pandas as pd

    from quadimpact.studies.trial_analysis import quantiles

    q = quantiles(pd.Series(np.asarray(values, dtype=float)))
    return q["median"], q["p90"]


def _numbers(t: pd.DataFrame, name: str, mask: np.ndarray, valid: np.ndarray) -> dict[str, Any]:
    """``name``, ``name_k``, ``name_low``, ``name_high``: the share of ``mask`` in ``valid``."""
    from quadimpact.studies.statistics import rate

    r = rate(int((mask & valid).sum()), int(valid.sum()))
    return {f"{name}_k": r.k, name: r.value, f"{name}_low": r.low, f"{name}_high": r.high}


def _common(t: pd.DataFrame, valid: np.ndarray) -> dict[str, Any]:
    """The counts every suite reports: trials, validity, failures, detections, CPU."""
    from quadimpact.results.costs import cost_ratio

    cost = cost_ratio(t[t["status"] != "failed"])
    return {
        "trials": int(len(t)),
        "valid": int(valid.sum()),
        "excluded": int((~valid).sum()),
        "failed_runs": int((t["status"] == "failed").sum()),
        "missed_detections": int((_flag(t, "not_detected") & valid).sum()),
        "false_detections": int((_flag(t, "false_detection") & valid).sum()),
        "cpu_s": float(cost["total_cpu_s"]),
        "cpu_ms_per_trial": 1e3 * cost["total_cpu_s"] / cost["runs"] if cost["runs"] else math.nan,
    }


def cell_numbers(t: pd.DataFrame, version: str = SUITE_VERSION) -> dict[str, Any]:
    """A cell's numbers (module docstring) from its trials table, as suite ``version`` counts."""
    s: Suite = suite(version)
    return held_hover_numbers(t) if s.held_hover else published_numbers(t)


def held_hover_numbers(t: pd.DataFrame) -> dict[str, Any]:
    """Suite 2's numbers of a cell (module docstring)."""
    import pandas as pd

    valid = _flag(t, "valid")
    success = _flag(t, "success") & valid
    out: dict[str, Any] = {
        **_common(t, valid),
        **_numbers(t, "success", success, valid),
        **_numbers(t, "published_success", _flag(t, "published_success"), valid),
        **_numbers(t, "hover", _flag(t, "held_hover"), valid),
        "declares_recovery": bool(pd.to_numeric(t["t_stage1_s"], errors="coerce").notna().any())
        if "t_stage1_s" in t
        else False,
    }
    num = {
        c: pd.to_numeric(t[c], errors="coerce").to_numpy(dtype=float)
        for c in ("time_to_held_hover_s", "held_hover_distance_m", "height_lost_m")
    }
    spreads = {
        "hover_s": num["time_to_held_hover_s"][success],
        "hover_distance_m": num["held_hover_distance_m"][success],
        "height_lost_m": num["height_lost_m"][valid],
    }
    for name, values in spreads.items():
        stem, unit = name.rsplit("_", 1)
        out[f"{stem}_p50_{unit}"], out[f"{stem}_p90_{unit}"] = _spread(values)
    return out


def published_numbers(t: pd.DataFrame) -> dict[str, Any]:
    """Suite 1's numbers of a cell: the published criteria (docs/BENCHMARK.md 8)."""
    import pandas as pd

    from quadimpact.results.costs import cost_ratio
    from quadimpact.studies.statistics import rate

    valid = _flag(t, "valid")
    success = _flag(t, "success") & valid
    declared = _flag(t, "recovered")
    r = rate(int(success.sum()), int(valid.sum()))
    hover = pd.to_numeric(t["time_to_hover_s"], errors="coerce").to_numpy(dtype=float)
    reached = valid & np.isfinite(hover)
    h = rate(int(reached.sum()), int(valid.sum()))
    num = {
        c: pd.to_numeric(t[c], errors="coerce").to_numpy(dtype=float)
        for c in ("time_to_recover_s", "height_lost_m", "horizontal_drift_m")
    }
    cost = cost_ratio(t[t["status"] != "failed"])
    out: dict[str, Any] = {
        "trials": int(len(t)),
        "valid": int(valid.sum()),
        "excluded": int((~valid).sum()),
        "failed_runs": int((t["status"] == "failed").sum()),
        "success_k": r.k,
        "success": r.value,
        "success_low": r.low,
        "success_high": r.high,
        "declares_recovery": bool(pd.to_numeric(t["t_stage1_s"], errors="coerce").notna().any())
        if "t_stage1_s" in t
        else False,
        "hover_k": h.k,
        "hover": h.value,
        "hover_low": h.low,
        "hover_high": h.high,
        "missed_detections": int((_flag(t, "not_detected") & valid).sum()),
        "false_detections": int((_flag(t, "false_detection") & valid).sum()),
        "cpu_s": float(cost["total_cpu_s"]),
        "cpu_ms_per_trial": 1e3 * cost["total_cpu_s"] / cost["runs"] if cost["runs"] else math.nan,
    }
    spreads = {
        "recover": num["time_to_recover_s"][success & declared],
        "hover": hover[reached],
        "height_lost": num["height_lost_m"][valid],
        "drift": num["horizontal_drift_m"][success & declared],
    }
    units = {"recover": "s", "hover": "s", "height_lost": "m", "drift": "m"}
    for name, values in spreads.items():
        p50, p90 = _spread(values)
        out[f"{name}_p50_{units[name]}"] = p50
        out[f"{name}_p90_{units[name]}"] = p90
    return out


def default_cache() -> Path:
    """The cache folder: ``$QUADIMPACT_BENCHMARK_CACHE``, else the user's cache folder's
    ``quadimpact/benchmark`` (``$XDG_CACHE_HOME``, default ``~/.cache``)."""
    explicit = os.environ.get(CACHE_ENV)
    if explicit:
        return Path(explicit)
    root = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(root) / "quadimpact" / "benchmark"


@dataclass
class CellCache:
    """Cells' trials tables by key (:func:`cell_key`): ``<key>.parquet`` and ``<key>.json``.

    ``folder`` None: no cache (nothing read, nothing kept).
    """

    folder: Path | None

    def get(self, key: str) -> tuple[pd.DataFrame, dict[str, Any]] | None:
        """The table and the facts of a cached cell (None: not there, or unreadable)."""
        if self.folder is None:
            return None
        import pandas as pd

        try:
            facts = json.loads((self.folder / f"{key}.json").read_text(encoding="utf-8"))
            table = pd.read_parquet(self.folder / f"{key}.parquet")
        except (OSError, ValueError):
            return None
        return table, facts

    def put(self, key: str, table: pd.DataFrame, facts: dict[str, Any]) -> None:
        """Keep a cell (atomically); a cache that cannot be written is left alone."""
        if self.folder is None:
            return
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            atomic_write(self.folder / f"{key}.parquet", lambda tmp: table.to_parquet(tmp))
            text = json.dumps(facts, indent=1, sort_keys=True) + "\n"
            atomic_write(
                self.folder / f"{key}.json", lambda tmp: tmp.write_text(text, encoding="utf-8")
            )
        except OSError:
            pass
