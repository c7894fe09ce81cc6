"""The recovery study: a Monte Carlo of impact trials, its figures and its report.

``quadimpact recovery`` (docs/RECOVERY.md section 8) samples impact trials
(``kind = "impact-trial"``) over the authors' distribution, runs them through
the sweep machinery (resumable, the same table on any number of cores) and
writes ``trials.parquet``, the figures and ``report.md``.

* :mod:`~quadimpact.studies.recovery.recovery_spec`: the Monte Carlo spec
  (:class:`~quadimpact.studies.recovery.recovery_spec.RecoveryStudy`, the authors'
  distribution, the trials' sampling), light enough for the command line to
  check a study's options before anything else loads;
* :mod:`~quadimpact.studies.recovery.recovery_study`: the run
  (:func:`~quadimpact.studies.recovery.recovery_study.run_study`) and the trials table;
* :mod:`~quadimpact.studies.recovery.recovery_analysis`: pure functions of the table: the
  Wilson interval, bins, outcome classes, the numbers of the report;
* :mod:`~quadimpact.studies.recovery.recovery_figures`: the figures;
* :mod:`~quadimpact.studies.recovery.recovery_report`: ``report.md``;
* :mod:`~quadimpact.studies.recovery.baselines`: nominal against recovery on the same
  conditions (the paper's Figure 4 grid, the Table III crashes without the
  motor power-off).
"""

__all__ = ["DEFAULT_N", "ESTIMATORS", "IMUS", "MODELS", "PRE_IMPACTS", "SENSORS"]

# The study's choices, here so that the command line needs nothing heavy.
#: Trials of a study by default.
DEFAULT_N = 10_000
#: Model variants of the study (docs/VARIANTS.md).
MODELS = ("default", "classic", "recovery-replica", "pole-replica")
#: IMU presets (``quadimpact.inputs.sensors.IMU_PRESETS``).
IMUS = ("ideal", "noisy", "impact", "authors-2016")
#: Presets of sensors (``quadimpact.inputs.sensors.SENSOR_PRESETS``).
SENSORS = ("ideal", "noisy", "impact", "indoor", "onboard", "authors-2016")
#: Built-in state estimators (``quadimpact.inputs.estimators``; a registered one is accepted too).
ESTIMATORS = ("ideal", "complementary", "ekf", "ekf-additive", "nav-ekf")
#: Pre-impact behaviours of the recovery controller in the study.
PRE_IMPACTS = ("spin-down", "hold")
