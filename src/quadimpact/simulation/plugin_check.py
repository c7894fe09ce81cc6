"""The pre-flight check of plug-ins: a controller or estimator checked before any run flies it.

A plug-in that raises, or has the wrong signature, would otherwise fail every
run of a sweep, each a failed row (docs/CONTROLLERS.md, "When a plug-in
fails"). :func:`check_plugins` looks at the plug-ins a scenario names and,
for each, in a few seconds (the step is compiled alone, not the loop):

1. **its signature**: a compiled step (``numba.njit``) taking
   ``step(t, meas, ctrl, mem, veh, dt, cmd)`` (a controller) or
   ``estimator(t, dt, meas, ecfg, est)`` (an estimator), 7 or 5 parameters;
2. **its packing**: the scenario prepared (parameters packed, the run checked);
3. **one tick**: the step compiled alone with bounds checking, called once
   on the records of the scenario's first control tick (the loop's own
   ``start``), and checked: it compiles for the loop's types, it raises
   nothing, indexes no slot past an array's end, returns nothing (it writes
   ``cmd``, or the estimate in ``est``) and leaves every rotor command, or
   the estimate, finite.

Any failure is a :class:`~quadimpact.simulation.plugin_kernel.PluginError`
(an ``InputError``: one line, exit status 2 from the CLI) naming the plug-in,
its function and the rule broken. A plug-in that raises only later (another
state, another trial) is caught when it does
(:mod:`~quadimpact.simulation.plugin_kernel`).
"""

from __future__ import annotations

import inspect
import math
from typing import Any

import numpy as np

from quadimpact.core import controller_slots as CTL
from quadimpact.core import estimator_slots as ESL
from quadimpact.core import layout as L
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.kernel import BUILTIN
from quadimpact.core.records import new_data, new_output
from quadimpact.errors import InputError, one_line
from quadimpact.inputs.controllers import controller_entry
from quadimpact.inputs.estimators import estimator_entry
from quadimpact.inputs.registry import is_compiled
from quadimpact.simulation.plugin_kernel import (
    WRITES,
    PluginError,
    PluginStep,
    step_name,
    typing_text,
)
from quadimpact.simulation.setup import prepare

__all__ = ["SIGNATURES", "check_first_run", "check_plugins", "check_signature"]

#: The step each kind of plug-in registers: its parameters, and what it writes.
SIGNATURES: dict[str, tuple[tuple[str, ...], str]] = {
    "controller": (("t", "meas", "ctrl", "mem", "veh", "dt", "cmd"), WRITES["controller"]),
    "estimator": (("t", "dt", "meas", "ecfg", "est"), WRITES["estimator"]),
}
#: The estimate's slots an estimator's step must leave finite.
_ESTIMATE = (
    ("ES_Q", ESL.ES_Q, 4),
    ("ES_VEL", ESL.ES_VEL, 3),
    ("ES_POS", ESL.ES_POS, 3),
    ("ES_BIAS", ESL.ES_BIAS, 3),
    ("ES_W", ESL.ES_W, 3),
)


def _plugins(scenario: Any) -> list[tuple[str, Any]]:
    """The plug-in entries a scenario names: ``[(kind, entry), ...]`` (built-ins left out)."""
    found = []
    for kind, lookup, name in (
        ("controller", controller_entry, getattr(scenario, "controller", None)),
        ("estimator", estimator_entry, getattr(scenario, "estimator", None)),
    ):
        if name is None:
            continue
        entry = lookup(name)
        if entry.step is not None:
            found.append((kind, entry))
    return found


def check_signature(kind: str, entry: Any) -> PluginStep:
    """Check a plug-in's step by its signature (cheap: nothing compiles).

    Parameters
    ----------
    kind : {"controller", "estimator"}
    entry : ControllerEntry or EstimatorEntry
        A registered plug-in (with a ``step``).

    Returns
    -------
    PluginStep
        How messages name it.

    Raises
    ------
    PluginError
        Not a ``numba.njit`` function, or not the step's parameters.
    """
    params, _ = SIGNATURES[kind]
    step = entry.step
    who = PluginStep(kind, entry.name, step_name(step))
    expected = f"{who.function}({', '.join(params)})"
    if not is_compiled(step):
        raise PluginError(f"{who}: must be compiled with numba.njit (got {type(step).__name__})")
    try:
        signature = inspect.signature(step.py_func)
    except (TypeError, ValueError):  # pragma: no cover (a Python function has one)
        raise PluginError(f"{who}: its signature cannot be read; expected {expected}") from None
    given = list(signature.parameters.values())
    positional = (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)
    if len(given) != len(params) or any(p.kind not in positional for p in given):
        raise PluginError(
            f"{who}: a {kind} step takes {len(params)} parameters, {expected} "
            f"(got {who.function}{signature})"
        )
    return who


def _standalone(step: Any) -> Any:
    """The step compiled alone, with bounds checking (an index past an array's end raises)."""
    from numba import njit

    options = {
        k: v
        for k, v in step.targetoptions.items()
        if k not in ("cache", "nopython", "_nrt", "boundscheck")
    }
    return njit(_nrt=True, boundscheck=True, **options)(step.py_func)


def _call(who: PluginStep, step: Any, args: tuple[Any, ...]) -> Any:
    """One call of the standalone step; its compile or run error as one line."""
    from numba.core.errors import NumbaError

    checked = _standalone(step)
    try:
        checked.compile(tuple(checked.typeof_pyval(a) for a in args))
    except NumbaError as exc:
        raise PluginError(
            f"{who}: does not compile for the loop's records: {typing_text(exc)}"
        ) from None
    try:
        checked(*args)
    except IndexError as exc:
        raise PluginError(
            f"{who}, called at the first tick, raised IndexError ({one_line(str(exc))}): it "
            "reads or writes a slot past the end of an array (a field that is not there)"
        ) from None
    except Exception as exc:
        raised = one_line(f"{type(exc).__name__}: {exc}".rstrip(": "))
        raise PluginError(
            f"{who}, called at the first tick, raised {raised}: a plug-in's step must not raise"
        ) from None
    return checked


def _returns_nothing(who: PluginStep, checked: Any, kind: str) -> None:
    """The step returns nothing: what it gives the loop, it writes into its arrays."""
    from numba.core import types

    for signature in checked.nopython_signatures:
        returned = signature.return_type
        if returned not in (types.none, types.void):
            _, writes = SIGNATURES[kind]
            raise PluginError(f"{who}: returns {returned}; a {kind} step returns nothing: {writes}")


def _first_tick(scenario: Any, plugins: list[tuple[PluginStep, Any]], kind_of: dict) -> None:
    """Prepare the scenario and call each step once on the records of its first tick."""
    try:
        # the built-in loop's start only: nothing compiles, and no run calls the plug-in
        # before its first tick is checked here (a wall approach's shooting would)
        setup = prepare(scenario, BUILTIN, plugins=False)
    except InputError:
        raise
    except Exception as exc:
        who = " and ".join(str(w) for w, _ in plugins)
        raise PluginError(
            f"{who}: a run with it cannot be prepared: {type(exc).__name__}: {one_line(str(exc))}"
        ) from None
    m = setup.model()
    m = m._replace(ctrl=m.ctrl.copy(), ecfg=m.ecfg.copy())
    m.ctrl[CTL.C_STEP] = m.ecfg[ESL.EC_STEP] = 0.0  # the loop's start calls no plug-in here
    d = new_data(m)
    o = new_output(m, 0, 16, contact_columns=False, rows=False)
    BUILTIN.start(m, d, o)  # the records at t0: the measurement, the initial estimate
    t0 = float(m.span[L.SPAN_T0])
    for who, entry in plugins:
        kind = kind_of[who]
        if kind == "controller":
            n = int(m.veh[VS.V_N_ROTORS])
            cmd = np.array(d.x[L.X_ROTOR : L.X_ROTOR + L.MAX_ROTORS])  # the rotors' speeds
            dt = float(m.opts[L.O_DT_CONTROL])
            checked = _call(who, entry.step, (t0, d.meas, m.ctrl, d.mem, m.veh, dt, cmd))
            _returns_nothing(who, checked, kind)
            bad = [j for j in range(n) if not math.isfinite(cmd[j])]
            if bad:
                raise PluginError(
                    f"{who}: left cmd[{bad[0]}] = {cmd[bad[0]]} at the first tick; "
                    "every rotor-speed command must be finite (rad/s)"
                )
        else:
            checked = _call(who, entry.step, (t0, 0.0, d.meas, m.ecfg, d.est))
            _returns_nothing(who, checked, kind)
            for name, start, width in _ESTIMATE:
                values = d.est[start : start + width]
                if not np.all(np.isfinite(values)):
                    raise PluginError(
                        f"{who}: left est[{name}] = {np.array2string(values, precision=3)} "
                        "at the first IMU sample; the estimate must be finite"
                    )


def check_plugins(scenario: Any, where: str = "") -> list[PluginStep]:
    """Check the plug-ins a validated scenario names, before any run (module docstring).

    Parameters
    ----------
    scenario : WallApproach, FlightScenario or ImpactTrial
        A run that flies the plug-ins (the first of a sweep or study).
    where : str, optional
        Put before the message (``"--controller: "``).

    Returns
    -------
    list of PluginStep
        The plug-ins checked (empty: built-ins only, nothing done).

    Raises
    ------
    PluginError
        One line naming the plug-in, its function and the rule.
    """
    try:
        found = _plugins(scenario)
        if not found:
            return []
        steps = [(check_signature(kind, entry), entry) for kind, entry in found]
        kind_of = {who: kind for (kind, _), (who, _) in zip(found, steps, strict=True)}
        _first_tick(scenario, steps, kind_of)
    except PluginError as exc:
        raise PluginError(f"{where}{exc}") from None
    return [who for who, _ in steps]


def check_first_run(spec: Any, where: str = "") -> list[PluginStep]:
    """:func:`check_plugins` on a sweep's first run (cheap when it names no plug-in).

    ``spec``: a ``quadimpact.sweep.SweepSpec`` (its ``scenario_dict(0)`` and
    ``where``), e.g. a study's sweep before it starts.
    """
    from quadimpact.inputs.scenarios import scenario_from_dict

    return check_plugins(scenario_from_dict(spec.scenario_dict(0), where=spec.where), where)
