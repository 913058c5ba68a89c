"""Tests of `stringstab.tuning`: the gain repair (region growing, projection).

One folder of the table in docs/architecture.md, "The tests".
"""
