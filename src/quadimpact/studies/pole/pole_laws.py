"""The pole study's two laws side by side: a variant's recovery arm against the default law.

With ``PoleStudy(model="pole-replica")`` every grid point is flown three
times: by the baseline, by the recovery controller in the variant (arm
``recovery``) and by the default staged law (arm ``recovery-default``).
:func:`compare_laws` counts where the two laws differ, overall and by pitch
band; :func:`example_point` picks, among the points where the default law
fails and the variant does not, the one nearest the middle of them; and
:func:`write_law_examples` flies that point again under each law and draws
each run (``example_default_law.png``, ``example_<variant>.png``).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import pandas as pd

    from quadimpact.sweep.spec import SweepSpec

__all__ = [
    "compare_laws",
    "example_figure_name",
    "example_point",
    "spread",
    "write_law_examples",
]

#: The arms compared: the study's variant (``recovery``) and the default law.
VARIANT_ARM = "recovery"
DEFAULT_ARM = "recovery-default"


def _by_point(table: pd.DataFrame, arm: str) -> pd.DataFrame:
    part = table[table["arm"] == arm]
    return part.set_index(["pitch_deg", "lateral_offset_m"]).sort_index()


def spread(values: pd.Series | np.ndarray) -> dict[str, float]:
    """``n``, ``min``, ``median`` and ``max`` of the finite values (``{"n": 0}`` if none)."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return {"n": 0}
    return {
        "n": int(v.size),
        "min": float(v.min()),
        "median": float(np.median(v)),
        "max": float(v.max()),
    }


def compare_laws(table: pd.DataFrame) -> dict[str, Any]:
    """Where the variant's recovery arm and the default law's differ, point by point.

    Parameters
    ----------
    table : pandas.DataFrame
        ``trials.parquet`` of a study with both arms (``recovery`` and
        ``recovery-default``).

    Returns
    -------
    dict
        ``both``, ``variant_only``, ``default_only``, ``neither``: grid points
        by which law loses less than 2 m there; ``bands``: per pitch band the
        same counts; ``variant_only_where`` and ``default_only_where``: the
        |pitch| (deg) and |offset| (m) of those points; ``example``: the point
        of :func:`example_point` (or None).
    """
    var = _by_point(table, VARIANT_ARM)
    dflt = _by_point(table, DEFAULT_ARM).reindex(var.index)
    v_ok = var["success"].to_numpy(dtype=bool)
    d_ok = dflt["success"].to_numpy(dtype=bool)
    bands = var["pitch_band"].to_numpy()
    pitch = np.abs(np.asarray(var.index.get_level_values(0), dtype=float))
    offset = np.asarray(var.index.get_level_values(1), dtype=float)

    def counts(mask: np.ndarray) -> dict[str, int]:
        return {
            "n": int(mask.sum()),
            "both": int((mask & v_ok & d_ok).sum()),
            "variant_only": int((mask & v_ok & ~d_ok).sum()),
            "default_only": int((mask & ~v_ok & d_ok).sum()),
            "neither": int((mask & ~v_ok & ~d_ok).sum()),
        }

    out: dict[str, Any] = counts(np.ones(len(var), dtype=bool))
    order = sorted(set(bands), key=lambda b: float(str(b).split("-")[0]))
    out["bands"] = [{"band": str(b), **counts(bands == b)} for b in order]
    for name, mask in (("variant_only", v_ok & ~d_ok), ("default_only", ~v_ok & d_ok)):
        out[f"{name}_where"] = {
            "abs_pitch_deg": spread(pitch[mask]),
            "abs_offset_m": spread(np.abs(offset[mask])),
        }
    out["example"] = example_point(table)
    return out


def example_point(table: pd.DataFrame) -> dict[str, Any] | None:
    """The grid point where the default law fails and the variant does not, nearest the
    middle of all such points.

    The middle is the median |pitch| and the median offset of those points; the
    distance scales |pitch| by the grid's largest |pitch| and the offset by its
    largest |offset|; ties go to the smaller |pitch|, then the smaller offset.

    Returns
    -------
    dict or None
        ``pitch_deg``, ``lateral_offset_m``, the ``run_id`` of each arm there
        (``run_ids``: arm -> run id) and ``height_lost_m`` of each; None when
        there is no such point.
    """
    var = _by_point(table, VARIANT_ARM)
    dflt = _by_point(table, DEFAULT_ARM).reindex(var.index)
    mask = var["success"].to_numpy(dtype=bool) & ~dflt["success"].to_numpy(dtype=bool)
    if not mask.any():
        return None
    pitch = np.abs(np.asarray(var.index.get_level_values(0), dtype=float))
    offset = np.asarray(var.index.get_level_values(1), dtype=float)
    p_scale = max(float(pitch.max()), 1e-12)
    o_scale = max(float(np.abs(offset).max()), 1e-12)
    p, o = pitch[mask], offset[mask]
    d = ((p - np.median(p)) / p_scale) ** 2 + ((o - np.median(o)) / o_scale) ** 2
    k = int(np.lexsort((o, p, d))[0])
    i = int(np.flatnonzero(mask)[k])
    key = var.index[i]
    return {
        "pitch_deg": float(key[0]),
        "lateral_offset_m": float(key[1]),
        "run_ids": {
            VARIANT_ARM: int(var["run_id"].iloc[i]),
            DEFAULT_ARM: int(dflt["run_id"].iloc[i]),
        },
        "height_lost_m": {
            VARIANT_ARM: float(var["height_lost_m"].iloc[i]),
            DEFAULT_ARM: float(dflt["height_lost_m"].iloc[i]),
        },
    }


def example_figure_name(arm: str, model: str) -> str:
    """The file of the example's figure of ``arm`` in a study of variant ``model``."""
    law = "default_law" if arm == DEFAULT_ARM else model.replace("-", "_")
    return f"example_{law}.png"


def write_law_examples(
    spec: SweepSpec, example: dict[str, Any], out: Path, *, altitude_m: float, model: str
) -> list[Path]:
    """Fly the example point again under each law and write each run's figure into ``out``.

    ``spec``: the study's sweep (the runs are its own, the same scenarios as
    the table's rows); ``altitude_m``: the start altitude (m); ``model``: the
    variant. Each run must repeat its row's height lost, or this raises
    ``RuntimeError``.
    """
    from quadimpact.inputs.scenarios import scenario_from_dict
    from quadimpact.results.figures import save_figure
    from quadimpact.simulation import simulate
    from quadimpact.studies.recovery.recovery_figures import example_figure

    paths = []
    for arm in (DEFAULT_ARM, VARIANT_ARM):
        run_id = example["run_ids"][arm]
        result = simulate(scenario_from_dict(spec.scenario_dict(run_id), where=f"run {run_id}"))
        lost = float(altitude_m) - float(result.summary["final_altitude_m"])
        if lost != example["height_lost_m"][arm]:  # pragma: no cover
            raise RuntimeError(f"run {run_id}: the example run does not repeat its table row")
        law = "the default law" if arm == DEFAULT_ARM else f"the {model} law"
        title = (
            f"Pitch {example['pitch_deg']:g}°, offset {example['lateral_offset_m']:+.2f} m, "
            f"{law}: {lost:.2f} m lost"
        )
        path = out / example_figure_name(arm, model)
        paths.append(save_figure(example_figure(result, title=title), path))
    return paths
