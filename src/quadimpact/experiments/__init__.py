"""The paper's experiments (section V): the seven crashes, flight logs, comparisons."""
