"""Tests of `stringstab.sweep`: Dask sweeps.

One folder of the table in docs/architecture.md, "The tests".
"""
