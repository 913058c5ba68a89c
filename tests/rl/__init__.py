"""Tests of `stringstab.rl`: the TD3 trainer, its environment, the evaluation.

One folder of the table in docs/architecture.md, "The tests".
"""
