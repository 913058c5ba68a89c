"""Tests of README and `docs/`: every example runs, the printed numbers and formulas, the site.

One folder of the table in docs/architecture.md, "The tests".
"""
