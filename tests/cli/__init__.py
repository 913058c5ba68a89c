"""Tests of `stringstab.cli`: each command end to end, its inputs, outputs, refusals, exit codes.

One folder of the table in docs/architecture.md, "The tests".
"""
