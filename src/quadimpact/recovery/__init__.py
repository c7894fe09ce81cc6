"""The recovery study: a Monte Carlo of impact trials, its figures and its report.

``quadimpact recovery`` (docs/RECOVERY.md section 8) samples impact trials
(``kind = "impact-trial"``) over the authors' distribution, runs them through
the sweep machinery (resumable, the same table on any number of cores) and
writes ``trials.parquet``, the figures and ``report.md``.

* :mod:`~quadimpact.recovery.spec`: the Monte Carlo spec
  (:class:`~quadimpact.recovery.spec.RecoveryStudy`, the authors'
  distribution, the trials' sampling), light enough for the command line to
  check a study's options before anything else loads;
* :mod:`~quadimpact.recovery.study`: the run
  (:func:`~quadimpact.recovery.study.run_study`) and the trials table;
* :mod:`~quadimpact.recovery.analysis`: pure functions of the table: the
  Wilson interval, bins, outcome classes, the numbers of the report;
* :mod:`~quadimpact.recovery.figures`: the figures;
* :mod:`~quadimpact.recovery.report`: ``report.md``;
* :mod:`~quadimpact.recovery.baselines`: nominal against recovery on the same
  conditions (the paper's Figure 4 grid, the Table III crashes without the
  motor power-off).
"""

__all__ = ["DEFAULT_N", "ESTIMATORS", "IMUS", "MODELS", "PRE_IMPACTS", "SENSORS"]

# The study's choices, here so that the command line needs nothing heavy.
#: Trials of a study by default.
DEFAULT_N = 10_000
#: Model variants of the study (docs/VARIANTS.md).
MODELS = ("default", "recovery-replica")
#: IMU presets (``quadimpact.inputs.sensors.IMU_PRESETS``).
IMUS = ("ideal", "noisy", "impact")
#: Presets of sensors (``quadimpact.inputs.sensors.SENSOR_PRESETS``).
SENSORS = ("ideal", "noisy", "impact", "indoor")
#: Built-in state estimators (``quadimpact.inputs.estimators``; a registered one is accepted too).
ESTIMATORS = ("ideal", "complementary", "ekf")
#: Pre-impact behaviours of the recovery controller in the study.
PRE_IMPACTS = ("spin-down", "hold")
