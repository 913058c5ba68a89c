"""Tests of `stringstab.sumo`: Eclipse SUMO runs (skipped without the extra).

One folder of the table in docs/architecture.md, "The tests".
"""
