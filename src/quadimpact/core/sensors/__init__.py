"""Sensors: what a controller measures, as a stage of the compiled loop.

* ``record.py``: the measurement record a controller gets at a control tick
  (layout ``MS_*``): the state estimate (today an ideal estimator: the true
  state) and the latest IMU sample and detection verdict;
* ``imu.py``: the IMU (specific force with the lever-arm terms, gyro; noise,
  bias, saturation, low-pass), sampled by the run loop on the dense output;
* ``detection.py``: impact detection from the IMU samples alone and the
  wall-normal estimate.

A new sensor is a module here with a ``*_sample`` function called from
``step.py`` where the IMU's is, its configuration slots in ``layout``, and its
fields in the measurement record.
"""
