"""The recovery benchmark (``quadimpact benchmark``, docs/BENCHMARK.md)."""
