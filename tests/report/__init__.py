"""Tests of `stringstab.report`: the run reports.

One folder of the table in docs/architecture.md, "The tests".
"""
