"""Estimators of a flight log: the impact, the wall contact, the pre-impact
conditions and the rest after the crash; their parameters are the constants here.

Pure functions of the log's arrays (the on-board ``accel`` and ``motors``
topics; the motion capture as ``t`` on its own clock, ``p`` in NED and ``C``
body -> NED), so that any reader can use them; the methods are explained in
``docs/EXPERIMENTS.md``. The bumpers' reach toward the wall is that of the
bundled Spiri (:func:`bumper_rim_extent`).
"""

from __future__ import annotations

import math
from functools import cache
from typing import Any

import numpy as np
import pandas as pd

from quadimpact.experiments.logs import PreImpact
from quadimpact.inputs.vehicle import Vehicle, load_vehicle
from quadimpact.linalg import dot, lstsq, matvec, norm
from quadimpact.rotations import inclination_deg, matrix_to_euler_zyx_deg, wrap_angle_deg

__all__ = [
    "ATTITUDE_SYSTEMATIC_DEG",
    "ATTITUDE_WINDOW_S",
    "CONTACT_MIN_DECELERATION_M_S2",
    "FIT_WINDOW_S",
    "FIT_WINDOWS_SPREAD_S",
    "IMPACT_RATE_THRESHOLD",
    "IMPACT_SEARCH_AFTER_S",
    "IMPACT_SEARCH_BEFORE_S",
    "LOOKBACK_S",
    "MAX_EXTRAPOLATION_S",
    "MOCAP_GAP_S",
    "POWER_OFF_RPM",
    "REST_HOLD_S",
    "REST_RATE_THRESHOLD",
    "approach_speed",
    "bumper_rim_extent",
    "estimate_pre_impact",
    "find_impact",
    "locate_contact",
    "polyfit_at",
    "rest_time",
    "segments",
]

#: Impact rule: first on-board sample whose x-y magnitude of the ``accel``
#: topic exceeds this (the topic's own unit, most likely deg/s: see the docs).
IMPACT_RATE_THRESHOLD = 100.0
#: The impact search window around the first motor power-off (RPM == 1), s.
IMPACT_SEARCH_BEFORE_S = 0.25
IMPACT_SEARCH_AFTER_S = 0.15
#: A motor speed at or below this (RPM) is off: 1 = powered off by the motor
#: controller (stall protection), 0 = disarmed.
POWER_OFF_RPM = 1.0
#: Wall contact on the motion capture: the approach speed (local linear fit over
#: +-STOP_HALF_WINDOW_S) first falls below STOP_FRACTION of its median over
#: [t - STOP_REF_S[0], t - STOP_REF_S[1]] within +-CONTACT_SEARCH_S of the
#: on-board impact (the clocks differ by up to ~0.1 s).
STOP_HALF_WINDOW_S = 0.03
STOP_FRACTION = 0.5
STOP_REF_S = (0.20, 0.05)
STOP_MIN_APPROACH_M_S = 0.2
CONTACT_SEARCH_S = 0.2
#: Change-point fit around the stop: X(t) = c0 + c1 tau + c2 tau^2 - a/2 max(tau - tau_c, 0)^2
#: over [t_stop - CHANGEPOINT_BEFORE_S - FIT_WINDOW_S, t_stop + CHANGEPOINT_AFTER_S],
#: tau_c on a grid of CHANGEPOINT_STEP_S over [t_stop - CHANGEPOINT_BEFORE_S, t_stop].
CHANGEPOINT_BEFORE_S = 0.08
CHANGEPOINT_AFTER_S = 0.02
CHANGEPOINT_STEP_S = 0.001
#: The change point counts as the wall contact only with at least this deceleration.
CONTACT_MIN_DECELERATION_M_S2 = 15.0
#: Pre-impact velocity: quadratic fit of the position over [t_c - FIT_WINDOW_S, t_c],
#: differentiated at t_c; the spread over FIT_WINDOWS_SPREAD_S enters the uncertainty.
FIT_WINDOW_S = 0.20
FIT_WINDOWS_SPREAD_S = (0.15, 0.25)
#: The speed is also reported this long before the contact (``speed_lookback_m_s``).
LOOKBACK_S = 0.10
#: Pre-impact attitude: linear fit of each angle over [t_c - ATTITUDE_WINDOW_S, t_c].
ATTITUDE_WINDOW_S = 0.10
#: Systematic attitude uncertainty of the motion-capture body frame (it reads a
#: tilt of about 2 deg with the vehicle at rest on the floor).
ATTITUDE_SYSTEMATIC_DEG = 2.0
#: Largest extrapolation of the position fit past the last motion-capture sample, s.
MAX_EXTRAPOLATION_S = 0.15
#: Motion-capture gaps longer than this split the data (no differentiation across), s.
MOCAP_GAP_S = 0.05
#: At rest after the impact: the on-board ``accel`` magnitude stays below
#: REST_RATE_THRESHOLD (its unit) for REST_HOLD_S.
REST_RATE_THRESHOLD = 20.0
REST_HOLD_S = 0.5


# ------------------------------------------------------------------ geometry
@cache
def _bumpers(vehicle: Vehicle) -> tuple[np.ndarray, np.ndarray, float]:
    centres, _u, n = vehicle.bumper_frames()
    return centres, n, float(vehicle.bumper_radius_m)


def bumper_rim_extent(
    C: np.ndarray, direction: np.ndarray, vehicle: Vehicle | None = None
) -> np.ndarray:
    """Farthest reach of each bumper rim along ``direction``, from the CM.

    Parameters
    ----------
    C : numpy.ndarray, shape (..., 3, 3)
        Attitude matrices, body FRD -> inertial.
    direction : numpy.ndarray, shape (3,)
        Unit vector (inertial), e.g. the wall normal into the wall (+X).
    vehicle : Vehicle, optional
        Whose bumper circles (docs/MODEL.md section 4); default the bundled Spiri,
        the vehicle of the crash set.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        ``max over the rim of (point - CM) . direction`` per bumper, m.
    """
    rotors, n, radius = _bumpers(load_vehicle("spiri") if vehicle is None else vehicle)
    m = np.asarray(direction, dtype=float)
    centres = np.einsum("...ij,kj->...ki", C, rotors)  # (..., 4, 3)
    normals = np.einsum("...ij,kj->...ki", C, n)
    w = m - np.einsum("...k,...ki->...ki", dot(normals, m), normals)
    wn = norm(w)
    return dot(centres, m) + radius * wn  # (w/|w|).m = |w|


# ------------------------------------------------------------------ fits
def segments(t: np.ndarray, gap: float) -> np.ndarray:
    """Segment id per sample: a new segment after every gap longer than ``gap``."""
    if len(t) == 0:
        return np.zeros(0, dtype=int)
    return np.concatenate([[0], np.cumsum(np.diff(t) > gap)])


def polyfit_at(t: np.ndarray, y: np.ndarray, deg: int) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares polynomial (np.polyfit order) and its covariance; t already centred."""
    A = np.vander(t, deg + 1)
    coef, gram_inverse = lstsq(A, y)
    r = y - matvec(A, coef)
    dof = max(len(t) - (deg + 1), 1)
    s2 = float(np.add.reduce(r * r)) / dof
    return coef, s2 * gram_inverse


def _velocity_fit(
    tau: np.ndarray, positions: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Velocity, acceleration and the velocity's variance at ``tau = 0`` of each position
    component (quadratic fits over the samples at ``tau``, s before the contact)."""
    vel = np.empty(3)
    acc = np.empty(3)
    var = np.empty(3)
    for i in range(3):
        co, cov = polyfit_at(tau, positions[:, i], 2)
        vel[i], acc[i], var[i] = co[1], 2.0 * co[0], cov[1, 1]
    return vel, acc, var


def _attitude_at(
    tau: np.ndarray, C: np.ndarray, dtc: float
) -> tuple[dict[str, float], dict[str, float]]:
    """Roll, pitch, yaw (unwrapped) and inclination at ``tau = 0`` (deg; linear fits over
    the attitude samples ``C`` at ``tau``), and their uncertainties: the fit's residual
    scatter, the slope times the contact time's uncertainty ``dtc`` (s), and
    :data:`ATTITUDE_SYSTEMATIC_DEG`."""
    roll, pitch, yaw = matrix_to_euler_zyx_deg(C)
    yaw_u = np.degrees(np.unwrap(np.radians(yaw)))
    incl = inclination_deg(C)
    ang: dict[str, float] = {}
    unc: dict[str, float] = {}
    for key, series in (("roll_deg", roll), ("pitch_deg", pitch), ("yaw_deg", yaw_u),
                        ("inclination_deg", incl)):  # fmt: skip
        if len(tau) >= 3:
            co, cov = polyfit_at(tau, series, 1)
            val = float(co[1])
            resid = float(np.sqrt(cov[1, 1]))
            slope = float(co[0])
        else:
            val, resid, slope = float(np.mean(series)), float(np.std(series)), 0.0
        ang[key] = val
        unc[key] = math.sqrt(resid**2 + (slope * dtc) ** 2 + ATTITUDE_SYSTEMATIC_DEG**2)
    return ang, unc


# ------------------------------------------------------------------ the impact
def find_impact(
    accel: pd.DataFrame | None, motors: pd.DataFrame | None, name: str
) -> tuple[float, tuple[float, float], float | None]:
    """The impact on the on-board clock: (time, (last quiet sample, first spike), power-off).

    The first on-board sample with ``|accel_xy| > IMPACT_RATE_THRESHOLD`` within
    [t_off - IMPACT_SEARCH_BEFORE_S, t_off + IMPACT_SEARCH_AFTER_S] of the first
    motor power-off t_off (RPM == POWER_OFF_RPM after take-off), or anywhere
    without one. ``accel``: ``t_s, x_raw, y_raw``; ``motors``: ``t_s, rpm1..4``;
    ``name`` starts error messages.
    """
    acc = accel
    mot = motors
    if acc is None or acc.empty:
        raise ValueError(f"{name}: no accel topic, cannot find the impact")
    t = acc["t_s"].to_numpy()
    mag = np.hypot(acc["x_raw"].to_numpy(), acc["y_raw"].to_numpy())
    t_off: float | None = None
    if mot is not None and not mot.empty:
        rpm = mot[["rpm1", "rpm2", "rpm3", "rpm4"]].to_numpy()
        flying = np.maximum.accumulate(rpm.max(axis=1) > 1000.0)
        off = flying & (rpm == POWER_OFF_RPM).any(axis=1)
        if off.any():
            t_off = float(mot["t_s"].to_numpy()[np.argmax(off)])
    if t_off is not None:
        window = (t >= t_off - IMPACT_SEARCH_BEFORE_S) & (t <= t_off + IMPACT_SEARCH_AFTER_S)
    else:
        window = np.ones(len(t), dtype=bool)
    hits = np.flatnonzero(window & (mag > IMPACT_RATE_THRESHOLD))
    if hits.size == 0:
        raise ValueError(f"{name}: no accelerometer spike above the threshold")
    i = int(hits[0])
    before = float(t[i - 1]) if i > 0 else float(t[i])
    return float(t[i]), (before, float(t[i])), t_off


def rest_time(accel: pd.DataFrame, impact_s: float) -> float | None:
    """First on-board time after the impact from which ``|accel|`` stays below
    ``REST_RATE_THRESHOLD`` for ``REST_HOLD_S`` (None: not before the log ends)."""
    acc = accel
    t = acc["t_s"].to_numpy()
    mag = np.sqrt((acc[["x_raw", "y_raw", "z_raw"]].to_numpy() ** 2).sum(axis=1))
    after = np.flatnonzero(t > impact_s)
    for k in after:
        w = (t >= t[k]) & (t <= t[k] + REST_HOLD_S)
        if t[w][-1] - t[k] >= 0.9 * REST_HOLD_S and np.all(mag[w] < REST_RATE_THRESHOLD):
            return float(t[k])
    return None


# ------------------------------------------------------------------ the contact
def approach_speed(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Local approach speed: slope of a linear fit of ``x`` over +-``STOP_HALF_WINDOW_S``."""
    v = np.full(len(t), np.nan)
    for k in range(len(t)):
        s = np.abs(t - t[k]) <= STOP_HALF_WINDOW_S
        if s.sum() >= 3:
            v[k] = lstsq(np.vander(t[s] - t[k], 2), x[s])[0][0]
    return v


def locate_contact(
    mocap: dict[str, np.ndarray] | None,
    impact_s: float,
    wall_x_default: float,
    offset_default: float,
) -> dict[str, Any]:
    """Locate the wall contact on the motion capture (step 1 of :func:`estimate_pre_impact`).

    ``mocap``: ``t`` (its own clock), ``p`` (NED, m), ``C`` (body -> NED); the
    set's wall plane and clock offset serve when the contact is not observed.
    Returns ``offset``, ``t_mocap``, ``method``, ``observed``, ``notes``,
    ``a_dec``, ``stop``.
    """
    res: dict[str, Any] = {"offset": offset_default, "t_mocap": math.nan,
                           "method": "none", "observed": False, "notes": [],
                           "a_dec": math.nan, "stop": math.nan}  # fmt: skip
    mc = mocap
    if mc is None:
        res["notes"].append("no motion capture in this log")
        return res
    t, x = mc["t"], mc["p"][:, 0]
    ti = impact_s
    stop = _stop(t, x, ti)
    if stop is not None:
        res["stop"] = stop
        best = _changepoint(t, x, stop)
        if best is not None and best[1] >= CONTACT_MIN_DECELERATION_M_S2:
            res.update(t_mocap=best[0], method="changepoint", observed=True, a_dec=best[1])
            res["offset"] = best[0] - ti
            return res
        res["notes"].append(
            f"a stop at {stop - ti:+.3f} s (mocap clock - impact) without a clear "
            "deceleration; not taken as the contact"
        )
    _unobserved_contact(res, mc, ti, stop, wall_x_default, offset_default)
    return res


def _stop(t: np.ndarray, x: np.ndarray, ti: float) -> float | None:
    """The first motion-capture time within ``CONTACT_SEARCH_S`` of the impact ``ti`` where
    the approach speed drops below ``STOP_FRACTION`` of its recent median (None: none)."""
    near = np.flatnonzero(np.abs(t - ti) <= CONTACT_SEARCH_S)
    if not near.size:
        return None
    lo = max(near[0] - 60, 0)
    sl = slice(lo, near[-1] + 1)
    ts, xs = t[sl], x[sl]
    vloc = approach_speed(ts, xs)
    for k in range(len(ts)):
        if abs(ts[k] - ti) > CONTACT_SEARCH_S:
            continue
        ref = (ts >= ts[k] - STOP_REF_S[0]) & (ts <= ts[k] - STOP_REF_S[1])
        if ref.sum() < 5 or np.isnan(vloc[ref]).all():
            continue
        vr = float(np.nanmedian(vloc[ref]))
        if vr > STOP_MIN_APPROACH_M_S and vloc[k] < STOP_FRACTION * vr:
            return float(ts[k])
    return None


def _changepoint(t: np.ndarray, x: np.ndarray, stop: float) -> tuple[float, float] | None:
    """The contact time and deceleration of the best change-point fit of ``X(t)`` around
    the stop: quadratic before, an extra constant deceleration after (None: no fit with a
    deceleration)."""
    f = (t >= stop - CHANGEPOINT_BEFORE_S - FIT_WINDOW_S) & (t <= stop + CHANGEPOINT_AFTER_S)
    tf, xf = t[f], x[f]
    best: tuple[float, float, np.ndarray] | None = None
    grid = np.arange(stop - CHANGEPOINT_BEFORE_S, stop + 0.5 * CHANGEPOINT_STEP_S,
                     CHANGEPOINT_STEP_S)  # fmt: skip
    for tc in grid:
        tau = tf - tc
        A = np.column_stack([np.ones_like(tau), tau, tau**2,
                             -0.5 * np.maximum(tau, 0.0) ** 2])  # fmt: skip
        co = lstsq(A, xf)[0]
        sse = float(np.sum((xf - matvec(A, co)) ** 2))
        if co[3] < 0:
            continue
        if best is None or sse < best[1]:
            best = (float(tc), sse, co)
    return None if best is None else (best[0], float(best[2][3]))


def _unobserved_contact(
    res: dict[str, Any],
    mc: dict[str, np.ndarray],
    ti: float,
    stop: float | None,
    wall_x_default: float,
    offset_default: float,
) -> None:
    """A contact not observed: the position fit extrapolated to the set's wall plane, or
    the on-board impact plus the set's clock offset (``res`` updated, with a note)."""
    t, x = mc["t"], mc["p"][:, 0]
    t_lim = ti + offset_default
    # usable approach: the gap-free segment holding the last sample before the
    # expected contact, up to its end (at most CONTACT_SEARCH_S later) or the stop
    seg = segments(t, MOCAP_GAP_S)
    before = np.flatnonzero(t <= t_lim)
    if before.size == 0:
        res["notes"].append("no motion capture before the impact")
        return
    usable = (seg == seg[before[-1]]) & (t <= t_lim + CONTACT_SEARCH_S)
    if stop is not None:
        usable &= t < stop
    last = int(np.flatnonzero(usable)[-1]) if usable.any() else int(before[-1])
    f = usable & (t >= t[last] - FIT_WINDOW_S) & (t <= t[last])
    reach = bumper_rim_extent(mc["C"][last][None], np.array([1.0, 0.0, 0.0]))[0].max()
    if f.sum() >= 6:
        cx, _ = polyfit_at(t[f] - t[last], x[f], 2)
        # solve x_fit(tau) + reach = wall for tau in [0, MAX_EXTRAPOLATION_S]
        taus = np.linspace(0.0, MAX_EXTRAPOLATION_S, 1501)
        gap = np.polyval(cx, taus) + reach - wall_x_default
        if x[last] + reach >= wall_x_default - 0.05 or np.any(gap >= 0):
            k = int(np.argmax(gap >= 0)) if np.any(gap >= 0) else 0
            tcm = float(t[last] + taus[k])
            res.update(t_mocap=tcm, method="wall-extrapolation", offset=tcm - ti)
            res["notes"].append(
                f"contact not observed: position fit extrapolated {taus[k]:.3f} s past "
                f"the last usable sample to the set's wall plane X = {wall_x_default} m"
            )
            return
    if t[last] < t_lim - MAX_EXTRAPOLATION_S:
        res["notes"].append(
            f"motion capture ends {t_lim - t[last]:.3f} s before the impact: no estimate"
        )
        return
    res.update(t_mocap=t_lim, method="clock-offset")
    far = wall_x_default - (x[last] + reach)
    res["notes"].append(
        "contact not observed: impact placed at the on-board impact plus the set's clock "
        f"offset; the vehicle is {far:.2f} m short of the set's wall plane there"
    )


def _no_estimate(impact_s: float, method: str, notes: list[str]) -> PreImpact:
    """Pre-impact conditions that could not be estimated: every quantity NaN, the time the
    on-board impact ``impact_s`` (s), with the contact's ``method`` and the ``notes``."""
    nan = math.nan
    return PreImpact(nan, nan, nan, nan, nan, nan, nan, time_s=impact_s,
                     method=method, notes=tuple(notes))  # fmt: skip


def _contact_time_uncertainty(t: np.ndarray, last: int, tc: float, observed: bool) -> float:
    """The contact time's uncertainty (s): half the local sample interval of the
    motion-capture times ``t`` around ``last`` (the last sample before the contact ``tc``)
    when the contact was ``observed``, else the span extrapolated past ``last``; at least
    0.01 s where neither is known."""
    if observed:
        local = np.diff(t[max(last - 3, 0) : last + 2])
        return 0.5 * float(np.median(local)) if local.size else 0.01
    return max(tc - t[last], 0.01)


def _velocity_at_contact(
    t: np.ndarray, p: np.ndarray, pre: np.ndarray, tc: float, dtc: float
) -> tuple[np.ndarray, np.ndarray, float]:
    """Velocity (m/s) and acceleration (m/s^2) at the contact ``tc`` (NED; quadratic fits of
    the positions ``p`` over :data:`FIT_WINDOW_S` of the samples ``pre`` before it), and the
    approach speed's uncertainty (m/s): the fit's standard error, half the spread over
    :data:`FIT_WINDOWS_SPREAD_S` and the acceleration times the contact time's uncertainty
    ``dtc`` (s)."""

    def fit(window: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return _velocity_fit(t[pre & (t >= tc - window)] - tc, p[pre & (t >= tc - window)])

    vel, acc, var = fit(FIT_WINDOW_S)
    spread = [fit(w)[0][0] for w in FIT_WINDOWS_SPREAD_S
              if (pre & (t >= tc - w)).sum() >= 6]  # fmt: skip
    sp = float(np.ptp(spread + [vel[0]]) / 2.0) if spread else 0.0
    return vel, acc, math.sqrt(var[0] + sp**2 + (acc[0] * dtc) ** 2)


def _wall_at_contact(
    mc: dict[str, np.ndarray],
    last: int,
    tc: float,
    speed: float,
    contact: dict[str, Any],
    wall_x_default: float,
    notes: list[str],
) -> tuple[int, float]:
    """The leading bumper (1-based) and the wall plane's X (m, NED) at the contact ``tc``:
    the last motion-capture sample before it (index ``last``) moved to ``tc`` at the
    approach ``speed`` (m/s) plus the bumpers' reach when the contact was observed (a note
    added to ``notes`` when that is over 5 cm from the set's ``wall_x_default``), the set's
    ``wall_x_default`` when extrapolated, NaN when placed by the clock offset."""
    t, p, C = mc["t"], mc["p"], mc["C"]
    reach = bumper_rim_extent(C[last][None], np.array([1.0, 0.0, 0.0]))[0]
    x_c = float(p[last, 0] + speed * (tc - t[last]))
    lead = int(np.argmax(reach)) + 1
    wall_x = x_c + float(reach.max()) if contact["observed"] else wall_x_default
    if contact["method"] == "clock-offset":
        wall_x = math.nan
    if contact["observed"] and abs(wall_x - wall_x_default) > 0.05:
        notes.append(
            f"leading rim at the contact at X = {wall_x:.3f} m, "
            f"{wall_x - wall_x_default:+.3f} m from the set's wall plane"
        )
    return lead, wall_x


def _attitude_samples(
    t: np.ndarray, C: np.ndarray, pre: np.ndarray, tc: float, last: int
) -> tuple[np.ndarray, np.ndarray]:
    """The attitude samples (their times in s relative to the contact ``tc``, and ``C``
    body -> NED) over :data:`ATTITUDE_WINDOW_S` before ``tc`` among those ``pre`` before
    it; over the window before the last sample ``last`` if that holds fewer than 3."""
    sa = pre & (t >= tc - ATTITUDE_WINDOW_S)
    if sa.sum() < 3:
        sa = pre & (t >= t[last] - ATTITUDE_WINDOW_S)
    return t[sa] - tc, C[sa]


def estimate_pre_impact(
    mocap: dict[str, np.ndarray] | None,
    contact: dict[str, Any],
    impact_s: float,
    wall_x_default: float,
) -> PreImpact:
    """Pre-impact conditions from the motion capture (method in ``docs/EXPERIMENTS.md``).

    1. Contact time t_c on the motion-capture clock: the approach speed
       (linear fit over +-``STOP_HALF_WINDOW_S``) drops below
       ``STOP_FRACTION`` of its recent median (the stop), then a
       change-point fit of X(t) (quadratic before, extra constant
       deceleration after) over the stop's neighbourhood gives t_c; it is
       accepted with a deceleration >= ``CONTACT_MIN_DECELERATION_M_S2``.
       Otherwise the position fit is extrapolated to ``SET1_WALL_X_M``
       (at most ``MAX_EXTRAPOLATION_S``) or, failing that, t_c is the
       on-board impact plus ``SET1_MOCAP_CLOCK_OFFSET_S``.
    2. Velocity and acceleration: quadratic fit of each position component
       over [t_c - ``FIT_WINDOW_S``, t_c] (samples before t_c only),
       differentiated at t_c; ``speed_m_s`` is its X component. Its
       uncertainty combines the fit's standard error, the spread over
       ``FIT_WINDOWS_SPREAD_S`` and the acceleration times the contact-time
       uncertainty (half the local sample interval, or the extrapolated
       span).
    3. Attitude: linear fit of each angle over [t_c - ``ATTITUDE_WINDOW_S``,
       t_c] evaluated at t_c; uncertainty: residual scatter, slope times
       the contact-time uncertainty, and ``ATTITUDE_SYSTEMATIC_DEG``.
    """
    c = contact
    notes = list(c["notes"])
    if mocap is None or not math.isfinite(c["t_mocap"]):
        return _no_estimate(impact_s, c["method"], notes)
    t, p, C = mocap["t"], mocap["p"], mocap["C"]
    tc = float(c["t_mocap"])
    pre = t < tc
    last = int(np.flatnonzero(pre)[-1])
    dtc = _contact_time_uncertainty(t, last, tc, bool(c["observed"]))
    n_fit = int((pre & (t >= tc - FIT_WINDOW_S)).sum())
    if n_fit < 6:
        notes.append(f"only {n_fit} samples in the fit window: no estimate")
        return _no_estimate(impact_s, c["method"], notes)
    vel, acc, u_speed = _velocity_at_contact(t, p, pre, tc, dtc)
    speed_lookback = float(vel[0] - acc[0] * LOOKBACK_S)
    # altitude at t_c from the same fit
    s = pre & (t >= tc - FIT_WINDOW_S)
    altitude = float(-polyfit_at(t[s] - tc, p[s, 2], 2)[0][-1])
    ang, unc = _attitude_at(*_attitude_samples(t, C, pre, tc, last), dtc)
    heading = float(wrap_angle_deg(ang["yaw_deg"]))
    rear = abs(heading) > 90.0
    equiv = float(wrap_angle_deg(heading - 180.0)) if rear else heading
    lead, wall_x = _wall_at_contact(mocap, last, tc, float(vel[0]), c, wall_x_default, notes)
    unc.update(
        speed_m_s=u_speed,
        heading_deg=unc["yaw_deg"],
        heading_front_equiv_deg=unc["yaw_deg"],
        altitude_m=math.sqrt(0.005**2 + (vel[2] * dtc) ** 2),
        time_s=dtc,
    )
    return PreImpact(
        heading_deg=heading,
        speed_m_s=float(vel[0]),
        inclination_deg=ang["inclination_deg"],
        roll_deg=ang["roll_deg"],
        pitch_deg=ang["pitch_deg"],
        yaw_deg=heading,
        altitude_m=altitude,
        uncertainty=unc,
        time_s=tc - c["offset"],
        velocity_m_s=(float(vel[0]), float(vel[1]), float(vel[2])),
        acceleration_m_s2=(float(acc[0]), float(acc[1]), float(acc[2])),
        speed_lookback_m_s=speed_lookback,
        heading_front_equiv_deg=equiv,
        rear_first=rear,
        leading_bumper=lead,
        wall_x_m=wall_x,
        contact_observed=bool(c["observed"]),
        method=str(c["method"]),
        notes=tuple(notes),
    )
