"""The estimators' slots: their configuration ``ecfg`` and state ``est`` (no compiled code).

``core/estimators/__init__.py`` dispatches on ``ecfg[EC_KIND]`` and draws
the initial estimate from ``ecfg``'s errors (``EC_*``, :data:`NECFG`
numbers); every estimator writes the common estimate at the head of ``est``
(``ES_Q``... ``ES_GATED``, :data:`NEST` numbers), which ``write_estimate``
gives the controllers. A plug-in's parameters and state follow
(``EC_USER``, ``ES_USER``), then each built-in's own block (``EC_OWN``,
``ES_OWN``), which it declares in its module (``core/estimators/*.py``).
The declaration lives in this module, which imports no compiled code, so
that the packer (``packing/estimator_block.py``) loads no Numba. It lies
in ``core/``, not in ``core/estimators/``, whose package loads compiled
code. Every slot keeps the offset and the name it had in
``core/layout.py``.
"""

from quadimpact.core.block import Block

# ---- estimator ecfg (NECFG): what every estimator has (its kind, the initial estimate's
# error), a plug-in's block, then EC_OWN: the built-in estimator's own block, which it
# declares in its module (core/estimators/*.py; one estimator per run: the built-ins'
# blocks are alternatives over the same numbers)
_ecfg = Block("ecfg", "EC_")
EC_KIND = _ecfg.slot("EC_KIND")  # EST_*
EC_INIT_ATT = _ecfg.slot("EC_INIT_ATT", 3)  # initial attitude error, rotation vector (body), rad
EC_INIT_VEL = _ecfg.slot("EC_INIT_VEL", 3)  # initial velocity error, inertial, m/s
EC_INIT_POS = _ecfg.slot("EC_INIT_POS", 3)  # initial position error, inertial, m
EC_INIT_BIAS = _ecfg.slot("EC_INIT_BIAS", 3)  # initial gyro bias error, rad/s
EC_OBSERVER = _ecfg.slot("EC_OBSERVER")  # 1: out of the loop (controller, detector read the truth)
EC_INIT_EULER = _ecfg.slot("EC_INIT_EULER", 3)  # initial ZYX Euler errors (roll, pitch, yaw), rad
EC_INIT_BIAS_ZERO = _ecfg.slot("EC_INIT_BIAS_ZERO")  # 1: the gyro bias estimate starts at 0
N_USER_ECFG = 16
EC_USER = _ecfg.slot("EC_USER", N_USER_ECFG)  # a plug-in estimator's parameters
EC_STEP = _ecfg.slot("EC_STEP")  # a plug-in estimator's step: its entry address (as C_STEP)
N_OWN_ECFG = 48
EC_OWN = _ecfg.slot("EC_OWN", N_OWN_ECFG)  # a built-in's own block (core/estimators/*.py)
NECFG = _ecfg.end("NECFG")

# ---- estimator state est (NEST): the estimate after the latest IMU sample (what every
# estimator writes), a plug-in's state, then ES_OWN: a built-in's own state, declared in
# its module (core/estimators/*.py; alternatives over the same numbers, as EC_OWN)
_est = Block("est", "ES_")
ES_Q = _est.slot("ES_Q", 4)  # attitude estimate, body -> inertial, scalar first
ES_BIAS = _est.slot("ES_BIAS", 3)  # gyro bias estimate, rad/s
ES_VEL = _est.slot("ES_VEL", 3)  # CM velocity estimate, inertial, m/s
ES_POS = _est.slot("ES_POS", 3)  # CM position estimate, inertial, m
ES_W = _est.slot("ES_W", 3)  # estimated body rates (gyro minus bias) at the latest sample, rad/s
ES_T = _est.slot("ES_T")  # s, time of the latest sample processed (NaN: none)
ES_N = _est.slot("ES_N")  # samples processed
ES_GATED = _est.slot("ES_GATED")  # 1: the accelerometer correction was gated at the latest sample
N_USER_EST = 32
ES_USER = _est.slot("ES_USER", N_USER_EST)  # a plug-in estimator's own state
N_OWN_EST = 1920
ES_OWN = _est.slot("ES_OWN", N_OWN_EST)  # a built-in's own state (core/estimators/*.py)
NEST = _est.end("NEST")
