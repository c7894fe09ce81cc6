"""Sensors: what a controller measures, as a stage of the compiled loop.

* ``measurement.py``: the measurement record a controller gets at a control
  tick (layout ``MS_*``) and its one writer of the state estimate;
* ``imu.py``: the IMU (specific force with the lever-arm terms, gyro; noise,
  bias, saturation, low-pass), sampled by the run loop on the dense output;
* ``detection.py``: impact detection from the IMU samples alone and the
  wall-normal estimate (with the estimated attitude).

A new sensor is a module here with a ``*_sample`` function called from the
loop where the IMU's is (``step.py``'s ``_sample_sensors``), its configuration
slots (a ``Block`` in ``layout.py``), its fields in the measurement record,
and its packing (``packing/sensor_block.py``); docs/ARCHITECTURE.md has the
recipe.
"""
