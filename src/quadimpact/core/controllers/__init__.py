"""Built-in controllers, compiled, and the dispatch the cached run loop calls.

Interface of a controller step (built-in or plugged in, all Numba ``njit``)::

    step(t, meas, ctrl, mem, veh, dt, cmd) -> None

* ``t``: time of the control tick, s;
* ``meas``: the measurement record (layout ``MS_*``): the state estimate
  ``meas[MS_X:MS_X+NX]`` (today the true state), the latest IMU sample and the
  impact detector's verdict and wall-normal estimate;
* ``ctrl``: packed settings (layout ``C_*``): kind, references, the inverse
  allocation, the vehicle's rotor range, and the controller's own parameter
  block at ``C_PARAMS``;
* ``mem``: ``NMEM`` float64 slots the controller owns across ticks (zeroed at
  the start of a run); ``mem[MEM_STAGE]`` is reported as its stage;
* ``veh``: the packed vehicle; ``dt``: the control period, s;
* ``cmd``: the rotor-speed commands it writes, rad/s, one for each of the
  vehicle's ``n = int(veh[V_N_ROTORS])`` rotors.

The run loop then applies the generic speed and slew limits
(``actuators.apply_command``) and holds the command for the period.

One module per controller: ``paper.py``, ``cascade_pid.py``, ``recovery.py``;
each declares its parameter blocks and memory slots (``P_*`` and ``M_*`` in
``common.py``, shared by the PID laws; ``R_*``, ``RM_*`` in ``recovery.py``;
``PB_*`` in ``residual.py``), each a ``Block`` placed after the head it
extends. A new built-in is its module with its blocks, a branch below, and an
entry in the Python-side registry (``quadimpact.inputs.controllers``); a
controller that is not built in is registered there with its step
(``register_controller(name, step=...)``): the step is compiled alone and
the cached loop calls it by its address (``ctrl[C_STEP]``,
``core/plugin_call.py``).
"""

import numpy as np

from quadimpact.core.compiled import compiled
from quadimpact.core.controller_slots import C_KIND
from quadimpact.core.controllers.cascade_pid import cascade_pid_step
from quadimpact.core.controllers.paper import paper_step
from quadimpact.core.controllers.recovery import recovery_step
from quadimpact.core.layout import CTRL_CASCADE_PID, CTRL_PAPER, CTRL_RECOVERY, X_ROTOR
from quadimpact.core.sensors.measurement_slots import MS_X
from quadimpact.core.vehicle_slots import V_N_ROTORS


@compiled
def hold_step(
    t: float,
    meas: np.ndarray,
    ctrl: np.ndarray,
    mem: np.ndarray,
    veh: np.ndarray,
    dt: float,
    cmd: np.ndarray,
) -> None:
    """No controller: the rotors keep their current speeds."""
    for j in range(int(veh[V_N_ROTORS])):
        cmd[j] = meas[MS_X + X_ROTOR + j]


@compiled
def builtin_step(
    t: float,
    meas: np.ndarray,
    ctrl: np.ndarray,
    mem: np.ndarray,
    veh: np.ndarray,
    dt: float,
    cmd: np.ndarray,
) -> None:
    """Dispatch to the built-in controller named by ``ctrl[C_KIND]`` (``CTRL_*``)."""
    kind = int(ctrl[C_KIND])
    if kind == CTRL_PAPER:
        paper_step(t, meas, ctrl, mem, veh, dt, cmd)
    elif kind == CTRL_CASCADE_PID:
        cascade_pid_step(t, meas, ctrl, mem, veh, dt, cmd)
    elif kind == CTRL_RECOVERY:
        recovery_step(t, meas, ctrl, mem, veh, dt, cmd)
    else:
        hold_step(t, meas, ctrl, mem, veh, dt, cmd)
