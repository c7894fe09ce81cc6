"""Validated inputs as the compiled core's flat arrays, one module per block.

The kernel reads numbers from fixed slots (``core/layout.py``); this layer
writes them. Each block has its module:

* :mod:`.vehicle_block`: ``veh`` (mass, inertia, rotors) and ``feat`` (the contact
  features), packed once per vehicle object; the allocation matrix;
* :mod:`.world_block`: ``shapes`` (planes, cylinders, boxes) and the packed shapes as
  plain data for ``scenario.json`` (and back);
* :mod:`.controller_block`: ``ctrl`` (the controller's head, references, parameter
  block, a waypoint flight's slots), a packer per built-in controller;
* :mod:`.options_block`: ``opts`` (model switches, crash rule, integrator settings)
  and a power-off schedule's rates;
* :mod:`.sensor_block`: ``scfg`` (the IMU, the impact detector) and the IMU's
  seeded noise;
* :mod:`.estimator_block`: the added sensors' slots and noise, ``ecfg`` (the
  estimator), a packer per built-in estimator;
* :mod:`.constants`: the control rate, units and integrator defaults every
  block uses.

The layer sits between ``inputs`` (validated objects) and ``simulation``
(which assembles a run from the blocks); it imports neither ``simulation``
nor anything above it (``tests/test_layering.py``). Nothing here is imported
by this ``__init__``: import the module you need.
"""
