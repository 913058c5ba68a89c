"""Tests of `stringstab.plots`: every figure.

One folder of the table in docs/architecture.md, "The tests".
"""
