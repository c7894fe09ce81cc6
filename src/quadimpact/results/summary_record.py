"""The summary of a run as a typed record: one part per concern, each field with its meaning.

A run's summary (``summary.json``, a sweep's row) is a :class:`Summary`: the
parts below, in order, each a dataclass whose fields are summary keys, every
field declared once with its kind, unit and meaning (:func:`metric`), nested
tables as parts of their own (:func:`table`):

================  ==========================================================
part              what
================  ==========================================================
``run``           status, warnings, the model variant and switches, controller
``impact``        the initial impact, later impacts, the crash (every run)
``span``          start and end times, the controller's references, version
``wall``          the wall plane and the approach solve (a run with a wall)
``request``       what a wall approach asked for (wall approaches only)
``excursion``     the attitude excursion of the output samples (with samples)
``recovery``      detection and the recovery controller's stages (every run)
``estimation``    the estimator, the added sensors, the estimate's errors
``outcome``       one sentence on what the run did
``integrator``    the integrator's counters (added when the run is read)
``cost``          what the run cost, CPU seconds (added when the run is read)
================  ==========================================================

Everything that describes the summary is derived from these classes: the
flattened keys with kinds and units (:func:`summary_keys`, which is
``quadimpact.results.schema.SUMMARY_KEYS``), the sweep table's columns, and
the table of docs/RESULTS.md (:func:`markdown_table`, checked by
``tests/results/test_schema.py``). A new metric is one field here, and the
line that computes it.

Run ``python -m quadimpact.results.summary_record`` to print the docs' table.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field, fields, make_dataclass
from typing import Any, ClassVar

__all__ = [
    "ApproachTable",
    "CostTable",
    "EstimationPart",
    "ExcursionPart",
    "ImpactPart",
    "IntegratorTable",
    "Key",
    "ModelOptionsTable",
    "OutcomePart",
    "PHASES",
    "QUANTITIES",
    "RecoveryPart",
    "ReferencesTable",
    "RequestPart",
    "RunPart",
    "SpanPart",
    "Summary",
    "WallPart",
    "markdown_table",
    "metric",
    "summary_keys",
    "table",
]


@dataclass(frozen=True)
class Key:
    """One summary key: flattened name, kind (f, i, b, s, j), unit and meaning."""

    name: str
    kind: str
    unit: str
    description: str


#: Kinds: ``f`` float64, ``i`` integer, ``b`` boolean, ``s`` text, ``j`` a list or table
#: (JSON text in a sweep's table); in words for the docs.
KIND_WORDS = {"f": "number", "i": "integer", "b": "true/false", "s": "text", "j": "list"}


def metric(kind: str, unit: str, description: str) -> Any:
    """A summary field: its kind (``KIND_WORDS``), unit (SI; ``1`` dimensionless) and meaning."""
    if kind not in KIND_WORDS:
        raise ValueError(f"kind: must be one of {', '.join(KIND_WORDS)} (got {kind!r})")
    return field(default=None, metadata={"key": (kind, unit, description)})


def table(part: type) -> Any:
    """A nested table (``summary.json``'s ``{"references": {...}}``), flattened with ``__``."""
    return field(default=None, metadata={"table": part})


_LAYOUTS: dict[type, tuple[tuple[str, bool], ...]] = {}


def _field_layout(cls: type) -> tuple[tuple[str, bool], ...]:
    """A part class's fields in order, each with whether it is a nested table (a
    :class:`Part`, or a mapping given as is), kept per class: every run's summary walks
    them."""
    layout = _LAYOUTS.get(cls)
    if layout is None:
        layout = _LAYOUTS[cls] = tuple((f.name, "table" in f.metadata) for f in fields(cls))
    return layout


_PLAIN: dict[type, tuple[tuple[str, ...], bool]] = {}


def _plain_layout(cls: type) -> tuple[tuple[str, ...], bool]:
    """A part class's field names in order and whether any is a nested table, kept per class."""
    plain = _PLAIN.get(cls)
    if plain is None:
        layout = _field_layout(cls)
        plain = _PLAIN[cls] = (tuple(n for n, _ in layout), any(t for _, t in layout))
    return plain


class Part:
    """A part of the summary: a dataclass of :func:`metric` and :func:`table` fields."""

    #: Table name in ``summary.json`` when the part is a nested table ('' for a top part).
    name: ClassVar[str] = ""

    @classmethod
    def keys(cls, prefix: str = "") -> list[Key]:
        """The part's flattened keys, in order."""
        out: list[Key] = []
        for f in fields(cls):
            name = f"{prefix}__{f.name}" if prefix else f.name
            if "table" in f.metadata:
                out += f.metadata["table"].keys(name)
            else:
                kind, unit, description = f.metadata["key"]
                out.append(Key(name, kind, unit, description))
        return out

    def to_dict(self) -> dict[str, Any]:
        """The part's keys and values, nested tables as dicts (a table left None stays None)."""
        values = self.__dict__  # a dataclass's fields (read here without getattr: every run)
        names, tables = _plain_layout(type(self))
        if not tables:
            return {name: values[name] for name in names}
        out: dict[str, Any] = {}
        for name, is_table in _field_layout(type(self)):
            value = values[name]
            out[name] = value.to_dict() if is_table and isinstance(value, Part) else value
        return out

    @classmethod
    def of(cls, values: dict[str, Any]) -> Any:
        """The part from a mapping of its fields (``TypeError`` on a key it does not have)."""
        return cls(**values)


# ----------------------------------------------------------------- tables
@dataclass
class ModelOptionsTable(Part):
    """The model variant's switches in force (``quadimpact.inputs.model.ModelOptions``)."""

    yaw_reaction: str = metric("s", "", "rotor drag-torque sense and allocation yaw row")
    bumper1_yaw_twice: bool = metric("b", "", "bumper 1's contact yaw moment counted twice")
    initial_rotor_speeds: str = metric("s", "", "initial rotor speed rule")
    attitude_mapping: str = metric("s", "", "heading/inclination to roll/pitch mapping")
    crash_rule: str = metric("s", "", "crash rule")
    approach_start: str = metric("s", "", "wall-approach start rule")
    spinup_reaction: str = metric("s", "", "rotor spin-up reaction (spin sign or not)")
    detection_tick_reference: str = metric("s", "", "recovery target at detection tick")
    contact_gate_m: float = metric("f", "m", "contact force gate on the CM distance (0: off)")
    pre_impact: str = metric("s", "", "recovery pre-impact rule of the model")
    recovery_law: str = metric("s", "", "tuning of the staged recovery law")
    cut_step_motors: list = metric("j", "", "motors a power-off cuts at the next tick")
    bumper_force_scale: list = metric("j", "", "factor on each bumper's contact force")


@dataclass
class ReferencesTable(Part):
    """The controller's references."""

    altitude_m: float = metric("f", "m", "controller altitude reference")
    roll_rad: float = metric("f", "rad", "controller roll reference")
    pitch_rad: float = metric("f", "rad", "controller pitch reference")
    yaw_rad: float = metric("f", "rad", "controller yaw reference")


@dataclass
class ApproachTable(Part):
    """The wall approach's solve (docs/STUDIES.md 1.1)."""

    start_time_s: float = metric("f", "s", "wall approach: start time")
    start_x_m: float = metric("f", "m", "wall approach: start X")
    start_speed_m_s: float = metric("f", "m/s", "wall approach: start speed")
    late_start: bool = metric("b", "", "wall approach: started late, at rest")
    speed_residual_m_s: float = metric("f", "m/s", "wall approach: speed residual")


@dataclass
class RequestedTable(Part):
    """What a wall approach asked for."""

    heading_deg: float = metric("f", "deg", "wall approach: requested heading")
    inclination_deg: float = metric("f", "deg", "wall approach: requested inclination")
    speed_m_s: float = metric("f", "m/s", "wall approach: requested impact speed")
    impact_time_s: float = metric("f", "s", "wall approach: requested impact time")


@dataclass
class ExcursionTable(Part):
    """The attitude excursion over the output samples (docs/STUDIES.md 2)."""

    roll_excursion_deg: float = metric("f", "deg", "largest roll departure")
    pitch_excursion_deg: float = metric("f", "deg", "largest pitch departure")
    yaw_excursion_deg: float = metric("f", "deg", "largest yaw departure")
    tilt_max_deg: float = metric("f", "deg", "largest tilt from the reference")


@dataclass
class IntegratorTable(Part):
    """The integrator's counters."""

    steps: int = metric("i", "1", "accepted steps")
    rejected_steps: int = metric("i", "1", "rejected steps")
    rhs_evaluations: int = metric("i", "1", "right-hand-side evaluations")
    control_ticks: int = metric("i", "1", "controller updates")
    output_rows: int = metric("i", "1", "time-series rows")
    wall_time_s: float = metric("f", "s", "wall-clock time of the kernel (not in sweeps)")


@dataclass
class CostTable(Part):
    """What the run cost (``quadimpact.results.costs``)."""

    kernel_cpu_s: float = metric("f", "s", "CPU time in the compiled loop (shooting runs included)")
    total_cpu_s: float = metric("f", "s", "CPU time of the whole run, scenario to summary or row")
    compile_cpu_s: float = metric(
        "f", "s", "CPU time compiling a plug-in's loop in this run (in neither of the others)"
    )


# ------------------------------------------------------------------ parts
@dataclass
class RunPart(Part):
    """How the run went and what ran it."""

    status: str = metric("s", "", "completed, crashed or failed")
    reason: str = metric("s", "", "why a run failed (empty otherwise)")
    warnings: list = metric("j", "", "warnings of the run, one sentence each")
    model: str = metric("s", "", "model variant")
    model_options: ModelOptionsTable = table(ModelOptionsTable)
    controller: str = metric("s", "", "controller name")
    vehicle: str = metric("s", "", "vehicle name")


@dataclass
class ImpactPart(Part):
    """The initial impact, the later ones and the crash (docs/STUDIES.md 2)."""

    delta_init_m: float = metric("f", "m", "largest peak deflection of the initial impact")
    peak_force_n: float = metric("f", "N", "largest peak normal force of the initial impact")
    initial_impact_duration_s: float = metric("f", "s", "duration of the initial impact")
    first_contact_s: float = metric("f", "s", "time of the first contact with an obstacle")
    impact_speed_m_s: float = metric(
        "f", "m/s", "CM speed along the contact normal at first contact"
    )
    heading_deg: float = metric("f", "deg", "requested heading (wall approach)")
    inclination_deg: float = metric("f", "deg", "requested inclination (wall approach)")
    impact_heading_deg: float = metric("f", "deg", "yaw at the first contact")
    impact_inclination_deg: float = metric("f", "deg", "inclination at the first contact")
    leading_bumpers: list = metric("j", "", "bumpers of the initial impact")
    aft_bumpers: list = metric("j", "", "the other bumpers")
    response_type: str = metric("s", "", "A, B, C, D or Other (docs/STUDIES.md 3)")
    n_episodes: int = metric("i", "1", "contact episodes with obstacles")
    n_grazes: int = metric(
        "i", "1", "grazes: obstacle episodes of under 1 % of the largest impulse "
        "(docs/STUDIES.md 2.2)",
    )  # fmt: skip
    n_subsequent_impacts: int = metric("i", "1", "impacts after the initial one")
    n_subsequent_episodes: int = metric("i", "1", "episodes in those impacts")
    subsequent_impacts: list = metric("j", "", "bumpers of each subsequent impact")
    crash_time_s: float = metric("f", "s", "time of the crash (null: none)")
    power_off_time_s: float = metric("f", "s", "time the motor power-off started (null: none)")
    crash_position_m: list = metric("j", "m", "CM position at the crash, inertial NED")
    max_penetration_m: float = metric("f", "m", "deepest penetration of any bumper")
    bumper_model_valid: bool = metric("b", "", "max_penetration_m within the bumper radius")


@dataclass
class SpanPart(Part):
    """When the run started and ended, what the controller aimed at, what produced it."""

    t_start_s: float = metric("f", "s", "start time of the run")
    t_final_s: float = metric("f", "s", "time reached")
    references: ReferencesTable = table(ReferencesTable)
    quadimpact_version: str = metric("s", "", "version that produced the run")


@dataclass
class WallPart(Part):
    """The wall plane of a run that has one, and its approach solve."""

    wall_distance_m: float = metric("f", "m", "X of the wall plane")
    crash_distance_from_wall_m: float = metric("f", "m", "wall X minus CM X at the crash")
    approach: ApproachTable = table(ApproachTable)


@dataclass
class RequestPart(Part):
    """What a wall approach asked for (the run's reached values are in ``impact``)."""

    requested: RequestedTable = table(RequestedTable)


@dataclass
class ExcursionPart(Part):
    """The attitude excursion, when the run wrote output samples."""

    attitude_excursion: ExcursionTable = table(ExcursionTable)


@dataclass
class RecoveryPart(Part):
    """Detection and the recovery controller's stages (docs/RECOVERY.md 6)."""

    pre_impact: str = metric("s", "", "recovery controller's pre-impact behaviour in force")
    detection_threshold_m_s2: float = metric("f", "m/s^2", "impact detector threshold (null: off)")
    detected: bool = metric("b", "", "the detector fired")
    not_detected: bool = metric("b", "", "a contact happened and was never detected")
    false_detection: bool = metric("b", "", "the detector fired before any contact")
    n_detections: int = metric("i", "1", "rising edges of the detection condition")
    t_detect_s: float = metric("f", "s", "time of the detecting IMU sample")
    detection_latency_s: float = metric("f", "s", "detection time minus first contact")
    normal_error_deg: float = metric("f", "deg", "wall-normal estimate vs the true contact normal")
    t_stage1_s: float = metric("f", "s", "recovery: tick of entry into stage 1 (detected)")
    t_stage2_s: float = metric("f", "s", "recovery: tick of entry into stage 2 (tilted away)")
    t_stage3_s: float = metric("f", "s", "recovery: tick of entry into stage 3 (level)")
    t_stage4_s: float = metric("f", "s", "recovery: tick of entry into stage 4 (recovered)")
    recovered: bool = metric("b", "", "stage 4 reached before the final time")
    time_to_recover_s: float = metric("f", "s", "detection to stage 4")
    t_stage5_s: float = metric(
        "f", "s", "recovery: tick of entry into stage 5 (hover, position hold)"
    )
    time_to_hover_s: float = metric(
        "f",
        "s",
        "detection to the first tick from which the true speed < 0.2 m/s and tilt < 5° "
        "hold for 0.5 s",
    )
    held_hover: bool = metric(
        "b",
        "",
        "a held hover after the first obstacle contact: true speed < 0.2 m/s, tilt < 5°, "
        "body rate < 20°/s and no contact, for 0.5 s (benchmark suite 2)",
    )
    time_to_held_hover_s: float = metric(
        "f", "s", "first obstacle contact to the start of the held hover"
    )
    held_hover_distance_m: float = metric(
        "f", "m", "horizontal distance from the CM at the first obstacle contact to the hover point"
    )
    touched_after_hover: bool = metric(
        "b", "", "a contact began at or after the start of the held hover"
    )
    height_loss_stage2_m: float = metric("f", "m", "altitude at detection minus at stage 2 entry")
    height_loss_stage3_m: float = metric("f", "m", "altitude at detection minus at stage 3 entry")
    height_loss_m: float = metric("f", "m", "altitude at detection minus at stage 4 entry")
    horizontal_drift_stage2_m: float = metric("f", "m", "horizontal distance detection -> stage 2")
    horizontal_drift_stage3_m: float = metric("f", "m", "horizontal distance detection -> stage 3")
    horizontal_drift_m: float = metric("f", "m", "horizontal distance detection -> stage 4")
    min_altitude_m: float = metric("f", "m", "lowest CM altitude of the run")
    impacts_after_detection: int = metric("i", "1", "impacts starting after the detection")
    max_tilt_deg: float = metric("f", "deg", "after detection: largest tilt from vertical")
    max_rate_rad_s: float = metric("f", "rad/s", "after detection: largest body rate")
    final_speed_m_s: float = metric("f", "m/s", "CM speed at the end of the run")
    final_altitude_m: float = metric("f", "m", "CM altitude at the end of the run")
    first_contact_bumper: int = metric(
        "i",
        "1",
        "feature (bumper) of the first obstacle contact: its number 1..n in the "
        "vehicle's features (null: no contact)",
    )
    first_contact_normal: list = metric(
        "j",
        "",
        "the contact normal of that first contact, inertial NED, unit, out of the "
        "obstacle (null: no contact)",
    )


#: (name in the keys, unit suffix) of the estimate's four errors, in the loop's order.
QUANTITIES: tuple[tuple[str, str], ...] = (
    ("attitude", "deg"),
    ("velocity", "m_s"),
    ("bias", "rad_s"),
    ("position", "m"),
)
#: The phases of a run the errors are kept for, in the loop's order.
PHASES: tuple[str, ...] = ("pre", "crash", "post")
_ERR_UNITS = {"deg": "deg", "m_s": "m/s", "rad_s": "rad/s", "m": "m"}
_PHASE_TEXT = {
    "pre": "before the first contact",
    "crash": "first contact to stage 4 (or the end)",
    "post": "after stage 4",
}
_ERROR_FIELDS = [
    (
        f"est_{q}_{stat}_{phase}_{unit}",
        float,
        metric("f", _ERR_UNITS[unit], f"estimation: {q} error, "
               f"{'RMS' if stat == 'rms' else 'maximum'}, {_PHASE_TEXT[phase]}"),
    )
    for q, unit in QUANTITIES
    for phase in PHASES
    for stat in ("rms", "max")
]  # fmt: skip

EstimationPart = make_dataclass(
    "EstimationPart",
    [
        ("estimator", str, metric("s", "", "the state estimator (docs/ESTIMATION.md)")),
        ("estimator_settings", str, metric("s", "", "its parameters, `name=value, ...`")),
        ("sensors", str, metric("s", "", "the preset of sensors given (null: none)")),
        ("impact_disturbance", bool, metric("b", "", "the IMU's impact disturbance was on")),
        ("magnetometer", bool, metric("b", "", "the run had a magnetometer")),
        ("pose_sensor", bool, metric("b", "", "the run had a pose sensor")),
        *_ERROR_FIELDS,
        (
            "est_attitude_rms_run_deg",
            float,
            metric("f", "deg", "estimation: attitude error, RMS over the whole run"),
        ),
        (
            "est_attitude_rms_not_crash_deg",
            float,
            metric(
                "f",
                "deg",
                "estimation: attitude error, RMS over the run but the crash (the pre and post "
                "phases together)",
            ),
        ),
    ],
    bases=(Part,),
    namespace={
        "__doc__": "The estimator, the added sensors and the estimate's errors by phase "
        "(docs/ESTIMATION.md 4)."
    },  # fmt: skip
)
EstimationPart.__module__ = __name__


@dataclass
class OutcomePart(Part):
    """One sentence on what the run did."""

    outcome: str = metric("s", "", "one sentence on what the run did")


@dataclass
class CountersPart(Part):
    """The integrator's counters and the run's cost, added when the run is read."""

    integrator: IntegratorTable = table(IntegratorTable)
    cost: CostTable = table(CostTable)


# ---------------------------------------------------------------- summary
@dataclass
class Summary:
    """A run's summary: its parts, in order (a part that does not apply is None)."""

    run: RunPart
    impact: ImpactPart
    span: SpanPart
    wall: WallPart | None
    request: RequestPart | None
    excursion: ExcursionPart | None
    recovery: RecoveryPart
    estimation: Any  # EstimationPart
    outcome: OutcomePart
    counters: CountersPart | None = None

    #: The part classes in order, and whether each is always there.
    PARTS: ClassVar[tuple[tuple[str, type, bool], ...]] = ()

    def to_dict(self) -> dict[str, Any]:
        """The summary as ``summary.json`` holds it: the parts' keys in order; a part that
        does not apply adds nothing, a table left None in a part adds nothing either."""
        out: dict[str, Any] = {}
        parts = self.__dict__
        for name, _, _ in self.PARTS:
            part = parts[name]
            if part is None:
                continue
            values = part.__dict__  # its fields, read without getattr (every run)
            names, tables = _plain_layout(type(part))
            if not tables:
                for key in names:
                    out[key] = values[key]
                continue
            for key, is_table in _field_layout(type(part)):
                value = values[key]
                if is_table:
                    if value is None:
                        continue
                    if isinstance(value, Part):
                        value = value.to_dict()
                out[key] = value
        return out


Summary.PARTS = (
    ("run", RunPart, True),
    ("impact", ImpactPart, True),
    ("span", SpanPart, True),
    ("wall", WallPart, False),
    ("request", RequestPart, False),
    ("excursion", ExcursionPart, False),
    ("recovery", RecoveryPart, True),
    ("estimation", EstimationPart, True),
    ("outcome", OutcomePart, True),
    ("counters", CountersPart, False),
)


def summary_keys() -> tuple[Key, ...]:
    """Every summary key, flattened with ``__``, in order (the schema of ``summary.json``)."""
    return tuple(k for _, part, _ in Summary.PARTS for k in part.keys())


def optional_keys() -> frozenset[str]:
    """The keys of the parts that only some runs have (a wall, a wall approach, samples)."""
    return frozenset(
        k.name for _, part, always in Summary.PARTS if not always and part is not CountersPart
        for k in part.keys()
    )  # fmt: skip


def markdown_table() -> str:
    """The table of docs/RESULTS.md: every key with its kind, unit and meaning."""
    rows = ["| key | kind | unit | meaning |", "|---|---|---|---|"]
    for k in summary_keys():
        unit = "" if k.unit in ("", "1") and k.kind in "sbj" else k.unit
        rows.append(f"| `{k.name}` | {KIND_WORDS[k.kind]} | {unit} | {k.description} |")
    return "\n".join(rows)


def _check_unique() -> None:
    names = [k.name for k in summary_keys()]
    twice = {n for n in names if names.count(n) > 1}
    if twice:  # pragma: no cover - a declaration error
        raise RuntimeError(f"summary keys declared twice: {sorted(twice)}")


_check_unique()
assert dataclasses.is_dataclass(EstimationPart)

if __name__ == "__main__":
    print(markdown_table())
