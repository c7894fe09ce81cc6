"""The controllers' settings ``ctrl``: declared with their owner (no compiled code).

``ctrl`` holds what the run tells its controller (``C_*``, :data:`NCTRL`
numbers): the controller's kind, its references, the vehicle's inverse
allocation and rotor range, the waypoint, then :data:`NPARAM` slots
(``C_PARAMS``) that each controller lays out for itself with a Block of
array ``"ctrl.params"`` (``core/controllers/``), the learned residual's
block (``C_POLICY``) and a plug-in's entry address (``C_STEP``).
``core/controllers/__init__.py`` dispatches on ``C_KIND`` and each law
reads its slots; the run loop reads the kind and the plug-in's address
to call the step. The declaration lives in this module, which imports no
compiled code, so that the packer (``packing/controller_block.py``) and
the policy file's checks load no Numba. It lies in ``core/``, not in
``core/controllers/``, whose package loads compiled code. Every slot keeps
the offset and the name it had in ``core/layout.py``.
"""

from quadimpact.core.block import Block
from quadimpact.core.layout import MAX_ROTORS

# ---- controller ctrl (NCTRL): a common head, then NPARAM slots that each
# controller lays out for itself with a Block of array "ctrl.params.<name>"
# (core/controllers/)
_ctrl = Block("ctrl", "C_")
C_KIND = _ctrl.slot("C_KIND")  # CTRL_*
C_H_REF = _ctrl.slot("C_H_REF")  # m, altitude reference
C_PHI_REF = _ctrl.slot("C_PHI_REF")  # rad
C_THETA_REF = _ctrl.slot("C_THETA_REF")  # rad
C_PSI_REF = _ctrl.slot("C_PSI_REF")  # rad
C_Z_REF = _ctrl.slot("C_Z_REF", 3)  # the reference attitude's body z axis, inertial (unit)
N_WRENCH = 4  # the allocation's wrench components: thrust, roll, pitch and yaw torques
C_N_ROTORS = _ctrl.slot("C_N_ROTORS")  # n, the vehicle's rotor count (the allocation's rows)
C_ALLOC_INV = _ctrl.slot("C_ALLOC_INV", N_WRENCH * MAX_ROTORS)  # (pseudo-)inverse allocation:
#   rotor j's row (its Omega_j^2 per thrust, tau_x, tau_y, tau_z) at C_ALLOC_INV + N_WRENCH j
C_OMEGA_MIN = _ctrl.slot("C_OMEGA_MIN")  # rad/s, the vehicle's rotor speed range
C_OMEGA_MAX = _ctrl.slot("C_OMEGA_MAX")
C_WAYPOINT_ON = _ctrl.slot("C_WAYPOINT_ON")  # 1: cascade-pid's position loop (a waypoint flight)
C_HOLD_POS = _ctrl.slot("C_HOLD_POS", 3)  # m, inertial NED: the position held before C_WAYPOINT_T
C_WAYPOINT = _ctrl.slot("C_WAYPOINT", 3)  # m, inertial NED: the waypoint (X, Y; Z is C_H_REF's)
C_WAYPOINT_T = _ctrl.slot("C_WAYPOINT_T")  # s, when the waypoint replaces the held position
C_POS_GAINS = _ctrl.slot("C_POS_GAINS", 4)  # K_p 1/s, K_v 1/s, v_max m/s, tilt_max rad
NPARAM = 64
C_PARAMS = _ctrl.slot("C_PARAMS", NPARAM)  # the controller's own parameters
NPOLICY = 1024
# the learned residual's network (its block at C_POLICY: core/controllers/residual.py; its
# file: inputs/policy_file.py): what it reads, what it corrects, its widest hidden layer
N_FEATURES = 24  # what the network reads (residual.features)
N_OUTPUTS = 3  # thrust, p_des, q_des corrections
MAX_HIDDEN = 32  # the widest hidden layer a policy may have (fits in NPOLICY)
F_SCALE_M_S2 = 16.0  # m/s^2, the features' scale of the accelerometer's specific force
T_CAP_S = 2.0  # s, the features' cap on the time since the detection (the latest fade end)
C_POLICY = _ctrl.slot("C_POLICY", NPOLICY)  # a learned residual on the recovery law (first
#   slot: its hidden width, 0 = none; core/controllers/residual.py lays out the rest)
C_STEP = _ctrl.slot("C_STEP")  # a plug-in's step: its entry address in this process (0: none;
#   core/plugin_call.py), set when a run is prepared, never packed from a scenario
NCTRL = _ctrl.end("NCTRL")
