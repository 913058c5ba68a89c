"""Tests of `stringstab.io`: gain and log readers, result files, output folders.

One folder of the table in docs/architecture.md, "The tests".
"""
