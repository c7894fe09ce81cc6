"""Estimation metrics of a run (docs/ESTIMATION.md 4): the estimate's errors by phase.

The loop accumulates, at every IMU sample, each error of the estimate
against the truth (``core/estimators/estimate_errors.py``): the attitude error (the
angle of ``q_hat (x) q^-1``, deg), the velocity error (``|v_hat - v|``, m/s,
inertial CM velocity), the gyro-bias error (``|b_hat - b|``, rad/s) and the
position error (``|p_hat - p|``, m), in three phases: ``pre`` (before the
first contact with an obstacle), ``crash`` (from it to the entry into stage 4
of the recovery controller, or to the end), ``post`` (after stage 4). This
module turns the sums into the RMS and the maximum of each (``None`` for a
phase without samples), the attitude error's RMS over the whole run and over
the run but the crash (``not_crash``: the pre and post phases together, the
authors' "not-crash" figure).
"""

from __future__ import annotations

import math
from dataclasses import fields
from typing import Any

import numpy as np

from quadimpact.core import layout as L
from quadimpact.results.summary_record import PHASES, QUANTITIES, EstimationPart

__all__ = ["ESTIMATION_KEYS", "PHASES", "QUANTITIES", "estimation_metrics"]

ESTIMATION_KEYS: tuple[str, ...] = tuple(
    f.name for f in fields(EstimationPart) if f.name.startswith("est_")
)
"""The metric keys, in summary order (``est_attitude_rms_pre_deg`` ...): the estimation
part's (:class:`quadimpact.results.summary_record.EstimationPart`)."""


_PHASE_KEYS: tuple[tuple[str, str], ...] = tuple(
    (f"est_{q}_rms_{phase}_{unit}", f"est_{q}_max_{phase}_{unit}")
    for q, unit in QUANTITIES
    for phase in PHASES
)
"""The (rms, max) keys of each quantity and phase, in the stats' order."""


def estimation_metrics(st: np.ndarray) -> dict[str, Any]:
    """RMS and maximum of each error in each phase, from the kernel's stats (``ST_EST_ERR``)."""
    sums = st[L.ST_EST_ERR : L.ST_EST_ERR + 3 * len(_PHASE_KEYS)].tolist()  # Python floats
    out: dict[str, Any] = {}
    for i, (rms_key, max_key) in enumerate(_PHASE_KEYS):
        sq, peak, n = sums[3 * i], sums[3 * i + 1], sums[3 * i + 2]
        ok = n > 0 and math.isfinite(sq)
        out[rms_key] = math.sqrt(sq / n) if ok else None
        out[max_key] = peak if ok else None
    sq = sum(sums[3 * p] for p in range(L.N_PHASES))
    n = sum(sums[3 * p + 2] for p in range(L.N_PHASES))
    out["est_attitude_rms_run_deg"] = math.sqrt(sq / n) if n > 0 and math.isfinite(sq) else None
    sq = sums[0] + sums[6]  # the attitude's pre and post phases (the rest of the run)
    n = sums[2] + sums[8]
    out["est_attitude_rms_not_crash_deg"] = (
        math.sqrt(sq / n) if n > 0 and math.isfinite(sq) else None
    )
    return out
