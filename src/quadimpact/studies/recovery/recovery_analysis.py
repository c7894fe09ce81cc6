"""The recovery study's numbers: pure functions of the trials table.

Outcome classes partition the trials (:data:`OUTCOME_CLASSES`, checked in
this order):

* ``invalid: started in contact``: the trial could not run because its
  vehicle starts already touching the wall (``simulation/checks.py``: an
  input error for a single run, a failed row with that reason in a sweep);
* ``failed``: the run failed numerically (``status = "failed"``);
* ``invalid: bumper model exceeded``: a bumper went deeper than its radius
  (``bumper_model_valid = False``): the body itself would be in the wall,
  beyond what the contact model covers, so the outcome means nothing;
* ``false detection``: the detector fired before any contact;
* ``not detected``: there was a contact and the detector never fired (a
  failure of the detector, not of the recovery);
* ``no contact``: no contact and no detection;
* ``recovered below ground level``: the impact was detected and stage 4 was
  reached, but the vehicle's altitude went below 0 on the way
  (``min_altitude_m < 0``): the start altitude is measured from a ground at
  0 that the trial does not model (``ground = "none"``), so it flew through
  where the ground would be: not a success;
* ``recovered``: the impact was detected and stage 4 was reached, never
  below altitude 0;
* ``not recovered``: the impact was detected and stage 4 was not reached (a
  failed recovery).

The first three are **excluded** (:data:`EXCLUDED_CLASSES`): they say nothing
of the recovery, so the rates are over the **valid** trials (all the others)
and the report and the command's summary line say how many were excluded and
why. Two success rates, each with its 95 % Wilson score interval
(:func:`wilson_interval`): the **success rate** is the valid trials that
reached stage 4 (the table's ``recovered`` column: a false detection that
reached stage 4 counts) and never went below altitude 0, over the valid
trials; the **recovery rate of the detected impacts** is the ``recovered``
class over the trials whose impact was detected (classes ``recovered``,
``recovered below ground level`` and ``not recovered``).

Bins: the inclination toward the wall, ``inclination_deg = -pitch_deg``, in
10-deg bins centred on multiples of 10 deg (edges at ..., -15, -5, 5, 15, ...;
-45..45 deg gives nine bins), and the speed in 0.25-m/s bins with edges at
multiples of 0.25 m/s. Each bin is closed on the left and open on the right,
but the last, closed on both sides.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

import numpy as np
import pandas as pd

from quadimpact.studies.recovery.estimation_numbers import estimation_numbers
from quadimpact.studies.statistics import rate
from quadimpact.studies.trial_analysis import (  # the analysis the studies share, here too
    BELOW_GROUND,
    EXCLUDED_CLASSES,
    INCLINATION_BIN,
    OUTCOME_CLASSES,
    SPEED_BIN,
    _flag,
    add_derived,
    bin_edges,
    binned,
    outcome_class,
    quantiles,
    success_mask,
    valid_mask,
)

__all__ = [
    "BELOW_GROUND",
    "EXCLUDED_CLASSES",
    "INCLINATION_BIN",
    "OUTCOME_CLASSES",
    "SPEED_BIN",
    "add_derived",
    "bin_edges",
    "binned",
    "class_conditions",
    "example_trial",
    "failure_analysis",
    "outcome_class",
    "quantiles",
    "rate_by",
    "success_mask",
    "summarise",
    "valid_mask",
]

#: Tilt beyond which a vehicle has turned over (its up axis points down), deg.
FLIP_DEG = 90.0
#: The trial conditions, for the example trial (nearest the medians of these).
CONDITIONS = ("roll_deg", "pitch_deg", "yaw_deg", "speed_m_s")


# ------------------------------------------------------------------- bins


# --------------------------------------------------------------- outcomes


# ----------------------------------------------------------------- numbers
def _success(table: pd.DataFrame) -> np.ndarray:
    return success_mask(table)


def rate_by(table: pd.DataFrame, column: str) -> pd.DataFrame:
    """Success rate (successes / valid trials) per bin of ``column``, with Wilson intervals.

    Returns
    -------
    pandas.DataFrame
        One row per category of ``column`` (empty bins included):
        ``bin``, ``n`` (valid trials), ``recovered`` (successes), ``rate``,
        ``low``, ``high``, ``not_detected``, ``false_detection``, ``excluded``
        (trials of the bin left out of ``n``).
    """
    success = pd.Series(_success(table), index=table.index)
    valid = pd.Series(valid_mask(table), index=table.index)
    rows = []
    for label, group in table.groupby(column, observed=False, sort=True):
        n_valid = int(valid[group.index].sum())
        r = rate(int(success[group.index].sum()), n_valid)
        rows.append({
            "bin": str(label), "n": r.n, "recovered": r.k, "rate": r.value, "low": r.low,
            "high": r.high, "not_detected": int(_flag(group, "not_detected").sum()),
            "false_detection": int(_flag(group, "false_detection").sum()),
            "excluded": len(group) - n_valid,
        })  # fmt: skip
    return pd.DataFrame(rows)


def _stage_reached(table: pd.DataFrame) -> np.ndarray:
    """The last recovery stage each trial entered (0: none)."""
    stage = np.zeros(len(table), dtype=int)
    for k in (1, 2, 3, 4):
        stage = np.where(table[f"t_stage{k}_s"].notna().to_numpy(), k, stage)
    return stage


def failure_analysis(table: pd.DataFrame) -> dict[str, Any]:
    """Where and how recovery fails: the ``not recovered`` trials against the recovered ones.

    Returns
    -------
    dict
        ``n_failed``; ``inclination`` and ``speed`` (:func:`quantiles` of the
        failures' conditions); ``threshold_deg``: the lower edge of the first
        inclination bin from which every bin has a success rate below 50 %
        (None if none); ``stage_reached`` (last stage -> count);
        ``flipped`` (share tilted beyond 90 deg, failures and recovered);
        ``impacts_after_detection``, ``fall_m`` (set-point altitude minus the
        lowest altitude), ``final_speed_m_s`` (quantiles, failures and
        recovered); ``worst_cells`` (the map's cells with the lowest success).
    """
    cls = table["outcome_class"].astype(str)
    failed = table[cls == "not recovered"]
    recovered = table[cls == "recovered"]
    out: dict[str, Any] = {"n_failed": len(failed), "n_recovered": len(recovered)}
    out["inclination"] = quantiles(failed["inclination_deg"])
    out["speed"] = quantiles(failed["speed_m_s"])
    out["roll"] = quantiles(failed["roll_deg"].abs())
    out["yaw"] = quantiles(failed["yaw_deg"].abs())
    by_incl = rate_by(table, "inclination_bin")
    below = (by_incl["rate"] < 0.5) & (by_incl["n"] > 0)
    threshold = None
    for i in range(len(by_incl)):
        if below.iloc[i:].all() and (by_incl["n"].iloc[i:] > 0).any():
            threshold = by_incl["bin"].iloc[i]
            break
    out["threshold_bin"] = threshold
    stages = pd.Series(_stage_reached(failed)).value_counts().sort_index()
    out["stage_reached"] = {int(k): int(v) for k, v in stages.items()}

    def share(group: pd.DataFrame, mask: np.ndarray) -> float:
        return float(mask.mean()) if len(group) else math.nan

    out["flipped"] = {
        name: share(g, g["max_tilt_deg"].to_numpy(dtype=float) > FLIP_DEG)
        for name, g in (("failed", failed), ("recovered", recovered))
    }
    out["hit_again"] = {
        name: share(g, g["impacts_after_detection"].fillna(0).to_numpy(dtype=float) >= 1)
        for name, g in (("failed", failed), ("recovered", recovered))
    }
    for key, values in (
        ("impacts_after_detection", lambda g: g["impacts_after_detection"].astype(float)),
        ("fall_m", lambda g: g["references__altitude_m"] - g["min_altitude_m"]),
        ("final_speed_m_s", lambda g: g["final_speed_m_s"]),
        ("max_tilt_deg", lambda g: g["max_tilt_deg"]),
    ):
        out[key] = {name: quantiles(values(g)) for name, g in (("failed", failed),
                                                             ("recovered", recovered))}  # fmt: skip
    cells = (
        table[valid_mask(table)]
        .assign(success=_success(table[valid_mask(table)]))
        .groupby(["inclination_bin", "speed_bin"], observed=True)["success"]
        .agg(["sum", "count"])
        .reset_index()
    )
    cells["rate"] = cells["sum"] / cells["count"]
    worst = cells.sort_values(["rate", "count"], ascending=[True, False], kind="mergesort")
    out["worst_cells"] = [
        {"inclination_bin": str(r.inclination_bin), "speed_bin": str(r.speed_bin),
         "recovered": int(r.sum), "n": int(r.count), "rate": float(r.rate)}
        for r in worst.head(3).itertuples()
    ]  # fmt: skip
    return out


def class_conditions(table: pd.DataFrame, classes: Iterable[str]) -> dict[str, dict[str, Any]]:
    """Per class (those with trials): its count and the quantiles of its trials' conditions.

    Conditions: ``inclination_deg``, ``speed_m_s``, ``|roll|``, ``|yaw|``, and
    the initial impact's ``peak_force_n`` (NaN-free values only).
    """
    cls = table["outcome_class"].astype(str)
    out = {}
    for name in classes:
        g = table[cls == name]
        if len(g):
            out[name] = {
                "n": len(g),
                "inclination_deg": quantiles(g["inclination_deg"]),
                "speed_m_s": quantiles(g["speed_m_s"]),
                "abs_roll_deg": quantiles(g["roll_deg"].abs()),
                "abs_yaw_deg": quantiles(g["yaw_deg"].abs()),
                "peak_force_n": quantiles(g["peak_force_n"]) if "peak_force_n" in g else None,
            }
    return out


def summarise(table: pd.DataFrame) -> dict[str, Any]:
    """Every number of the report, from the trials table (with :func:`add_derived` columns).

    Returns
    -------
    dict
        ``n``; ``classes`` (class -> count); ``n_valid`` (trials not
        excluded) and ``excluded`` (excluded class -> count); ``success``
        (:class:`Rate`, :func:`success_mask` over the valid trials);
        ``success_detected`` (the ``recovered`` class over the detected
        impacts); ``below_ground`` (recovered below ground level); ``false_recovered``
        (false detections that reached stage 4); ``by_inclination`` and
        ``by_speed`` (:func:`rate_by`); ``time_to_recover_s``,
        ``height_loss_m``, ``horizontal_drift_m``, ``stage1_duration_s`` ..
        ``stage3_duration_s`` (:func:`quantiles` over the recovered trials);
        ``detection_latency_s``, ``normal_error_deg`` (over the detected
        impacts); ``failures`` (:func:`failure_analysis`); ``conditions``
        (:func:`class_conditions` of every class).
    """
    cls = table["outcome_class"].astype(str)
    counts = {c: int((cls == c).sum()) for c in OUTCOME_CLASSES}
    n = len(table)
    detected = counts["recovered"] + counts[BELOW_GROUND] + counts["not recovered"]
    good = table[cls == "recovered"]
    seen = table[cls.isin(["recovered", BELOW_GROUND, "not recovered"])]
    n_valid = int(valid_mask(table).sum())
    return {
        "n": n,
        "classes": counts,
        "n_valid": n_valid,
        "excluded": {c: counts[c] for c in EXCLUDED_CLASSES},
        "below_ground": counts[BELOW_GROUND],
        "success": rate(int(_success(table).sum()), n_valid),
        "success_detected": rate(counts["recovered"], detected),
        "false_recovered": int((_success(table) & (cls == "false detection").to_numpy()).sum()),
        "by_inclination": rate_by(table, "inclination_bin"),
        "by_speed": rate_by(table, "speed_bin"),
        "time_to_recover_s": quantiles(good["time_to_recover_s"]),
        "height_loss_m": quantiles(good["height_loss_m"]),
        "horizontal_drift_m": quantiles(good["horizontal_drift_m"]),
        **{
            f"stage{k}_duration_s": quantiles(good[f"t_stage{k + 1}_s"] - good[f"t_stage{k}_s"])
            for k in (1, 2, 3)
        },
        "detection_latency_s": quantiles(seen["detection_latency_s"]),
        "normal_error_deg": quantiles(seen["normal_error_deg"]),
        "failures": failure_analysis(table),
        "conditions": class_conditions(table, OUTCOME_CLASSES),
        "estimation": estimation_numbers(table),
    }


#: The example trial is chosen among this many first trials of a study.
EXAMPLE_AMONG = 10_000


def example_trial(table: pd.DataFrame) -> int:
    """The ``run_id`` of the trial nearest the median conditions, among the first trials.

    Distance: the root sum of squares over roll, pitch, yaw and speed of each
    condition's difference from its median, divided by that condition's
    range in the table (1 where it does not vary); ties go to the lowest run_id.
    Only the first :data:`EXAMPLE_AMONG` trials (by ``run_id``) are considered,
    so that a study of millions chooses it at once, before its trials run.
    """
    t = table.sort_values("run_id")
    t = t[t["run_id"] < EXAMPLE_AMONG] if len(t) > EXAMPLE_AMONG else t
    d = np.zeros(len(t))
    for name in CONDITIONS:
        x = t[name].to_numpy(dtype=float)
        span = float(x.max() - x.min()) or 1.0
        d += ((x - np.median(x)) / span) ** 2
    return int(t["run_id"].to_numpy()[int(np.argmin(d))])
