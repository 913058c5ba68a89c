"""Tests of `stringstab.mixed`: mixed strings and `stringstab platoon`.

One folder of the table in docs/architecture.md, "The tests".
"""
