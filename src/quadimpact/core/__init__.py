"""Compiled core of quadimpact (Numba ``njit``).

One module per pipeline stage: ``rigid_body`` (Newton-Euler and quaternion
kinematics), ``rotors`` (thrust, reaction and gyroscopic moments),
``contact`` (bumper geometry and the Hunt-Crossley law), ``dynamics`` (the
right-hand side that sums them), ``control`` (the controllers and the
allocation), ``integrator`` (Dormand-Prince 5(4) with dense output),
``events`` (root location on the dense output) and ``run`` (the loop that
ties them). Array slots are named in ``layout``.
"""
