"""``quadimpact run``: one scenario (a file, flags, or both) to a result folder."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import click

from quadimpact.cli.options import (
    CONTROLLER,
    MODEL,
    file_argument,
    max_record_option,
    number_option,
    out_option,
    plugin_option,
    policy_option,
)
from quadimpact.errors import InputError, input_error_from_validation, one_line

__all__ = ["EXIT_RUN_FAILED", "build_scenario", "format_summary", "run"]

# click parameter name -> (scenario field, flag as typed)
_FLAGS: dict[str, tuple[str, str]] = {
    "heading": ("heading_deg", "--heading"),
    "inclination": ("inclination_deg", "--inclination"),
    "speed": ("speed_m_s", "--speed"),
    "impact_time": ("impact_time_s", "--impact-time"),
    "wall_distance": ("wall_distance_m", "--wall-distance"),
    "altitude": ("altitude_m", "--altitude"),
    "start_altitude": ("start_altitude_m", "--start-altitude"),
    "final_time": ("final_time_s", "--final-time"),
    "model": ("model", "--model"),
    "controller": ("controller", "--controller"),
    "vehicle": ("vehicle", "--vehicle"),
    "rotor_mode": ("rotor_mode", "--rotor-mode"),
    "friction": ("friction_coefficient", "--friction"),
    "ground": ("ground", "--ground"),
    "output_rate": ("output_rate_hz", "--output-rate"),
    "rtol": ("rtol", "--rtol"),
    "atol": ("atol", "--atol"),
    "roll": ("roll_deg", "--roll"),
    "pitch": ("pitch_deg", "--pitch"),
    "yaw": ("yaw_deg", "--yaw"),
    "start_distance": ("start_distance_m", "--start-distance"),
    "imu": ("imu", "--imu"),
    "seed": ("seed", "--seed"),
    "sensors": ("sensors", "--sensors"),
    "estimator": ("estimator", "--estimator"),
}
#: Scenario field -> its flag as typed (in error messages).
_FLAG_OF = {field: flag for field, flag in _FLAGS.values()}
#: The fields a preset of sensors (``--sensors``) fills where the scenario leaves them unset.
_PRESET_FIELDS = ("imu", "magnetometer", "pose_sensor", "instruments")
_WALL_ONLY = {
    "heading_deg",
    "inclination_deg",
    "speed_m_s",
    "impact_time_s",
    "wall_distance_m",
    "altitude_m",
    "start_altitude_m",
}
#: Exit status of a run whose status is "failed" (numerical failure; see ``run --help``).
EXIT_RUN_FAILED = 3
_OUTPUT_FILES = (
    "summary.json, scenario.json, timeseries.parquet, episodes.csv, imu.parquet, fig5.png, "
    "fig6.png, imu.png"
)


def _flag(flag: str, metavar: str | None, help: str, type: Any = None) -> Any:
    """A flag of ``run`` (a number by default), also named by its file key (``--roll-deg``)."""
    field = next(f for f, typed in _FLAGS.values() if typed == flag)
    alias = "--" + field.replace("_", "-")
    extra = {} if type is None else {"type": type}
    return number_option(flag, metavar, help, alias=None if alias == flag else alias, **extra)


@click.command("run")
@file_argument("scenario", "[SCENARIO.toml]")
@_flag(
    "--heading",
    "DEG",
    "Yaw relative to the wall normal, deg in [-360, 360]; 0 points the nose at the "
    "wall (bumpers 1 and 4 lead). [default: 0]",
)
@_flag(
    "--inclination",
    "DEG",
    "Tilt of the body z axis toward the wall, in the vertical plane through the wall "
    "normal, deg in [-60, 60]. [default: 0]",
)
@_flag(
    "--speed",
    "M/S",
    "Speed of the centre of mass toward the wall at first contact, m/s in (0, 20]. [default: 0.75]",
)
@_flag("--impact-time", "S", "Time of the first contact, s (> 0, < final time). [default: 0.5]")
@_flag("--wall-distance", "M", "Wall position along inertial X (NED), m. [default: 1.5]")
@_flag("--altitude", "M", "Altitude set-point and initial altitude, m (> 0). [default: 2]")
@_flag(
    "--start-altitude",
    "M",
    "Wall approach: initial altitude when it differs from the set-point, m (>= 0): the "
    "controller climbs (or descends) toward --altitude on the way to the wall, as in the "
    "authors' crash runs (with --roll, --pitch and --impact-time). [default: the set-point]",
)
@_flag("--final-time", "S", "End of the simulation, s in (0, 600]. [default: 3]")
@click.option(
    "--kind",
    type=click.Choice(["wall-approach", "impact-trial"]),
    help="Scenario kind without a file: the paper's wall approach, or an impact trial of "
    "the recovery benchmark (the Navi 0.32 m from the wall at 5 m, docs/RECOVERY.md 5.1; "
    "--roll, --pitch, --yaw, --speed, --start-distance, --altitude set it). A file sets "
    "its own kind. [default: wall-approach]",
)
@_flag(
    "--roll",
    "DEG",
    "Initial roll, deg (ZYX): an impact trial's, or a wall approach's "
    "attitude instead of its heading/inclination mapping (with --pitch). [default: 0]",
)
@_flag(
    "--pitch",
    "DEG",
    "Initial pitch, deg in (-90, 90) (ZYX); the inclination toward the "
    "wall is about -pitch. [default: 0]",
)
@_flag("--yaw", "DEG", "Impact trial: initial yaw, deg in [-180, 180]. [default: 0]")
@_flag(
    "--start-distance",
    "M",
    "Impact trial: CM distance from the wall at the start, m; "
    "no bumper may touch the wall then. [default: 0.32]",
)
@_flag(
    "--imu",
    "PRESET",
    "IMU preset: 'ideal' or 'noisy' (docs/RECOVERY.md 1.4). [default: ideal]",
    type=click.Choice(["ideal", "noisy"]),
)
@_flag(
    "--sensors",
    "PRESET",
    "A preset of sensors: ideal, noisy, impact, indoor (impact + magnetometer + pose "
    "sensor), onboard (impact + magnetometer, barometer, rangefinder, optical flow) or "
    "one a plug-in registers; it fills the sensors the scenario leaves unset "
    "(docs/ESTIMATION.md). [default: the IMU alone]",
    type=click.STRING,
)
@_flag(
    "--estimator",
    "NAME",
    "State estimator the controller reads: ideal (the true state), complementary, ekf, "
    "nav-ekf (with the onboard sensors) or a registered one. [default: ideal]",
    type=click.STRING,
)
@_flag(
    "--seed",
    "S",
    "Seed of the run's random draws (the IMU's noise and biases), an integer >= 0. [default: 0]",
    type=click.IntRange(min=0, max=2**63 - 1),
)
@click.option(
    "--model",
    type=MODEL,
    help="Model variant: 'default' is physically consistent; 'paper-replica' reproduces "
    "the authors' simulator, errors included, to match the published figures; "
    "'recovery-replica' their later recovery simulator; 'pole-replica' the default model "
    "with the recovery law retuned as in their pole study. [default: default]",
)
@click.option(
    "--option",
    "options",
    multiple=True,
    metavar="NAME=VALUE",
    help="Change one switch of the model variant (repeatable), e.g. crash_rule=cm-ground, "
    "cut_step_motors=[2] or bumper_force_scale=1,2,1,1. Switches: yaw_reaction, spinup_reaction, "
    "bumper1_yaw_twice, initial_rotor_speeds, attitude_mapping, crash_rule, approach_start, "
    "detection_tick_reference, contact_gate_m, pre_impact, cut_step_motors, "
    "bumper_force_scale (docs/VARIANTS.md).",
)
@click.option(
    "--param",
    "params",
    multiple=True,
    metavar="NAME=VALUE",
    help="Set one parameter of the controller (repeatable), as [controller_params] of a "
    "scenario file does, e.g. --controller recovery --param k_att_1_s=25 "
    "(docs/RECOVERY.md 3.5, docs/CONTROLLERS.md).",
)
@policy_option
@click.option(
    "--controller",
    type=CONTROLLER,
    help="'paper': the authors' discrete PID as they ran it; 'cascade-pid': the same "
    "structure with running integrals, anti-windup and rotor limits; 'recovery': a "
    "pre-impact behaviour, then the staged recovery law after the impact is detected; "
    "or any registered controller. [default: paper]",
)
@click.option(
    "--vehicle",
    metavar="NAME_OR_PATH",
    help="Bundled vehicle name or path to a vehicle TOML file. [default: spiri]",
)
@click.option(
    "--rotor-mode",
    type=click.Choice(["ideal", "first-order"]),
    help="'ideal': commanded rotor speeds apply at once (the paper); 'first-order': "
    "motor lag with the vehicle's time constant. [default: ideal]",
)
@_flag(
    "--friction",
    "MU",
    "Coulomb friction coefficient at the bumpers (>= 0; 0 = the paper). [default: 0]",
)
@click.option(
    "--ground",
    type=click.Choice(["crash", "contact", "none"]),
    help="'crash': the CM reaching the ground ends the run; 'contact': the ground is a "
    "contact surface for the bumper rims only (the body passes through it: docs/MODEL.md "
    "4.9); 'none': no ground. [default: crash]",
)
@_flag("--output-rate", "HZ", "Sampling rate of the output time series, Hz. [default: 1000]")
@_flag("--rtol", None, "Integrator relative tolerance, in (0, 0.1). [default: kernel default]")
@_flag("--atol", None, "Integrator absolute tolerance, > 0. [default: kernel default]")
@out_option(
    "results/run",
    "Output folder (created if needed). A folder holding an earlier run is replaced: its "
    "files and the pictures drawn from it go; one holding anything else is refused.",
)
@max_record_option(
    "Largest record (time series and IMU samples: final time x output rate) the run "
    "may allocate; a larger one is refused before it starts, with its estimate."
)
@click.option(
    "--viz",
    is_flag=True,
    help="Also write the pictures: snapshots.png/.pdf, animation.mp4 and viewer.html "
    "(as 'quadimpact snapshots', 'animate' and 'view' do).",
)
@plugin_option
def run(
    scenario: Path | None,
    out: Path,
    options: tuple[str, ...],
    params: tuple[str, ...],
    kind: str | None,
    viz: bool,
    max_record_mb: float,
    policy: str | None,
    **flags: Any,
) -> None:
    """Simulate one scenario and write its results to --out.

    Every flag is also named by its scenario file key (--heading-deg for
    heading_deg, --friction-coefficient for friction_coefficient...).

    Without SCENARIO.toml this is the paper's wall approach: the Spiri holds
    the given heading, inclination and altitude and is started so that its
    first bumper touches a vertical wall 1.5 m ahead at t = 0.5 s with the
    given speed; 3 s are simulated. A scenario file sets the same fields
    (or is a general "flight", or an "impact-trial"); flags override the
    file's values.

    The paper's example (its Figures 5 and 6):

    \b
      quadimpact run --heading 45 --inclination 15 --speed 0.75 \\
          --model paper-replica --out results/paper-example-replica

    Writes summary.json, scenario.json (the world that ran), timeseries.parquet,
    episodes.csv, imu.parquet and the figures.

    \b
    Exit status:
      0  the run completed or crashed (a simulated crash is a result)
      1  an unexpected error, or the result folder could not be written
      2  bad input (flag, file, value): nothing was simulated; or a plug-in
         controller or estimator that failed (docs/CONTROLLERS.md)
      3  the run failed numerically (status "failed", e.g. the state became
         NaN); its folder is still written, with the reason in summary.json
    """
    from quadimpact.results.files import check_out_dir

    if policy is not None:  # the same as --param policy=FILE (the recovery controller's)
        params = (*params, f"policy={json.dumps(policy)}")
    built = build_scenario(scenario, flags, options, params=params, kind=kind)
    from quadimpact.simulation.checks import check_record_size  # the compiled geometry

    check_record_size(built, max_record_mb, "--max-record-mb")
    check_out_dir(out, "run")
    vehicle = built.build_vehicle()
    click.echo(f"quadimpact: {_describe(built, vehicle.name)} ...", err=True)

    from quadimpact.simulation import simulate
    from quadimpact.simulation.plugin_check import check_plugins

    check_plugins(built)  # a plug-in controller or estimator: its signature, one tick
    result = simulate(built)
    try:
        result.write(out)
    except OSError as exc:
        raise click.ClickException(
            f"{out}: the result folder could not be written ({exc.strerror or exc}); "
            "nothing was changed there"
        ) from None
    click.echo(format_summary(result.summary, out, built))
    if viz:
        from quadimpact.cli.viz_commands import make_all

        for path in make_all(out, result):
            click.echo(f"picture        {path}")
    if result.summary.get("status") == "failed":
        click.get_current_context().exit(EXIT_RUN_FAILED)


def _option_value(text: str) -> Any:
    """A ``--option`` value as the scenario file would read it: a number, a boolean, a word, a list.

    ``0.3`` is the number 0.3 and ``true``/``false`` (any case) booleans, as in
    a TOML file; a quoted TOML string is its content; a list of numbers is
    written as in TOML (``[2]``, ``[1, 2, 1, 1]``) or bare with commas
    (``1,2,1,1``); anything else is the text itself (``crash_rule=cm-ground``).
    """
    import tomllib

    lowered = text.lower()
    if lowered in ("true", "false"):
        return lowered == "true"
    toml = f"[{text}]" if "," in text and not text.startswith("[") else text
    try:
        value = tomllib.loads(f"v = {toml}")["v"]
    except (tomllib.TOMLDecodeError, KeyError):
        return text
    if isinstance(value, list):
        numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
        return value if numbers and all(math.isfinite(v) for v in value) else text
    if isinstance(value, float) and not math.isfinite(value):
        return text  # nan, inf: refused by the field's own check, with the text shown
    return value if isinstance(value, (int, float, str, bool)) else text


def _parse_options(options: tuple[str, ...], flag: str = "--option") -> dict[str, Any]:
    """``NAME=VALUE`` pairs of ``--option`` (``--param``) to a dict (values read as in a file)."""
    parsed: dict[str, Any] = {}
    for item in options:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise InputError(f"{flag}: must be NAME=VALUE (got {item!r})")
        rule = _non_finite(value.strip())
        if rule:
            raise InputError(f"{flag}: {name.strip()}: {rule} (got {value.strip()!r})")
        parsed[name.strip()] = _option_value(value.strip())
    return parsed


def _non_finite(text: str) -> str:
    """The rule a value breaks when it reads as a number that is not finite ('' otherwise):
    ``nan``, ``inf``, ``1e999`` or a list holding one."""
    import tomllib

    toml = f"[{text}]" if "," in text and not text.startswith("[") else text
    try:
        value = tomllib.loads(f"v = {toml}")["v"]
    except (tomllib.TOMLDecodeError, KeyError):
        return ""
    values = value if isinstance(value, list) else [value]
    if any(isinstance(v, float) and not math.isfinite(v) for v in values):
        return "must be finite numbers" if isinstance(value, list) else "must be a finite number"
    return ""


def build_scenario(
    scenario_path: Path | None,
    flags: Mapping[str, Any],
    options: tuple[str, ...] = (),
    *,
    params: tuple[str, ...] = (),
    kind: str | None = None,
) -> Any:
    """Build the scenario of a ``run``: the file's values, then the flags on top.

    Parameters
    ----------
    scenario_path : pathlib.Path or None
        Scenario TOML file; ``None``: a wall approach from the defaults.
    flags : mapping
        Click parameter name -> value (``None``: not given).
    options : tuple of str
        ``NAME=VALUE`` model switches from ``--option``.
    params : tuple of str, keyword
        ``NAME=VALUE`` controller parameters from ``--param``.
    kind : str, keyword
        ``--kind``: the scenario kind without a file (a file's own kind must match).

    Returns
    -------
    WallApproach or FlightScenario or ImpactTrial
        The validated scenario (of the file's ``kind``).

    Raises
    ------
    InputError
        Naming the file and field, or the flag, that is wrong.
    """
    from quadimpact.inputs.toml_files import apply_overrides, read_toml_file

    if scenario_path is not None:
        # a missing, unreadable or malformed file is said before the scenarios' import (1 s)
        read_toml_file(scenario_path)
    from quadimpact.inputs.scenarios import _KINDS

    data, explicit = _file_fields(scenario_path, kind)
    kind = data.get("kind", "wall-approach")
    cls = _KINDS[kind]
    given = {_FLAGS[key][0]: value for key, value in flags.items() if value is not None}
    _check_flags_apply(given, cls, kind, scenario_path)
    if "sensors" in given:  # --sensors fills what the file does not set itself, as in a file
        for field in _PRESET_FIELDS:
            if field not in explicit:
                data.pop(field, None)
    parsed_params: dict[str, Any] = {}
    if params:
        parsed_params = _parse_options(params, "--param")
        data["controller_params"] = {**(data.get("controller_params") or {}), **parsed_params}
    if options:
        data["model_options"] = {**(data.get("model_options") or {}), **_model_options(options)}
    data = apply_overrides(data, given)
    return _validated(cls, data, scenario_path, given, parsed_params)


def _file_fields(scenario_path: Path | None, kind: str | None) -> tuple[dict[str, Any], set[str]]:
    """The scenario file's fields (validated, defaults filled in) and the names of those it
    sets itself; without a file, only ``--kind``'s (none without it). A file's kind other
    than ``--kind`` is refused."""
    from quadimpact.inputs.scenarios import load_scenario_file

    if scenario_path is None:
        return ({} if kind is None else {"kind": kind}), set()
    loaded = load_scenario_file(scenario_path)
    data = loaded.model_dump()
    if kind is not None and data.get("kind", "wall-approach") != kind:
        raise InputError(
            f"--kind {kind}: {scenario_path} has kind = {data.get('kind')!r} (a file sets "
            "its own kind; leave --kind out)"
        )
    return data, set(loaded.model_fields_set)


def _check_flags_apply(
    given: Mapping[str, Any], cls: Any, kind: str, scenario_path: Path | None
) -> None:
    """Refuse a flag (``given``: field -> value) whose field the scenario kind (``cls``) does
    not have, naming the flag, the kind it applies to and where the kind came from."""
    for field in given:
        if field not in cls.model_fields:
            named = {"wall-approach": "a wall approach", "impact-trial": "an impact trial"}
            where = (
                f"{scenario_path} has kind = {kind!r}" if scenario_path
                else named.get(kind, f"a {kind}")
            )  # fmt: skip
            if field in _WALL_ONLY:
                rule = "applies to wall-approach scenarios only"
            else:
                rule = "applies to impact trials only (--kind impact-trial, or a file's kind)"
            raise InputError(f"{_FLAG_OF[field]}: {rule} ({where})")


def _model_options(options: tuple[str, ...]) -> dict[str, Any]:
    """The ``--option NAME=VALUE`` model switches, each checked as a model option."""
    from pydantic import ValidationError

    from quadimpact.inputs.model import ModelOptions

    parsed = _parse_options(options)
    try:
        ModelOptions.model_validate(parsed)
    except ValidationError as exc:
        raise input_error_from_validation(exc, "--option", model=ModelOptions) from None
    return parsed


def _validated(
    cls: Any,
    data: dict[str, Any],
    scenario_path: Path | None,
    given: Mapping[str, Any],
    parsed_params: Mapping[str, Any],
) -> Any:
    """The scenario of kind ``cls`` from ``data``; an error names what is wrong as given: a
    ``--param`` (of ``parsed_params``), the flag of a cross-field rule or of a field
    (``given``: field -> value), else the file's field."""
    from pydantic import ValidationError

    try:
        return cls.model_validate(data)
    except ValidationError as exc:
        loc = exc.errors()[0].get("loc", ())
        text = str(input_error_from_validation(exc, "", model=cls))
        name = text.removeprefix("controller_params.").partition(":")[0]
        if parsed_params and text.startswith("controller_params.") and name in parsed_params:
            raise InputError("--param: " + text.removeprefix("controller_params.")) from None
        if not loc and given:  # a cross-field rule (e.g. impact before final time)
            message = str(input_error_from_validation(exc))
            field = message.partition(":")[0]
            if field in given:
                message = _FLAG_OF[field] + message[len(field) :]
            raise InputError(message) from None
        if scenario_path is None or (loc and loc[0] in given):
            raise input_error_from_validation(exc, "", rename=_FLAG_OF, model=cls) from None
        raise input_error_from_validation(exc, str(scenario_path), model=cls) from None


def _describe(scenario: Any, vehicle_name: str) -> str:
    """One line saying what is about to be simulated."""
    kind = getattr(scenario, "kind", "")
    if kind == "wall-approach":
        what = (
            f"wall approach, heading {scenario.heading_deg:g} deg, inclination "
            f"{scenario.inclination_deg:g} deg, speed {scenario.speed_m_s:g} m/s"
        )
    elif kind == "impact-trial":
        what = (
            f"impact trial, roll {scenario.roll_deg:g} deg, pitch {scenario.pitch_deg:g} deg, "
            f"yaw {scenario.yaw_deg:g} deg, speed {scenario.speed_m_s:g} m/s"
        )
    else:
        what = f"flight with {len(scenario.surfaces)} surface(s)"
    return (
        f"simulating {what}; model {scenario.model}, controller {scenario.controller}, "
        f"vehicle {vehicle_name}"
    )


def _fmt(value: Any, scale: float = 1.0, unit: str = "", digits: int = 4) -> str:
    """A number for people: ``n/a`` for missing values."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return f"{value * scale:.{digits}g}{' ' + unit if unit else ''}"
    return str(value)


def _recovery_lines(summary: Mapping[str, Any]) -> list[str]:
    """Detection and stage 4 of a recovery run, for people."""
    t_detect = summary.get("t_detect_s")
    if t_detect is None:
        detected = "no detection"
    else:
        latency = summary.get("detection_latency_s")
        detected = f"at {_fmt(t_detect, unit='s')}"
        if summary.get("false_detection"):
            detected += " (before any contact: a false detection)"
        elif latency is not None:
            detected += f" ({_fmt(latency, 1000.0, 'ms', 3)} after the first contact)"
    t4 = summary.get("t_stage4_s")
    recovered = "stage 4 not reached" if t4 is None else f"stage 4 at {_fmt(t4, unit='s')}"
    if t4 is not None and summary.get("time_to_recover_s") is not None:
        recovered += f" ({_fmt(summary['time_to_recover_s'], unit='s')} after the detection)"
    low = summary.get("min_altitude_m")
    if t4 is not None and low is not None and low < 0:
        recovered += (
            f", but below ground level on the way (lowest altitude {_fmt(low, unit='m', digits=3)}"
            "; without a ground in the run it flew through where the ground would be: not a "
            "success in the recovery study)"
        )
    if summary.get("bumper_model_valid") is False:
        recovered += " (invalid: a bumper went deeper than its radius, beyond the bumper model)"
    return [f"detection      {detected}", f"recovered      {recovered}"]


def _response_type(summary: Mapping[str, Any], scenario: Any) -> str:
    """The response type with its meaning, or why there is none (docs/STUDIES.md 3)."""
    from quadimpact.simulation.response_types import RESPONSE_TYPE_MEANINGS, response_type_applies

    kind = getattr(scenario, "kind", None)
    if scenario is not None and not response_type_applies(kind, getattr(scenario, "ground", None)):
        words = {"impact-trial": "an impact trial", "flight": "a flight"}
        why = (
            words.get(kind, f"a {kind}")
            if kind != "wall-approach"
            else ("no ground, so no crash rule")
        )
        return f"n/a ({why}: the types A-D are defined for the wall approach with a crash rule)"
    rtype = summary.get("response_type")
    if not rtype:
        return "n/a"
    return f"{rtype} ({RESPONSE_TYPE_MEANINGS.get(str(rtype), '')})"


def format_summary(summary: Mapping[str, Any], out: Path, scenario: Any = None) -> str:
    """The short human summary printed after a run.

    Parameters
    ----------
    summary : mapping
        The run's summary (the content of summary.json).
    out : pathlib.Path
        The output folder.
    scenario : WallApproach or FlightScenario or ImpactTrial, optional
        The run's scenario: a response type is printed only where it is
        defined (a wall approach with a crash rule), with its meaning.

    Returns
    -------
    str
        Several lines.
    """
    from quadimpact.simulation.summary import episode_count

    status = str(summary.get("status", "n/a"))
    reason = summary.get("reason")
    leading = summary.get("leading_bumpers")
    if isinstance(leading, (list, tuple)):
        leading = ", ".join(str(b) for b in leading) or "none"
    crash = summary.get("crash_time_s")
    lines = [
        f"status         {status}" + (f" ({reason})" if reason else ""),
        f"delta_init     {_fmt(summary.get('delta_init_m'), 1000.0, 'mm')}",
        f"peak force     {_fmt(summary.get('peak_force_n'), unit='N')}",
        f"leading bumper {leading if leading is not None else 'n/a'}",
        f"response type  {_response_type(summary, scenario)}",
        f"episodes       {_fmt(episode_count(summary))}",
        f"crash time     {'no crash' if crash is None else _fmt(crash, unit='s')}",
    ]
    if summary.get("controller") == "recovery":
        lines += _recovery_lines(summary)
    for warning in summary.get("warnings") or []:
        lines.append(f"warning        {one_line(str(warning))}")
    lines.append(f"output         {out} ({_OUTPUT_FILES})")
    return "\n".join(lines)
