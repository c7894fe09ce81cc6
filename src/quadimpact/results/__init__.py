"""What a run produced, and its files and figures.

* :mod:`~quadimpact.results.result`: :class:`SimulationResult`, ``read_result``;
* :mod:`~quadimpact.results.files`: ``summary.json``, ``episodes.csv``,
  ``timeseries.parquet`` (their columns and units), the atomic file writer and
  the JSON converter used everywhere;
* :mod:`~quadimpact.results.figures`: Figures 5 and 6, the type map, the shared
  figure helpers;
* :mod:`~quadimpact.results.costs`: what a run cost (CPU time in the compiled
  loop and in the whole run: the summary's ``cost``) and the ratio studies print.

Results do not depend on the simulator: ``quadimpact.simulation`` builds them.
"""
