"""Training a recovery policy (``quadimpact train``): its trials, its reward, its optimiser.

* :mod:`~quadimpact.studies.training.trials`: the problem (vehicle, tasks, sensor
  set, seed) and its held-out trials, never the benchmark's;
* :mod:`~quadimpact.studies.training.flying`: flying prepared trials with candidate
  weights, and the reward (the benchmark's success);
* :mod:`~quadimpact.studies.training.trainer`: CMA-ES (``cma``, imported only here,
  when training), the resumable state, the learning curve and the policy file.
"""
