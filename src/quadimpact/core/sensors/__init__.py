"""Sensors: what a controller measures, as a stage of the compiled loop.

* ``measurement.py``: the measurement record a controller gets at a control
  tick (layout ``MS_*``) and its one writer of the state estimate;
* ``imu.py``: the IMU (specific force with the lever-arm terms, gyro; noise,
  bias, saturation, low-pass), sampled by the run loop on the dense output;
* ``detection.py``: impact detection from the IMU samples alone and the
  wall-normal estimate (with the estimated attitude);
* sensor components (``component.py``, ``registry.py``): the barometer,
  the rangefinder, the optical-flow camera, the magnetometer and the pose
  sensor, each one module registered in one line.

A new sensor is a component: docs/ARCHITECTURE.md 10 and
docs/howto/add-a-sensor.md have the checklist.
"""
