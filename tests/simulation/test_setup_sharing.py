"""Impact trials and wall approaches share their packing: kept or not, a packed run is the
same, bit for bit.

``simulation.resolve`` resolves the part of an impact trial or a wall approach
that its initial state, attitude and seed do not change once per process
(a ``ResolvedShared``, kept by ``simulation/sharing.py``), which is packed
once, and completes a copy per run. These tests pack runs with the kept packing and alone (the cache
emptied) and compare every array byte for byte (a wall approach's solved
start included); check that no state field reaches the shared part; and
that a changed field or vehicle file packs again.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from quadimpact.inputs.resolved import ResolvedShared
from quadimpact.inputs.scenarios import ImpactTrial, WallApproach
from quadimpact.inputs.world import Cylinder
from quadimpact.packing.run_model import output_grid, pack_shared
from quadimpact.simulation import resolve as R
from quadimpact.simulation import setup as S
from quadimpact.simulation.sharing import TRIAL_STATE_FIELDS, WALL_STATE_FIELDS, clear_kept

ARRAYS = ("x0", "veh", "feat", "shapes", "opts", "ctrl", "scfg", "noise", "ecfg", "snoise")
NOISY = {
    "imu": {"preset": "noisy", "gyro_bias_walk_rad_s_sqrt_s": 1e-3},
    "magnetometer": {"noise": 0.01},
    "estimator": "complementary",
    "estimator_params": {"initial_attitude_error_deg": 2.0, "initial_bias_error_rad_s": 0.01},
}
POLE = {"obstacles": [Cylinder(name="pole", point_m=(0.0, 0.0, 0.0), radius_m=0.05)]}


def _trials(extra: dict) -> list[ImpactTrial]:
    rng = np.random.default_rng(11)
    out = []
    for k in range(6):
        roll, pitch, yaw = rng.uniform(-30.0, 30.0, 3)
        out.append(
            ImpactTrial(
                controller="recovery",
                roll_deg=roll,
                pitch_deg=pitch,
                yaw_deg=yaw,
                speed_m_s=rng.uniform(0.3, 1.2),
                seed=k,
                final_time_s=0.5,
                **extra,
            )
        )
    return out


def _same(a: S.RunSetup, b: S.RunSetup) -> None:
    names = {f.name for f in dataclasses.fields(S.RunSetup)}
    assert set(vars(a)) == set(vars(b)) == names  # a run is a copy with its fields, no other
    for name in ARRAYS:
        x, y = np.asarray(getattr(a, name)), np.asarray(getattr(b, name))
        assert x.shape == y.shape and x.tobytes() == y.tobytes(), name
    assert (a.t0, a.tf, a.n_imu) == (b.t0, b.tf, b.n_imu)
    assert a.references == b.references and a.warnings == b.warnings
    assert a.resolved == b.resolved and a.shape_names == b.shape_names


def _same_shared(a: ResolvedShared, b: ResolvedShared) -> None:
    """Two resolved shared parts pack the same arrays, bit for bit."""
    pa, pb = pack_shared(a), pack_shared(b)
    for name, x, y in zip(pa.model._fields, pa.model, pb.model, strict=True):
        x, y = np.asarray(x), np.asarray(y)
        assert x.shape == y.shape and x.tobytes() == y.tobytes(), name
    assert pa.n_imu == pb.n_imu and pa.resolved == pb.resolved
    assert a.warnings == b.warnings
    assert [x.name for x in a.surfaces] == [x.name for x in b.surfaces]


@pytest.mark.parametrize("extra", [{}, NOISY, POLE], ids=["ideal-imu", "noisy-sensors", "pole"])
def test_a_trial_packed_with_the_kept_packing_is_the_trial_packed_alone(extra: dict) -> None:
    trials = _trials(extra)
    kept = [S.prepare(t) for t in trials]  # the first packs the shared part, the rest reuse it
    for trial, setup in zip(trials, kept, strict=True):
        clear_kept()
        _same(setup, S.prepare(trial))
    # the kept runs do not share what a run owns
    assert kept[0].ctrl is not kept[1].ctrl and kept[0].scfg is not kept[1].scfg
    assert kept[0].warnings is not kept[1].warnings
    if extra is NOISY:  # the seeds really draw: different noise, biases and initial errors
        assert not np.array_equal(kept[0].noise, kept[1].noise)
        assert not np.array_equal(kept[0].snoise, kept[1].snoise)
        assert not np.array_equal(kept[0].ecfg, kept[1].ecfg)


@pytest.mark.parametrize("field", TRIAL_STATE_FIELDS)
def test_no_state_field_reaches_the_shared_packing(field: str) -> None:
    base = {**NOISY, **POLE, "controller": "recovery", "final_time_s": 0.5}
    changed = {
        "seed": 7,
        "start_distance_m": 0.4,
        "lateral_offset_m": 0.02,
        "altitude_m": 1.3,
    }.get(field, 0.37 if field == "speed_m_s" else 12.5)
    clear_kept()
    one = R.trial_shared(ImpactTrial(**base))
    clear_kept()
    two = R.trial_shared(ImpactTrial(**base, **{field: changed}))
    _same_shared(one, two)
    assert one.front is not None and one.front[0] == two.front[0]


def test_a_changed_field_or_vehicle_file_packs_again(tmp_path: Path) -> None:
    clear_kept()
    a = S.prepare(ImpactTrial(controller="recovery", friction_coefficient=0.3, final_time_s=0.5))
    b = S.prepare(ImpactTrial(controller="recovery", friction_coefficient=0.6, final_time_s=0.5))
    assert not np.array_equal(a.feat, b.feat)
    bundled = Path(S.__file__).parents[1] / "inputs" / "vehicles" / "navi.toml"
    path = tmp_path / "mine.toml"
    path.write_text(bundled.read_text())
    trial = ImpactTrial(controller="recovery", vehicle=str(path), final_time_s=0.5)
    mass = S.prepare(trial).veh.copy()
    text = path.read_text()
    old = next(line for line in text.splitlines() if line.startswith("mass_kg"))
    path.write_text(text.replace(old, "mass_kg = 0.9"))
    assert not np.array_equal(S.prepare(trial).veh, mass)


def test_kept_runs_share_their_output_times_and_pair_table_while_they_are_theirs() -> None:
    """A trial's model takes the output times and the pair table its shared packing
    computed once (the same arrays), equal to those computed afresh; a run whose
    times or shapes differ gets its own."""
    clear_kept()
    a, b = (S.prepare(t) for t in _trials({})[:2])
    ma, mb = a.model(), b.model()
    assert ma.t_out is mb.t_out and ma.pairs is mb.pairs
    fresh = S.prepare(_trials({})[3])
    assert np.array_equal(ma.t_out, output_grid(a.t0, a.tf, a.output_rate_hz))
    assert np.array_equal(ma.pairs, S.pair_table(a.feat, a.shapes))
    longer = a.model(tf=0.75)
    assert longer.t_out[-1] == 0.75 and longer.t_out.shape[0] > ma.t_out.shape[0]
    assert a.model(x0=a.x0.copy()).t_out is ma.t_out  # the same times: the same grid
    other_shapes = a.shapes.copy()
    assert a.model(shapes=other_shapes).pairs is not ma.pairs
    assert fresh.model().t_out is ma.t_out  # the same kept packing (same fields but state)


def _approaches(model: str) -> list[WallApproach]:
    out = []
    for k, (heading, incl, speed) in enumerate(
        [(0.0, -10.0, 0.75), (45.0, 15.0, 0.5), (45.0, 5.0, 1.0), (0.0, 20.0, 0.5)]
    ):  # the second and the last start late
        out.append(
            WallApproach(
                heading_deg=heading,
                inclination_deg=incl,
                speed_m_s=speed,
                model=model,
                seed=k,
                imu={"preset": "noisy"},
                final_time_s=0.6,
            )
        )
    return out


@pytest.mark.parametrize("model", ["default", "paper-replica"])
def test_a_wall_approach_packed_with_the_kept_packing_is_the_approach_packed_alone(model):
    runs = _approaches(model)
    kept = [S.prepare(r) for r in runs]
    assert any(k.approach["late_start"] for k in kept)
    for run, setup in zip(runs, kept, strict=True):
        clear_kept()
        alone = S.prepare(run)
        _same(setup, alone)
        assert setup.approach == alone.approach and setup.x0.tobytes() == alone.x0.tobytes()
    assert kept[0].ctrl is not kept[1].ctrl and kept[0].noise is not kept[1].noise


@pytest.mark.parametrize("field", WALL_STATE_FIELDS)
def test_no_wall_approach_state_field_reaches_the_shared_packing(field: str) -> None:
    base = {"imu": {"preset": "noisy"}, "final_time_s": 0.6}
    attitude = {"roll_deg": 3.0, "pitch_deg": -4.0}  # given together
    changed = {
        "seed": {"seed": 7},
        "speed_m_s": {"speed_m_s": 0.37},
        "impact_time_s": {"impact_time_s": 0.4},
        "altitude_m": {"altitude_m": 1.3},
        "start_altitude_m": {"start_altitude_m": 1.7},
        "roll_deg": attitude,
        "pitch_deg": attitude,
    }.get(field, {field: 12.5})
    clear_kept()
    one = R.wall_shared(WallApproach(**base))
    clear_kept()
    two = R.wall_shared(WallApproach(**base, **changed))
    _same_shared(one, two)
