"""Tests of `stringstab.identify`: recorded platoons, the fitted laws, their certificates.

One folder of the table in docs/architecture.md, "The tests".
"""
