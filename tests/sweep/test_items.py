"""A sweep's runs are validated once, in the sweep: the workers copy them from the base.

``SweepSpec.validate`` checks, run by run, that the copy of the validated base
with the run's swept values (``inputs.derive.ScenarioFactory``) is the
validated run, values and types; the workers then build every run that way
(``sweep.items.scenario_of``) and validate nothing again.
"""

from __future__ import annotations

import pickle

import pytest

from quadimpact.inputs.derive import ScenarioFactory, same_scenario
from quadimpact.inputs.scenarios import scenario_from_dict
from quadimpact.studies.recovery.recovery_study import RecoveryStudy
from quadimpact.sweep import SweepSpec
from quadimpact.sweep.backends import make_chunks
from quadimpact.sweep.items import RunInputs, scenario_of

SPECS = {
    "recovery study": lambda: RecoveryStudy(n=40, imu="noisy").sweep_spec(),
    "grid of scenario and vehicle fields": lambda: SweepSpec(
        base={"model": "paper-replica", "vehicle_overrides": {"mass_kg": 1.2}},
        grid={
            "heading_deg": [0, 45],
            "inclination_deg": "-5,10",
            "restitution": [0.5, 0.9],
            "controller": ["paper", "cascade-pid"],
            "seed": [1, 2],
        },
    ),  # fmt: skip
    "sample with choices": lambda: SweepSpec(
        base={"kind": "impact-trial", "ground": "contact"},
        sample={
            "n": 20,
            "seed": 3,
            "ranges": {"speed_m_s": [0.5, 2.0], "roll_deg": [-10, 10]},
            "choices": {
                "model": ["default", "recovery-replica"],
                "rotor_slew_limit_rad_s2": [5000.0, "vehicle"],
            },
        },
    ),  # fmt: skip
}


@pytest.mark.parametrize("name", list(SPECS))
def test_copied_runs_are_the_validated_runs(name):
    spec = SPECS[name]()
    spec.validate()
    assert spec.sweep_base().derive
    items = [item for chunk in make_chunks(spec, range(spec.n_runs), 7) for item in chunk]
    assert len(items) == spec.n_runs
    for run_id, job, _columns in pickle.loads(pickle.dumps(items)):  # as a worker gets them
        assert isinstance(job, RunInputs)
        copied = scenario_of(job, where=f"run {run_id}")
        validated = scenario_from_dict(spec.scenario_dict(run_id))
        assert same_scenario(copied, validated, spec.columns), run_id
        assert copied.model_dump() == validated.model_dump()
        assert job.get("final_time_s", 3.0) == validated.final_time_s


def test_a_chunk_pickles_its_base_once():
    spec = RecoveryStudy(n=64).sweep_spec()
    spec.validate()
    one = pickle.dumps(next(make_chunks(spec, range(1), 1)))
    many = pickle.dumps(next(make_chunks(spec, range(64), 64)))
    assert len(many) < 64 * len(one) / 3  # the base once, then about 200 bytes a run


def test_nested_fields_are_validated_in_the_workers():
    """A swept IMU preset is a table once validated: those runs are validated in full."""
    spec = SweepSpec(base={"kind": "impact-trial"}, grid={"imu": ["ideal", "noisy"]})
    spec.validate()
    assert not spec.sweep_base().derive
    for run_id, job, _ in next(make_chunks(spec, range(2), 2)):
        assert scenario_of(job, "x") == scenario_from_dict(spec.scenario_dict(run_id))


def test_without_the_sweeps_check_the_workers_validate():
    spec = RecoveryStudy(n=2).sweep_spec()  # not validated: nothing is copied
    assert not spec.sweep_base().derive
    run_id, job, _ = next(make_chunks(spec, range(1), 1))[0]
    assert scenario_of(job, "x") == scenario_from_dict(spec.scenario_dict(run_id))


def test_an_integer_field_takes_the_integer_of_a_whole_float():
    factory = ScenarioFactory({"kind": "impact-trial"})
    assert factory.derives(["seed", "roll_deg", "model", "restitution"]) is False  # not a field
    factory = ScenarioFactory({"kind": "impact-trial"}, vehicle_fields=["restitution"])
    s = factory.scenario({"seed": 12.0, "roll_deg": 3, "restitution": 0.4})
    assert s.seed == 12 and type(s.seed) is int
    assert s.roll_deg == 3.0 and type(s.roll_deg) is float
    assert s.vehicle_overrides == {"restitution": 0.4}
