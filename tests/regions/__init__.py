"""Tests of `stringstab.regions`: the stability-region maps.

One folder of the table in docs/architecture.md, "The tests".
"""
