"""Nominal against recovery on the same conditions (docs/RECOVERY.md 5.2 and 5.3).

* The wall approach (docs/STUDIES.md 1) over a grid, run again with
  ``controller = "recovery"`` and ``pre_impact = "nominal"`` (the nominal
  controller, ``paper`` by default, until the detection; the staged law
  after it): :func:`recovery_base`, then :func:`grid_comparison` and
  :func:`saved_by_type` on the two sweep tables.
* The seven real crashes of the paper's Table III at their conditions but
  without the motor power-off, with the nominal controller and with
  recovery: :func:`crashes_without_power_off`.

A run is **saved** by recovery when, with recovery, it does not crash and
reaches stage 4.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import pandas as pd

from quadimpact.experiments.crashes import TABLE3, scenario_path
from quadimpact.inputs.scenarios import scenario_from_dict
from quadimpact.inputs.toml_files import locate_vehicle, read_toml_file
from quadimpact.simulation import simulate
from quadimpact.simulation.response_types import RESPONSE_TYPES

__all__ = [
    "crashes_without_power_off",
    "grid_comparison",
    "recovery_base",
    "saved_by_type",
]


def recovery_base(base: Mapping[str, Any], nominal: str = "paper") -> dict[str, Any]:
    """``base`` with the recovery controller, flying its ``nominal`` controller until detection."""
    return {
        **base,
        "controller": "recovery",
        "pre_impact": "nominal",
        "nominal_controller": nominal,
    }


def _crashed(table: pd.DataFrame) -> pd.Series:
    return table["crash_time_s"].notna()


def grid_comparison(
    nominal: pd.DataFrame, recovery: pd.DataFrame, keys: Sequence[str]
) -> pd.DataFrame:
    """The nominal and the recovery run of each grid point side by side.

    Parameters
    ----------
    nominal, recovery : pandas.DataFrame
        Sweep tables over the same grid (``runs.parquet``).
    keys : sequence of str
        The grid's fields (one row per combination in each table).

    Returns
    -------
    pandas.DataFrame
        ``keys``, ``nominal_type`` (A, B, C, D, Other; ``failed``),
        ``nominal_crashed``, ``recovery_type``, ``crashed`` (with recovery),
        ``detected``, ``recovered`` (stage 4 reached), ``saved`` (not
        crashed and stage 4 reached), ``t_stage4_s``, ``height_loss_m``.
    """
    keys = list(keys)
    left = nominal[keys].copy()
    left["nominal_type"] = nominal["response_type"].where(nominal["status"] != "failed", "failed")
    left["nominal_crashed"] = _crashed(nominal).to_numpy()
    right = recovery[keys].copy()
    right["recovery_type"] = recovery["response_type"].where(
        recovery["status"] != "failed", "failed"
    )
    right["crashed"] = _crashed(recovery).to_numpy()
    right["detected"] = recovery["detected"].fillna(False).astype(bool).to_numpy()
    right["recovered"] = recovery["recovered"].fillna(False).astype(bool).to_numpy()
    right["t_stage4_s"] = recovery["t_stage4_s"].to_numpy()
    right["height_loss_m"] = recovery["height_loss_m"].to_numpy()
    both = left.merge(right, on=keys, how="inner", validate="one_to_one")
    if len(both) != len(nominal) or len(both) != len(recovery):
        raise ValueError("grid_comparison: the two tables do not cover the same grid")
    both["saved"] = both["recovered"] & ~both["crashed"]
    return both


def saved_by_type(comparison: pd.DataFrame) -> pd.DataFrame:
    """Per nominal response type: runs, with recovery not crashed, stage 4, saved (both).

    Rows: the types A, B, C, D, Other present (then ``failed``), and ``all``.
    """
    rows = []
    order = [t for t in (*RESPONSE_TYPES, "failed") if (comparison["nominal_type"] == t).any()]
    for label, group in [(t, comparison[comparison["nominal_type"] == t]) for t in order] + [
        ("all", comparison)
    ]:
        rows.append({
            "nominal_type": label, "runs": len(group),
            "nominal_crashed": int(group["nominal_crashed"].sum()),
            "detected": int(group["detected"].sum()),
            "not_crashed": int((~group["crashed"]).sum()),
            "stage4": int(group["recovered"].sum()), "saved": int(group["saved"].sum()),
        })  # fmt: skip
    return pd.DataFrame(rows)


def _crash_scenario(number: int, model: str, recovery: bool) -> Any:
    path = scenario_path(number)
    data = locate_vehicle(read_toml_file(path), path.parent)
    data.pop("power_off", None)
    data["model"] = model
    if recovery:
        data = recovery_base(data)
    return scenario_from_dict(data, where=f"crash {number}")


def crashes_without_power_off(models: Sequence[str] = ("default",)) -> pd.DataFrame:
    """Table III's crashes without the motor power-off: nominal and recovery, per model.

    Returns
    -------
    pandas.DataFrame
        One row per crash and model: ``crash``, ``model``, the conditions
        (``heading_deg`` as flown, ``speed_m_s``, ``inclination_deg``,
        ``altitude_m``), ``type_experiment`` (with power-off, the paper's),
        ``nominal_type`` and ``nominal_crash_s`` (nominal controller, no
        power-off), ``recovery_type``, ``recovery_crash_s``, ``detected``,
        ``t_detect_s``, ``stage`` (last stage entered), ``recovered``,
        ``t_stage4_s``, ``height_loss_m``, ``min_altitude_m``, ``saved``.
    """
    rows = []
    for model in models:
        for crash in TABLE3:
            nominal = simulate(_crash_scenario(crash.number, model, recovery=False))
            scenario = _crash_scenario(crash.number, model, recovery=True)
            s = simulate(scenario).summary
            stage = max((k for k in (1, 2, 3, 4) if s.get(f"t_stage{k}_s") is not None),
                        default=0)  # fmt: skip
            rows.append({
                "crash": crash.number, "model": model,
                "heading_deg": float(scenario.heading_deg), "speed_m_s": crash.speed_m_s,
                "inclination_deg": crash.inclination_deg, "altitude_m": float(scenario.altitude_m),
                "type_experiment": crash.type_experiment,
                "nominal_type": nominal.summary["response_type"],
                "nominal_crash_s": nominal.summary["crash_time_s"],
                "recovery_type": s["response_type"], "recovery_crash_s": s["crash_time_s"],
                "detected": bool(s["detected"]), "t_detect_s": s["t_detect_s"],
                "stage": stage, "recovered": bool(s["recovered"]),
                "t_stage4_s": s["t_stage4_s"], "height_loss_m": s["height_loss_m"],
                "min_altitude_m": s["min_altitude_m"],
                "saved": bool(s["recovered"]) and s["crash_time_s"] is None,
            })  # fmt: skip
    return pd.DataFrame(rows)
