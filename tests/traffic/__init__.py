"""Tests of `stringstab.traffic`: the platoon simulator, radio, sensors, metrics, leaders.

One folder of the table in docs/architecture.md, "The tests".
"""
