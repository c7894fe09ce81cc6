"""A flight toward a waypoint: the ``cascade-pid`` controller's position loop.

A flight scenario's ``[waypoint]`` makes the ``cascade-pid`` controller (on
its own, or as the ``recovery`` controller's pre-impact behaviour) hold its
start position, then fly to the waypoint from ``time_s`` on, its altitude and
heading held by their loops (docs/CONTROLLERS.md, "Waypoint flight")::

    [waypoint]
    x_m = 2.5
    y_m = 0.0
    time_s = 4.0
"""

from __future__ import annotations

from pydantic import BaseModel, Field

from quadimpact.inputs.types import MODEL_CONFIG, Real

__all__ = ["Waypoint"]


class Waypoint(BaseModel):
    """A horizontal waypoint and the position loop that flies to it.

    Attributes
    ----------
    x_m, y_m : float
        The waypoint, inertial NED, m (the altitude is the altitude reference).
    time_s : float
        Until this time the loop holds the start position (a hover), s.
    kp_1_s : float
        Position error to velocity reference, 1/s.
    kv_1_s : float
        Velocity error to acceleration reference, 1/s.
    v_max_m_s : float
        Horizontal speed limit of the velocity reference, m/s.
    tilt_max_deg : float
        Tilt limit: the acceleration reference at most ``g tan(tilt_max)``, deg.
    """

    model_config = MODEL_CONFIG

    x_m: Real = Field(..., description="Waypoint X, inertial NED, m.")
    y_m: Real = Field(0.0, description="Waypoint Y, inertial NED, m.")
    time_s: Real = Field(0.0, ge=0, description="Hold the start position until this time, s.")
    kp_1_s: Real = Field(1.0, ge=0, description="Position -> velocity gain, 1/s.")
    kv_1_s: Real = Field(2.0, ge=0, description="Velocity -> acceleration gain, 1/s.")
    v_max_m_s: Real = Field(2.5, gt=0, description="Speed limit, m/s.")
    tilt_max_deg: Real = Field(30.0, gt=0, lt=80, description="Tilt limit, deg.")
