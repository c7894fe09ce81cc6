"""The trials' analysis shared by the studies and the benchmark: classes, bins, criteria.

The recovery study, the pole study and the benchmark read their trials the
same way; the functions they share live here, so that no study reaches into
another's modules:

* the **trial inputs** of an impact-trial sweep (:func:`trial_inputs`) and the
  wall trials' table (:func:`trial_table`, :func:`add_derived`);
* the **outcome classes** of a trial (:data:`OUTCOME_CLASSES`, checked in this
  order): ``invalid: started in contact`` (its vehicle starts touching the
  obstacle: a failed row with that reason), ``failed`` (a numerical failure),
  ``invalid: bumper model exceeded`` (a bumper went deeper than its radius:
  the outcome means nothing), ``false detection`` (the detector fired before
  any contact), ``not detected`` (a contact the detector never saw), ``no
  contact``, ``recovered below ground level`` (stage 4 reached, but the
  altitude went below 0 on the way), ``recovered`` and ``not recovered``. The
  first three are **excluded** from the rates (:data:`EXCLUDED_CLASSES`,
  :func:`valid_mask`, :func:`model_valid`);
* the **criteria**: the wall's published success (:func:`success_mask`:
  stage 4 and never below altitude 0) and the grids' (:func:`height_lost`:
  less than :data:`SUCCESS_LOSS_M` lost over the run);
* **bins**: the inclination toward the wall (``-pitch``) in 10-deg bins
  centred on multiples of 10 deg, the speed in 0.25-m/s bins
  (:func:`binned`, each closed on the left, the last on both sides), and the
  grids' pitch bands (:func:`pitch_bands`);
* **quantiles** of a column (:func:`quantiles`) and the recovery arm of a
  grid point (:func:`recovery_arm`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

import numpy as np

from quadimpact.inputs.model import resolve_model_options
from quadimpact.inputs.scenarios import ImpactTrial

if TYPE_CHECKING:
    import pandas as pd

    from quadimpact.sweep import SweepSpec

__all__ = [
    "BAND_DEG",
    "BELOW_GROUND",
    "EXCLUDED_CLASSES",
    "INCLINATION_BIN",
    "OUTCOME_CLASSES",
    "SPEED_BIN",
    "SUCCESS_LOSS_M",
    "TRIAL_FIELDS",
    "add_derived",
    "bin_edges",
    "binned",
    "height_lost",
    "model_valid",
    "outcome_class",
    "pitch_bands",
    "quantiles",
    "recovery_arm",
    "success_mask",
    "trial_inputs",
    "trial_table",
    "valid_mask",
    "wall_trial_table",
]

#: The trial inputs every row of a wall trials table carries (the recovery study's
#: ``recovery_spec.TRIAL_FIELDS``, which stays light for the command line).
TRIAL_FIELDS = ("roll_deg", "pitch_deg", "yaw_deg", "speed_m_s", "seed")


#: (width, offset) of the inclination bins, deg: edges at offset + k width.
INCLINATION_BIN = (10.0, 5.0)

#: (width, offset) of the speed bins, m/s.
SPEED_BIN = (0.25, 0.0)

#: The class of a trial that recovered but went below altitude 0 (not a success).
BELOW_GROUND = "recovered below ground level"

OUTCOME_CLASSES = (
    "recovered",
    BELOW_GROUND,
    "not recovered",
    "not detected",
    "false detection",
    "no contact",
    "invalid: bumper model exceeded",
    "invalid: started in contact",
    "failed",
)

#: Classes left out of the rates (they say nothing of the recovery).
EXCLUDED_CLASSES = ("invalid: started in contact", "invalid: bumper model exceeded", "failed")

#: Height lost over the run below which a trial is a success (the authors' criterion), m.
SUCCESS_LOSS_M = 2.0

#: Width of the pitch bands of the success table, deg.
BAND_DEG = 5.0

# ------------------------------------------------------------------- bins


def bin_edges(values: Iterable[float], width: float, offset: float = 0.0) -> np.ndarray:
    """Edges ``offset + k width`` covering every finite value (at least one bin)."""
    v = np.asarray(list(values) if not isinstance(values, np.ndarray) else values, float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return np.array([offset, offset + width])
    lo = math.floor(round((v.min() - offset) / width, 9))
    hi = math.ceil(round((v.max() - offset) / width, 9))
    hi = max(hi, lo + 1)
    return offset + width * np.arange(lo, hi + 1, dtype=float)


def _edge(x: float) -> str:
    return f"{x:g}" if abs(x) > 1e-12 else "0"


def binned(values: pd.Series, width: float, offset: float = 0.0) -> pd.Series:
    """Each value's bin label (``"[lo, hi)"``, the last ``"[lo, hi]"``), ordered categories."""
    import pandas as pd

    v = values.to_numpy(dtype=float)
    edges = bin_edges(v, width, offset)
    n_bins = len(edges) - 1
    labels = [
        f"[{_edge(a)}, {_edge(b)}{']' if i == n_bins - 1 else ')'}"
        for i, (a, b) in enumerate(zip(edges[:-1], edges[1:], strict=True))
    ]
    index = np.searchsorted(edges, v, side="right") - 1
    index = np.clip(index, 0, n_bins - 1)
    codes = np.where(np.isfinite(v), index, -1)
    cat = pd.Categorical.from_codes(codes, categories=labels, ordered=True)
    return pd.Series(cat, index=values.index)


def pitch_bands(abs_pitch: np.ndarray) -> list[str]:
    """Each |pitch|'s band of :data:`BAND_DEG` (0-4, 5-9, ...), labelled by the values in it.

    The largest |pitch| joins the band below when it would be alone in its own
    (the authors' 45 deg joins 40-44: 40-45).
    """
    a = np.asarray(abs_pitch, dtype=float)
    idx = np.floor(a / BAND_DEG + 1e-9).astype(int)
    top = int(idx.max()) if idx.size else 0
    if top > 0 and np.unique(a[idx == top]).size == 1:
        idx[idx == top] = top - 1
    labels = {}
    for k in np.unique(idx):
        values = a[idx == k]
        lo, hi = float(values.min()), float(values.max())
        labels[k] = f"{lo:g}-{hi:g}" if hi > lo else f"{lo:g}"
    return [labels[k] for k in idx]


# --------------------------------------------------------------- outcomes


def _flag(table: pd.DataFrame, column: str) -> np.ndarray:
    """A nullable boolean column as a plain array (null: False)."""
    return table[column].fillna(False).to_numpy(dtype=bool)


def outcome_class(table: pd.DataFrame) -> pd.Series:
    """Each trial's class (:data:`OUTCOME_CLASSES`, see the module docstring)."""
    import pandas as pd

    from quadimpact.simulation.checks import STARTED_IN_CONTACT

    failed = (table["status"] == "failed").to_numpy()
    reason = (
        table["reason"].fillna("").astype(str) if "reason" in table
        else pd.Series("", index=table.index)
    )  # fmt: skip
    in_contact = failed & reason.str.contains(STARTED_IN_CONTACT, regex=False).to_numpy()
    too_deep = (
        (table["bumper_model_valid"] == False).fillna(False).to_numpy(dtype=bool)  # noqa: E712
        if "bumper_model_valid" in table
        else np.zeros(len(table), dtype=bool)
    )
    false = _flag(table, "false_detection")
    missed = _flag(table, "not_detected")
    detected = _flag(table, "detected")
    recovered = _flag(table, "recovered")
    below = _below_ground(table)
    classes = np.select(
        [in_contact, failed, too_deep, false, missed, ~detected, recovered & below, recovered],
        ["invalid: started in contact", "failed", "invalid: bumper model exceeded",
         "false detection", "not detected", "no contact", BELOW_GROUND, "recovered"],
        default="not recovered",
    )  # fmt: skip
    return pd.Series(
        pd.Categorical(classes, categories=OUTCOME_CLASSES), index=table.index, name="outcome"
    )


def _below_ground(table: pd.DataFrame) -> np.ndarray:
    """Trials whose altitude went below 0 (the level the start altitude is measured from)."""
    if "min_altitude_m" not in table:
        return np.zeros(len(table), dtype=bool)
    return (table["min_altitude_m"].astype(float) < 0.0).fillna(False).to_numpy(dtype=bool)


def valid_mask(table: pd.DataFrame) -> np.ndarray:
    """The trials the rates count: not of an :data:`EXCLUDED_CLASSES` class."""
    return ~table["outcome_class"].astype(str).isin(EXCLUDED_CLASSES).to_numpy()


def model_valid(table: pd.DataFrame) -> np.ndarray:
    """The trials whose outcome means something, whatever the task (the benchmark's
    suite 2): not started in contact and no bumper beyond its radius. A run that failed
    numerically stays: it counts as a failure, never as a success."""
    from quadimpact.simulation.checks import STARTED_IN_CONTACT

    failed = (table["status"] == "failed").to_numpy()
    reason = table["reason"].fillna("").astype(str) if "reason" in table else None
    in_contact = (
        failed & reason.str.contains(STARTED_IN_CONTACT, regex=False).to_numpy()
        if reason is not None
        else np.zeros(len(table), dtype=bool)
    )
    too_deep = (
        (table["bumper_model_valid"] == False).fillna(False).to_numpy(dtype=bool)  # noqa: E712
        if "bumper_model_valid" in table
        else np.zeros(len(table), dtype=bool)
    )
    return ~(in_contact | too_deep)


def success_mask(table: pd.DataFrame) -> np.ndarray:
    """The successes: valid, stage 4 reached (``recovered``), never below altitude 0."""
    cls = table["outcome_class"].astype(str).to_numpy()
    return _flag(table, "recovered") & valid_mask(table) & (cls != BELOW_GROUND)


def height_lost(runs: pd.DataFrame, altitude_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Each run's height lost (m: the altitude at the start minus at the end) and success
    (less than :data:`SUCCESS_LOSS_M` lost, the run not failed)."""
    import pandas as pd

    final = pd.to_numeric(runs["final_altitude_m"], errors="coerce").to_numpy(dtype=float)
    lost = float(altitude_m) - final
    ok = np.isfinite(lost) & (lost < SUCCESS_LOSS_M) & (runs["status"] != "failed").to_numpy()
    return lost, ok


# ----------------------------------------------------------------- tables

_TRIAL_DEFAULTS = {name: ImpactTrial.model_fields[name].default for name in TRIAL_FIELDS}


def add_derived(table: pd.DataFrame) -> pd.DataFrame:
    """The table with ``inclination_deg`` (= -pitch), its bin, the speed bin and the class."""
    t = table.copy()
    t["inclination_deg"] = -t["pitch_deg"].astype(float)
    t["inclination_bin"] = binned(t["inclination_deg"], *INCLINATION_BIN)
    t["speed_bin"] = binned(t["speed_m_s"].astype(float), *SPEED_BIN)
    t["outcome_class"] = outcome_class(t)
    return t


def trial_inputs(spec: SweepSpec, runs: pd.DataFrame | None = None) -> pd.DataFrame:
    """Roll, pitch, yaw (deg), speed (m/s) and IMU seed of every run of a sweep.

    From each run's swept value (its input column in ``runs``, the sweep's
    table, when given), else the base scenario's, else the impact trial's
    default. Indexed by ``run_id``; without ``runs``, each run's inputs are
    computed from the spec (slower: a million trials take seconds).
    """
    import numpy as np
    import pandas as pd

    index = pd.RangeIndex(spec.n_runs, name="run_id")
    if runs is None:
        rows = [spec.inputs(run_id) for run_id in range(spec.n_runs)]
        runs = pd.DataFrame({name: [r.get(name) for r in rows] for name in spec.columns})
        runs["run_id"] = np.arange(spec.n_runs)
    by_id = runs.set_index("run_id").reindex(index)
    frame = pd.DataFrame(index=index)
    for name in TRIAL_FIELDS:
        fallback = float(spec.base.get(name, _TRIAL_DEFAULTS[name]))
        if name in spec.columns:
            values = pd.to_numeric(by_id[name], errors="coerce").to_numpy(dtype=float)
            frame[name] = np.where(np.isnan(values), fallback, values)
        else:
            frame[name] = np.full(spec.n_runs, fallback)
    frame["seed"] = frame["seed"].astype("int64")
    return frame


def trial_table(runs: pd.DataFrame, spec: SweepSpec) -> pd.DataFrame:
    """``trials.parquet``: the sweep's rows, the trial inputs and the derived columns."""
    table = runs.sort_values("run_id").reset_index(drop=True)
    inputs = trial_inputs(spec, table).reindex(table["run_id"].to_numpy())
    for name in TRIAL_FIELDS:
        table[name] = inputs[name].to_numpy()
    return add_derived(table)


wall_trial_table = trial_table
"""The wall task's trials table (the benchmark's name for :func:`trial_table`)."""


def quantiles(values: pd.Series) -> dict[str, float]:
    """Count, median, 90th percentile, min and max of the finite values (NaN when none)."""
    v = values.to_numpy(dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return {"n": 0, "median": math.nan, "p90": math.nan, "min": math.nan, "max": math.nan}
    return {
        "n": int(v.size),
        "median": float(np.median(v)),
        "p90": float(np.quantile(v, 0.9)),
        "min": float(v.min()),
        "max": float(v.max()),
    }


def recovery_arm(model: str | None, baseline: str = "paper") -> dict[str, Any]:
    """The recovery controller flying ``baseline`` until the detection, as a sweep run.

    ``model``: the run's model variant (None: the sweep's base's). A variant that
    forces a pre-impact behaviour (the pole replica's ``hold``) has it named in the
    run, so that the table's ``model`` and ``pre_impact`` columns (the swept
    inputs', which take the place of the summary's) are the ones in force.
    """
    arm: dict[str, Any] = {
        "controller": "recovery",
        "pre_impact": "nominal",
        "nominal_controller": baseline,
    }
    if model is None:
        return arm
    forced = resolve_model_options(model).pre_impact
    if forced != "scenario":
        arm["pre_impact"] = forced
    arm["model"] = model
    return arm
