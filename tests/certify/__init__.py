"""Tests of `stringstab.certify`: every certificate (continuous, θ_r, sampled, multi-rate, boxes,
strings) against independent truth, the one way in, the verdicts.

One folder of the table in docs/architecture.md, "The tests".
"""
