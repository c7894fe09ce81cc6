"""What users write, validated: vehicles, scenarios, surfaces, model options, input files.

* :mod:`~quadimpact.inputs.types`: validated number and array types;
* :mod:`~quadimpact.inputs.toml_files`: the TOML reader, the vehicle-path rule and
  the overrides of file values (flags, swept values);
* :mod:`~quadimpact.inputs.vehicle`: :class:`Vehicle`, the bundled vehicles
  (``vehicles/*.toml``);
* :mod:`~quadimpact.inputs.world`: :class:`Plane`, the one contact surface type;
* :mod:`~quadimpact.inputs.model`: :class:`ModelOptions` and the model variants;
* :mod:`~quadimpact.inputs.scenarios`: :class:`WallApproach`,
  :class:`FlightScenario` and scenario files.

Nothing here runs a simulation; problems are one-line
:class:`~quadimpact.errors.InputError`.
"""
