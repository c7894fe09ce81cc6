"""The pole study (docs/OBSTACLES.md 3): the Navi against a pole, with and without recovery.

The authors' grid: pitch 0 to -45 deg in 1-deg steps (46 values) times the
sideways offset from the pole's centre line, -0.35 to 0.35 m in 0.01 m steps
(71 values), each trial flown twice: by a baseline without recovery (the
``paper`` controller holding the initial attitude and the 2 m altitude) and
by the ``recovery`` controller flying that same baseline until the
detection. Outcome: the height lost over the 3-s run, less than 2 m a
success. :mod:`quadimpact.studies.pole.pole_study` runs it on the resumable sweep
machinery; :mod:`quadimpact.studies.pole.pole_figures` draws the maps and the success by
pitch band; :mod:`quadimpact.studies.pole.pole_report` writes ``report.md``.
"""

from quadimpact.studies.pole.pole_study import PoleResult, PoleStudy, run_pole_study

__all__ = ["PoleResult", "PoleStudy", "run_pole_study"]
