"""Each parameter's default is decided in one place: the resolve step, never the packer.

``simulation/resolve.py`` turns a scenario into a frozen resolved description
with every default applied; ``packing/run_model.py``'s ``pack`` writes it. These
tests resolve runs of every built-in component (both bundled vehicles, the
three controllers under every recovery-law tuning, every estimator, every
sensor preset and sensor component, every obstacle kind) and check two
things. The resolved description holds a number wherever a packer writes one:
a ``None`` left in it means "none" and is declared below (a new optional
parameter fails here until it is resolved or declared). And no packer substitutes a default
for a missing value: every number a packer reads, made ``None``, is refused
(a ``None -> g`` fallback in a packer would pack it instead).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator

import numpy as np
import pytest
from pydantic import BaseModel

from quadimpact.core import controller_slots as CTL
from quadimpact.core.controllers import recovery as REC
from quadimpact.core.geometry.sphere import SphereObstacle
from quadimpact.inputs.estimators import BUILTIN as BUILTIN_ESTIMATORS
from quadimpact.inputs.model import MODEL_VARIANTS, RECOVERY_LAWS
from quadimpact.inputs.resolved import ResolvedRun, ResolvedShared
from quadimpact.inputs.scenarios import FlightScenario, ImpactTrial, WallApproach
from quadimpact.inputs.sensors import BUILTIN_SENSOR_PRESETS
from quadimpact.inputs.world import Box, Cylinder, Plane
from quadimpact.packing.run_model import pack, pack_shared
from quadimpact.simulation.resolve import resolve
from quadimpact.simulation.setup import prepare

#: The parameters whose ``None`` is a value of its own (not "the default"), by model:
#: what the packer writes for it is a code of the kernel, not a number chosen for it.
NONE_IS_A_VALUE = {
    "RecoveryParams": {
        "lean_cut_deg",  # never cut (2.0: no sine reaches it)
        "hover_set_point_m",  # hold where hover_hold says
        "policy",  # no learned residual
    },
    "ResolvedImu": {
        "accel_range_m_s2",  # no saturation
        "gyro_range_rad_s",  # no saturation
        "impact_disturbance",  # none
        "filter_time_constant_s",  # only with filter = "first-order"
        "filter_window",  # only with filter = "moving-average"
    },
    "Vehicle": {
        "bumper_centres_m",  # on the rotor hubs: the vehicle's geometry (contact_features)
        "features",  # the four bumper rings (contact_features)
        "rotor_slew_limit_rpm_per_s",  # not known
    },
    "Cylinder": {"length_m"},  # infinite
}
#: Fields of the resolved shared part that may be ``None``: what is absent.
SHARED_NONE = {"wall", "front", "slew_limit_rad_s2"}

OBSTACLES = {
    "plane": Plane(name="slab", point_m=(0.3, 0.0, 0.0), normal=(-1.0, 0.0, 0.0)),
    "cylinder": Cylinder(name="pole", point_m=(0.0, 0.0, 0.0), radius_m=0.05),
    "box": Box(name="edge", centre_m=(0.2, 0.0, -1.0), half_extents_m=(0.1, 0.2, 1.5)),
    "sphere": SphereObstacle(name="ball", centre_m=(0.4, 0.0, -1.0), radius_m=0.3),
}


def _scenarios() -> Iterator[tuple[str, object]]:
    for vehicle in ("spiri", "navi"):
        yield f"wall-{vehicle}", WallApproach(vehicle=vehicle, final_time_s=0.6)
        yield f"flight-{vehicle}", FlightScenario(vehicle=vehicle, final_time_s=0.5)
        for controller in ("paper", "cascade-pid"):
            yield (
                f"trial-{vehicle}-{controller}",
                ImpactTrial(vehicle=vehicle, controller=controller, final_time_s=0.5),
            )
    for model in MODEL_VARIANTS:  # every recovery-law tuning
        yield f"recovery-{model}", ImpactTrial(model=model, controller="recovery")
    yield (
        "recovery-amag-g",
        ImpactTrial(controller="recovery", controller_params={"a_mag_m_s2": None}),
    )
    for estimator in BUILTIN_ESTIMATORS:
        for preset in BUILTIN_SENSOR_PRESETS:
            yield (
                f"{estimator}-{preset}",
                ImpactTrial(controller="recovery", estimator=estimator, sensors=preset),
            )
    for kind, obstacle in OBSTACLES.items():
        yield f"obstacle-{kind}", ImpactTrial(controller="recovery", obstacles=[obstacle])
    yield "ground-contact", FlightScenario(ground="contact", final_time_s=0.5)


SCENARIOS = dict(_scenarios())


def _none_fields(params: BaseModel) -> set[str]:
    return {name for name in type(params).model_fields if getattr(params, name) is None}


def test_every_recovery_law_tuning_is_flown_by_a_model_variant() -> None:
    tunings = {v["recovery_law"] for v in MODEL_VARIANTS.values()}
    assert tunings == set(RECOVERY_LAWS)


@pytest.mark.parametrize("name", SCENARIOS)
def test_the_resolved_run_holds_a_number_wherever_a_packer_writes_one(name: str) -> None:
    r = resolve(SCENARIOS[name])
    shared = r.shared
    components = [shared.controller.params, shared.estimator.params, shared.imu, shared.vehicle]
    components += [*shared.instruments.values(), *shared.surfaces, shared.options]
    context = shared.estimator.context
    components += [c for c in (context.magnetometer, context.pose_sensor) if c is not None]
    for component in components:
        allowed = NONE_IS_A_VALUE.get(type(component).__name__, set())
        assert _none_fields(component) <= allowed, type(component).__name__
    for f in dataclasses.fields(ResolvedShared):
        if f.name not in SHARED_NONE:
            assert getattr(shared, f.name) is not None, f.name
    for number in ("duration_s", "control_rate_hz", "output_rate_hz", "rtol", "atol"):
        assert math.isfinite(getattr(shared, number)) and getattr(shared, number) > 0.0
    assert r.x0 is not None or r.shot is not None
    assert set(r.references) == {"altitude_m", "roll_rad", "pitch_rad", "yaw_rad"}


def test_the_recovery_law_push_of_none_is_the_vehicles_g_decided_when_resolved() -> None:
    """``a_mag_m_s2 = None`` (the classic law) is the vehicle's g, ``hover_a_max_m_s2`` g/2:
    in the resolved parameters, which the packer writes as they are."""
    trial = ImpactTrial(
        model="classic", controller="recovery", vehicle_overrides={"gravity_m_s2": 9.5}
    )
    r = resolve(trial)
    assert r.shared.controller.given.a_mag_m_s2 is None  # as the scenario says (reported)
    assert r.shared.controller.params.a_mag_m_s2 == 9.5
    assert r.shared.controller.params.hover_a_max_m_s2 == 4.75
    ctrl = prepare(trial).ctrl
    assert ctrl[CTL.C_PARAMS + REC.R_A_MAG] == 9.5
    assert ctrl[CTL.C_PARAMS + REC.R_HOVER_GAINS + 3] == 4.75


def _fingerprint(r: ResolvedShared) -> bytes:
    shared = pack_shared(r)
    parts = [np.asarray(a, dtype=float).tobytes() for a in shared.model]
    for extra in (shared.est.initial_std, shared.est.extra_std):
        parts.append(b"-" if extra is None else np.asarray(extra).tobytes())
    return b"|".join(parts)


def _nudged(value: object) -> object:
    if isinstance(value, tuple):
        return tuple(0.5 + 1.5 * float(v) for v in value)
    return 0.5 + 1.5 * float(value)  # type: ignore[arg-type]


def _numbers(params: BaseModel) -> list[str]:
    out = []
    for name in type(params).model_fields:
        value = getattr(params, name)
        if isinstance(value, bool) or value is None:
            continue
        if isinstance(value, (int, float)) or (
            isinstance(value, tuple) and value and all(isinstance(v, (int, float)) for v in value)
        ):
            out.append(name)
    return out


def _with(r: ResolvedShared, part: str, **update: object) -> ResolvedShared:
    """A copy of ``r`` (its packing not kept) with parameters of its controller or
    estimator changed."""
    old = getattr(r, part)
    new = dataclasses.replace(old, params=old.params.model_copy(update=update))
    return dataclasses.replace(r, **{part: new})


PACKED = {
    "recovery-nav-ekf": ImpactTrial(controller="recovery", estimator="nav-ekf", sensors="onboard"),
    "recovery-classic-ekf": ImpactTrial(
        model="classic", controller="recovery", estimator="ekf", sensors="indoor"
    ),
    "cascade-complementary": ImpactTrial(
        controller="cascade-pid", estimator="complementary", sensors="indoor"
    ),
    "paper-ekf-additive": ImpactTrial(estimator="ekf-additive", sensors="authors-2016"),
}


@pytest.mark.parametrize("name", PACKED)
def test_no_packer_substitutes_a_default_for_a_missing_number(name: str) -> None:
    """Every number of the controller's and the estimator's parameters that a packer
    reads (changing it changes the arrays) is refused when it is ``None`` (but those
    whose ``None`` is a value of its own)."""
    r = resolve(PACKED[name]).shared
    base = _fingerprint(dataclasses.replace(r))
    read = 0
    for part in ("controller", "estimator"):
        params = getattr(r, part).params
        values_of_their_own = NONE_IS_A_VALUE.get(type(params).__name__, set())
        for field in set(_numbers(params)) - values_of_their_own:
            nudged = _with(r, part, **{field: _nudged(getattr(params, field))})
            if _fingerprint(nudged) == base:
                continue  # not packed (a value the resolve step used, or an unused slot)
            read += 1
            try:
                pack_shared(_with(r, part, **{field: None}))
            except (TypeError, ValueError):
                continue
            pytest.fail(f"{part} parameter {field} = None was packed (a default in the packer)")
    assert read >= 10  # the check has teeth: it found the packed numbers


@pytest.mark.parametrize("field", ["rtol", "atol", "control_rate_hz", "duration_s"])
def test_the_options_packer_takes_no_default_for_a_missing_setting(field: str) -> None:
    r = resolve(ImpactTrial(controller="recovery")).shared
    with pytest.raises((TypeError, ValueError)):
        pack_shared(dataclasses.replace(r, **{field: None}))


def test_a_resolved_run_packs_in_one_call_as_prepare_packs_it() -> None:
    trial = ImpactTrial(controller="recovery", sensors="impact", estimator="ekf", seed=3)
    r = resolve(trial)
    assert isinstance(r, ResolvedRun)
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.shared.rtol = 1.0  # type: ignore[misc]
    packed = pack(r).model
    setup = prepare(trial)
    for name, a in zip(packed._fields, packed, strict=True):
        assert np.asarray(a).tobytes() == np.asarray(getattr(setup.run, name)).tobytes(), name
