"""Episodes table, impact grouping and metrics on hand-made inputs (docs/STUDIES.md section 2)."""

import math

import numpy as np
import pandas as pd
import pytest

from quadimpact.core import layout as L
from quadimpact.core.recording_slots import (
    E_FEATURE,
    E_OPEN,
    E_PEAK_DELTA,
    E_PEAK_FORCE,
    E_SHAPE,
    E_T_END,
    E_T_PEAK,
    E_T_PEAK_FORCE,
    E_T_START,
    E_V_I,
    NEP,
    OUT_CMD,
    OUT_DELTA,
    OUT_T,
    OUT_X,
    out_width,
)
from quadimpact.results.files import EPISODE_COLUMNS, TIMESERIES_COLUMNS
from quadimpact.rotations import euler_zyx_to_quat
from quadimpact.simulation.metrics import (
    EpisodeLists,
    attitude_excursion_deg,
    group_impacts,
    impact_metrics,
    impacts_in,
    short_impacts,
)
from quadimpact.simulation.tables import (
    episode_columns,
    episode_lists_of,
    episodes_frame,
    timeseries_frame,
)

SURFACES = ("wall", "ground")
D = math.pi / 180.0


def raw_episodes(*eps: dict, extra_rows: int = 2) -> np.ndarray:
    """Kernel-style episode buffer; ``bumper`` given 1-based here, stored 0-based."""
    raw = np.full((len(eps) + extra_rows, NEP), -999.0)  # garbage beyond n
    for i, e in enumerate(eps):
        raw[i, E_FEATURE] = e["bumper"] - 1
        raw[i, E_SHAPE] = SURFACES.index(e.get("surface", "wall"))
        raw[i, E_T_START] = e["t0"]
        raw[i, E_T_END] = e["t1"]
        raw[i, E_V_I] = e.get("v_i", 0.7)
        raw[i, E_PEAK_DELTA] = e.get("peak", 0.01)
        raw[i, E_T_PEAK] = 0.5 * (e["t0"] + e["t1"])
        raw[i, E_PEAK_FORCE] = e.get("force", 10.0)
        raw[i, E_T_PEAK_FORCE] = 0.5 * (e["t0"] + e["t1"])
        raw[i, E_OPEN] = 1.0 if e.get("open", False) else 0.0
    return raw


def frame(*eps: dict) -> pd.DataFrame:
    return episodes_frame(raw_episodes(*eps), len(eps), SURFACES)


def ep(bumper: int, t0: float, t1: float, **kw: object) -> dict:
    return {"bumper": bumper, "t0": t0, "t1": t1, **kw}


# ---------------------------------------------------------------- episodes table


def test_episodes_frame_columns_mapping_and_sorting() -> None:
    df = frame(
        ep(4, 0.5, 0.53, peak=0.021, force=40.0),
        ep(2, 0.7, 0.72, surface="ground"),
        ep(1, 0.5, 0.52, peak=0.020, force=38.0, v_i=0.71),
    )
    assert tuple(df.columns) == EPISODE_COLUMNS
    assert df["bumper"].tolist() == [1, 4, 2]  # by start, then bumper
    assert df["surface"].tolist() == ["wall", "wall", "ground"]
    assert df["peak_delta_m"].tolist() == [0.020, 0.021, 0.01]
    assert df["v_i_m_s"].iloc[0] == 0.71
    assert df["open"].dtype == bool and not df["open"].any()
    assert df["bumper"].dtype == np.int64
    assert list(df.index) == [0, 1, 2]


def test_episodes_frame_empty_has_contract_columns() -> None:
    df = episodes_frame(np.zeros((5, NEP)), 0, SURFACES)
    assert len(df) == 0
    assert tuple(df.columns) == EPISODE_COLUMNS


@pytest.mark.parametrize("build", [episodes_frame, episode_lists_of])
def test_episodes_frame_rejects_bad_indices(build) -> None:
    """The table and the summary's lists refuse the same records, with the same words."""
    raw = raw_episodes(ep(1, 0.5, 0.6))
    raw[0, E_SHAPE] = 5
    with pytest.raises(ValueError, match=r"surface index outside 0\.\.1 \(got \[5\]\)"):
        build(raw, 1, SURFACES)
    raw = raw_episodes(ep(1, 0.5, 0.6))
    raw[0, E_FEATURE] = 3.6  # rounds to 4: bumper 5 of a four-bumper vehicle
    with pytest.raises(ValueError, match=r"feature index outside 0\.\.3 \(got \[4\]\)"):
        build(raw, 1, SURFACES)
    with pytest.raises(ValueError, match="row count"):
        build(raw, 10, SURFACES)


def test_episode_lists_are_the_columns_as_lists_ties_and_all() -> None:
    """What a summary reads (lists from the raw rows) is the table's columns, same order:
    by start, then bumper, and rows tied on both in the kernel's order."""
    rng = np.random.default_rng(3)
    for n in (0, 1, 2, 7, 15):
        eps = [
            ep(
                int(rng.integers(1, 5)),
                float(rng.choice([0.5, 0.51, 0.6])),  # many ties of start
                0.0,
                surface=str(rng.choice(SURFACES)),
                peak=float(rng.random()),
                force=float(rng.random()),
                open=bool(rng.random() < 0.3),
            )
            for _ in range(n)
        ]
        for e in eps:
            e["t1"] = e["t0"] + float(rng.choice([0.0, 0.01, 0.02]))
        raw = raw_episodes(*eps)
        cols = episode_columns(raw, n, SURFACES)
        lists = episode_lists_of(raw, n, SURFACES)
        assert type(lists) is EpisodeLists and list(lists) == list(cols)
        for name, values in cols.items():
            assert lists[name] == values.tolist(), name
            assert [type(v) for v in lists[name]] == [type(v) for v in values.tolist()], name
        assert impact_metrics(lists) == impact_metrics(cols)


def test_the_impacts_of_episode_lists_are_found_once_per_exclusion() -> None:
    """The summary's metrics, its short-impact warning and the recovery metrics share
    one grouping per set of excluded surfaces, and get what a fresh grouping gives."""
    raw = raw_episodes(ep(1, 0.5, 0.52), ep(2, 0.51, 0.55), ep(3, 0.7, 0.7001, surface="ground"))
    lists = episode_lists_of(raw, 3, SURFACES)
    first = impacts_in(lists, ("ground",), 0.01)
    assert impacts_in(lists, ["ground"], 0.01) is first  # kept
    assert impacts_in(lists, ("ground", "pole"), 0.01) is first  # no "pole" episode: the same
    assert impacts_in(lists, (), 0.01) is not first  # another exclusion, found again
    assert first == impacts_in(dict(lists), ("ground",), 0.01)  # a plain mapping: not kept
    assert short_impacts(lists, 0.1, graze_fraction=0.01) == (1, 0.55 - 0.5)


# ---------------------------------------------------------------- time series


def test_timeseries_frame_columns_and_derived_quantities() -> None:
    n = 3
    raw = np.zeros((n + 2, out_width(4)))
    q = euler_zyx_to_quat(10 * D, -15 * D, 90 * D)
    for i in range(n):
        raw[i, OUT_T] = 0.001 * i
        raw[i, OUT_X + L.X_POS : OUT_X + L.X_POS + 3] = [1.0 + i, 0.5, -2.0]
        raw[i, OUT_X + L.X_VEL : OUT_X + L.X_VEL + 3] = [0.75, 0.0, 0.0]
        raw[i, OUT_X + L.X_QUAT : OUT_X + L.X_QUAT + 4] = q
        raw[i, OUT_X + L.X_OMEGA : OUT_X + L.X_OMEGA + 3] = [0.1, 0.2, 0.3]
        raw[i, OUT_X + L.X_ROTOR : OUT_X + L.X_ROTOR + 4] = [600, 610, 620, 630]
        raw[i, OUT_DELTA : OUT_DELTA + 4] = [0.001, 0.002, 0.003, 0.004]
        raw[i, OUT_DELTA + 4 : OUT_DELTA + 8] = [1.0, 2.0, 3.0, 4.0]
        raw[i, OUT_CMD : OUT_CMD + 4] = [700, 710, 720, 730]
    ts = timeseries_frame(raw, n)
    assert tuple(ts.columns) == TIMESERIES_COLUMNS
    assert len(ts) == n
    np.testing.assert_allclose(ts["t_s"], [0.0, 0.001, 0.002])
    np.testing.assert_allclose(ts["x_m"], [1.0, 2.0, 3.0])
    np.testing.assert_allclose(ts["altitude_m"], 2.0)
    np.testing.assert_allclose(ts["roll_deg"], 10.0, atol=1e-12)
    np.testing.assert_allclose(ts["pitch_deg"], -15.0, atol=1e-12)
    np.testing.assert_allclose(ts["yaw_deg"], 90.0, atol=1e-12)
    # Body forward velocity 0.75 m/s; yaw 90 deg points body x mostly along inertial +Y,
    # pitch -15 deg (nose down, tilted toward the motion) gives a +Z (down) component.
    np.testing.assert_allclose(ts["vx_m_s"], 0.0, atol=1e-12)
    np.testing.assert_allclose(ts["vy_m_s"], 0.75 * math.cos(15 * D), atol=1e-12)
    np.testing.assert_allclose(ts["vz_m_s"], 0.75 * math.sin(15 * D), atol=1e-12)
    np.testing.assert_allclose(ts["u_m_s"], 0.75)
    np.testing.assert_allclose(ts[["q0", "q1", "q2", "q3"]].to_numpy()[0], q)
    assert ts["r_rad_s"].iloc[0] == 0.3
    assert ts["omega3_rad_s"].iloc[0] == 620
    assert ts["omega_cmd4_rad_s"].iloc[0] == 730
    assert ts["delta2_m"].iloc[0] == 0.002
    assert ts["force4_n"].iloc[0] == 4.0


def test_timeseries_frame_empty() -> None:
    ts = timeseries_frame(np.zeros((4, out_width(4))), 0)
    assert tuple(ts.columns) == TIMESERIES_COLUMNS and len(ts) == 0


# ---------------------------------------------------------------- grouping


def test_group_impacts_returns_iloc_positions_in_time_order() -> None:
    df = pd.DataFrame(
        {
            "bumper": [3, 4, 1, 4],
            "t_start_s": [0.60, 0.50, 0.51, 0.50],
            "t_end_s": [0.61, 0.52, 0.53, 0.50],
        }
    )
    # rows 1 and 3 start together (tie broken by bumper, 4 == 4 keeps row order),
    # row 2 starts before the group's end, row 0 after.
    assert group_impacts(df) == [[1, 3, 2], [0]]


def test_group_impacts_empty() -> None:
    assert group_impacts(frame()) == []


# ---------------------------------------------------------------- metrics


def test_no_contact_at_all() -> None:
    m = impact_metrics(frame())
    assert math.isnan(m["delta_init_m"]) and math.isnan(m["peak_force_n"])
    assert math.isnan(m["initial_impact_start_s"]) and math.isnan(m["initial_impact_duration_s"])
    assert m["leading_bumpers"] == [] and m["aft_bumpers"] == []
    assert m["n_episodes"] == 0
    assert m["n_subsequent_impacts"] == 0 and m["n_subsequent_episodes"] == 0
    assert m["subsequent_impacts"] == []


def test_single_episode() -> None:
    m = impact_metrics(frame(ep(4, 0.5, 0.52, peak=0.031, force=55.0)))
    assert m["delta_init_m"] == 0.031
    assert m["peak_force_n"] == 55.0
    assert m["initial_impact_start_s"] == 0.5
    assert m["initial_impact_end_s"] == 0.52
    assert m["initial_impact_duration_s"] == pytest.approx(0.02, abs=1e-15)
    assert m["leading_bumpers"] == [4]
    assert m["aft_bumpers"] == [1, 2, 3]
    assert m["n_episodes"] == 1
    assert m["n_subsequent_impacts"] == 0 and m["n_subsequent_episodes"] == 0


def test_simultaneous_two_bumper_initial_impact_psi_0() -> None:
    m = impact_metrics(
        frame(
            ep(4, 0.5, 0.531, peak=0.0212, force=41.0),
            ep(1, 0.5, 0.530, peak=0.0210, force=42.0),
        )
    )
    assert m["leading_bumpers"] == [1, 4]
    assert m["aft_bumpers"] == [2, 3]
    assert m["delta_init_m"] == 0.0212  # the larger of bumpers 1 and 4
    assert m["peak_force_n"] == 42.0
    assert m["initial_impact_end_s"] == 0.531
    assert m["n_subsequent_impacts"] == 0


def test_chained_overlap_joins_after_first_episode_ended() -> None:
    m = impact_metrics(
        frame(
            ep(4, 0.50, 0.52, peak=0.02),
            ep(1, 0.51, 0.55, peak=0.01),  # starts during bumper 4's episode
            ep(2, 0.54, 0.56, peak=0.03),  # starts after 4 ended, before 1 ended: joins
            ep(3, 0.60, 0.61, peak=0.005),  # after the chain ended: new impact
        )
    )
    assert m["leading_bumpers"] == [1, 2, 4]
    assert m["aft_bumpers"] == [3]
    assert m["delta_init_m"] == 0.03
    assert m["initial_impact_start_s"] == 0.50
    assert m["initial_impact_end_s"] == 0.56
    assert m["n_subsequent_impacts"] == 1
    assert m["n_subsequent_episodes"] == 1
    assert m["subsequent_impacts"] == [[3]]


def test_grazing_contacts() -> None:
    # A zero-length graze at the same instant as the real onset joins the initial
    # impact; a later graze is a subsequent impact of its own.
    m = impact_metrics(
        frame(
            ep(1, 0.5, 0.5, peak=1e-9, force=1e-6),
            ep(4, 0.5, 0.52, peak=0.02, force=30.0),
            ep(3, 0.8, 0.8 + 1e-6, peak=2e-8, force=1e-5),
        )
    )
    assert m["leading_bumpers"] == [1, 4]
    assert m["delta_init_m"] == 0.02
    assert m["n_episodes"] == 3
    assert m["n_subsequent_impacts"] == 1
    assert m["subsequent_impacts"] == [[3]]


def test_alternating_subsequent_impacts_type_d_pattern() -> None:
    # Paper Figure 5: leading bumper 4, then alternating aft 2 / leading 4 with small
    # contacts on the side bumpers 1 and 3.
    m = impact_metrics(
        frame(
            ep(4, 0.50, 0.53, peak=0.035),
            ep(2, 0.60, 0.63, peak=0.02),
            ep(4, 0.70, 0.72, peak=0.015),
            ep(2, 0.80, 0.83, peak=0.012),
            ep(1, 0.805, 0.81, peak=0.001),
            ep(4, 0.90, 0.92, peak=0.010),
            ep(3, 0.91, 0.915, peak=0.0005),
        )
    )
    assert m["leading_bumpers"] == [4]
    assert m["aft_bumpers"] == [1, 2, 3]
    assert m["delta_init_m"] == 0.035
    assert m["n_episodes"] == 7
    assert m["n_subsequent_impacts"] == 4
    assert m["n_subsequent_episodes"] == 6
    assert m["subsequent_impacts"] == [[2], [4], [2, 1], [4, 3]]


def test_ground_episodes_excluded() -> None:
    eps = frame(
        ep(2, 0.40, 0.60, surface="ground", peak=0.05, force=99.0),
        ep(4, 0.50, 0.52, peak=0.02, force=30.0),
        ep(2, 1.20, 1.30, surface="ground"),
        ep(3, 1.21, 1.25, surface="ground"),
    )
    m = impact_metrics(eps)
    assert m["n_episodes"] == 1
    assert m["leading_bumpers"] == [4]
    assert m["delta_init_m"] == 0.02 and m["peak_force_n"] == 30.0
    assert m["n_subsequent_impacts"] == 0
    # Without exclusion the ground contact at 0.40 s would lead.
    m_all = impact_metrics(eps, exclude_surfaces=())
    assert m_all["n_episodes"] == 4
    assert m_all["leading_bumpers"] == [2, 4]
    assert m_all["n_subsequent_impacts"] == 1


def test_open_episode_at_run_end() -> None:
    eps = frame(
        ep(4, 0.50, 0.52, peak=0.02),
        ep(2, 2.90, 3.00, open=True),  # still in contact at the final time, 3 s
        ep(1, 2.95, 2.97),
    )
    assert eps["open"].tolist() == [False, True, False]
    m = impact_metrics(eps)
    assert m["n_subsequent_impacts"] == 1
    assert m["n_subsequent_episodes"] == 2
    assert m["subsequent_impacts"] == [[2, 1]]


def test_open_initial_impact_lasts_to_run_end() -> None:
    m = impact_metrics(frame(ep(4, 2.5, 3.0, open=True), ep(1, 2.9, 2.95)))
    assert m["initial_impact_end_s"] == 3.0
    assert m["initial_impact_duration_s"] == pytest.approx(0.5)
    assert m["leading_bumpers"] == [1, 4]


# ---------------------------------------------------------------- attitude excursion


def _euler_ts(rows: list[tuple[float, float, float]], with_quat: bool) -> pd.DataFrame:
    a = np.array(rows, dtype=float)
    ts = pd.DataFrame({"roll_deg": a[:, 0], "pitch_deg": a[:, 1], "yaw_deg": a[:, 2]})
    if with_quat:
        q = euler_zyx_to_quat(*np.radians(a).T)
        for k in range(4):
            ts[f"q{k}"] = q[:, k]
    return ts


@pytest.mark.parametrize("with_quat", [True, False])
def test_attitude_excursion(with_quat: bool) -> None:
    refs = {"roll_rad": 0.0, "pitch_rad": -15 * D, "yaw_rad": 45 * D, "altitude_m": 2.0}
    rows = [(0.0, -15.0, 45.0), (10.0, -15.0, 45.0), (0.0, -40.0, 45.0), (0.0, -15.0, -170.0)]
    m = attitude_excursion_deg(_euler_ts(rows, with_quat), refs)
    assert m["roll_excursion_deg"] == pytest.approx(10.0)
    assert m["pitch_excursion_deg"] == pytest.approx(25.0)
    assert m["yaw_excursion_deg"] == pytest.approx(145.0)  # wrap(-170 - 45) = 145
    # Yaw change of 215 deg at a 15 deg tilt: cos(tilt) = s^2 cos(215) + c^2.
    s, c = math.sin(15 * D), math.cos(15 * D)
    tilt_yaw = math.degrees(math.acos(s * s * math.cos(215 * D) + c * c))
    assert tilt_yaw > 25.0
    assert m["tilt_max_deg"] == pytest.approx(tilt_yaw, abs=1e-9)


def test_attitude_excursion_roll_wraps_through_180() -> None:
    refs = {"roll_rad": 170 * D, "pitch_rad": 0.0, "yaw_rad": 0.0, "altitude_m": 2.0}
    m = attitude_excursion_deg(_euler_ts([(-175.0, 0.0, 0.0)], True), refs)
    assert m["roll_excursion_deg"] == pytest.approx(15.0)
    assert m["tilt_max_deg"] == pytest.approx(15.0)


def test_attitude_excursion_empty() -> None:
    refs = {"roll_rad": 0.0, "pitch_rad": 0.0, "yaw_rad": 0.0, "altitude_m": 2.0}
    m = attitude_excursion_deg(_euler_ts([(0.0, 0.0, 0.0)], True).iloc[:0], refs)
    assert all(math.isnan(v) for v in m.values())
